// The glTF extensions a file uses: what covrast does with each (gltf_extension_support), the
// warning for each one it does not honour, and the list a scene keeps for `covrast info`.
#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include "test_gltf_files.hpp"
#include "test_tempdir.hpp"

namespace {

std::string triangle_using(const std::vector<std::string>& used,
                           const std::vector<std::string>& required = {}) {
  covrast::test::GltfBuilder builder;
  const int positions = builder.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  builder.single_mesh({{{"attributes", {{"POSITION", positions}}}}});
  builder.gltf["extensionsUsed"] = used;
  if (!required.empty()) builder.gltf["extensionsRequired"] = required;
  return builder.glb();
}

int count_containing(const std::vector<std::string>& lines, const std::string& text) {
  return int(std::count_if(lines.begin(), lines.end(), [&](const std::string& line) {
    return line.find(text) != std::string::npos;
  }));
}

}  // namespace

TEST_CASE("gltf extensions: each is honoured, ignored with a warning or cannot be read",
          "[gltf][extensions]") {
  using covrast::GltfExtensionSupport;
  CHECK(covrast::gltf_extension_support("KHR_texture_transform").support ==
        GltfExtensionSupport::Honoured);
  CHECK(covrast::gltf_extension_support("KHR_materials_diffuse_transmission").support ==
        GltfExtensionSupport::Ignored);
  CHECK(covrast::gltf_extension_support("EXT_meshopt_compression").support ==
        GltfExtensionSupport::Honoured);
  CHECK(covrast::gltf_extension_support("KHR_texture_basisu").support ==
        GltfExtensionSupport::Unreadable);
  CHECK(covrast::gltf_extension_support("EXT_made_up").effect.find("unknown") != std::string::npos);

  covrast::test::TempDir dir("covrast-ext");
  const std::filesystem::path file = dir / "t.glb";
  std::ofstream(file, std::ios::binary) << triangle_using(
      {"KHR_texture_transform", "KHR_materials_diffuse_transmission", "EXT_made_up"});
  // A model file renders lit: the material extension warns, so does the unknown one; the
  // honoured one does not.
  const covrast::Scene lit = covrast::load_mesh_scene(file, 32, 32);
  CHECK(lit.gltf_extensions_used == std::vector<std::string>{"EXT_made_up",
                                                             "KHR_materials_diffuse_transmission",
                                                             "KHR_texture_transform"});
  CHECK(count_containing(lit.warnings,
                         "KHR_materials_diffuse_transmission, which covrast ignores") == 1);
  CHECK(count_containing(lit.warnings, "EXT_made_up, which covrast ignores") == 1);
  CHECK(count_containing(lit.warnings, "KHR_texture_transform") == 0);
  // An unlit scene: the material extension changes nothing there, so it does not warn.
  std::ofstream(dir / "s.json")
      << R"({"width": 8, "height": 8, "camera": {"eye": [0, 0, 5], "target": [0, 0, 0],
            "up": [0, 1, 0], "fovy_deg": 40, "near": 0.1, "far": 10},
            "meshes": [{"gltf": "t.glb"}, {"gltf": "t.glb"}]})";
  const covrast::Scene unlit = covrast::load_scene(dir / "s.json");
  CHECK(count_containing(unlit.warnings, "KHR_materials_diffuse_transmission") == 0);
  CHECK(count_containing(unlit.warnings, "EXT_made_up") == 1);  // once for the file
  CHECK(unlit.gltf_extensions_used.size() == 3);
  // Required and not readable: refused, naming it.
  std::ofstream(file, std::ios::binary)
      << triangle_using({"KHR_texture_basisu"}, {"KHR_texture_basisu"});
  CHECK_THROWS_WITH(covrast::load_mesh_scene(file, 32, 32),
                    Catch::Contains("requires the glTF extension KHR_texture_basisu"));
}

TEST_CASE("gltf extensions: a texture whose only image is KHR_texture_basisu is named",
          "[gltf][extensions]") {
  covrast::test::GltfBuilder b;
  const int pos = b.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  const int uv = b.add_floats({0, 0, 1, 0, 0, 1}, "VEC2");
  b.single_mesh(nlohmann::json::array(
      {{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"material", 0}}}));
  b.gltf["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  b.gltf["textures"] = {{{"extensions", {{"KHR_texture_basisu", {{"source", 0}}}}}}};
  b.gltf["images"] = {{{"uri", "t.ktx2"}}};
  b.gltf["extensionsUsed"] = {"KHR_texture_basisu"};
  covrast::test::TempDir dir("covrast-ext");
  std::ofstream(dir / "b.glb", std::ios::binary) << b.glb();
  CHECK_THROWS_WITH(covrast::load_mesh_scene(dir / "b.glb", 16, 16),
                    Catch::Contains("material 0 baseColorTexture: the texture has no image "
                                    "covrast can read (no \"source\"; only KHR_texture_basisu, "
                                    "which covrast cannot read)"));
}
