// Hidden back-face culling: the load-time topology analysis (analyze_mesh_topology: closed,
// consistently oriented, orientation sign, bounds) and the renderer's use of it
// (RenderOptions::cull_hidden_backfaces): culling must never change an aliased image, must
// happen for closed meshes seen from outside (mirrored instances too), and must not happen
// when the eye is inside, the near or far plane cuts the mesh, the mesh is open, or the
// analysis is missing or stale. In coverage mode, culling may only bring the image closer
// to the reference.
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "test_meshes.hpp"
#include "test_splits.hpp"
#include "test_tempdir.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using covrast::analyze_mesh_topology;
using covrast::ColorSource;
using covrast::MeshData;
using covrast::MeshInstance;
using covrast::ModeKind;
using covrast::RenderOptions;
using covrast::RenderResult;
using covrast::Scene;
using covrast::test::uv_sphere;

/// The cube [-1, 1]^3: 8 shared vertices, 12 triangles, counter-clockwise seen from outside.
/// With `per_face_vertices`, each face has its own 4 vertices (24 in all, equal positions).
std::shared_ptr<MeshData> cube(bool per_face_vertices = false) {
  auto m = std::make_shared<MeshData>();
  m->source = "cube";
  auto corner = [](int i) {
    return glm::vec3(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f);
  };
  if (!per_face_vertices) {
    for (int i = 0; i < 8; ++i) m->positions.push_back(corner(i));
  }
  // Each face: the axis bit, its value, and the corners in cyclic order around the face.
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int a = 1 << axis, u = 1 << ((axis + 1) % 3), v = 1 << ((axis + 2) % 3);
      const int base = side ? a : 0;
      std::array<int, 4> quad = {base, base | u, base | u | v, base | v};
      // (u, v, axis) is right-handed: the cycle is counter-clockwise seen from +axis, so
      // keep it on the + side and reverse it on the - side.
      if (side == 0) std::reverse(quad.begin(), quad.end());
      std::array<std::uint32_t, 4> id;
      for (int k = 0; k < 4; ++k) {
        if (per_face_vertices) {
          id[k] = std::uint32_t(m->positions.size());
          m->positions.push_back(corner(quad[k]));
        } else {
          id[k] = std::uint32_t(quad[k]);
        }
      }
      m->indices.insert(m->indices.end(), {id[0], id[1], id[2], id[0], id[2], id[3]});
    }
  }
  return m;
}

std::shared_ptr<MeshData> reversed(std::shared_ptr<MeshData> m) {
  for (std::size_t t = 0; t + 2 < m->indices.size(); t += 3)
    std::swap(m->indices[t + 1], m->indices[t + 2]);
  return m;
}

/// Appends `b`'s triangles, moved by `offset`, to `a`.
void append(MeshData& a, const MeshData& b, glm::vec3 offset) {
  const auto base = std::uint32_t(a.positions.size());
  for (const glm::vec3& p : b.positions) a.positions.push_back(p + offset);
  for (std::uint32_t i : b.indices) a.indices.push_back(base + i);
}

int orientation_of(std::shared_ptr<MeshData> m) {
  analyze_mesh_topology(*m);
  return m->closed_orientation;
}

std::shared_ptr<MeshData> analyzed(std::shared_ptr<MeshData> m) {
  analyze_mesh_topology(*m);
  return m;
}

/// 128 x 96, eye on +z looking at the origin.
Scene base_scene(double eye_z = 8.0, double near = 1.0, double far = 50.0) {
  Scene s;
  s.width = 128;
  s.height = 96;
  s.background_linear = glm::vec3(0.02f, 0.03f, 0.05f);
  s.camera.eye = glm::dvec3(0.0, 0.0, eye_z);
  s.camera.target = glm::dvec3(0.0);
  s.camera.up = glm::dvec3(0.0, 1.0, 0.0);
  s.camera.fovy_deg = 40.0;
  s.camera.near = near;
  s.camera.far = far;
  return s;
}

void add(Scene& s, std::shared_ptr<const MeshData> mesh, const glm::dmat4& model, glm::vec3 color,
         ColorSource source = ColorSource::Uniform) {
  MeshInstance instance;
  instance.mesh = std::move(mesh);
  instance.model = model;
  instance.color_source = source;
  instance.color_linear = color;
  s.meshes.push_back(std::move(instance));
}

glm::dmat4 translate_scale(glm::dvec3 t, glm::dvec3 scale) {
  return glm::scale(glm::translate(glm::dmat4(1.0), t), scale);
}

RenderResult render_scene(const Scene& s, ModeKind mode, bool cull, int threads = 2,
                          int tile = 64) {
  RenderOptions o;
  o.mode.kind = mode;
  o.mode.samples = mode == ModeKind::Reference ? 64 : 1;
  o.cull_hidden_backfaces = cull;
  o.threads = threads;
  o.tile = tile;
  return covrast::render(s, o);
}

/// Renders aliased with and without culling; requires byte-identical colour images and no
/// culling when off. Returns the number of back faces culled.
std::uint64_t aliased_culled_identical(const Scene& s) {
  const RenderResult on = render_scene(s, ModeKind::Aliased, true);
  const RenderResult off = render_scene(s, ModeKind::Aliased, false);
  CHECK(off.stats.triangles_backface_culled == 0);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < on.color.rgb.size(); ++i)
    differing += on.color.rgb[i] != off.color.rgb[i] ? 1 : 0;
  CHECK(differing == 0);
  // Culled triangles are counted in triangles_culled too; the rest reach set-up.
  CHECK(on.stats.triangles_culled ==
        off.stats.triangles_culled + on.stats.triangles_backface_culled);
  CHECK(on.stats.triangles_setup + on.stats.triangles_backface_culled == off.stats.triangles_setup);
  return on.stats.triangles_backface_culled;
}

/// Triangles of the scene that face away from the eye, from the exact world geometry (double):
/// the count culling should reach, up to slivers whose facing flips when snapped.
std::uint64_t geometric_back_faces(const Scene& s) {
  std::uint64_t count = 0;
  for (const MeshInstance& inst : s.meshes) {
    const MeshData& m = *inst.mesh;
    const double sign = m.closed_orientation * (glm::determinant(inst.model) > 0.0 ? 1.0 : -1.0);
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
      glm::dvec3 p[3];
      for (int k = 0; k < 3; ++k)
        p[k] = glm::dvec3(inst.model * glm::dvec4(glm::dvec3(m.positions[m.indices[t + k]]), 1.0));
      const double facing = glm::dot(glm::cross(p[1] - p[0], p[2] - p[0]), s.camera.eye - p[0]);
      count += sign * facing < 0.0 ? 1 : 0;
    }
  }
  return count;
}

/// Largest per-channel difference of two 8-bit images.
int max_abs_diff8(const covrast::Image& a, const covrast::Image& b) {
  int worst = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i)
    worst = std::max(worst, std::abs(a.rgb[i] - b.rgb[i]));
  return worst;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Topology analysis
// ---------------------------------------------------------------------------------------

TEST_CASE("analysis: closed cubes, both windings, welded per-face vertices", "[cull]") {
  CHECK(orientation_of(cube()) == 1);
  CHECK(orientation_of(reversed(cube())) == -1);
  CHECK(orientation_of(cube(true)) == 1);
  CHECK(orientation_of(reversed(cube(true))) == -1);
  auto m = analyzed(cube());
  CHECK(m->bounds_min == glm::vec3(-1.0f));
  CHECK(m->bounds_max == glm::vec3(1.0f));
  CHECK(m->analyzed_triangle_count == 12);
}

TEST_CASE("analysis: open, non-manifold and mixed meshes are not closed", "[cull]") {
  SECTION("a box missing one face") {
    auto m = cube();
    m->indices.resize(m->indices.size() - 6);
    CHECK(orientation_of(m) == 0);
  }
  SECTION("a box missing one triangle") {
    auto m = cube();
    m->indices.resize(m->indices.size() - 3);
    CHECK(orientation_of(m) == 0);
  }
  SECTION("one face wound the wrong way") {
    auto m = cube();
    std::swap(m->indices[1], m->indices[2]);
    std::swap(m->indices[4], m->indices[5]);
    CHECK(orientation_of(m) == 0);
  }
  SECTION("an edge used three times: a fin on a cube edge") {
    auto m = cube();
    m->positions.push_back(glm::vec3(-3.0f, -3.0f, 0.0f));
    m->indices.insert(m->indices.end(), {0, 4, 8});  // edge (0, 4): x = y = -1
    CHECK(orientation_of(m) == 0);
  }
  SECTION("an edge used four times, twice each way: two cubes sharing an edge") {
    auto m = cube();
    append(*m, *cube(), glm::vec3(2.0f, 2.0f, 0.0f));
    // Weld makes them share the edge x = y = 1 of the first and x = y = -1 of the second.
    CHECK(orientation_of(m) == 0);
  }
  SECTION("two separate cubes, one of them inside out") {
    auto m = cube();
    append(*m, *reversed(cube()), glm::vec3(5.0f, 0.0f, 0.0f));
    CHECK(orientation_of(m) == 0);
  }
  SECTION("a flat two-sided square: closed, zero volume") {
    auto m = std::make_shared<MeshData>();
    m->positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    m->indices = {0, 1, 2, 0, 2, 3, 0, 2, 1, 0, 3, 2};
    CHECK(orientation_of(m) == 0);
  }
  SECTION("an index out of range or a NaN position (meshes built in code)") {
    auto m = cube();
    m->indices[5] = 99;
    CHECK(orientation_of(m) == 0);
    auto n = cube();
    n->positions[3].x = std::numeric_limits<float>::quiet_NaN();
    CHECK(orientation_of(n) == 0);
  }
  SECTION("no triangles") {
    auto m = std::make_shared<MeshData>();
    CHECK(orientation_of(m) == 0);
  }
}

TEST_CASE("analysis: degenerate triangles are ignored, separate cubes and spheres are closed",
          "[cull]") {
  SECTION("a cube plus triangles with two equal (welded) vertices") {
    auto m = cube();
    m->positions.push_back(glm::vec3(1.0f, 1.0f, 1.0f));  // same position as vertex 7
    m->indices.insert(m->indices.end(), {0, 0, 1, 7, 8, 2});
    CHECK(orientation_of(m) == 1);
  }
  SECTION("two separate cubes, both outwards, and both inwards") {
    auto m = cube();
    append(*m, *cube(), glm::vec3(5.0f, 0.0f, 0.0f));
    CHECK(orientation_of(m) == 1);
    CHECK(m->bounds_max == glm::vec3(6.0f, 1.0f, 1.0f));
    CHECK(orientation_of(reversed(m)) == -1);
  }
  SECTION("uv spheres") {
    CHECK(orientation_of(uv_sphere(8, 16)) == 1);
    CHECK(orientation_of(uv_sphere(64, 128)) == 1);
    CHECK(orientation_of(reversed(uv_sphere(8, 16))) == -1);
  }
}

TEST_CASE("analysis: load_mesh and load_scene analyse the meshes they load", "[cull]") {
  const auto sphere =
      covrast::load_mesh(std::filesystem::path(COVRAST_SOURCE_DIR) / "scenes" / "sphere5k.obj");
  CHECK(sphere->closed_orientation == 1);
  CHECK(sphere->analyzed_triangle_count == sphere->triangle_count());

  const covrast::test::TempDir temp("covrast-test-cull");
  const std::filesystem::path& dir = temp.path();
  {
    // The cube, inside out, as OBJ (1-based indices).
    auto m = reversed(cube());
    std::ofstream obj(dir / "cube.obj");
    for (const glm::vec3& p : m->positions) obj << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
    for (std::size_t t = 0; t < m->indices.size(); t += 3)
      obj << "f " << m->indices[t] + 1 << ' ' << m->indices[t + 1] + 1 << ' '
          << m->indices[t + 2] + 1 << '\n';
    std::ofstream json(dir / "scene.json");
    json << R"({"width": 32, "height": 32, "meshes": [{"obj": "cube.obj"}], "camera": )"
         << R"({"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fovy_deg": 45, )"
         << R"("near": 1, "far": 10}})";
  }
  const auto loaded = covrast::load_mesh(dir / "cube.obj");
  const Scene scene = covrast::load_scene(dir / "scene.json");
  CHECK(loaded->closed_orientation == -1);
  CHECK(loaded->bounds_min == glm::vec3(-1.0f));
  REQUIRE(scene.meshes.size() == 1);
  CHECK(scene.meshes[0].mesh->closed_orientation == -1);
}

// ---------------------------------------------------------------------------------------
// Rendering
// ---------------------------------------------------------------------------------------

TEST_CASE("closed spheres seen from outside: back faces culled, aliased image unchanged",
          "[cull]") {
  const auto sphere = analyzed(uv_sphere(24, 48));
  Scene s = base_scene();
  // Overlapping spheres at different depths, one of them non-uniformly scaled and rotated.
  add(s, sphere, translate_scale({-0.8, 0.2, 0.0}, {1.2, 1.2, 1.2}), {0.9f, 0.4f, 0.1f});
  add(s, sphere, translate_scale({0.6, -0.1, -1.5}, {1.0, 1.4, 0.8}), {0.1f, 0.6f, 0.9f});
  s.meshes.back().model = glm::rotate(s.meshes.back().model, 0.7, glm::dvec3(1, 1, 0));
  add(s, sphere, translate_scale({0.3, 0.5, 1.0}, {0.5, 0.5, 0.5}), {0.3f, 0.9f, 0.3f});
  const std::uint64_t culled = aliased_culled_identical(s);
  // Each sphere shows less than half of its 2112 faces from outside in perspective, so more
  // than half of them face away; snapping may flip the facing of a few edge-on slivers.
  const std::uint64_t expected = geometric_back_faces(s);
  CHECK(expected > 3 * sphere->triangle_count() / 2);
  CHECK(culled + 20 >= expected);
  CHECK(culled <= expected + 20);

  SECTION("same images and counts for every thread count and tile size") {
    RenderOptions o;
    o.mode.kind = ModeKind::Aliased;
    o.cull_hidden_backfaces = true;
    const RenderResult a = covrast::test::expect_same_bytes_for_every_split(
        s, o, {{2, 16}}, [&](const RenderResult& b, const RenderResult&, covrast::test::Split) {
          CHECK(b.stats.triangles_backface_culled == culled);
        });
    CHECK(a.stats.triangles_backface_culled == culled);
  }
  SECTION("the cube, in both windings") {
    Scene c = base_scene();
    add(c, analyzed(cube()), glm::rotate(glm::dmat4(1.0), 0.5, glm::dvec3(1, 2, 0)),
        {0.8f, 0.8f, 0.2f});
    add(c, analyzed(reversed(cube())),
        glm::rotate(translate_scale({1.5, 0.5, -2.0}, glm::dvec3(0.7)), 1.1, glm::dvec3(0, 1, 1)),
        {0.2f, 0.5f, 0.8f});
    const std::uint64_t expected = geometric_back_faces(c);
    CHECK(expected >= 6);
    CHECK(aliased_culled_identical(c) == expected);
  }
}

TEST_CASE("a mirrored instance (det < 0) culls its other facing and stays identical", "[cull]") {
  const auto sphere = analyzed(uv_sphere(24, 48));
  Scene plain = base_scene();
  add(plain, sphere, translate_scale({0.2, 0.1, 0.0}, {1.5, 1.5, 1.5}), {0.9f, 0.5f, 0.2f});
  Scene mirrored = base_scene();
  add(mirrored, sphere, translate_scale({0.2, 0.1, 0.0}, {-1.5, 1.5, 1.5}), {0.9f, 0.5f, 0.2f});
  REQUIRE(glm::determinant(mirrored.meshes[0].model) < 0.0);
  const std::uint64_t plain_culled = aliased_culled_identical(plain);
  const std::uint64_t mirrored_culled = aliased_culled_identical(mirrored);
  // Culling the wrong facing would keep fewer than half (and change the image).
  CHECK(plain_culled > sphere->triangle_count() / 2);
  CHECK(mirrored_culled > sphere->triangle_count() / 2);
  const std::uint64_t expected = geometric_back_faces(mirrored);
  CHECK(mirrored_culled + 10 >= expected);
  CHECK(mirrored_culled <= expected + 10);
  // An inside-out mesh mirrored: culled like the plain sphere.
  Scene both = base_scene();
  add(both, analyzed(reversed(uv_sphere(24, 48))), mirrored.meshes[0].model, {0.9f, 0.5f, 0.2f});
  CHECK(aliased_culled_identical(both) > sphere->triangle_count() / 2);

  SECTION("the model matrix changed between frames of one Renderer") {
    RenderOptions o;
    o.mode.kind = ModeKind::Aliased;
    o.threads = 2;
    covrast::Renderer renderer(plain, o);
    const RenderResult first = renderer.render_frame();
    plain.meshes[0].model = mirrored.meshes[0].model;
    const RenderResult second = renderer.render_frame();
    CHECK(first.stats.triangles_backface_culled == plain_culled);
    CHECK(second.stats.triangles_backface_culled == mirrored_culled);
    CHECK(second.color.rgb == render_scene(mirrored, ModeKind::Aliased, false).color.rgb);
  }
}

TEST_CASE("nothing is culled with the eye inside a closed box", "[cull]") {
  Scene s = base_scene(0.5, 0.1, 50.0);
  add(s, analyzed(cube()), translate_scale({0.0, 0.0, 0.0}, glm::dvec3(5.0)), {0.7f, 0.7f, 0.7f},
      ColorSource::PerTriangle);
  const RenderResult on = render_scene(s, ModeKind::Aliased, true);
  CHECK(on.stats.triangles_backface_culled == 0);
  CHECK(on.color.rgb == render_scene(s, ModeKind::Aliased, false).color.rgb);
  // The inside of the box fills the view.
  CHECK(on.stats.triangles_setup > 0);
}

TEST_CASE("a sphere cut by the near or the far plane is not culled", "[cull]") {
  // 8066 vertices: the cut vertices lie past the first transform block (4096 vertices), so the
  // per-block outcode union is what stops culling.
  const auto sphere = analyzed(uv_sphere(64, 128));
  REQUIRE(sphere->positions.size() > 8000);
  // The camera looks up +y at the south pole; the near plane at distance 2.5 cuts off the
  // vertices with y < -0.5: rings past 2/3 of the way from the north pole.
  Scene cut = base_scene();
  cut.camera.eye = glm::dvec3(0.0, -3.0, 0.0);
  cut.camera.up = glm::dvec3(0.0, 0.0, 1.0);
  cut.camera.near = 2.5;
  add(cut, sphere, glm::dmat4(1.0), {0.8f, 0.3f, 0.3f});
  CHECK(aliased_culled_identical(cut) == 0);

  // A second, uncut sphere in the same frame is culled as if alone.
  Scene other = cut;
  other.meshes.clear();
  add(other, sphere, translate_scale({1.0, 3.0, 0.0}, glm::dvec3(0.4)), {0.3f, 0.8f, 0.3f});
  const std::uint64_t alone = aliased_culled_identical(other);
  CHECK(alone > 0);
  Scene both = cut;
  both.meshes.push_back(other.meshes[0]);
  CHECK(aliased_culled_identical(both) == alone);

  // The far plane through the sphere.
  Scene far = base_scene(8.0, 1.0, 8.0);
  add(far, sphere, glm::dmat4(1.0), {0.8f, 0.3f, 0.3f});
  CHECK(aliased_culled_identical(far) == 0);
  // Just past it: culled.
  far.camera.far = 9.5;
  CHECK(aliased_culled_identical(far) > 0);
}

TEST_CASE("open, unanalysed and stale meshes are never culled", "[cull]") {
  SECTION("a sphere missing one triangle") {
    auto open = uv_sphere(24, 48);
    open->indices.resize(open->indices.size() - 3);
    analyze_mesh_topology(*open);
    Scene s = base_scene();
    add(s, open, glm::dmat4(1.0), {0.8f, 0.8f, 0.8f});
    CHECK(aliased_culled_identical(s) == 0);
  }
  SECTION("a sphere never analysed (the defaults)") {
    Scene s = base_scene();
    add(s, uv_sphere(24, 48), glm::dmat4(1.0), {0.8f, 0.8f, 0.8f});
    CHECK(aliased_culled_identical(s) == 0);
  }
  SECTION("an analysed sphere whose triangles were edited afterwards") {
    auto sphere = analyzed(uv_sphere(24, 48));
    sphere->indices.resize(sphere->indices.size() / 2);
    Scene s = base_scene();
    add(s, sphere, glm::dmat4(1.0), {0.8f, 0.8f, 0.8f});
    CHECK(aliased_culled_identical(s) == 0);
  }
  SECTION("culling switched off") {
    Scene s = base_scene();
    add(s, analyzed(uv_sphere(24, 48)), glm::dmat4(1.0), {0.8f, 0.8f, 0.8f});
    CHECK(render_scene(s, ModeKind::Coverage, false).stats.triangles_backface_culled == 0);
    CHECK(render_scene(s, ModeKind::Coverage, true).stats.triangles_backface_culled > 0);
  }
}

TEST_CASE("coverage mode: culling brings closed spheres no further from the reference", "[cull]") {
  const auto sphere = analyzed(uv_sphere(24, 48));
  Scene s = base_scene();
  s.width = 96;
  s.height = 72;
  add(s, sphere, translate_scale({-0.6, 0.1, 0.0}, glm::dvec3(1.1)), {0.9f, 0.4f, 0.1f});
  add(s, sphere, translate_scale({0.7, -0.2, -1.0}, glm::dvec3(1.0)), {0.1f, 0.6f, 0.9f});
  const RenderResult reference = render_scene(s, ModeKind::Reference, true);
  const RenderResult on = render_scene(s, ModeKind::Coverage, true);
  const RenderResult off = render_scene(s, ModeKind::Coverage, false);
  CHECK(on.stats.triangles_backface_culled > sphere->triangle_count());
  const int error_on = max_abs_diff8(on.color, reference.color);
  const int error_off = max_abs_diff8(off.color, reference.color);
  INFO("max |coverage - reference| per channel: culling on " << error_on << ", off " << error_off);
  CHECK(error_on <= error_off);
  // The reference itself does not depend on culling (it resolves the nearest sample).
  CHECK(render_scene(s, ModeKind::Reference, false).color.rgb == reference.color.rgb);
}
