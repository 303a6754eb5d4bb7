// Tests of the glTF features beyond plain triangle lists (src/scene/mesh_gltf.cpp): strips and
// fans, points and lines counted in a warning, extensionsRequired, KHR_draco_mesh_compression
// (streams encoded here with libdraco), morph targets, skins, EXT_mesh_gpu_instancing and the
// scene's camera from a glTF file. Every
// file is written here by GltfBuilder (test_gltf_files.hpp); nothing is read from outside the test.
#include <covrast/error.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "test_cli_run.hpp"
#include "test_gltf_files.hpp"
#include "test_tempdir.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using covrast::InputError;
using covrast::test::GltfBuilder;
using nlohmann::json;

namespace {

class TempDir : public covrast::test::TempDir {
 public:
  TempDir() : covrast::test::TempDir("covrast-test-gltf") {}

  fs::path write(const std::string& name, const std::string& contents) const {
    const fs::path file = path() / name;
    std::ofstream out(file, std::ios::binary);
    out << contents;
    return file;
  }
};

/// A scene of one glTF file, looking down -z at the origin from (0, 0, 3), unlit.
json scene_of(const std::string& gltf_file) {
  return {{"width", 32},
          {"height", 32},
          {"camera",
           {{"eye", {0, 0, 3}},
            {"target", {0, 0, 0}},
            {"up", {0, 1, 0}},
            {"fovy_deg", 45.0},
            {"near", 0.5},
            {"far", 10.0}}},
          {"meshes", {{{"gltf", gltf_file}}}}};
}

/// The z component of (b - a) x (c - a) for every triangle: > 0 for counter-clockwise seen
/// from +z.
std::vector<float> winding_z(const covrast::MeshData& mesh) {
  std::vector<float> z;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const glm::vec3 a = mesh.positions[mesh.indices[t]];
    const glm::vec3 b = mesh.positions[mesh.indices[t + 1]];
    const glm::vec3 c = mesh.positions[mesh.indices[t + 2]];
    z.push_back(glm::cross(b - a, c - a).z);
  }
  return z;
}

/// A row of 5 vertices zig-zagging along x in the plane z = 0 (0, 2, 4 above, 1, 3 below), so
/// that the strip's first triangle (0, 1, 2) is counter-clockwise seen from +z.
std::vector<float> zigzag_positions() {
  return {-1, 1, 0, -0.5f, -1, 0, 0, 1, 0, 0.5f, -1, 0, 1, 1, 0};
}

}  // namespace

TEST_CASE("glTF TRIANGLE_STRIP and TRIANGLE_FAN give n - 2 triangles in the spec's order",
          "[gltf]") {
  TempDir dir;
  GltfBuilder b;
  const int positions = b.add_floats(zigzag_positions(), "VEC3");
  // The fan walks the convex outline 1 3 4 2 0 counter-clockwise around its first vertex.
  const int fan_indices = b.add_u16({1, 3, 4, 2, 0}, "SCALAR");
  b.single_mesh(
      {{{"attributes", {{"POSITION", positions}}}, {"mode", 5}},
       {{"attributes", {{"POSITION", positions}}}, {"mode", 6}, {"indices", fan_indices}}});
  const auto mesh = covrast::load_mesh(dir.write("modes.glb", b.glb()));
  // Strip triangle i: (v_i, v_{i+1+i%2}, v_{i+2-i%2}); fan triangle i: (v_{i+1}, v_{i+2}, v_0),
  // with the fan's vertices 5..9 after the strip's 0..4.
  REQUIRE(mesh->indices == std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2, 2, 3, 4,  //
                                                      8, 9, 6, 9, 7, 6, 7, 5, 6});
  REQUIRE(mesh->triangle_count() == 6);
  for (const float z : winding_z(*mesh)) REQUIRE(z > 0.0f);  // all counter-clockwise
}

TEST_CASE("a glTF strip is drawn: the pixels it covers take the file's colour", "[gltf]") {
  TempDir dir;
  GltfBuilder b;
  // A quad [-1, 1]^2 as a 4-vertex strip, red by its material.
  const int positions = b.add_floats({-1, -1, 0, 1, -1, 0, -1, 1, 0, 1, 1, 0}, "VEC3");
  b.single_mesh({{{"attributes", {{"POSITION", positions}}}, {"mode", 5}, {"material", 0}}});
  b.gltf["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {1, 0, 0, 1}}}}}};
  dir.write("quad.glb", b.glb());
  std::ofstream(dir / "scene.json") << scene_of("quad.glb").dump();
  const covrast::Scene scene = covrast::load_scene(dir / "scene.json");
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode("coverage");
  options.threads = 1;
  const covrast::Image image = covrast::render(scene, options).color;
  // The quad spans +-1 at distance 3 with a 45 degree view: tan(22.5) * 3 = 1.24 > 1, so the
  // middle 24 x 24 pixels are inside it and the corners outside.
  for (const auto& [x, y] : {std::pair{16, 16}, std::pair{6, 6}, std::pair{25, 25}}) {
    const std::uint8_t* p = image.pixel(x, y);
    REQUIRE(p[0] == 255);
    REQUIRE(p[1] == 0);
    REQUIRE(p[2] == 0);
  }
  REQUIRE(image.pixel(0, 0)[0] == 0);
}

TEST_CASE("glTF points and lines are counted in one warning, not drawn", "[gltf]") {
  TempDir dir;
  GltfBuilder b;
  const int positions = b.add_floats(zigzag_positions(), "VEC3");
  const json attributes = {{"POSITION", positions}};
  b.single_mesh({{{"attributes", attributes}, {"mode", 0}},
                 {{"attributes", attributes}, {"mode", 1}},
                 {{"attributes", attributes}, {"mode", 1}},
                 {{"attributes", attributes}, {"mode", 2}},
                 {{"attributes", attributes}, {"mode", 3}},
                 {{"attributes", attributes}, {"mode", 5}}});
  dir.write("lines.glb", b.glb());
  std::ofstream(dir / "scene.json") << scene_of("lines.glb").dump();
  const covrast::Scene scene = covrast::load_scene(dir / "scene.json");
  REQUIRE(scene.triangle_count() == 3);
  REQUIRE(scene.warnings ==
          std::vector<std::string>{(dir.path() / "lines.glb").lexically_normal().string() +
                                   ": 5 primitives not drawn (POINTS 1, LINES 2, LINE_LOOP 1, "
                                   "LINE_STRIP 1): covrast draws triangles only"});
  // --strict turns the warning into an error: exit 2, no image.
  const auto result = covrast::test::run_cli_in(
      dir.path(), {"render", "scene.json", "-o", "out.png", "--strict"}, true);
  REQUIRE(result.exit_code == 2);
  REQUIRE_THAT(result.err, Contains("primitives not drawn"));
  REQUIRE_FALSE(fs::exists(dir / "out.png"));
}

TEST_CASE("bad glTF primitive modes are InputErrors naming file and primitive", "[gltf]") {
  TempDir dir;
  GltfBuilder b;
  const int positions = b.add_floats({0, 0, 0, 1, 0, 0}, "VEC3");
  b.single_mesh({{{"attributes", {{"POSITION", positions}}}, {"mode", 5}}});
  REQUIRE_THROWS_WITH(
      covrast::load_mesh(dir.write("short.glb", b.glb())),
      Contains("short.glb: mesh 0 primitive 0: TRIANGLE_STRIP needs at least 3 vertices, got 2"));
  b.gltf["meshes"][0]["primitives"][0]["mode"] = 6;
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("short_fan.glb", b.glb())),
                      Contains("TRIANGLE_FAN needs at least 3 vertices, got 2"));
  b.gltf["meshes"][0]["primitives"][0]["mode"] = 7;
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("mode7.glb", b.glb())),
                      Contains("mode7.glb: mesh 0 primitive 0: unknown mode 7"));
}

TEST_CASE("a glTF file requiring an extension covrast lacks is an InputError naming it", "[gltf]") {
  TempDir dir;
  GltfBuilder b;
  const int positions = b.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  b.single_mesh({{{"attributes", {{"POSITION", positions}}}}});
  b.gltf["extensionsUsed"] = {"KHR_texture_basisu", "KHR_materials_unlit"};
  b.gltf["extensionsRequired"] = {"KHR_materials_unlit", "KHR_texture_basisu"};
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("basisu.glb", b.glb())),
                      Contains("basisu.glb: requires the glTF extension "
                               "KHR_texture_basisu, which covrast does not implement"));
  std::ofstream(dir / "scene.json") << scene_of("basisu.glb").dump();
  const auto result =
      covrast::test::run_cli_in(dir.path(), {"render", "scene.json", "-o", "out.png"}, true);
  REQUIRE(result.exit_code == 2);
  REQUIRE_THAT(result.err, Contains("KHR_texture_basisu"));

  // Extensions only used, not required, load (and are ignored where covrast lacks them).
  b.gltf["extensionsRequired"] = {"KHR_materials_unlit"};
  REQUIRE(covrast::load_mesh(dir.write("unlit.glb", b.glb()))->triangle_count() == 1);
  b.gltf.erase("extensionsRequired");
  REQUIRE(covrast::load_mesh(dir.write("used.glb", b.glb()))->triangle_count() == 1);
}

TEST_CASE("KHR_mesh_quantization: normalized short positions load as v / 32767", "[gltf]") {
  TempDir dir;
  GltfBuilder b;
  const int positions = b.add_i16({0, 0, 0, 0, 32767, 0, 0, 0, 0, -32767, 0, 0}, "VEC4", true);
  // VEC4 is not a position type: first the error, then the right VEC3 (padded to 4 bytes per
  // element by a byteStride of 8).
  b.single_mesh({{{"attributes", {{"POSITION", positions}}}}});
  b.gltf["extensionsRequired"] = {"KHR_mesh_quantization"};
  b.gltf["extensionsUsed"] = {"KHR_mesh_quantization"};
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("vec4.glb", b.glb())),
                      Contains("POSITION must be VEC3"));
  b.gltf["accessors"][static_cast<std::size_t>(positions)]["type"] = "VEC3";
  b.gltf["accessors"][static_cast<std::size_t>(positions)]["count"] = 3;
  b.gltf["bufferViews"][0]["byteStride"] = 8;
  const auto mesh = covrast::load_mesh(dir.write("quantized.glb", b.glb()));
  REQUIRE(mesh->positions == std::vector<glm::vec3>{{0, 0, 0}, {1, 0, 0}, {0, -1, 0}});
}

namespace {

/// Two counter-clockwise triangles of the square [0, 1]^2 at z = 0.5 with normals +z,
/// compressed by libdraco (sequential, lossless), POSITION as unique id 0 and NORMAL as 1.
std::string draco_square() {
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(2);
  const int position =
      builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int normal = builder.AddAttribute(draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32);
  const draco::Vector3f p[4] = {{0, 0, 0.5f}, {1, 0, 0.5f}, {1, 1, 0.5f}, {0, 1, 0.5f}};
  const draco::Vector3f n(0, 0, 1);
  builder.SetAttributeValuesForFace(position, draco::FaceIndex(0), p[0].data(), p[1].data(),
                                    p[2].data());
  builder.SetAttributeValuesForFace(position, draco::FaceIndex(1), p[0].data(), p[2].data(),
                                    p[3].data());
  for (const int face : {0, 1}) {
    builder.SetAttributeValuesForFace(normal, draco::FaceIndex(face), n.data(), n.data(), n.data());
  }
  const std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  REQUIRE(mesh != nullptr);
  draco::Encoder encoder;
  encoder.SetSpeedOptions(10, 10);  // sequential coding, no quantization set: lossless
  draco::EncoderBuffer out;
  REQUIRE(encoder.EncodeMeshToBuffer(*mesh, &out).ok());
  return std::string(out.data(), out.size());
}

/// A glTF document whose one primitive is `stream` (draco_square's layout), with accessors
/// that have no bufferView, as the extension prescribes.
GltfBuilder draco_document(const std::string& stream, int points) {
  GltfBuilder b;
  const int view = b.add_view(stream);
  b.gltf["accessors"] = {{{"componentType", 5126}, {"count", points}, {"type", "VEC3"}},
                         {{"componentType", 5126}, {"count", points}, {"type", "VEC3"}},
                         {{"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}};
  b.single_mesh({{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}},
                  {"indices", 2},
                  {"extensions",
                   {{"KHR_draco_mesh_compression",
                     {{"bufferView", view}, {"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}}}}}}});
  b.gltf["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  b.gltf["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  return b;
}

/// The mesh's triangles as corner positions, each rotated to start at its smallest corner
/// and sorted, so that two meshes compare whatever order the encoder chose.
std::vector<std::array<glm::vec3, 3>> canonical_triangles(const covrast::MeshData& mesh) {
  const auto less = [](const glm::vec3& a, const glm::vec3& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  };
  std::vector<std::array<glm::vec3, 3>> triangles;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    std::array<glm::vec3, 3> corners = {mesh.positions[mesh.indices[t]],
                                        mesh.positions[mesh.indices[t + 1]],
                                        mesh.positions[mesh.indices[t + 2]]};
    while (less(corners[1], corners[0]) || less(corners[2], corners[0])) {
      std::rotate(corners.begin(), corners.begin() + 1, corners.end());
    }
    triangles.push_back(corners);
  }
  std::sort(triangles.begin(), triangles.end(), [&](const auto& a, const auto& b) {
    return std::lexicographical_compare(a.begin(), a.end(), b.begin(), b.end(), less);
  });
  return triangles;
}

}  // namespace

TEST_CASE("KHR_draco_mesh_compression primitives decode with libdraco (.glb and .gltf)", "[gltf]") {
  TempDir dir;
  const std::string stream = draco_square();
  draco::DecoderBuffer probe;
  probe.Init(stream.data(), stream.size());
  const auto decoded = draco::Decoder().DecodeMeshFromBuffer(&probe);
  REQUIRE(decoded.ok());
  const int points = static_cast<int>(decoded.value()->num_points());
  GltfBuilder b = draco_document(stream, points);

  const std::vector<std::array<glm::vec3, 3>> expected = {
      {glm::vec3(0, 0, 0.5f), glm::vec3(1, 0, 0.5f), glm::vec3(1, 1, 0.5f)},
      {glm::vec3(0, 0, 0.5f), glm::vec3(1, 1, 0.5f), glm::vec3(0, 1, 0.5f)}};
  const auto glb_mesh = covrast::load_mesh(dir.write("square.glb", b.glb()));
  REQUIRE(canonical_triangles(*glb_mesh) == expected);
  REQUIRE(glb_mesh->corner_normals == std::vector<glm::vec3>(6, glm::vec3(0, 0, 1)));

  // The same document as .gltf text with the buffer as a data: URI.
  const auto text_mesh = covrast::load_mesh(dir.write("square.gltf", b.gltf_text()));
  REQUIRE(canonical_triangles(*text_mesh) == expected);

  // A stream that does not decode, and an attribute id the stream lacks: InputErrors.
  GltfBuilder broken = draco_document(stream.substr(0, stream.size() / 2), points);
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("broken.glb", broken.glb())),
                      Contains("broken.glb: mesh 0 primitive 0: KHR_draco_mesh_compression: "
                               "cannot decode"));
  GltfBuilder missing = draco_document(stream, points);
  missing.gltf["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]
              ["attributes"]["NORMAL"] = 7;
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("missing.glb", missing.glb())),
                      Contains("missing.glb: mesh 0 primitive 0: KHR_draco_mesh_compression: "
                               "NORMAL names Draco attribute 7, which the stream does not hold"));
  // The POSITION accessor's count must equal the stream's points (the extension requires it,
  // and it bounds what covrast copies from the stream by the checked accessor count).
  GltfBuilder miscounted = draco_document(stream, points + 1);
  REQUIRE_THROWS_WITH(
      covrast::load_mesh(dir.write("miscounted.glb", miscounted.glb())),
      Contains("miscounted.glb: mesh 0 primitive 0: KHR_draco_mesh_compression: the stream "
               "holds " +
               std::to_string(points) + " points, the POSITION accessor's count is " +
               std::to_string(points + 1) + " (they must be equal)"));
}

namespace {

/// The triangle (0,0,0), (1,0,0), (0,1,0) with NORMAL +z, as POSITION and NORMAL accessors.
json unit_triangle(GltfBuilder& b) {
  const int positions = b.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  const int normals = b.add_floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
  return {{"POSITION", positions}, {"NORMAL", normals}};
}

void require_positions(const covrast::MeshData& mesh, const std::vector<glm::vec3>& expected) {
  REQUIRE(mesh.positions.size() == expected.size());
  for (std::size_t v = 0; v < expected.size(); ++v) {
    for (int c = 0; c < 3; ++c) {
      INFO("vertex " << v << " component " << c);
      REQUIRE(mesh.positions[v][c] == Approx(expected[v][c]).margin(1e-6));
    }
  }
}

}  // namespace

TEST_CASE("glTF morph targets apply the mesh's default weights, or the node's", "[gltf]") {
  TempDir dir;
  GltfBuilder b;
  const json attributes = unit_triangle(b);
  // Target 0 lifts vertex 2 by (0, 1, 0) and tilts its normal by (1, 0, 0); target 1 moves
  // vertex 1 by (1, 0, 0).
  const int lift = b.add_floats({0, 0, 0, 0, 0, 0, 0, 1, 0}, "VEC3");
  const int tilt = b.add_floats({0, 0, 0, 0, 0, 0, 1, 0, 0}, "VEC3");
  const int stretch = b.add_floats({0, 0, 0, 1, 0, 0, 0, 0, 0}, "VEC3");
  b.gltf["scenes"] = {{{"nodes", {0, 1}}}};
  // Node 0 uses the mesh's weights (0.5, 0.25); node 1, moved by z = 1, its own (1, 0).
  b.gltf["nodes"] = {{{"mesh", 0}},
                     {{"mesh", 0}, {"weights", {1.0, 0.0}}, {"translation", {0, 0, 1}}}};
  const json targets = {{{"POSITION", lift}, {"NORMAL", tilt}}, {{"POSITION", stretch}}};
  const json primitive = {{"attributes", attributes}, {"targets", targets}};
  b.gltf["meshes"] = {{{"weights", {0.5, 0.25}}, {"primitives", {primitive}}}};
  const auto mesh = covrast::load_mesh(dir.write("morph.glb", b.glb()));
  // p = p_0 + sum_i w_i d_i.
  require_positions(*mesh, {{0, 0, 0},
                            {1.25f, 0, 0},
                            {0, 1.5f, 0},  //
                            {0, 0, 1},
                            {1, 0, 1},
                            {0, 2, 1}});
  // Vertex 2's normal: normalize((0, 0, 1) + w (1, 0, 0)), w = 0.5, then 1.
  REQUIRE(mesh->corner_normals.size() == 6);
  const float a = static_cast<float>(1 / std::sqrt(1.25)), s = static_cast<float>(std::sqrt(0.5));
  REQUIRE(mesh->corner_normals[2].x == Approx(0.5f * a));
  REQUIRE(mesh->corner_normals[2].z == Approx(a));
  REQUIRE(mesh->corner_normals[5].x == Approx(s));
  REQUIRE(mesh->corner_normals[5].z == Approx(s));
  REQUIRE(mesh->corner_normals[0] == glm::vec3(0, 0, 1));

  b.gltf["meshes"][0]["weights"] = {0.5};
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("weights.glb", b.glb())),
                      Contains("weights.glb: mesh 0 primitive 0: 2 morph targets but 1 weights"));
}

namespace {

/// A skinned triangle: joint 0 is node 1 (the origin), joint 1 is node 2 at (0, 1, 0) turned
/// by 90 degrees about +z, bound at (0, 1, 0) (inverse bind matrix: translate by (0, -1, 0)).
/// The mesh node 0 is moved by (100, 0, 0), which skinning must ignore. Vertices: (1, 0, 0)
/// on joint 0, (0, 2, 0) on joint 1, (0, 1, 0) half on each.
GltfBuilder skinned_triangle() {
  GltfBuilder b;
  const int positions = b.add_floats({1, 0, 0, 0, 2, 0, 0, 1, 0}, "VEC3");
  const int normals = b.add_floats({0, 0, 1, 1, 0, 0, 0, 0, 1}, "VEC3");
  const int joints = b.add_u16({0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}, "VEC4");
  const int weights = b.add_floats({1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0}, "VEC4");
  const int inverse_binds = b.add_floats({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0,  0, 1,  //
                                          1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1},
                                         "MAT4");
  const double h = std::sqrt(0.5);
  b.gltf["scenes"] = {{{"nodes", {0, 1}}}};
  b.gltf["nodes"] = {{{"mesh", 0}, {"skin", 0}, {"translation", {100, 0, 0}}},
                     {{"children", {2}}},
                     {{"translation", {0, 1, 0}}, {"rotation", {0, 0, h, h}}}};
  b.gltf["skins"] = {{{"joints", {1, 2}}, {"inverseBindMatrices", inverse_binds}}};
  b.gltf["meshes"] = {{{"primitives",
                        {{{"attributes",
                           {{"POSITION", positions},
                            {"NORMAL", normals},
                            {"JOINTS_0", joints},
                            {"WEIGHTS_0", weights}}}}}}}};
  return b;
}

}  // namespace

TEST_CASE("glTF skins pose the vertices by the joints' static transforms", "[gltf]") {
  TempDir dir;
  GltfBuilder b = skinned_triangle();
  const auto mesh = covrast::load_mesh(dir.write("skin.glb", b.glb()));
  // v' = sum_i w_i G(joint_i) IBM_i v; joint 1: T(0,1,0) Rz(90) T(0,-1,0) (0,2,0) = (-1,1,0);
  // (0,1,0) is a fixed point of both joints.
  require_positions(*mesh, {{1, 0, 0}, {-1, 1, 0}, {0, 1, 0}});
  // Vertex 1's normal (1, 0, 0) turns with joint 1 to (0, 1, 0).
  REQUIRE(mesh->corner_normals[1].x == Approx(0.0f).margin(1e-6));
  REQUIRE(mesh->corner_normals[1].y == Approx(1.0f));

  b.gltf["skins"][0]["joints"] = {1};
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("joints.glb", b.glb())),
                      Contains("joints.glb: mesh 0 primitive 0: joint 1 out of range (1 joints)"));
  b = skinned_triangle();
  b.gltf["scenes"][0]["nodes"] = {0};
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("scene.glb", b.glb())),
                      Contains("scene.glb: node 0: skin 0: joint node 1 is not in the scene"));
}

TEST_CASE("glTF skin joints must be unsigned integers within the skin (issue 28)", "[gltf]") {
  TempDir dir;
  // Float joints (-1e10 or -1) and signed bytes (-1) were converted to indices: a crash or
  // a read before the joint matrices. The component type is checked, naming the accessor.
  const auto with_joints = [](const std::function<int(GltfBuilder&)>& add) {
    GltfBuilder b = skinned_triangle();
    b.gltf["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] = add(b);
    return b;
  };
  const std::string message =
      "mesh 0 primitive 0: JOINTS_0 (accessor 5) has component type 5126: joints must be "
      "UNSIGNED_BYTE (5121) or UNSIGNED_SHORT (5123)";
  for (const float value : {-1e10f, -1.0f, std::numeric_limits<float>::quiet_NaN()}) {
    const GltfBuilder b = with_joints([&](GltfBuilder& g) {
      return g.add_floats({value, 0, 0, 0, value, 0, 0, 0, value, 0, 0, 0}, "VEC4");
    });
    REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("float.glb", b.glb())),
                        Contains("float.glb: " + message));
  }
  GltfBuilder b = with_joints([](GltfBuilder& g) {
    std::string bytes(12, '\0');
    bytes[0] = bytes[4] = bytes[8] = '\xff';  // -1 as a signed byte
    const int view = g.add_view(bytes);
    g.gltf["accessors"].push_back(
        {{"bufferView", view}, {"componentType", 5120}, {"count", 3}, {"type", "VEC4"}});
    return static_cast<int>(g.gltf["accessors"].size()) - 1;
  });
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("byte.glb", b.glb())),
                      Contains("byte.glb: mesh 0 primitive 0: JOINTS_0 (accessor 5) has component "
                               "type 5120: joints must be"));
  // Weights: FLOAT or normalized unsigned integers only.
  b = skinned_triangle();
  b.gltf["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] =
      b.add_u16({65535, 0, 0, 0, 65535, 0, 0, 0, 65535, 0, 0, 0}, "VEC4");
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("weights.glb", b.glb())),
                      Contains("weights.glb: mesh 0 primitive 0: WEIGHTS_0 (accessor 5) has "
                               "component type 5123: weights must be FLOAT"));
  b.gltf["accessors"][5]["normalized"] = true;
  const auto mesh = covrast::load_mesh(dir.write("normalized.glb", b.glb()));
  REQUIRE(mesh->positions.size() == 3);
  // An unsigned joint number past the skin's joints is an error, not a read past them.
  b = skinned_triangle();
  b.gltf["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] =
      b.add_u16({65535, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}, "VEC4");
  REQUIRE_THROWS_WITH(
      covrast::load_mesh(dir.write("range.glb", b.glb())),
      Contains("range.glb: mesh 0 primitive 0: joint 65535 out of range (2 joints)"));
}

TEST_CASE("EXT_mesh_gpu_instancing draws the mesh once per instance", "[gltf]") {
  TempDir dir;
  GltfBuilder b;
  const json attributes = unit_triangle(b);
  const double h = std::sqrt(0.5);
  // Instance 0: at (0, 5, 0); instance 1: turned by 90 degrees about +z; instance 2: mirrored
  // in x (its winding must be turned back). All under a node moved by (10, 0, 0).
  const int translation = b.add_floats({0, 5, 0, 0, 0, 0, 0, 0, 0}, "VEC3");
  const int rotation = b.add_floats(
      {0, 0, 0, 1, 0, 0, static_cast<float>(h), static_cast<float>(h), 0, 0, 0, 1}, "VEC4");
  const int scale = b.add_floats({1, 1, 1, 1, 1, 1, -1, 1, 1}, "VEC3");
  b.single_mesh({{{"attributes", attributes}}});
  b.gltf["nodes"][0]["translation"] = {10, 0, 0};
  b.gltf["nodes"][0]["extensions"] = {
      {"EXT_mesh_gpu_instancing",
       {{"attributes", {{"TRANSLATION", translation}, {"ROTATION", rotation}, {"SCALE", scale}}}}}};
  b.gltf["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
  b.gltf["extensionsRequired"] = {"EXT_mesh_gpu_instancing"};
  const auto mesh = covrast::load_mesh(dir.write("instances.glb", b.glb()));
  require_positions(*mesh, {{10, 5, 0},
                            {11, 5, 0},
                            {10, 6, 0},  //
                            {10, 0, 0},
                            {10, 1, 0},
                            {9, 0, 0},  //
                            {10, 0, 0},
                            {9, 0, 0},
                            {10, 1, 0}});
  REQUIRE(mesh->indices == std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5, 6, 8, 7});
  for (const float z : winding_z(*mesh)) REQUIRE(z > 0.0f);

  b.gltf["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] =
      b.add_floats({1, 1, 1}, "VEC3");
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("counts.glb", b.glb())),
                      Contains("counts.glb: node 0: EXT_mesh_gpu_instancing: TRANSLATION, "
                               "ROTATION and SCALE counts differ"));
}

namespace {

/// A red square [-1, 1]^2 at z = 0 (node 0); camera 0 (perspective, yfov 0.5, znear 0.5,
/// zfar 50) at node 2, a child of node 1: node 1 moves by (0, 0, -5), node 2 by (0, 0, 10),
/// so the camera is at (0, 0, 5) looking down -z at the square. Camera 1 is orthographic (at
/// node 3, at (0, 0, -5)),
/// camera 2 is on no node, camera 3 (at node 4, like camera 0) has no zfar.
GltfBuilder camera_file() {
  GltfBuilder b;
  const int positions = b.add_floats({-1, -1, 0, 1, -1, 0, -1, 1, 0, 1, 1, 0}, "VEC3");
  b.gltf["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {1, 0, 0, 1}}}}}};
  b.gltf["meshes"] = {
      {{"primitives",
        {{{"attributes", {{"POSITION", positions}}}, {"mode", 5}, {"material", 0}}}}}};
  b.gltf["cameras"] = {
      {{"type", "perspective"},
       {"perspective", {{"yfov", 0.5}, {"znear", 0.5}, {"zfar", 50}, {"aspectRatio", 2.0}}}},
      {{"type", "orthographic"},
       {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.5}, {"zfar", 50}}}},
      {{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.5}, {"zfar", 50}}}},
      {{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.5}}}}};
  b.gltf["scenes"] = {{{"nodes", {0, 1}}}};
  b.gltf["nodes"] = {{{"mesh", 0}},
                     {{"translation", {0, 0, -5}}, {"children", {2, 3, 4}}},
                     {{"translation", {0, 0, 10}}, {"camera", 0}},
                     {{"camera", 1}},
                     {{"translation", {0, 0, 10}}, {"camera", 3}}};
  return b;
}

/// A scene of `meshes` (in that order) whose camera is {"gltf": `camera`}.
json camera_scene(const json& camera, const json& meshes) {
  return {{"width", 32}, {"height", 16}, {"camera", {{"gltf", camera}}}, {"meshes", meshes}};
}

}  // namespace

TEST_CASE("a scene may take its camera from its first glTF mesh", "[gltf]") {
  TempDir dir;
  dir.write("cameras.glb", camera_file().glb());
  dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const auto load = [&](const json& scene) {
    std::ofstream(dir / "scene.json") << scene.dump();
    return covrast::load_scene(dir / "scene.json");
  };
  // The first glTF entry (after an OBJ one) with its model matrix: a move by (0, 0, 1).
  const json translated = {{"gltf", "cameras.glb"},
                           {"model", {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 1}, {0, 0, 0, 1}}}};
  const covrast::Scene scene =
      load(camera_scene(0, {{{"obj", "tri.obj"}}, translated, {{"gltf", "cameras.glb"}}}));
  REQUIRE(scene.camera.eye == glm::dvec3(0, 0, 6));  // (0,0,10) + (0,0,-5) + (0,0,1)
  REQUIRE(scene.camera.target == glm::dvec3(0, 0, 5));
  REQUIRE(scene.camera.up == glm::dvec3(0, 1, 0));
  REQUIRE(scene.camera.fovy_deg == Approx(0.5 * 180 / 3.14159265358979323846));
  REQUIRE(scene.camera.near == 0.5);
  REQUIRE(scene.camera.far == 50.0);

  // Without zfar (an infinite projection) the far plane lies beyond every mesh.
  const covrast::Scene infinite = load(camera_scene(3, {{{"gltf", "cameras.glb"}}}));
  REQUIRE(infinite.camera.far >= 2 * std::sqrt(2.0 + 25.0));

  // The camera sees the red square filling the middle of the image; the image's size, not
  // aspectRatio (2 here too), decides the aspect.
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode("coverage");
  options.threads = 1;
  const covrast::Image image = covrast::render(scene, options).color;
  REQUIRE(image.pixel(16, 8)[0] == 255);
  REQUIRE(image.pixel(16, 8)[1] == 0);
  REQUIRE(image.pixel(0, 0)[0] == 0);  // tan(0.25) * 5 = 1.28 > 1: the corners are outside
}

TEST_CASE("bad glTF cameras are InputErrors naming the scene key and the camera", "[gltf]") {
  TempDir dir;
  dir.write("cameras.glb", camera_file().glb());
  dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const json gltf_mesh = {{{"gltf", "cameras.glb"}}};
  const std::vector<std::pair<json, std::string>> cases = {
      {camera_scene(2, gltf_mesh), "camera.gltf: camera 2 of 'cameras.glb' is on no node"},
      {camera_scene(4, gltf_mesh),
       "camera.gltf: camera 4 of 'cameras.glb' does not exist (4 "
       "cameras)"},
      {camera_scene(-1, gltf_mesh), "camera.gltf: expected a camera index >= 0, got -1"},
      {camera_scene(0, {{{"obj", "tri.obj"}}}), "camera.gltf: the scene has no glTF mesh"},
      {{{"width", 8},
        {"height", 8},
        {"camera", {{"gltf", 0}, {"fovy_deg", 40}}},
        {"meshes", gltf_mesh}},
       "camera: with \"gltf\" give no other camera key"}};
  for (const auto& [scene, message] : cases) {
    std::ofstream(dir / "scene.json") << scene.dump();
    REQUIRE_THROWS_WITH(covrast::load_scene(dir / "scene.json"),
                        Contains("scene.json: " + message));
  }
}
