// Format-independent mesh loading: reading files, the NaN/Inf triangle filter shared by the
// OBJ and glTF parsers, and the public load_mesh entry point (format chosen by extension).
#include "scene/scene_internal.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <system_error>

namespace covrast {
namespace detail {

bool read_whole_file(const std::filesystem::path& path, std::string& contents, std::string& error) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec) {
    error = ec.message();
    return false;
  }
  if (std::filesystem::is_directory(status)) {
    error = std::make_error_code(std::errc::is_a_directory).message();
    return false;
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    error = std::error_code(errno, std::generic_category()).message();
    return false;
  }
  contents.clear();
  char buffer[1 << 16];
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof buffer, file)) > 0) contents.append(buffer, got);
  const bool failed = std::ferror(file) != 0;
  const int saved_errno = errno;
  std::fclose(file);
  if (failed) {
    error = std::error_code(saved_errno, std::generic_category()).message();
    return false;
  }
  return true;
}

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
    if (materials) mesh.triangle_materials[kept / 3] = mesh.triangle_materials[t / 3];
    mesh.indices[kept++] = a;
    mesh.indices[kept++] = b;
    mesh.indices[kept++] = c;
  }
  mesh.indices.resize(kept);
  if (normals) mesh.corner_normals.resize(kept);
  if (materials) mesh.triangle_materials.resize(kept / 3);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    if (bad[i]) mesh.positions[i] = glm::vec3(0.0f);
  }
  return dropped;
}

bool is_glb(std::string_view bytes) { return bytes.substr(0, 4) == "glTF"; }

}  // namespace detail

std::shared_ptr<MeshData> load_mesh(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
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
