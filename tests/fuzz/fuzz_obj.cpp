// Fuzz target: the Wavefront OBJ parser (detail::parse_obj, on bytes in memory). Any answer
// but a mesh or an InputError is a finding; a mesh must be consistent (indices in range, one
// colour per position when there are colours, three corner normals per triangle) and hold only
// finite positions where a triangle uses them (the parser drops the rest with a warning).
#include "fuzz_support.hpp"

#include "scene/scene_internal.hpp"

#include <cmath>

namespace {

void check_mesh(const covrast::MeshData& mesh) {
  bool ok = mesh.indices.size() % 3 == 0 &&
            (mesh.colors_linear.empty() || mesh.colors_linear.size() == mesh.positions.size()) &&
            (mesh.corner_normals.empty() || mesh.corner_normals.size() == mesh.indices.size());
  for (const std::uint32_t index : mesh.indices) {
    ok = ok && index < mesh.positions.size() && std::isfinite(mesh.positions[index].x) &&
         std::isfinite(mesh.positions[index].y) && std::isfinite(mesh.positions[index].z);
  }
  if (!ok) {
    std::fprintf(stderr, "covrast fuzz: inconsistent mesh from the OBJ parser\n");
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // An empty folder: "mtllib" names resolve there and are missing (a warning), so the target
  // reads nothing but its input.
  const std::filesystem::path base_dir = covrast::fuzz::scratch_dir() / "obj-base";
  static const bool made = std::filesystem::create_directories(base_dir);
  (void)made;
  covrast::fuzz::expect_input_error_only([&] {
    const covrast::detail::LoadedMesh mesh =
        covrast::detail::parse_obj(covrast::fuzz::as_text(data, size), "fuzz.obj", base_dir);
    check_mesh(*mesh.data);
  });
  return 0;
}
