// Tests of alpha (docs/transparency.md): BLEND composited in exact depth order whatever the
// draw order (coverage and reference against the analytic front-to-back composite, a partly
// covered pixel over an opaque edge against the per-sample reference and a hand-computed
// area split), MASK at its cutoff, vertex alpha times factor alpha, and the same bytes for
// every thread count and tile size. Scenes are built here.
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>
#include "test_hooks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "core/testing_hooks.hpp"
#include "test_gltf_files.hpp"
#include "test_meshes.hpp"
#include "test_splits.hpp"
#include "test_tempdir.hpp"

using covrast::test::max_difference;
using covrast::test::render_mode;

namespace {

constexpr int kSide = 32;

/// A 32x32 scene whose camera maps the square [-d, d]^2 at distance d in front of it onto the
/// whole image: pixel p (from the left or top) lies at p / 16 - 1 times d.
covrast::Scene flat_scene(glm::vec3 background_linear) {
  covrast::Scene scene;
  scene.width = kSide;
  scene.height = kSide;
  scene.background_linear = background_linear;
  scene.camera.eye = {0.0, 0.0, 1.0};
  scene.camera.target = {0.0, 0.0, 0.0};
  scene.camera.up = {0.0, 1.0, 0.0};
  scene.camera.fovy_deg = 90.0;
  scene.camera.near = 0.5;
  scene.camera.far = 10.0;
  return scene;
}

/// A rectangle facing the camera at distance `d` covering pixels [x0, x1] x [y0, y1] (image
/// coordinates, y down), with optional vertex alphas.
std::shared_ptr<const covrast::MeshData> rect(double x0, double y0, double x1, double y1, double d,
                                              std::vector<float> alphas = {}) {
  const auto wx = [d](double px) { return float(d * (px / 16.0 - 1.0)); };
  const auto wy = [d](double py) { return float(d * (1.0 - py / 16.0)); };
  const float z = float(1.0 - d);
  covrast::MeshArrays a;
  a.name = "rect";
  a.positions = {
      {wx(x0), wy(y1), z}, {wx(x1), wy(y1), z}, {wx(x1), wy(y0), z}, {wx(x0), wy(y0), z}};
  a.indices = {0, 1, 2, 0, 2, 3};
  a.alphas = std::move(alphas);
  return covrast::make_mesh(std::move(a));
}

covrast::Material material(covrast::AlphaMode mode, double base_alpha, double cutoff = 0.5) {
  covrast::Material m;
  m.model = covrast::ShadingModel::Unlit;
  m.alpha_mode = mode;
  m.base_alpha = base_alpha;
  m.alpha_cutoff = cutoff;
  return m;
}

int code(double linear) {
  return int(std::lround(255.0 * covrast::linear_to_srgb(float(std::clamp(linear, 0.0, 1.0)))));
}

/// A transparent layer of the analytic composite: colour (linear), alpha, pixel box.
struct Layer {
  glm::dvec3 color;
  double alpha;
  double x0, y0, x1, y1, d;
};

/// The front-to-back composite at a point, layers sorted nearest first.
glm::dvec3 composite_at(std::vector<Layer> layers, double px, double py, glm::dvec3 behind) {
  std::sort(layers.begin(), layers.end(), [](const Layer& a, const Layer& b) { return a.d < b.d; });
  glm::dvec3 c(0.0);
  double t = 1.0;
  for (const Layer& l : layers) {
    if (px < l.x0 || px > l.x1 || py < l.y0 || py > l.y1) continue;
    c += t * l.alpha * l.color;
    t *= 1.0 - l.alpha;
  }
  return c + t * behind;
}

/// Pixels of `image` whose square lies inside or outside every layer's box (no edge crosses
/// them) equal the composite at their centre within `tolerance` codes.
void require_interior_composite(const covrast::Image& image, const std::vector<Layer>& layers,
                                glm::dvec3 background, int tolerance) {
  int checked = 0;
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      bool crossed = false;
      for (const Layer& l : layers) {
        const bool x_cut = (l.x0 > x && l.x0 < x + 1) || (l.x1 > x && l.x1 < x + 1);
        const bool y_cut = (l.y0 > y && l.y0 < y + 1) || (l.y1 > y && l.y1 < y + 1);
        crossed = crossed || x_cut || y_cut;
      }
      if (crossed) continue;
      const glm::dvec3 c = composite_at(layers, x + 0.5, y + 0.5, background);
      const std::uint8_t* p = image.pixel(x, y);
      INFO("pixel " << x << ", " << y);
      REQUIRE(std::abs(p[0] - code(c.r)) <= tolerance);
      REQUIRE(std::abs(p[1] - code(c.g)) <= tolerance);
      REQUIRE(std::abs(p[2] - code(c.b)) <= tolerance);
      ++checked;
    }
  }
  REQUIRE(checked > 500);
}

const std::vector<Layer> kQuads = {
    {{0.8, 0.05, 0.02}, 0.5, 4, 4, 20, 20, 1.0},
    {{0.03, 0.7, 0.1}, 0.6, 10, 6, 26, 22, 2.0},
    {{0.05, 0.1, 0.9}, 0.7, 8.5, 12.5, 24.5, 28.5, 4.0},
};
const glm::dvec3 kBackground(0.2, 0.2, 0.2);

/// The quads of kQuads as BLEND instances, added in the order `order`.
covrast::Scene blend_quads(const std::vector<int>& order) {
  covrast::Scene scene = flat_scene(glm::vec3(kBackground));
  for (const int i : order) {
    const Layer& l = kQuads[std::size_t(i)];
    covrast::MeshInstance& inst =
        covrast::add_instance(scene, rect(l.x0, l.y0, l.x1, l.y1, l.d),
                              {.material = material(covrast::AlphaMode::Blend, l.alpha)});
    inst.color_linear = glm::vec3(l.color);
  }
  return scene;
}

}  // namespace

TEST_CASE("BLEND quads composite in depth order whatever the draw order", "[transparency]") {
  std::vector<int> order = {0, 1, 2};
  covrast::Image first_coverage, first_reference;
  int orders = 0;
  do {
    const covrast::Scene scene = blend_quads(order);
    const covrast::Image coverage = render_mode(scene, "coverage", 1);
    const covrast::Image reference = render_mode(scene, "reference", 1);
    if (orders == 0) {
      first_coverage = coverage;
      first_reference = reference;
      require_interior_composite(coverage, kQuads, kBackground, 1);
      require_interior_composite(reference, kQuads, kBackground, 1);
    }
    INFO("order " << order[0] << order[1] << order[2]);
    REQUIRE(coverage.rgb == first_coverage.rgb);
    REQUIRE(reference.rgb == first_reference.rgb);
    // Edge pixels too: exact areas against 4096 samples per pixel.
    REQUIRE(max_difference(coverage, reference) <= 1);
    ++orders;
  } while (std::next_permutation(order.begin(), order.end()));
  REQUIRE(orders == 6);
}

TEST_CASE("A BLEND surface partly covering a pixel over an opaque edge", "[transparency]") {
  // Opaque: the lower half of the image from y = 16.5 (distance 2); transparent (distance 1):
  // the right part from x = 10.5. Pixel (10, 16) is cut into four quarters.
  const glm::dvec3 opaque_color(0.9, 0.6, 0.1), clear_color(0.05, 0.2, 0.8);
  const double alpha = 0.4;
  covrast::Scene scene = flat_scene(glm::vec3(kBackground));
  covrast::add_instance(scene, rect(0, 16.5, 32, 32, 2.0)).color_linear = glm::vec3(opaque_color);
  covrast::add_instance(scene, rect(10.5, 0, 32, 32, 1.0),
                        {.material = material(covrast::AlphaMode::Blend, alpha)})
      .color_linear = glm::vec3(clear_color);
  const covrast::Image coverage = render_mode(scene, "coverage", 1);
  const covrast::Image reference = render_mode(scene, "reference", 1);
  // Quarters: top-left background, bottom-left opaque, top-right clear over background,
  // bottom-right clear over opaque.
  const glm::dvec3 expected =
      0.25 * (kBackground + opaque_color + (alpha * clear_color + (1 - alpha) * kBackground) +
              (alpha * clear_color + (1 - alpha) * opaque_color));
  for (const covrast::Image* image : {&coverage, &reference}) {
    const std::uint8_t* p = image->pixel(10, 16);
    REQUIRE(std::abs(p[0] - code(expected.r)) <= 1);
    REQUIRE(std::abs(p[1] - code(expected.g)) <= 1);
    REQUIRE(std::abs(p[2] - code(expected.b)) <= 1);
  }
  REQUIRE(max_difference(coverage, reference) <= 1);
}

TEST_CASE("Slanted BLEND edges over opaque edges match the per-sample reference",
          "[transparency]") {
  // Triangles with edges at odd slopes: a transparent one over two opaque ones that meet in
  // a crossing edge, and one opaque triangle in front of part of the transparent one.
  covrast::Scene scene = flat_scene(glm::vec3(kBackground));
  auto triangle = [](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, double d) {
    const auto w = [d](glm::dvec2 p) {
      return glm::vec3(float(d * (p.x / 16.0 - 1.0)), float(d * (1.0 - p.y / 16.0)),
                       float(1.0 - d));
    };
    covrast::MeshArrays arrays;
    arrays.name = "triangle";
    arrays.positions = {w(a), w(b), w(c)};
    arrays.indices = {0, 2, 1};  // a, b, c clockwise on screen (y down) = counter-clockwise
    return covrast::make_mesh(std::move(arrays));
  };
  covrast::add_instance(scene, triangle({-2, 3.3}, {31.2, 7.7}, {5.1, 30.4}, 3.0)).color_linear = {
      0.8f, 0.1f, 0.1f};
  covrast::add_instance(scene, triangle({30.1, 1.2}, {33.0, 29.6}, {2.3, 26.9}, 2.5))
      .color_linear = {0.1f, 0.8f, 0.1f};
  covrast::add_instance(scene, triangle({3.7, 2.1}, {28.4, 13.3}, {12.6, 31.0}, 1.5),
                        {.material = material(covrast::AlphaMode::Blend, 0.55)})
      .color_linear = {0.1f, 0.2f, 0.9f};
  covrast::add_instance(scene, triangle({17.3, 9.9}, {26.6, 24.2}, {11.1, 21.7}, 1.2),
                        {.material = material(covrast::AlphaMode::Blend, 0.35)})
      .color_linear = {0.9f, 0.9f, 0.2f};
  covrast::add_instance(scene, triangle({20.2, 15.5}, {31.0, 30.0}, {14.0, 29.5}, 1.0))
      .color_linear = {0.6f, 0.3f, 0.7f};
  const covrast::Image coverage = render_mode(scene, "coverage", 1);
  const covrast::Image reference = render_mode(scene, "reference", 1);
  REQUIRE(max_difference(coverage, reference) <= 2);
}

TEST_CASE("MASK keeps alpha at and above the cutoff, drops below", "[transparency]") {
  const double cutoff = 0.5;
  const struct {
    double alpha;
    bool kept;
  } cases[] = {
      {cutoff, true}, {std::nextafter(cutoff, 1.0), true}, {std::nextafter(cutoff, 0.0), false}};
  for (const auto& c : cases) {
    covrast::Scene scene = flat_scene(glm::vec3(0.0f));
    covrast::add_instance(scene, rect(4, 4, 28, 28, 1.0),
                          {.material = material(covrast::AlphaMode::Mask, c.alpha, cutoff)})
        .color_linear = {1.0f, 1.0f, 1.0f};
    for (const char* mode :
         {"coverage", "coverage-blend", "reference", "aliased", "msaa:4", "ssaa:4"}) {
      const covrast::Image image = render_mode(scene, mode, 1);
      INFO(mode << " alpha " << c.alpha);
      REQUIRE(image.pixel(16, 16)[0] == (c.kept ? 255 : 0));
      REQUIRE(image.pixel(2, 2)[0] == 0);
    }
  }
}

TEST_CASE("MASK with a vertex alpha ramp: kept where the centre's alpha passes", "[transparency]") {
  // Alpha 0 at the left edge, 1 at the right (a fronto-parallel quad, so linear in x): the
  // pixel centre x + 0.5 passes 0.5 from x = 16 on; per sample the edge is at x = 16 exactly.
  covrast::Scene scene = flat_scene(glm::vec3(0.0f));
  covrast::add_instance(scene, rect(0, 0, 32, 32, 1.0, {0.0f, 1.0f, 1.0f, 0.0f}),
                        {.material = material(covrast::AlphaMode::Mask, 1.0, 0.5)})
      .color_linear = {1.0f, 1.0f, 1.0f};
  for (const char* mode : {"coverage", "reference", "aliased", "msaa:4", "ssaa:4"}) {
    const covrast::Image image = render_mode(scene, mode, 1);
    for (int x = 0; x < kSide; ++x) {
      INFO(mode << " x " << x);
      REQUIRE(image.pixel(x, 10)[0] == (x >= 16 ? 255 : 0));
    }
  }
}

TEST_CASE("Vertex alpha and base colour alpha multiply", "[transparency]") {
  covrast::Scene scene = flat_scene(glm::vec3(kBackground));
  covrast::add_instance(scene, rect(0, 0, 32, 32, 1.0, {0.5f, 0.5f, 0.5f, 0.5f}),
                        {.material = material(covrast::AlphaMode::Blend, 0.5)})
      .color_linear = {1.0f, 0.0f, 0.0f};
  const glm::dvec3 expected = 0.25 * glm::dvec3(1.0, 0.0, 0.0) + 0.75 * kBackground;
  for (const char* mode : {"coverage", "reference", "aliased", "msaa:4", "ssaa:4"}) {
    const covrast::Image image = render_mode(scene, mode, 1);
    INFO(mode);
    REQUIRE(image.pixel(16, 16)[0] == code(expected.r));
    REQUIRE(image.pixel(16, 16)[1] == code(expected.g));
  }
}

namespace {

/// 60 random overlapping triangles in a 48x48 image, a third of them BLEND and a sixth MASK,
/// over opaque ones.
covrast::Scene random_transparent_scene() {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> pos(-4.0, 52.0), unit(0.0, 1.0);
  covrast::Scene scene = flat_scene(glm::vec3(kBackground));
  scene.width = scene.height = 48;
  for (int i = 0; i < 60; ++i) {
    const double d = 1.0 + 2.0 * unit(rng);
    covrast::MeshArrays arrays;
    arrays.name = "random";
    for (int k = 0; k < 3; ++k) {
      arrays.positions.emplace_back(float(d * (pos(rng) / 24.0 - 1.0)),
                                    float(d * (1.0 - pos(rng) / 24.0)), float(1.0 - d));
    }
    arrays.indices = {0, 1, 2};
    arrays.alphas = {float(unit(rng)), float(unit(rng)), float(unit(rng))};
    const int kind = i % 6;
    const covrast::AlphaMode mode = kind < 2   ? covrast::AlphaMode::Blend
                                    : kind < 3 ? covrast::AlphaMode::Mask
                                               : covrast::AlphaMode::Opaque;
    covrast::add_instance(scene, covrast::make_mesh(std::move(arrays)),
                          {.material = material(mode, 0.3 + 0.7 * unit(rng))})
        .color_linear = glm::vec3(float(unit(rng)), float(unit(rng)), float(unit(rng)));
  }
  return scene;
}

}  // namespace

// Split in two so that the TSan step (scripts/tsan.sh, the [threads] tests) runs the modes
// whose threads share work, without the reference mode's minutes under TSan.
TEST_CASE("Transparency gives the same bytes for every thread count and tile size",
          "[transparency][threads]") {
  const covrast::Scene scene = random_transparent_scene();
  for (const char* mode : {"coverage", "msaa:4", "ssaa:4", "aliased"}) {
    covrast::test::expect_same_bytes_for_every_split(scene, mode);
  }
}

// [sanitizer-slow]: a minute under ASan+UBSan; the reference mode's splits run there in the
// supersampling tests, and its transparent composite in the other tests of this file.
TEST_CASE("Transparency gives the same bytes for every thread count and tile size: reference",
          "[transparency][sanitizer-slow]") {
  covrast::test::expect_same_bytes_for_every_split(random_transparent_scene(), "reference");
}

TEST_CASE("A closed BLEND mesh shows its back faces", "[transparency]") {
  // A closed cube around the view axis: its back faces are not culled when it is BLEND, so
  // the centre shows two layers of alpha 0.5 (0.75 of the colour), not one.
  covrast::MeshArrays cube;
  cube.name = "cube";
  cube.positions = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                    {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  cube.indices = {4, 5, 6, 4, 6, 7, 1, 0, 3, 1, 3, 2, 5, 1, 2, 5, 2, 6,
                  0, 4, 7, 0, 7, 3, 7, 6, 2, 7, 2, 3, 0, 1, 5, 0, 5, 4};
  const auto mesh = covrast::make_mesh(std::move(cube));
  REQUIRE(mesh->closed_orientation != 0);
  covrast::Scene scene = flat_scene(glm::vec3(0.0f));
  scene.camera.eye = {0.0, 0.0, 6.0};
  glm::dmat4 model(0.5);
  model[3][3] = 1.0;
  covrast::add_instance(scene, mesh,
                        {.model = model, .material = material(covrast::AlphaMode::Blend, 0.5)})
      .color_linear = {1.0f, 1.0f, 1.0f};
  for (const char* mode : {"coverage", "reference", "aliased", "msaa:4", "ssaa:4"}) {
    INFO(mode);
    REQUIRE(render_mode(scene, mode, 1).pixel(16, 16)[0] == code(0.75));
  }
}

TEST_CASE("Scene files and glTF files give the alpha mode, cutoff and alphas", "[transparency]") {
  covrast::test::TempDir dir("covrast-test-alpha");
  {
    std::ofstream obj(dir / "tri.obj");
    obj << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  }
  auto write_scene = [&](const std::string& material) {
    std::ofstream json(dir / "scene.json");
    json << R"({"width": 8, "height": 8, "camera": {"eye": [0, 0, 3], "target": [0, 0, 0],
      "up": [0, 1, 0], "fovy_deg": 45, "near": 0.5, "far": 10},
      "meshes": [{"obj": "tri.obj", "material": )"
         << material << "}]}";
    return dir / "scene.json";
  };
  const covrast::Scene scene = covrast::load_scene(
      write_scene(R"({"alpha_mode": "mask", "alpha_cutoff": 0.25, "base_alpha": 0.75})"));
  const covrast::Material& m = scene.meshes.at(0).materials.at(0);
  REQUIRE(m.alpha_mode == covrast::AlphaMode::Mask);
  REQUIRE(m.alpha_cutoff == 0.25);
  REQUIRE(m.base_alpha == 0.75);
  REQUIRE_THROWS_WITH(covrast::load_scene(write_scene(R"({"alpha_mode": "clear"})")),
                      Catch::Matchers::Contains("meshes[0].material.alpha_mode") &&
                          Catch::Matchers::Contains("\"clear\""));
  REQUIRE_THROWS_WITH(covrast::load_scene(write_scene(R"({"base_alpha": 1.5})")),
                      Catch::Matchers::Contains("meshes[0].material.base_alpha"));

  covrast::test::GltfBuilder b;
  const int positions = b.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  const int colors = b.add_floats({1, 1, 1, 0.25f, 1, 1, 1, 0.5f, 1, 1, 1, 1}, "VEC4");
  b.single_mesh(
      {{{"attributes", {{"POSITION", positions}, {"COLOR_0", colors}}}, {"material", 0}}});
  b.gltf["materials"] = {
      {{"alphaMode", "BLEND"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.5}}}}},
      {{"alphaMode", "MASK"}, {"alphaCutoff", 0.3}}};
  {
    std::ofstream gltf(dir / "alpha.gltf");
    gltf << b.gltf_text();
  }
  const auto mesh = covrast::load_mesh(dir / "alpha.gltf");
  REQUIRE(mesh->materials.at(0).alpha_mode == covrast::AlphaMode::Blend);
  REQUIRE(mesh->materials.at(0).base_alpha == 0.5);
  REQUIRE(mesh->materials.at(1).alpha_mode == covrast::AlphaMode::Mask);
  REQUIRE(mesh->materials.at(1).alpha_cutoff == 0.3);
  REQUIRE(mesh->color_alphas == std::vector<float>{0.25f, 0.5f, 1.0f});
  b.gltf["materials"][1]["alphaMode"] = "CLEAR";
  {
    std::ofstream gltf(dir / "bad.gltf");
    gltf << b.gltf_text();
  }
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir / "bad.gltf"),
                      Catch::Matchers::Contains("bad.gltf") &&
                          Catch::Matchers::Contains("material 1: alphaMode \"CLEAR\""));
}

TEST_CASE("BLEND surfaces leave the depth output to the opaque ones", "[transparency]") {
  // An opaque quad partly behind a BLEND quad, and a BLEND quad over the background: the
  // depth image equals that of the scene without the BLEND quads, in every mode.
  covrast::Scene opaque_only = flat_scene(glm::vec3(kBackground));
  covrast::add_instance(opaque_only, rect(2.5, 3.25, 20.75, 29, 2.0));
  covrast::Scene with_blend = opaque_only;
  covrast::add_instance(with_blend, rect(8.5, 0, 32, 20.5, 1.0),
                        {.material = material(covrast::AlphaMode::Blend, 0.6)});
  covrast::add_instance(with_blend, rect(0, 22.5, 12, 32, 1.5),
                        {.material = material(covrast::AlphaMode::Blend, 0.3)});
  for (const char* mode :
       {"coverage", "coverage-blend", "reference", "aliased", "msaa:4", "ssaa:4"}) {
    covrast::RenderOptions options;
    options.mode = covrast::parse_render_mode(mode);
    options.threads = 1;
    options.want_depth = true;
    const covrast::RenderResult a = covrast::render(opaque_only, options);
    const covrast::RenderResult b = covrast::render(with_blend, options);
    INFO(mode);
    REQUIRE(a.depth.depth == b.depth.depth);
    REQUIRE(a.color.rgb != b.color.rgb);
  }
}

TEST_CASE("The uniform-layer shortcut gives what the per-sample composite gives",
          "[transparency]") {
  // Interior pixels of the three quads take the shortcut; with the mask resolve forced they
  // take the 256-sample composite of the general formula.
  const covrast::Scene scene = blend_quads({2, 0, 1});
  const covrast::Image fast = render_mode(scene, "coverage", 1);
  const covrast::Image samples = [&] {
    const covrast::test::ScopedHook masks_only(
        covrast::detail::testing::coverage_hooks.mask_resolve, true);
    return render_mode(scene, "coverage", 1);
  }();
  REQUIRE(max_difference(fast, samples) <= 1);
}

TEST_CASE("Lit BLEND and MASK surfaces composite like unlit ones", "[transparency]") {
  // A lit scene: the transparent quad is lambert-lit, with a vertex alpha ramp; coverage
  // against the per-sample reference, and the lit colour is what shows through.
  covrast::Scene scene = flat_scene(glm::vec3(kBackground));
  covrast::Light light;
  light.direction = {0.0, 0.0, -1.0};
  light.intensity = 0.8;
  covrast::add_light(scene, light);
  covrast::Material lambert = material(covrast::AlphaMode::Opaque, 1.0);
  lambert.model = covrast::ShadingModel::Lambert;
  covrast::add_instance(scene, rect(0, 16.5, 32, 32, 2.0), {.material = lambert}).color_linear = {
      0.9f, 0.6f, 0.1f};
  covrast::Material clear = lambert;
  clear.alpha_mode = covrast::AlphaMode::Blend;
  clear.base_alpha = 0.8;
  covrast::add_instance(scene, rect(10.5, 0, 32, 32, 1.0, {0.2f, 1.0f, 1.0f, 0.2f}),
                        {.material = clear})
      .color_linear = {0.05f, 0.2f, 0.8f};
  covrast::Material cut = lambert;
  cut.alpha_mode = covrast::AlphaMode::Mask;
  cut.alpha_cutoff = 0.5;
  covrast::add_instance(scene, rect(2, 2, 9, 30, 1.5, {0.0f, 1.0f, 1.0f, 0.0f}), {.material = cut})
      .color_linear = {0.7f, 0.7f, 0.7f};
  const covrast::Image coverage = render_mode(scene, "coverage", 1);
  const covrast::Image reference = render_mode(scene, "reference", 1);
  // The MASK ramp's cut is per pixel in coverage, per sample in the reference: compare away
  // from its pixel column.
  int worst = 0;
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      if (x == 5) continue;
      for (int c = 0; c < 3; ++c) {
        worst = std::max(worst, std::abs(coverage.pixel(x, y)[c] - reference.pixel(x, y)[c]));
      }
    }
  }
  REQUIRE(worst <= 1);
  // Fully inside the transparent quad over the background: alpha = 0.8 x the ramp.
  const double alpha = 0.8 * (0.2 + 0.8 * (20.5 - 10.5) / 21.5);
  const glm::dvec3 lit = 0.8 * glm::dvec3(0.05, 0.2, 0.8);
  REQUIRE(std::abs(coverage.pixel(20, 5)[2] - code(alpha * lit.b + (1 - alpha) * kBackground.b)) <=
          1);
}
