// Fuzz target: the glTF 2.0 reader (detail::parse_gltf), JSON (.gltf) and binary (.glb: an
// input starting with "glTF"), on bytes in memory; external buffers resolve against an empty
// scratch folder. Any answer but a mesh or an InputError is a finding; a mesh must be
// consistent (indices in range, finite positions where a triangle uses them, one colour per
// position when there are colours, one material index per triangle when there are any).
#include "fuzz_mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path base_dir = covrast::fuzz::empty_folder("gltf-base");
  covrast::fuzz::expect_input_error_only([&] {
    const covrast::detail::LoadedMesh mesh =
        covrast::detail::parse_gltf(covrast::fuzz::as_text(data, size), "fuzz.gltf", base_dir);
    covrast::fuzz::check_mesh(*mesh.data, "glTF reader");
  });
  return 0;
}
