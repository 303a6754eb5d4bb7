// Wavefront OBJ reader for the subset covrast renders: "v x y z [r g b]", "vn x y z" and "f"
// with any index form (i, i/t, i//n, i/t/n; negative = relative to the vertices or normals
// defined so far). Polygons become the fan (0, k, k + 1), k = 1 .. n - 2, triangles in file
// order; normals become corner normals (MeshData::corner_normals). Everything else (vt, o, g,
// s, usemtl, mtllib, l, ...) is ignored, so a missing .mtl file never matters.
#include "scene/scene_internal.hpp"

#include <algorithm>
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

/// The normal index of a face corner "i/t/n" or "i//n", 1-based (negative = relative to the
/// normals read so far), resolved to 0-based but not yet checked against the count: normals
/// may be defined after the faces that use them, like vertices. kNoNormal when the corner
/// gives none.
constexpr long long kNoNormal = std::numeric_limits<long long>::min();
long long corner_normal(std::string_view token, std::size_t normal_count, const std::string& name,
                        std::size_t line) {
  const std::size_t first = token.find('/');
  if (first == std::string_view::npos) return kNoNormal;
  const std::size_t second = token.find('/', first + 1);
  if (second == std::string_view::npos) return kNoNormal;
  long long index = 0;
  if (!parse_integer(token.substr(second + 1), index)) {
    fail(name, line, "bad face vertex '" + printable(token) + "'");
  }
  // 0 and indices before the first normal can never exist: -1 stands for "missing".
  if (index > 0) return index - 1;
  const long long resolved = static_cast<long long>(normal_count) + index;
  return index < 0 && resolved >= 0 ? resolved : -1;
}

/// Corner normals from the resolved indices; a reference to a normal that does not exist
/// gives no normal there (that face uses its face normal), counted in a warning.
void resolve_corner_normals(const std::vector<long long>& refs,
                            const std::vector<glm::vec3>& normals, const std::string& name,
                            LoadedMesh& loaded) {
  std::size_t missing = 0;
  std::vector<glm::vec3>& out = loaded.data->corner_normals;
  out.assign(refs.size(), glm::vec3(0.0f));
  for (std::size_t c = 0; c < refs.size(); ++c) {
    if (refs[c] == kNoNormal) continue;
    if (refs[c] >= 0 && static_cast<std::size_t>(refs[c]) < normals.size()) {
      out[c] = normals[static_cast<std::size_t>(refs[c])];
    } else {
      ++missing;
    }
  }
  if (missing > 0) {
    loaded.warnings.push_back(name + ": " + std::to_string(missing) +
                              " face corners reference normals that do not exist (" +
                              std::to_string(normals.size()) + " vn lines); face normals used");
  }
}
}  // namespace

LoadedMesh parse_obj(std::string_view text, const std::string& display_name) {
  auto mesh = std::make_shared<MeshData>();
  mesh->source = display_name;
  std::vector<glm::vec3> colors_srgb;  // one per vertex, white where the file gives none
  bool any_color = false;
  std::vector<std::uint32_t> corners;
  std::vector<glm::vec3> normals;         // vn lines, in file order
  std::vector<long long> corner_normals;  // of the current face: see corner_normal()
  std::vector<long long> normal_refs;     // per triangle corner, as corner_normals
  bool any_face_normal = false;
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
    } else if (keyword == "vn") {
      double values[3] = {0.0, 0.0, 0.0};
      int count = 0;
      std::string_view token;
      while (tokens.next(token)) {
        if (count < 3 && !parse_double(token, values[count])) {
          fail(display_name, line_no, "bad number '" + printable(token) + "'");
        }
        ++count;
      }
      if (count != 3) fail(display_name, line_no, "normal needs x y z");
      normals.emplace_back(static_cast<float>(values[0]), static_cast<float>(values[1]),
                           static_cast<float>(values[2]));
    } else if (keyword == "f") {
      corners.clear();
      corner_normals.clear();
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
        corner_normals.push_back(corner_normal(token, normals.size(), display_name, line_no));
      }
      if (corners.size() < 3) {
        fail(display_name, line_no,
             "face needs at least 3 vertices, got " + std::to_string(corners.size()));
      }
      const bool face_normals = std::any_of(corner_normals.begin(), corner_normals.end(),
                                            [](long long n) { return n != kNoNormal; });
      if (face_normals && !any_face_normal) {
        // Faces before the first with normals: none (the face normal).
        normal_refs.assign(mesh->indices.size(), kNoNormal);
        any_face_normal = true;
      }
      for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        for (const std::size_t c : {std::size_t(0), k, k + 1}) {
          mesh->indices.push_back(corners[c]);
          if (any_face_normal) normal_refs.push_back(corner_normals[c]);
        }
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
  loaded.data = mesh;
  if (any_face_normal) resolve_corner_normals(normal_refs, normals, display_name, loaded);
  loaded.dropped_nonfinite_triangles = drop_nonfinite_triangles(*mesh);
  analyze_mesh_topology(*mesh);  // once per file: instances share the result
  loaded.data = std::move(mesh);
  return loaded;
}

}  // namespace covrast::detail
