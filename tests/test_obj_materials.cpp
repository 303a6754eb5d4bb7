// Tests of OBJ materials and polygons (docs/scene-format.md, "Wavefront OBJ"; src/scene/
// obj_material.cpp, obj_polygon.cpp, mesh_obj.cpp): mtllib/usemtl with Kd, Ks, Ns, Ke, d,
// map_Kd mapped onto covrast's materials, the warnings for missing libraries, unknown names
// and unused statements, bad MTL values as errors, ear clipping of concave polygons (exact
// areas, winding, corner normals), the fan kept for convex ones, the fallback for degenerate
// rings, and l/p statements counted. Every file is written here.
#include <covrast/error.hpp>
#include <covrast/image.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "test_cli_run.hpp"
#include "test_meshes.hpp"
#include "test_tempdir.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using covrast::Material;
using covrast::MeshData;
using covrast::ShadingModel;
using covrast::test::render_mode;
using nlohmann::json;

namespace {

class TempDir : public covrast::test::TempDir {
 public:
  TempDir() : covrast::test::TempDir("covrast-test-objmtl") {}
  fs::path write(const std::string& name, const std::string& contents) const {
    const fs::path file = path() / name;
    fs::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << contents;
    return file;
  }
};

/// A scene of one OBJ mesh seen head-on from (0, 0, 3); lit when `lights` is given.
json scene_of(const std::string& obj, const json& mesh_extra = json::object(),
              const json* lights = nullptr) {
  json mesh = {{"obj", obj}};
  mesh.update(mesh_extra);
  json scene = {{"width", 32},
                {"height", 32},
                {"camera",
                 {{"eye", {0, 0, 3}},
                  {"target", {0, 0, 0}},
                  {"up", {0, 1, 0}},
                  {"fovy_deg", 40},
                  {"near", 0.5},
                  {"far", 10}}},
                {"meshes", json::array({mesh})}};
  if (lights != nullptr) scene["lights"] = *lights;
  return scene;
}

std::string load_error(const fs::path& scene) {
  try {
    covrast::load_scene(scene);
  } catch (const covrast::InputError& e) {
    return e.what();
  }
  FAIL("no InputError for " << scene);
  return {};
}

/// Twice the signed area of triangle t of `mesh` in the xy plane.
double area2_xy(const MeshData& mesh, std::size_t t) {
  const glm::dvec3 a(mesh.positions[mesh.indices[3 * t]]);
  const glm::dvec3 b(mesh.positions[mesh.indices[3 * t + 1]]);
  const glm::dvec3 c(mesh.positions[mesh.indices[3 * t + 2]]);
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

const char* kTwoMaterials = R"(# two materials and their unused statements
newmtl shiny red
Kd 0.8 0.1 0.1
Ks 0.5 0.25 0.125
Ns 64
Ke 0.1 0 0.5
d 0.5
Ka 1 1 1
map_Kd -s 1 1 1 textures/red.png
newmtl green
Kd 0 1 0
Ks 0.5
illum 1
Tr 0.25
map_Bump bump.png
bump bump.png
newmtl plain
Kd 0.5
)";

// A triangle before any usemtl, two quads sharing the edge 2-3 (the left one red, the right
// one green), a triangle of the unknown material "nothing" and one of "plain".
const char* kTwoMaterialObj = R"(mtllib two.mtl
v -1 -1 0
v 0 -1 0
v 0 1 0
v -1 1 0
v 1 -1 0
v 1 1 0
f 1 2 3
usemtl shiny red
f 1 2 3 4
usemtl green
f 2 5 6 3
usemtl nothing
f 1 2 3
usemtl plain
f 1 2 3
)";

}  // namespace

TEST_CASE("OBJ mtllib/usemtl map Kd, Ks, Ns, Ke, d, map_Kd onto materials", "[obj][mtl]") {
  TempDir dir;
  dir.write("two.mtl", kTwoMaterials);
  dir.write("two.obj", kTwoMaterialObj);
  dir.write("scene.json", scene_of("two.obj").dump());
  std::filesystem::create_directories(dir / "textures");
  covrast::write_png(covrast::Image{2, 2, std::vector<std::uint8_t>(12, 200), {}},
                     dir / "textures/red.png");
  const covrast::Scene scene = covrast::load_scene(dir / "scene.json");
  const MeshData& mesh = *scene.meshes[0].mesh;
  // Materials in order of first use, then the default (lambert, white).
  REQUIRE(mesh.materials.size() == 4);
  const Material& red = mesh.materials[0];
  CHECK(red.model == ShadingModel::BlinnPhong);
  CHECK(red.specular_linear == glm::vec3(0.5f, 0.25f, 0.125f));
  CHECK(red.shininess == 64.0f);
  CHECK(red.emissive_linear == glm::vec3(0.1f, 0.0f, 0.5f));
  CHECK(red.base_alpha == 0.5);
  CHECK(red.base_color_texture_path ==
        (dir.path() / "textures/red.png").lexically_normal().string());
  REQUIRE(red.base_color_texture.texture != nullptr);  // map_Kd decoded (sRGB)
  CHECK(red.base_color_texture.texture->levels.front().width == 2);
  const Material& green = mesh.materials[1];
  CHECK(green.model == ShadingModel::Lambert);  // illum 1: no highlight even with Ks
  CHECK(green.base_alpha == 0.75);              // 1 - Tr
  CHECK(green.base_color_texture_path.empty());
  CHECK(mesh.materials[2].model == ShadingModel::Lambert);  // "plain": no Ks
  CHECK(mesh.materials[3].model == ShadingModel::Lambert);  // the default
  CHECK(mesh.materials[3].base_alpha == 1.0);
  // Triangles: default, red x2, green x2, unknown -> default, plain.
  REQUIRE(mesh.triangle_materials == std::vector<std::uint32_t>{3, 0, 0, 1, 1, 3, 2});
  // Base colours as vertex colours (Kd differs): each triangle's corners carry its Kd; the
  // vertices shared between materials were copied, at the same positions.
  REQUIRE(mesh.colors_linear.size() == mesh.positions.size());
  const glm::vec3 kd[] = {{0.8f, 0.1f, 0.1f}, {0.0f, 1.0f, 0.0f}, glm::vec3(0.5f), glm::vec3(1.0f)};
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      CHECK(mesh.colors_linear[mesh.indices[3 * t + k]] == kd[mesh.triangle_materials[t]]);
    }
  }
  CHECK(mesh.positions.size() > 6);
  CHECK(mesh.indices[3] != 0);  // red's corner at vertex 1, which the first triangle owns
  CHECK(mesh.positions[mesh.indices[3]] == mesh.positions[0]);
  REQUIRE(scene.meshes[0].color_source == covrast::ColorSource::Vertex);
  // One warning for the library's unused statements, one for the unknown name.
  const std::string mtl = (dir.path() / "two.mtl").lexically_normal().string();
  const std::string obj = (dir.path() / "two.obj").lexically_normal().string();
  CHECK(scene.warnings ==
        std::vector<std::string>{
            obj + ": 1 usemtl names not in its material libraries ('nothing'): the default "
                  "material used",
            mtl + ": 2 statements not used (bump 1, map_Bump 1): covrast does not render them",
            obj + ": 1 materials have a map_Kd but the file has no vt: UV (0, 0) used"});
}

TEST_CASE("OBJ materials: one Kd is the uniform colour, unlit and lit alike", "[obj][mtl]") {
  TempDir dir;
  // Kd = srgb_to_linear(0.6) exactly as the scene loader computes it, so that the two scenes
  // below must give the same bytes.
  const float kd = covrast::srgb_to_linear(0.6f);
  char kd_text[64];
  std::snprintf(kd_text, sizeof kd_text, "%.9g", double(kd));
  dir.write("m.mtl", std::string("newmtl m\nKd ") + kd_text + " " + kd_text + " " + kd_text +
                         "\nKs 0.25\nNs 20\n");
  const std::string quad = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n";
  dir.write("with.obj", "mtllib m.mtl\n" + quad + "usemtl m\nf 1 2 3 4\n");
  dir.write("without.obj", quad + "f 1 2 3 4\n");
  const json lights =
      json::array({{{"type", "point"}, {"position", {0.3, 0.2, 1.0}}, {"intensity", 0.8}},
                   {{"type", "ambient"}, {"intensity", 0.1}}});
  dir.write("unlit_with.json", scene_of("with.obj").dump());
  dir.write("unlit_without.json", scene_of("without.obj", {{"color", {0.6, 0.6, 0.6}}}).dump());
  dir.write("lit_with.json", scene_of("with.obj", json::object(), &lights).dump());
  dir.write(
      "lit_without.json",
      scene_of("without.obj",
               {{"color", {0.6, 0.6, 0.6}},
                {"material", {{"model", "blinn-phong"}, {"specular", 0.25}, {"shininess", 20}}}},
               &lights)
          .dump());
  const covrast::Scene unlit = covrast::load_scene(dir / "unlit_with.json");
  REQUIRE(unlit.meshes[0].color_source == covrast::ColorSource::Uniform);
  REQUIRE(unlit.meshes[0].color_linear == glm::vec3(kd));
  REQUIRE(unlit.warnings.empty());
  const covrast::Image a = render_mode(unlit, "coverage", 1);
  CHECK(a.rgb == render_mode(covrast::load_scene(dir / "unlit_without.json"), "coverage", 1).rgb);
  CHECK(int(a.pixel(16, 16)[0]) == 153);  // 0.6 * 255
  const covrast::Scene lit = covrast::load_scene(dir / "lit_with.json");
  REQUIRE(lit.meshes[0].materials[0].model == ShadingModel::BlinnPhong);
  const covrast::Image b = render_mode(lit, "coverage", 1);
  CHECK(b.rgb == render_mode(covrast::load_scene(dir / "lit_without.json"), "coverage", 1).rgb);
  CHECK(b.rgb != a.rgb);
}

TEST_CASE("OBJ: a missing .mtl and unknown names are warnings, --strict fails", "[obj][mtl]") {
  TempDir dir;
  dir.write("a.obj", "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n");
  dir.write("scene.json", scene_of("a.obj").dump());
  const covrast::Scene scene = covrast::load_scene(dir / "scene.json");
  const std::string obj = (dir.path() / "a.obj").lexically_normal().string();
  CHECK(scene.warnings == std::vector<std::string>{
                              obj + ":1: cannot open material library 'gone.mtl': No such file or "
                                    "directory; its materials are not used",
                              obj + ": 1 usemtl names not in its material libraries ('x'): the "
                                    "default material used"});
  CHECK(scene.meshes[0].mesh->materials.empty());  // as without materials
  CHECK(scene.meshes[0].mesh->triangle_count() == 1);
  const auto strict = covrast::test::run_cli_in(
      dir.path(), {"render", "scene.json", "-o", "out.png", "--strict"}, true);
  CHECK(strict.exit_code == 2);
  CHECK_THAT(strict.err, Contains("cannot open material library"));
  CHECK_FALSE(fs::exists(dir / "out.png"));
  const auto lenient =
      covrast::test::run_cli_in(dir.path(), {"render", "scene.json", "-o", "out.png"}, true);
  CHECK(lenient.exit_code == 0);
}

TEST_CASE("bad MTL values are InputErrors naming the .mtl file and line", "[obj][mtl]") {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"newmtl m\nKd 2 0 0\n", "bad.mtl:2: Kd: 2 out of range 0..1"},
      {"newmtl m\nKd 0.5 0.5\n", "bad.mtl:2: Kd: expected a number"},
      {"newmtl m\nNs -1\n", "bad.mtl:2: Ns: -1 out of range >= 0"},
      {"newmtl m\nd 1.5\n", "bad.mtl:2: d: 1.5 out of range 0..1"},
      {"newmtl m\nKe 1 x 1\n", "bad.mtl:2: Ke: expected a number"},
      {"Kd 1 1 1\n", "bad.mtl:1: Kd before the first newmtl"},
      {"newmtl m\nmap_Kd\n", "bad.mtl:2: map_Kd: expected a file name"},
  };
  for (const auto& [mtl, message] : cases) {
    TempDir dir;
    dir.write("bad.mtl", mtl);
    dir.write("a.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n");
    dir.write("scene.json", scene_of("a.obj").dump());
    INFO(mtl);
    CHECK_THAT(load_error(dir / "scene.json"), Contains(message));
  }
  TempDir dir;
  dir.write("a.obj", "mtllib\nv 0 0 0\n");
  dir.write("scene.json", scene_of("a.obj").dump());
  CHECK_THAT(load_error(dir / "scene.json"), Contains("a.obj:1: mtllib needs a file name"));
}

TEST_CASE("OBJ concave polygons are ear-clipped, convex ones keep the fan", "[obj][polygon]") {
  TempDir dir;
  // An L (area 3) whose reflex corner is (0, 1): the fan from (1, 1) would fold over (its
  // first triangle turns clockwise). Every corner has its own normal, to follow the corners.
  const char* obj = R"(v 1 1 0
v 0 1 0
v 0 2 0
v -1 2 0
v -1 0 0
v 1 0 0
vn 0 0 1
vn 0 0.1 1
vn 0 0.2 1
vn 0 0.3 1
vn 0 0.4 1
vn 0 0.5 1
f 1//1 2//2 3//3 4//4 5//5 6//6
)";
  const fs::path l_file = dir.write("l.obj", obj);
  const auto mesh = covrast::load_mesh(l_file);
  REQUIRE(mesh->triangle_count() == 4);
  double area2 = 0.0;
  for (std::size_t t = 0; t < 4; ++t) {
    CHECK(area2_xy(*mesh, t) >= 0.0);  // the ring's counter-clockwise winding kept
    area2 += area2_xy(*mesh, t);
  }
  CHECK(area2 == 6.0);  // exactly twice the L's area: no overlap, nothing outside
  // Each corner keeps its own vn: corner normal i belongs to vertex i.
  for (std::size_t c = 0; c < mesh->indices.size(); ++c) {
    CHECK(mesh->corner_normals[c] == glm::vec3(0.0f, 0.1f * float(mesh->indices[c]), 1.0f));
  }
  // The same L in a tilted plane whose normal is mostly -y (the projection is mirrored
  // back): the same split.
  std::string tilted;
  for (const auto& [x, y] :
       std::vector<std::pair<int, int>>{{1, 1}, {0, 1}, {0, 2}, {-1, 2}, {-1, 0}, {1, 0}}) {
    tilted +=
        "v " + std::to_string(x) + " " + std::to_string(0.25 * y) + " " + std::to_string(y) + "\n";
  }
  const auto tilted_mesh = covrast::load_mesh(dir.write("tilted.obj", tilted + "f 1 2 3 4 5 6\n"));
  CHECK(tilted_mesh->indices == mesh->indices);
  // A convex hexagon keeps the fan (0, k, k + 1), as before ear clipping existed.
  const auto hexagon =
      covrast::load_mesh(dir.write("hex.obj",
                                   "v 2 0 0\nv 1 2 0\nv -1 2 0\nv -2 0 0\nv -1 -2 0\nv 1 -2 0\n"
                                   "f 1 2 3 4 5 6\n"));
  CHECK(hexagon->indices == std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5});
}

TEST_CASE("a concave OBJ polygon renders only its own pixels", "[obj][polygon]") {
  TempDir dir;
  // A U opening upwards, counter-clockwise from its top left corner: the fan from there would
  // fill its gap.
  dir.write("u.obj",
            "v -0.25 0.75 0\nv -0.25 -0.25 0\nv 0.25 -0.25 0\nv 0.25 0.75 0\nv 0.75 0.75 0\n"
            "v 0.75 -0.75 0\nv -0.75 -0.75 0\nv -0.75 0.75 0\nf 8 7 6 5 4 3 2 1\n");
  dir.write("scene.json", scene_of("u.obj", {{"color", {1, 1, 1}}}).dump());
  const covrast::Scene scene = covrast::load_scene(dir / "scene.json");
  REQUIRE(scene.warnings.empty());
  const covrast::Image image = render_mode(scene, "aliased", 1);
  // The camera sees [-h, h], h = 3 tan(20 deg), across the 32 pixels at z = 0; px() is the
  // column of a world x (and 31 - px() the row of a world y).
  const double half = 3.0 * std::tan(20.0 * 3.14159265358979323846 / 180.0);
  const auto px = [&](double world) { return int((world + half) / (2.0 * half) * 32.0); };
  CHECK(int(image.pixel(px(0.0), 31 - px(0.4))[0]) == 0);     // inside the U's gap
  CHECK(int(image.pixel(px(0.0), 31 - px(-0.5))[0]) == 255);  // its bottom bar
  CHECK(int(image.pixel(px(-0.5), 31 - px(0.4))[0]) == 255);  // its left arm
}

TEST_CASE("degenerate OBJ polygons fall back to the fan with a warning, l and p counted",
          "[obj][polygon]") {
  TempDir dir;
  // A bow tie (self-intersecting, zero Newell normal) and four corners on one line.
  dir.write("bad.obj",
            "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\n"
            "f 1 2 3 4\nf 1 3 5 6\nl 1 2\nl 2 3 4\np 1\n");
  dir.write("scene.json", scene_of("bad.obj").dump());
  const covrast::Scene scene = covrast::load_scene(dir / "scene.json");
  const MeshData& mesh = *scene.meshes[0].mesh;
  CHECK(mesh.indices == std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 2, 4, 0, 4, 5});
  const std::string obj = (dir.path() / "bad.obj").lexically_normal().string();
  CHECK(scene.warnings ==
        std::vector<std::string>{
            obj + ": 2 polygons are degenerate, self-intersecting or have over 4096 corners: "
                  "split as the fan (0, k, k + 1)",
            obj + ": 2 line (l) and 1 point (p) statements not drawn: covrast draws faces only"});
}

TEST_CASE("OBJ map_Kd file names with spaces are read whole, after the options (issue 28)",
          "[obj][mtl][textures]") {
  TempDir dir;
  std::vector<std::uint8_t> texels(4 * 4 * 3, 90);
  covrast::write_png(covrast::Image{4, 4, texels, {}}, dir / "my tex.png");
  covrast::write_png(covrast::Image{4, 4, texels, {}}, dir / "-dash.png");
  const std::string obj =
      "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl a\n"
      "f 1/1 2/1 3/1\n";
  dir.write("m.obj", obj);
  // The last token ("tex.png") was taken: a missing file.
  for (const char* line :
       {"map_Kd my tex.png", "map_Kd  my tex.png  ", "map_Kd -s 1 1 1 my tex.png",
        "map_Kd -o 0.5 my tex.png", "map_Kd -bm 0.2 -clamp on my tex.png",
        "map_Kd -blendu on -blendv off -mm 0 1 -t 1 2 my tex.png",
        "map_Kd -imfchan r -texres 64 -cc off -boost 2 my tex.png"}) {
    INFO(line);
    dir.write("m.mtl", "newmtl a\n" + std::string(line) + "\n");
    const auto mesh = covrast::load_mesh(dir / "m.obj");
    REQUIRE(mesh->materials[0].base_color_texture.texture != nullptr);
    CHECK(mesh->materials[0].base_color_texture_path == (dir / "my tex.png").string());
  }
  // A name that starts with '-' but is no option is the file name.
  dir.write("m.mtl", "newmtl a\nmap_Kd -dash.png\n");
  CHECK(covrast::load_mesh(dir / "m.obj")->materials[0].base_color_texture.texture != nullptr);
  dir.write("m.mtl", "newmtl a\nmap_Kd -s 1 1 1\n");
  CHECK_THROWS_WITH(covrast::load_mesh(dir / "m.obj"),
                    Catch::Matchers::Contains("m.mtl:2: map_Kd: expected a file name"));
  dir.write("m.mtl", "newmtl a\nmap_Kd -bm\n");
  CHECK_THROWS_WITH(covrast::load_mesh(dir / "m.obj"),
                    Catch::Matchers::Contains("m.mtl:2: map_Kd: option -bm needs a value"));
}

TEST_CASE("OBJ map_Kd textures the surface in sRGB, one decode per file, missing is an error",
          "[obj][mtl][textures]") {
  TempDir dir;
  dir.write("quad.mtl", "newmtl a\nKd 1 1 1\nmap_Kd tex.png\nnewmtl b\nKd 1 1 1\nmap_Kd tex.png\n");
  dir.write("quad.obj",
            "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
            "vt 0 1\nusemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 1/1 3/3 4/4\n");
  dir.write("scene.json", scene_of("quad.obj").dump());
  // One colour everywhere, so every filter and level of detail gives exactly that texel.
  std::vector<std::uint8_t> texels;
  for (int i = 0; i < 16; ++i) texels.insert(texels.end(), {200, 100, 50});
  covrast::write_png(covrast::Image{4, 4, texels, {}}, dir / "tex.png");
  const covrast::Scene scene = covrast::load_scene(dir / "scene.json");
  const MeshData& mesh = *scene.meshes[0].mesh;
  REQUIRE(mesh.materials.size() >= 2);
  REQUIRE(mesh.materials[0].base_color_texture.texture != nullptr);
  CHECK(mesh.materials[0].base_color_texture.texture ==
        mesh.materials[1].base_color_texture.texture);
  CHECK(scene.warnings.empty());
  for (const char* mode : {"coverage", "aliased", "reference"}) {
    INFO(mode);
    const covrast::Image image = render_mode(scene, mode, 1);
    // Kd 1 x the texel, unlit: the texel's own sRGB bytes in the middle of the quad.
    const std::size_t centre = 3 * (16 * 32 + 16);
    CHECK(std::abs(int(image.rgb[centre]) - 200) <= 1);
    CHECK(std::abs(int(image.rgb[centre + 1]) - 100) <= 1);
    CHECK(std::abs(int(image.rgb[centre + 2]) - 50) <= 1);
  }
  // A missing map_Kd image: a warning naming it once (both materials use it), and the quad
  // drawn with Kd alone (docs/limits.md, "Missing files").
  std::filesystem::remove(dir / "tex.png");
  const covrast::Scene without = covrast::load_scene(dir / "scene.json");
  REQUIRE(without.warnings.size() == 1);
  CHECK_THAT(without.warnings[0], Catch::Matchers::Contains("map_Kd tex.png: no such file"));
  CHECK(without.meshes[0].mesh->materials[0].base_color_texture.texture == nullptr);
  const covrast::Image plain = render_mode(without, "coverage", 1);
  const std::size_t centre = 3 * (16 * 32 + 16);
  CHECK(int(plain.rgb[centre]) == 255);
  CHECK(int(plain.rgb[centre + 1]) == 255);
  CHECK(int(plain.rgb[centre + 2]) == 255);
}
