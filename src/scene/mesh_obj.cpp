// Wavefront OBJ reader for the subset covrast renders: "v x y z [r g b]" and "f" with any index
// form (i, i/t, i//n, i/t/n; negative = relative to the vertices defined so far). Polygons become
// the fan (0, k, k + 1), k = 1 .. n - 2, triangles in file order. Everything else (vt, vn, o, g,
// s, usemtl, mtllib, l, ...) is ignored, so a missing .mtl file never matters.
#include "scene/scene_internal.hpp"

#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

namespace covrast::detail {
namespace {

constexpr std::size_t kMaxVertices = std::numeric_limits<std::uint32_t>::max();

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// Splits one line into whitespace-separated tokens.
class Tokens {
 public:
  explicit Tokens(std::string_view line) : rest_(line) {}
  bool next(std::string_view& token) {
    std::size_t begin = 0;
    while (begin < rest_.size() && is_blank(rest_[begin])) ++begin;
    std::size_t end = begin;
    while (end < rest_.size() && !is_blank(rest_[end])) ++end;
    token = rest_.substr(begin, end - begin);
    rest_.remove_prefix(end);
    return !token.empty();
  }

 private:
  std::string_view rest_;
};

/// A token as it may appear in a one-line message: printable ASCII, shortened.
std::string printable(std::string_view token) {
  constexpr std::size_t kMaxShown = 32;
  std::string out;
  for (std::size_t i = 0; i < token.size() && i < kMaxShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    out += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  if (token.size() > kMaxShown) out += "...";
  return out;
}

[[noreturn]] void fail(const std::string& name, std::size_t line, const std::string& message) {
  throw InputError(name + ":" + std::to_string(line) + ": " + message);
}

/// from_chars rejects a leading '+', which some exporters write.
std::string_view strip_plus(std::string_view token) {
  if (token.size() >= 2 && token[0] == '+' && token[1] != '-' && token[1] != '+') {
    token.remove_prefix(1);
  }
  return token;
}

bool parse_double(std::string_view token, double& value) {
  token = strip_plus(token);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ptr != end) return false;
  if (ec == std::errc::result_out_of_range) {
    // Overflow must become +-inf (and the triangle is then dropped), underflow 0: strtod does
    // exactly that, from_chars leaves the value untouched.
    const std::string copy(token);
    value = std::strtod(copy.c_str(), nullptr);
    return true;
  }
  return ec == std::errc();
}

bool parse_integer(std::string_view token, long long& value) {
  token = strip_plus(token);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end;
}

std::string out_of_range(long long index, std::size_t vertex_count) {
  return "face index " + std::to_string(index) + " out of range (" + std::to_string(vertex_count) +
         " vertices)";
}

}  // namespace

LoadedMesh parse_obj(std::string_view text, const std::string& display_name) {
  auto mesh = std::make_shared<MeshData>();
  mesh->source = display_name;
  std::vector<glm::vec3> colors_srgb;  // one per vertex, white where the file gives none
  bool any_color = false;
  std::vector<std::uint32_t> corners;
  // Positive indices may point past the vertices read so far (OBJ does not forbid forward
  // references); the largest one is checked against the final count at the end.
  long long max_forward_index = 0;
  std::size_t max_forward_line = 0;

  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark
  std::size_t pos = 0;
  std::size_t line_no = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) {
      line = line.substr(0, hash);
    }
    Tokens tokens(line);
    std::string_view keyword;
    if (!tokens.next(keyword)) continue;

    if (keyword == "v") {
      double values[6] = {0.0, 0.0, 0.0, 1.0, 1.0, 1.0};
      int count = 0;
      std::string_view token;
      while (tokens.next(token)) {
        double value = 0.0;
        if (!parse_double(token, value))
          fail(display_name, line_no, "bad number '" + printable(token) + "'");
        if (count < 6) values[count] = value;
        ++count;
      }
      if (count < 3) fail(display_name, line_no, "vertex needs x y z");
      if (mesh->positions.size() >= kMaxVertices) fail(display_name, line_no, "too many vertices");
      mesh->positions.emplace_back(static_cast<float>(values[0]), static_cast<float>(values[1]),
                                   static_cast<float>(values[2]));
      // "v x y z w" carries a rational weight (meaningless for polygons); 6 or more numbers
      // are "v x y z r g b" with sRGB display values.
      if (count >= 6) any_color = true;
      colors_srgb.emplace_back(static_cast<float>(values[3]), static_cast<float>(values[4]),
                               static_cast<float>(values[5]));
      if (count < 6) colors_srgb.back() = glm::vec3(1.0f);
    } else if (keyword == "f") {
      corners.clear();
      const auto vertex_count = static_cast<long long>(mesh->positions.size());
      std::string_view token;
      while (tokens.next(token)) {
        const std::string_view index_text = token.substr(0, token.find('/'));
        long long index = 0;
        if (!parse_integer(index_text, index)) {
          fail(display_name, line_no, "bad face vertex '" + printable(token) + "'");
        }
        long long resolved = 0;
        if (index > 0) {
          if (index > static_cast<long long>(kMaxVertices)) {
            fail(display_name, line_no, out_of_range(index, mesh->positions.size()));
          }
          resolved = index - 1;
          if (index > vertex_count && index > max_forward_index) {
            max_forward_index = index;
            max_forward_line = line_no;
          }
        } else if (index < 0) {
          resolved = vertex_count + index;
          if (resolved < 0)
            fail(display_name, line_no, out_of_range(index, mesh->positions.size()));
        } else {
          fail(display_name, line_no, out_of_range(index, mesh->positions.size()));
        }
        corners.push_back(static_cast<std::uint32_t>(resolved));
      }
      if (corners.size() < 3) {
        fail(display_name, line_no,
             "face needs at least 3 vertices, got " + std::to_string(corners.size()));
      }
      for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        mesh->indices.push_back(corners[0]);
        mesh->indices.push_back(corners[k]);
        mesh->indices.push_back(corners[k + 1]);
      }
    }
  }
  if (max_forward_index > static_cast<long long>(mesh->positions.size())) {
    fail(display_name, max_forward_line, out_of_range(max_forward_index, mesh->positions.size()));
  }

  if (any_color) {
    mesh->colors_linear.reserve(colors_srgb.size());
    for (const glm::vec3& c : colors_srgb) {
      mesh->colors_linear.emplace_back(srgb_to_linear(c.r), srgb_to_linear(c.g),
                                       srgb_to_linear(c.b));
    }
  }
  LoadedMesh loaded;
  loaded.dropped_nonfinite_triangles = drop_nonfinite_triangles(*mesh);
  analyze_mesh_topology(*mesh);  // once per file: instances share the result
  loaded.data = std::move(mesh);
  return loaded;
}

}  // namespace covrast::detail
