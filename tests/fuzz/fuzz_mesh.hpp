// Shared by the mesh-reader fuzz targets (fuzz_obj, fuzz_gltf): the empty folder a reader
// resolves companion files in, and the consistency every mesh it returns must have.
#pragma once

#include "fuzz_support.hpp"
#include "scene/scene_internal.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace covrast::fuzz {

/// scratch_dir() / name, made empty: OBJ "mtllib" names and glTF external buffers resolve
/// there and are missing, so a target reads nothing but its input.
inline std::filesystem::path empty_folder(const std::string& name) {
  const std::filesystem::path dir = scratch_dir() / name;
  std::filesystem::create_directories(dir);
  return dir;
}

/// Aborts (a finding) unless `mesh` is consistent: whole triangles, indices in range, finite
/// positions where a triangle uses them, one colour per position and three corner normals per
/// triangle when there are any, one material index per triangle in range when there are any.
/// `reader` names the reader in the message.
inline void check_mesh(const MeshData& mesh, const char* reader) {
  bool ok =
      mesh.indices.size() % 3 == 0 &&
      (mesh.colors_linear.empty() || mesh.colors_linear.size() == mesh.positions.size()) &&
      (mesh.corner_normals.empty() || mesh.corner_normals.size() == mesh.indices.size()) &&
      (mesh.triangle_materials.empty() || mesh.triangle_materials.size() == mesh.triangle_count());
  for (const std::uint32_t index : mesh.indices) {
    ok = ok && index < mesh.positions.size() && std::isfinite(mesh.positions[index].x) &&
         std::isfinite(mesh.positions[index].y) && std::isfinite(mesh.positions[index].z);
  }
  for (const std::uint32_t material : mesh.triangle_materials) {
    ok = ok && material < mesh.materials.size();
  }
  if (!ok) {
    std::fprintf(stderr, "covrast fuzz: inconsistent mesh from the %s\n", reader);
    std::abort();
  }
}

}  // namespace covrast::fuzz
