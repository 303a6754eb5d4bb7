// Wavefront OBJ reader for the subset covrast renders: "v x y z [r g b]", "vn x y z", "f" with
// any index form (i, i/t, i//n, i/t/n; negative = relative to the vertices or normals defined
// so far), and materials ("mtllib", "usemtl"; obj_material.cpp). Convex polygons become the
// fan (0, k, k + 1), k = 1 .. n - 2, concave ones are ear-clipped (obj_polygon.cpp);
// triangles in file order; normals become corner normals (MeshData::corner_normals), "vt u [v
// [w]]" corner UVs (MeshData::corner_texcoords[0], v flipped to glTF's convention: OBJ's v = 0
// is the bottom of the image). "l" and "p" are counted in a warning; the rest (o, g, s, ...)
// carries nothing covrast draws.
#include "scene/obj_material.hpp"
#include "scene/obj_polygon.hpp"
#include "scene/obj_text.hpp"
#include "scene/scene_internal.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <map>
#include <set>
#include <vector>

namespace covrast::detail {
namespace {

constexpr std::size_t kMaxVertices = std::numeric_limits<std::uint32_t>::max();

[[noreturn]] void fail(const std::string& name, std::size_t line, const std::string& message) {
  fail_at(name, line, message);
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
  ObjParser(const std::string& name, const std::filesystem::path& base_dir)
      : name_(name), base_dir_(base_dir), mesh_(std::make_shared<MeshData>()) {
    mesh_->source = name;
  }

  /// One line, without its line end; `line_no` counts from 1.
  void read_line(std::string_view line, std::size_t line_no) {
    Tokens tokens(without_comment(line));
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
    } else if (keyword == "usemtl") {
      use_material(tokens.rest());
    } else if (keyword == "mtllib") {
      read_libraries(tokens, line_no);
    } else if (keyword == "l") {
      ++lines_;
    } else if (keyword == "p") {
      ++points_;
    }
  }

  /// After the last line: checks the forward references, converts the colours, splits the
  /// faces into triangles, resolves the corner normals and applies the materials.
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
    loaded.warnings = std::move(warnings_);
    split_faces(loaded);
    if (any_face_normal_) resolve_corner_normals(normal_refs_, normals_, name_, loaded);
    if (any_face_uv_) resolve_corner_texcoords(uv_refs_, texcoords_, name_, loaded);
    apply_obj_materials(library_, material_names_, triangle_names_, name_, loaded);
    for (const std::string& warning : library_.warnings) loaded.warnings.push_back(warning);
    load_color_maps(*mesh_, loaded);
    if (lines_ + points_ > 0) {
      loaded.warnings.push_back(name_ + ": " + std::to_string(lines_) + " line (l) and " +
                                std::to_string(points_) +
                                " point (p) statements not drawn: covrast draws faces only");
    }
    loaded.dropped_nonfinite_triangles = drop_nonfinite_triangles(*mesh_);
    analyze_mesh_topology(*mesh_);  // once per file: instances share the result
    loaded.data = std::move(mesh_);
    return loaded;
  }

 private:
  /// map_Kd (sRGB, docs/textures.md): each distinct file decoded once and shared by the
  /// materials naming it. A file that does not exist is a warning and its materials are drawn
  /// without it (docs/limits.md, "Missing files"); one that cannot be read or decoded is an
  /// InputError naming it.
  void load_color_maps(MeshData& mesh, LoadedMesh& loaded) const {
    std::map<std::string, std::shared_ptr<const Texture>> maps;
    std::set<std::string> missing;
    std::uint64_t texels = 0;  // of the file's decoded maps, within kMaxTextureTexels
    std::size_t without_uvs = 0;
    for (Material& m : mesh.materials) {
      if (m.base_color_texture_path.empty()) continue;
      if (missing.count(m.base_color_texture_path) != 0) continue;
      std::shared_ptr<const Texture>& texture = maps[m.base_color_texture_path];
      if (!texture) {
        // Named relative to the OBJ file, as the .mtl usually gives it (short enough to print).
        const std::filesystem::path path(m.base_color_texture_path);
        std::string shown = path.lexically_relative(base_dir_).string();
        if (shown.empty()) shown = path.filename().string();
        const std::string what = name_ + ": map_Kd " + printable(shown);
        std::error_code ec;
        if (!std::filesystem::exists(path, ec) && !ec) {
          loaded.warnings.push_back(what + ": no such file: its materials are drawn without it");
          missing.insert(m.base_color_texture_path);
          maps.erase(m.base_color_texture_path);
          continue;
        }
        texture = load_texture_file(path, what, true, texels);
      }
      m.base_color_texture.texture = texture;
      without_uvs += any_face_uv_ ? 0 : 1;
    }
    if (without_uvs > 0) {
      loaded.warnings.push_back(name_ + ": " + std::to_string(without_uvs) +
                                " materials have a map_Kd but the file has no vt: UV (0, 0) used");
    }
  }

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

  /// "f" and its corners, kept until finish() (a corner may name a vertex defined later).
  void read_face(Tokens& tokens, std::size_t line_no) {
    const std::size_t first = face_vertices_.size();
    std::string_view token;
    while (tokens.next(token)) {
      if (face_vertices_.size() - first == kMaxObjFaceCorners) {
        fail(name_, line_no,
             "face has more than " + std::to_string(kMaxObjFaceCorners) +
                 " corners (docs/limits.md)");
      }
      face_vertices_.push_back(corner_vertex(token, line_no));
      const long long normal = corner_normal(token, normals_.size(), name_, line_no);
      face_normals_.push_back(normal);
      any_face_normal_ = any_face_normal_ || normal != kNoNormal;
      const long long uv = corner_texcoord(token, texcoords_.size(), name_, line_no);
      face_uvs_.push_back(uv);
      any_face_uv_ = any_face_uv_ || uv != kNoNormal;
    }
    const std::size_t count = face_vertices_.size() - first;
    if (count < 3) {
      fail(name_, line_no, "face needs at least 3 vertices, got " + std::to_string(count));
    }
    face_sizes_.push_back(static_cast<std::uint32_t>(count));
    face_material_.push_back(current_material_);
  }

  /// Every face into triangles, in file order: the fan for convex polygons, ear clipping
  /// for concave ones (obj_polygon.cpp); fallbacks counted in a warning.
  void split_faces(LoadedMesh& loaded) {
    std::size_t first = 0, fallbacks = 0;
    std::vector<glm::dvec3> ring;
    std::vector<std::uint32_t> corners;
    for (std::size_t f = 0; f < face_sizes_.size(); ++f) {
      const std::size_t count = face_sizes_[f];
      ring.clear();
      corners.clear();
      bool finite = true;
      for (std::size_t c = 0; c < count && count > 3; ++c) {
        ring.emplace_back(mesh_->positions[face_vertices_[first + c]]);
        finite = finite && std::isfinite(ring.back().x + ring.back().y + ring.back().z);
      }
      if (count > 3 && finite) {
        if (triangulate_polygon(ring, corners) == PolygonSplit::Fallback) ++fallbacks;
      } else {
        // Triangles; and polygons with a NaN or infinite corner, dropped later anyway.
        for (std::uint32_t k = 1; k + 1 < count; ++k) corners.insert(corners.end(), {0, k, k + 1});
      }
      for (const std::uint32_t c : corners) {
        mesh_->indices.push_back(face_vertices_[first + c]);
        if (any_face_normal_) normal_refs_.push_back(face_normals_[first + c]);
        if (any_face_uv_) uv_refs_.push_back(face_uvs_[first + c]);
      }
      triangle_names_.insert(triangle_names_.end(), corners.size() / 3, face_material_[f]);
      first += count;
    }
    if (fallbacks > 0) {
      loaded.warnings.push_back(name_ + ": " + std::to_string(fallbacks) +
                                " polygons are degenerate, self-intersecting or have over " +
                                std::to_string(kMaxEarClipCorners) +
                                " corners: split as the fan (0, k, k + 1)");
    }
  }

  /// "usemtl name": the faces that follow use it (resolved in finish()).
  void use_material(std::string_view name) {
    const auto [it, added] =
        material_index_.try_emplace(std::string(name), std::uint32_t(material_names_.size()));
    if (added) material_names_.emplace_back(name);
    current_material_ = it->second;
  }

  /// "mtllib a.mtl [b.mtl ...]", relative to the OBJ file. The whole rest of the line is
  /// tried first as one name (names with spaces). An unreadable library is a warning.
  void read_libraries(Tokens& tokens, std::size_t line_no) {
    std::vector<std::string> files{std::string(tokens.rest())};
    if (files[0].empty()) fail(name_, line_no, "mtllib needs a file name");
    std::error_code ec;
    if (!std::filesystem::is_regular_file(base_dir_ / files[0], ec)) {
      files.clear();
      std::string_view token;
      while (tokens.next(token)) files.emplace_back(token);
    }
    for (const std::string& file : files) {
      const std::filesystem::path path = base_dir_ / std::filesystem::path(file);
      std::string text, error;
      if (!read_whole_file(path, text, error)) {
        warnings_.push_back(name_ + ":" + std::to_string(line_no) +
                            ": cannot open material library '" + printable(file) + "': " + error +
                            "; its materials are not used");
        continue;
      }
      parse_mtl(text, path.lexically_normal().string(), path.parent_path(), library_);
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
  const std::filesystem::path& base_dir_;
  std::shared_ptr<MeshData> mesh_;
  std::vector<glm::vec3> colors_srgb_;  ///< one per vertex, white where the file gives none
  bool any_color_ = false;
  std::vector<glm::vec3> normals_;  ///< vn lines, in file order
  // The faces as read: their corners' vertices and normals (see corner_normal()), sizes and
  // materials (indices into material_names_).
  std::vector<std::uint32_t> face_vertices_;
  std::vector<long long> face_normals_;
  std::vector<std::uint32_t> face_sizes_;
  std::vector<std::uint32_t> face_material_;
  std::vector<long long> normal_refs_;  ///< per triangle corner, as face_normals_
  bool any_face_normal_ = false;
  std::vector<glm::vec2> texcoords_;  ///< vt lines, in file order, v flipped
  std::vector<long long> face_uvs_;   ///< per face corner: see corner_texcoord()
  std::vector<long long> uv_refs_;    ///< per triangle corner, as face_uvs_
  bool any_face_uv_ = false;
  // Materials: the libraries read, the usemtl names in order of first use, each triangle's.
  MtlLibrary library_;
  std::vector<std::string> material_names_;
  std::map<std::string, std::uint32_t> material_index_;
  std::uint32_t current_material_ = kNoObjMaterial;
  std::vector<std::uint32_t> triangle_names_;
  std::size_t lines_ = 0, points_ = 0;  ///< "l" and "p" statements, not drawn
  std::vector<std::string> warnings_;   ///< found while reading (libraries)
  /// Positive indices may point past the vertices read so far (OBJ does not forbid forward
  /// references); the largest one is checked against the final count at the end.
  long long max_forward_index_ = 0;
  std::size_t max_forward_line_ = 0;
};

}  // namespace

LoadedMesh parse_obj(std::string_view text, const std::string& display_name,
                     const std::filesystem::path& base_dir) {
  check_obj_text(text, display_name);
  ObjParser parser(display_name, base_dir);
  for_each_line(
      text, [&](std::string_view line, std::size_t line_no) { parser.read_line(line, line_no); });
  return parser.finish();
}

}  // namespace covrast::detail
