// Format-independent mesh loading: reading files, the NaN/Inf triangle filter shared by the
// OBJ and glTF parsers, and the public load_mesh entry point (format chosen by extension).
#include "scene/scene_internal.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>

namespace covrast {
namespace detail {

std::size_t drop_nonfinite_triangles(MeshData& mesh) {
  std::vector<bool> bad(mesh.positions.size(), false);
  bool any_bad = false;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::vec3& p = mesh.positions[i];
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) {
      bad[i] = true;
      any_bad = true;
    }
  }
  if (!any_bad) return 0;
  std::size_t kept = 0;
  std::size_t dropped = 0;
  const bool normals = !mesh.corner_normals.empty();
  const bool materials = !mesh.triangle_materials.empty();
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    if (bad[a] || bad[b] || bad[c]) {
      ++dropped;
      continue;
    }
    // The per-triangle arrays move with their triangle (kept is 3 x the triangles kept).
    if (normals)
      std::copy_n(mesh.corner_normals.begin() + std::ptrdiff_t(t), 3,
                  mesh.corner_normals.begin() + std::ptrdiff_t(kept));
    for (std::vector<glm::vec2>& uv : mesh.corner_texcoords) {
      if (!uv.empty())
        std::copy_n(uv.begin() + std::ptrdiff_t(t), 3, uv.begin() + std::ptrdiff_t(kept));
    }
    if (!mesh.corner_tangents.empty())
      std::copy_n(mesh.corner_tangents.begin() + std::ptrdiff_t(t), 3,
                  mesh.corner_tangents.begin() + std::ptrdiff_t(kept));
    if (materials) mesh.triangle_materials[kept / 3] = mesh.triangle_materials[t / 3];
    mesh.indices[kept++] = a;
    mesh.indices[kept++] = b;
    mesh.indices[kept++] = c;
  }
  mesh.indices.resize(kept);
  if (normals) mesh.corner_normals.resize(kept);
  for (std::vector<glm::vec2>& uv : mesh.corner_texcoords) {
    if (!uv.empty()) uv.resize(kept);
  }
  if (!mesh.corner_tangents.empty()) mesh.corner_tangents.resize(kept);
  if (materials) mesh.triangle_materials.resize(kept / 3);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    if (bad[i]) mesh.positions[i] = glm::vec3(0.0f);
  }
  return dropped;
}

bool is_glb(std::string_view bytes) { return bytes.substr(0, 4) == "glTF"; }

void check_obj_text(std::string_view text, const std::string& name) {
  // OBJ is text: a NUL byte means binary data (a .glb, an image, a NUL-filled file), which
  // the line parser would skip line by line and load as nothing.
  if (is_glb(text))
    throw InputError(name + ": " +
                     "binary glTF (.glb), not an OBJ text file: name it with \"gltf\"");
  if (text.find('\0') != std::string_view::npos) {
    throw InputError(name + ": " + "binary data (a NUL byte at byte " +
                     std::to_string(text.find('\0')) + "), not an OBJ text file");
  }
  // JSON (a .gltf file, a scene) starts with an object or array; no OBJ statement does.
  std::string_view rest = text.substr(0, 3) == "\xEF\xBB\xBF" ? text.substr(3) : text;
  const std::size_t first = rest.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && (rest[first] == '{' || rest[first] == '[')) {
    throw InputError(name + ": " + "JSON, not an OBJ file (a .gltf file belongs under \"gltf\")");
  }
}

}  // namespace detail

std::shared_ptr<MeshData> load_mesh(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string ext = detail::lower_extension(path);
  if (ext != ".obj" && ext != ".gltf" && ext != ".glb") {
    throw InputError(name + ": unknown mesh format (expected .obj, .gltf or .glb)");
  }
  std::string bytes;
  std::string error;
  if (!detail::read_whole_file(path, bytes, error)) {
    throw InputError(name + ": cannot open: " + error);
  }
  if (ext == ".obj") return detail::parse_obj(bytes, name, path.parent_path()).data;
  return detail::parse_gltf(bytes, name, path.parent_path()).data;
}

}  // namespace covrast
