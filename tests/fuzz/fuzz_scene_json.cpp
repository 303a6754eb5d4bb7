// Fuzz target: the scene file reader (load_scene). The input is a scene file's bytes; it is
// written to a scratch folder beside two small mesh files it may name ("tri.obj" and
// "tri.gltf"), then loaded. Any answer but a scene or an InputError is a finding, and a scene
// that loads must pass check_scene (what the loader accepts, the renderer may assume).
#include "fuzz_support.hpp"

#include <covrast/scene.hpp>

namespace {

// A triangle as OBJ (with vertex colours and normals) and as glTF with an embedded buffer:
// positions (0,0,0), (1,0,0), (0,1,0) as floats, then indices 0 1 2 as unsigned shorts.
constexpr char kTriObj[] =
    "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nvn 0 0 1\nf 1//1 2//1 3//1\n";
constexpr char kTriGltf[] = R"({
"asset": {"version": "2.0"},
"scene": 0, "scenes": [{"nodes": [0, 1]}],
"nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
"cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
"meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
"buffers": [{"byteLength": 42, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIA"}],
"bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
"accessors": [
 {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
 {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]
})";

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  covrast::fuzz::write_scratch("tri.obj", kTriObj);
  covrast::fuzz::write_scratch("tri.gltf", kTriGltf);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path =
      covrast::fuzz::write_scratch("scene.json", covrast::fuzz::as_text(data, size));
  covrast::fuzz::expect_input_error_only([&] {
    const covrast::Scene scene = covrast::load_scene(path);
    covrast::check_scene(scene);
  });
  return 0;
}
