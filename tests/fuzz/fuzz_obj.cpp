// Fuzz target: the Wavefront OBJ parser (detail::parse_obj, on bytes in memory). Any answer
// but a mesh or an InputError is a finding; a mesh must be consistent (check_mesh in
// fuzz_mesh.hpp: indices in range, one colour per position when there are colours, three corner
// normals per triangle, material indices in range) and hold only finite positions where a
// triangle uses them (the parser drops the rest with a warning). "mtllib" names resolve in an
// empty folder, so the target reads nothing but its input.
#include "fuzz_mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path base_dir = covrast::fuzz::empty_folder("obj-base");
  covrast::fuzz::expect_input_error_only([&] {
    const covrast::detail::LoadedMesh mesh =
        covrast::detail::parse_obj(covrast::fuzz::as_text(data, size), "fuzz.obj", base_dir);
    covrast::fuzz::check_mesh(*mesh.data, "OBJ parser");
  });
  return 0;
}
