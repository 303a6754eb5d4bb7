// Fuzz target: the glTF 2.0 reader (detail::parse_gltf), JSON (.gltf) and binary (.glb: an
// input starting with "glTF"), on bytes in memory; external buffers resolve against an empty
// scratch folder. Any answer but a mesh or an InputError is a finding; a mesh must be
// consistent (indices in range, finite positions where a triangle uses them, one colour per
// position when there are colours, one material index per triangle when there are any).
#include "fuzz_support.hpp"

#include "scene/scene_internal.hpp"

#include <cmath>

namespace {

void check_mesh(const covrast::MeshData& mesh) {
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
    std::fprintf(stderr, "covrast fuzz: inconsistent mesh from the glTF reader\n");
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path base_dir = covrast::fuzz::scratch_dir() / "gltf-base";
  static const bool made = std::filesystem::create_directories(base_dir);
  (void)made;
  covrast::fuzz::expect_input_error_only([&] {
    const covrast::detail::LoadedMesh mesh =
        covrast::detail::parse_gltf(covrast::fuzz::as_text(data, size), "fuzz.gltf", base_dir);
    check_mesh(*mesh.data);
  });
  return 0;
}
