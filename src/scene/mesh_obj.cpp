// Wavefront OBJ reader for the subset covrast renders: "v x y z [r g b]", "vn x y z" and "f"
// with any index form (i, i/t, i//n, i/t/n; negative = relative to the vertices or normals
// defined so far). Polygons become the fan (0, k, k + 1), k = 1 .. n - 2, triangles in file
// order; normals become corner normals (MeshData::corner_normals), "vt u [v [w]]" corner UVs
// (MeshData::corner_texcoords[0], v flipped to glTF's convention: OBJ's v = 0 is the bottom
// of the image). Everything else (o, g, s, usemtl, mtllib, l, ...) is ignored, so a missing
// .mtl file never matters.
#include "scene/scene_internal.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
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

/// The texture-coordinate index of a face corner "i/t" or "i/t/n", 1-based (negative =
/// relative to the vt lines read so far), resolved like corner_normal; kNoNormal when the
/// corner gives none ("i" or "i//n").
long long corner_texcoord(std::string_view token, std::size_t texcoord_count,
                          const std::string& name, std::size_t line) {
  const std::size_t first = token.find('/');
  if (first == std::string_view::npos) return kNoNormal;
  const std::size_t second = token.find('/', first + 1);
  const std::string_view text = token.substr(
      first + 1, second == std::string_view::npos ? std::string_view::npos : second - first - 1);
  if (text.empty()) return kNoNormal;
  long long index = 0;
  if (!parse_integer(text, index)) fail(name, line, "bad face vertex '" + printable(token) + "'");
  if (index > 0) return index - 1;
  const long long resolved = static_cast<long long>(texcoord_count) + index;
  return index < 0 && resolved >= 0 ? resolved : -1;
}

/// Corner UVs from the resolved indices (zero where a corner has none); references to vt
/// lines that do not exist are counted in a warning.
void resolve_corner_texcoords(const std::vector<long long>& refs,
                              const std::vector<glm::vec2>& texcoords, const std::string& name,
                              LoadedMesh& loaded) {
  std::size_t missing = 0;
  std::vector<glm::vec2>& out = loaded.data->corner_texcoords[0];
  out.assign(refs.size(), glm::vec2(0.0f));
  for (std::size_t c = 0; c < refs.size(); ++c) {
    if (refs[c] == kNoNormal) continue;
    if (refs[c] >= 0 && static_cast<std::size_t>(refs[c]) < texcoords.size()) {
      out[c] = texcoords[static_cast<std::size_t>(refs[c])];
    } else {
      ++missing;
    }
  }
  if (missing > 0) {
    loaded.warnings.push_back(name + ": " + std::to_string(missing) +
                              " face corners reference texture coordinates that do not exist (" +
                              std::to_string(texcoords.size()) + " vt lines); (0, 0) used");
  }
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

/// One OBJ file's statements, read line by line into a MeshData.
class ObjParser {
 public:
  explicit ObjParser(const std::string& name) : name_(name), mesh_(std::make_shared<MeshData>()) {
    mesh_->source = name;
  }

  /// One line, without its line end; `line_no` counts from 1.
  void read_line(std::string_view line, std::size_t line_no) {
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) {
      line = line.substr(0, hash);
    }
    Tokens tokens(line);
    std::string_view keyword;
    if (!tokens.next(keyword)) return;
    if (keyword == "v") {
      read_vertex(tokens, line_no);
    } else if (keyword == "vn") {
      read_normal(tokens, line_no);
    } else if (keyword == "vt") {
      read_texcoord(tokens, line_no);
    } else if (keyword == "f") {
      read_face(tokens, line_no);
    }
  }

  /// After the last line: checks the forward references, converts the colours and resolves
  /// the corner normals.
  LoadedMesh finish() {
    if (max_forward_index_ > static_cast<long long>(mesh_->positions.size())) {
      fail(name_, max_forward_line_, out_of_range(max_forward_index_, mesh_->positions.size()));
    }
    if (any_color_) {
      mesh_->colors_linear.reserve(colors_srgb_.size());
      for (const glm::vec3& c : colors_srgb_) {
        mesh_->colors_linear.emplace_back(srgb_to_linear(c.r), srgb_to_linear(c.g),
                                          srgb_to_linear(c.b));
      }
    }
    LoadedMesh loaded;
    loaded.data = mesh_;
    if (any_face_normal_) resolve_corner_normals(normal_refs_, normals_, name_, loaded);
    if (any_face_uv_) resolve_corner_texcoords(uv_refs_, texcoords_, name_, loaded);
    loaded.dropped_nonfinite_triangles = drop_nonfinite_triangles(*mesh_);
    analyze_mesh_topology(*mesh_);  // once per file: instances share the result
    loaded.data = std::move(mesh_);
    return loaded;
  }

 private:
  /// "v x y z", "v x y z w" or "v x y z r g b".
  void read_vertex(Tokens& tokens, std::size_t line_no) {
    double values[6] = {0.0, 0.0, 0.0, 1.0, 1.0, 1.0};
    int count = 0;
    std::string_view token;
    while (tokens.next(token)) {
      double value = 0.0;
      if (!parse_double(token, value))
        fail(name_, line_no, "bad number '" + printable(token) + "'");
      if (count < 6) values[count] = value;
      ++count;
    }
    if (count < 3) fail(name_, line_no, "vertex needs x y z");
    if (mesh_->positions.size() >= kMaxVertices) fail(name_, line_no, "too many vertices");
    mesh_->positions.emplace_back(static_cast<float>(values[0]), static_cast<float>(values[1]),
                                  static_cast<float>(values[2]));
    // "v x y z w" carries a rational weight (meaningless for polygons); 6 or more numbers
    // are "v x y z r g b" with sRGB display values.
    if (count >= 6) any_color_ = true;
    colors_srgb_.emplace_back(static_cast<float>(values[3]), static_cast<float>(values[4]),
                              static_cast<float>(values[5]));
    if (count < 6) colors_srgb_.back() = glm::vec3(1.0f);
  }

  /// "vn x y z".
  void read_normal(Tokens& tokens, std::size_t line_no) {
    double values[3] = {0.0, 0.0, 0.0};
    int count = 0;
    std::string_view token;
    while (tokens.next(token)) {
      if (count < 3 && !parse_double(token, values[count])) {
        fail(name_, line_no, "bad number '" + printable(token) + "'");
      }
      ++count;
    }
    if (count != 3) fail(name_, line_no, "normal needs x y z");
    normals_.emplace_back(static_cast<float>(values[0]), static_cast<float>(values[1]),
                          static_cast<float>(values[2]));
  }

  /// "vt u [v [w]]": stored as (u, 1 - v), glTF's orientation; w is ignored.
  void read_texcoord(Tokens& tokens, std::size_t line_no) {
    double values[2] = {0.0, 0.0};
    int count = 0;
    std::string_view token;
    while (tokens.next(token)) {
      if (count < 2 && !parse_double(token, values[count])) {
        fail(name_, line_no, "bad number '" + printable(token) + "'");
      }
      ++count;
    }
    if (count < 1 || count > 3) fail(name_, line_no, "texture coordinate needs u [v [w]]");
    if (!std::isfinite(values[0]) || !std::isfinite(values[1])) {
      fail(name_, line_no, "texture coordinate must be finite");
    }
    texcoords_.emplace_back(static_cast<float>(values[0]), static_cast<float>(1.0 - values[1]));
  }

  /// "f" and its corners; the polygon becomes the fan (0, k, k + 1).
  void read_face(Tokens& tokens, std::size_t line_no) {
    corners_.clear();
    corner_normals_.clear();
    corner_uvs_.clear();
    std::string_view token;
    while (tokens.next(token)) {
      if (corners_.size() == kMaxObjFaceCorners) {
        fail(name_, line_no,
             "face has more than " + std::to_string(kMaxObjFaceCorners) +
                 " corners (docs/limits.md)");
      }
      corners_.push_back(corner_vertex(token, line_no));
      corner_normals_.push_back(corner_normal(token, normals_.size(), name_, line_no));
      corner_uvs_.push_back(corner_texcoord(token, texcoords_.size(), name_, line_no));
    }
    if (corners_.size() < 3) {
      fail(name_, line_no,
           "face needs at least 3 vertices, got " + std::to_string(corners_.size()));
    }
    const bool face_normals = std::any_of(corner_normals_.begin(), corner_normals_.end(),
                                          [](long long n) { return n != kNoNormal; });
    if (face_normals && !any_face_normal_) {
      // Faces before the first with normals: none (the face normal).
      normal_refs_.assign(mesh_->indices.size(), kNoNormal);
      any_face_normal_ = true;
    }
    const bool face_uvs = std::any_of(corner_uvs_.begin(), corner_uvs_.end(),
                                      [](long long t) { return t != kNoNormal; });
    if (face_uvs && !any_face_uv_) {
      uv_refs_.assign(mesh_->indices.size(), kNoNormal);
      any_face_uv_ = true;
    }
    for (std::size_t k = 1; k + 1 < corners_.size(); ++k) {
      for (const std::size_t c : {std::size_t(0), k, k + 1}) {
        mesh_->indices.push_back(corners_[c]);
        if (any_face_normal_) normal_refs_.push_back(corner_normals_[c]);
        if (any_face_uv_) uv_refs_.push_back(corner_uvs_[c]);
      }
    }
  }

  /// The 0-based vertex of a face corner "i", "i/t", "i//n" or "i/t/n": i > 0 counts from 1,
  /// i < 0 back from the latest vertex. A positive index past the vertices read so far is
  /// remembered and checked by finish().
  std::uint32_t corner_vertex(std::string_view token, std::size_t line_no) {
    const auto vertex_count = static_cast<long long>(mesh_->positions.size());
    const std::string_view index_text = token.substr(0, token.find('/'));
    long long index = 0;
    if (!parse_integer(index_text, index)) {
      fail(name_, line_no, "bad face vertex '" + printable(token) + "'");
    }
    if (index == 0) fail(name_, line_no, out_of_range(index, mesh_->positions.size()));
    if (index < 0) {
      const long long resolved = vertex_count + index;
      if (resolved < 0) fail(name_, line_no, out_of_range(index, mesh_->positions.size()));
      return static_cast<std::uint32_t>(resolved);
    }
    if (index > static_cast<long long>(kMaxVertices)) {
      fail(name_, line_no, out_of_range(index, mesh_->positions.size()));
    }
    if (index > vertex_count && index > max_forward_index_) {
      max_forward_index_ = index;
      max_forward_line_ = line_no;
    }
    return static_cast<std::uint32_t>(index - 1);
  }

  const std::string& name_;
  std::shared_ptr<MeshData> mesh_;
  std::vector<glm::vec3> colors_srgb_;  ///< one per vertex, white where the file gives none
  bool any_color_ = false;
  std::vector<std::uint32_t> corners_;     ///< of the current face
  std::vector<glm::vec3> normals_;         ///< vn lines, in file order
  std::vector<long long> corner_normals_;  ///< of the current face: see corner_normal()
  std::vector<long long> normal_refs_;     ///< per triangle corner, as corner_normals_
  bool any_face_normal_ = false;
  std::vector<glm::vec2> texcoords_;   ///< vt lines, in file order, v flipped
  std::vector<long long> corner_uvs_;  ///< of the current face: see corner_texcoord()
  std::vector<long long> uv_refs_;     ///< per triangle corner, as corner_uvs_
  bool any_face_uv_ = false;
  /// Positive indices may point past the vertices read so far (OBJ does not forbid forward
  /// references); the largest one is checked against the final count at the end.
  long long max_forward_index_ = 0;
  std::size_t max_forward_line_ = 0;
};

}  // namespace

LoadedMesh parse_obj(std::string_view text, const std::string& display_name) {
  check_obj_text(text, display_name);
  ObjParser parser(display_name);
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark
  std::size_t pos = 0;
  std::size_t line_no = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    parser.read_line(text.substr(pos, end - pos), ++line_no);
    pos = end + 1;
  }
  return parser.finish();
}

}  // namespace covrast::detail
