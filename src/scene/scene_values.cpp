// Scene file loader, the format's values (SceneReader, scene_reader.hpp): numbers, vectors,
// colours and the model matrix, each checked with a one-line InputError naming the file and
// the JSON key. sRGB display colours become linear light here.
#include "scene/scene_reader.hpp"

#include <cmath>
#include <cstddef>
#include <string>

namespace covrast::detail {

[[noreturn]] void fail(const std::string& file, const std::string& key,
                       const std::string& message) {
  throw InputError(file + ": " + key + ": " + message);
}

/// A JSON value shortened for a one-line message.
std::string shown(const json& value) {
  constexpr std::size_t kMaxShown = 40;
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > kMaxShown) text = text.substr(0, kMaxShown) + "...";
  return text;
}

const json& SceneReader::required(const json& object, const char* key,
                                  const std::string& path) const {
  const auto it = object.find(key);
  if (it == object.end()) fail(file_, path, "missing");
  return *it;
}

const json& SceneReader::require_object(const json& value, const std::string& path) const {
  if (!value.is_object()) fail(file_, path, "expected an object, got " + shown(value));
  return value;
}

double SceneReader::number(const json& value, const std::string& path) const {
  if (!value.is_number()) fail(file_, path, "expected a number, got " + shown(value));
  const double x = value.get<double>();
  if (!std::isfinite(x)) fail(file_, path, "expected a finite number, got " + shown(value));
  return x;
}

/// A number in [lo, hi].
double SceneReader::number_in(const json& value, const std::string& path, double lo,
                              double hi) const {
  const double x = number(value, path);
  if (x < lo || x > hi) {
    fail(file_, path,
         "expected a number in " + number_text(lo) + ".." + number_text(hi) + ", got " +
             shown(value));
  }
  return x;
}

int SceneReader::image_side(const json& root, const char* key) const {
  const json& value = required(root, key, key);
  // Unsigned first: a huge unsigned value must not wrap into range as a signed one.
  bool in_range = false;
  if (value.is_number_unsigned()) {
    const auto side = value.get<unsigned long long>();
    in_range = side >= 1 && side <= static_cast<unsigned long long>(kMaxImageSide);
  } else if (value.is_number_integer()) {
    const auto side = value.get<long long>();
    in_range = side >= 1 && side <= kMaxImageSide;
  }
  if (!in_range) {
    fail(file_, key,
         "expected an integer in 1.." + std::to_string(kMaxImageSide) + ", got " + shown(value));
  }
  return static_cast<int>(value.get<long long>());
}

glm::dvec3 SceneReader::vec3(const json& value, const std::string& path) const {
  if (!value.is_array() || value.size() != 3) {
    fail(file_, path, "expected [x,y,z], got " + shown(value));
  }
  return {number(value[0], path + "[0]"), number(value[1], path + "[1]"),
          number(value[2], path + "[2]")};
}

/// [r,g,b] sRGB display values in 0..1 -> linear light.
glm::vec3 SceneReader::srgb_color(const json& value, const std::string& path) const {
  if (!value.is_array() || value.size() != 3) {
    fail(file_, path, "expected [r,g,b], got " + shown(value));
  }
  glm::vec3 linear(0.0f);
  for (int c = 0; c < 3; ++c) {
    const std::string component_path = path + "[" + std::to_string(c) + "]";
    const double x = number(value[static_cast<std::size_t>(c)], component_path);
    if (x < 0.0 || x > 1.0) {
      fail(file_, component_path,
           "colour component must be in 0..1, got " + shown(value[static_cast<std::size_t>(c)]));
    }
    linear[c] = srgb_to_linear(static_cast<float>(x));
  }
  return linear;
}

/// [r,g,b] of linear light, each finite and >= 0 (light colours may exceed 1).
glm::vec3 SceneReader::linear_color(const json& value, const std::string& path) const {
  if (!value.is_array() || value.size() != 3) {
    fail(file_, path, "expected [r,g,b], got " + shown(value));
  }
  glm::vec3 color(0.0f);
  for (std::size_t c = 0; c < 3; ++c) {
    const std::string component_path = path + "[" + std::to_string(c) + "]";
    const double x = number(value[c], component_path);
    if (x < 0.0) fail(file_, component_path, "must be >= 0, got " + shown(value[c]));
    color[static_cast<int>(c)] = static_cast<float>(x);
  }
  return color;
}

/// A non-zero direction, normalised.
glm::dvec3 SceneReader::direction(const json& value, const std::string& path) const {
  const glm::dvec3 d = vec3(value, path);
  const double length = glm::length(d);
  if (!(length > 0.0) || !std::isfinite(length)) fail(file_, path, "must not be zero");
  return d / length;
}

/// Row-major: 4 rows of 4 numbers, or 16 numbers in row order; translation in the last
/// column. Stored column-major (GLM): model[col][row].
glm::dmat4 SceneReader::model_matrix(const json& value, const std::string& path) const {
  double rows[4][4] = {};
  if (value.is_array() && value.size() == 16) {
    for (std::size_t i = 0; i < 16; ++i) {
      rows[i / 4][i % 4] = number(value[i], path + "[" + std::to_string(i) + "]");
    }
  } else if (value.is_array() && value.size() == 4) {
    for (std::size_t r = 0; r < 4; ++r) {
      const std::string row_path = path + "[" + std::to_string(r) + "]";
      if (!value[r].is_array() || value[r].size() != 4) {
        fail(file_, row_path, "expected a row of 4 numbers, got " + shown(value[r]));
      }
      for (std::size_t c = 0; c < 4; ++c) {
        rows[r][c] = number(value[r][c], row_path + "[" + std::to_string(c) + "]");
      }
    }
  } else {
    fail(file_, path,
         "expected 4 rows of 4 numbers or 16 numbers (row-major), got " + shown(value));
  }
  if (rows[3][0] != 0.0 || rows[3][1] != 0.0 || rows[3][2] != 0.0 || rows[3][3] != 1.0) {
    fail(file_, path, "last row must be [0,0,0,1] (affine transform)");
  }
  glm::dmat4 model(1.0);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) model[c][r] = rows[r][c];
  }
  return model;
}

std::string SceneReader::number_text(double x) {
  std::string text = std::to_string(x);
  while (text.back() == '0') text.pop_back();
  if (text.back() == '.') text.pop_back();
  return text;
}

}  // namespace covrast::detail
