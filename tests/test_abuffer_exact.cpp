// Coverage mode, exact by construction: the A-buffer adds exact areas only where fragments
// provably do not overlap, and its fast paths give what the per-sample list resolve gives.
#include "core/testing_hooks.hpp"
#include "core/tile_raster.hpp"
#include "core/triangle_setup.hpp"
#include "raster/coverage/abuffer.hpp"
#include "raster/coverage/triangle_overlap.hpp"

#include <covrast/compare.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include "test_hooks.hpp"

#include "test_meshes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

namespace {

using covrast::ColorSource;
using covrast::MeshData;
using covrast::ModeKind;
using covrast::RenderOptions;
using covrast::Scene;
using covrast::detail::TriangleSetup;

constexpr double kPi = 3.14159265358979323846;

TriangleSetup make_triangle(const std::int32_t (&x)[3], const std::int32_t (&y)[3]) {
  TriangleSetup t{};
  for (int i = 0; i < 3; ++i) {
    t.x_fx8[i] = x[i];
    t.y_fx8[i] = y[i];
  }
  const std::int64_t area =
      std::int64_t(x[1] - x[0]) * (y[2] - y[0]) - std::int64_t(x[2] - x[0]) * (y[1] - y[0]);
  if (area < 0) {  // the set-up's orientation: positive doubled area
    std::swap(t.x_fx8[1], t.x_fx8[2]);
    std::swap(t.y_fx8[1], t.y_fx8[2]);
  }
  return t;
}

/// Area of the overlap of two triangles, by clipping one with the other's edges in double
/// (the coordinates are small integers, so this is accurate far below the test's threshold).
double overlap_area(const TriangleSetup& a, const TriangleSetup& b) {
  std::vector<std::pair<double, double>> poly;
  for (int i = 0; i < 3; ++i) poly.emplace_back(a.x_fx8[i], a.y_fx8[i]);
  for (int i = 0; i < 3 && !poly.empty(); ++i) {
    const int j = (i + 1) % 3;
    const double xi = b.x_fx8[i], yi = b.y_fx8[i];
    const double dx = b.x_fx8[j] - xi, dy = b.y_fx8[j] - yi;
    auto f = [&](std::pair<double, double> p) {
      return dx * (p.second - yi) - dy * (p.first - xi);
    };
    std::vector<std::pair<double, double>> out;
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const auto p = poly[k], q = poly[(k + 1) % poly.size()];
      const double fp = f(p), fq = f(q);
      if (fp >= 0) out.push_back(p);
      if ((fp >= 0) != (fq >= 0)) {
        const double u = fp / (fp - fq);
        out.emplace_back(p.first + u * (q.first - p.first), p.second + u * (q.second - p.second));
      }
    }
    poly = out;
  }
  double twice = 0;
  for (std::size_t k = 0; k < poly.size(); ++k) {
    const auto p = poly[k], q = poly[(k + 1) % poly.size()];
    twice += p.first * q.second - q.first * p.second;
  }
  return 0.5 * std::fabs(twice);
}

}  // namespace

TEST_CASE("triangle overlap: the separating-edge test is exact", "[coverage][overlap]") {
  // Vertices on a coarse grid make touching edges, shared vertices and collinear cases common.
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> coord(0, 12);
  int disjoint = 0, overlapping = 0, contained = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    auto random_triangle = [&] {
      for (;;) {
        const std::int32_t x[3] = {coord(rng) * 32, coord(rng) * 32, coord(rng) * 32};
        const std::int32_t y[3] = {coord(rng) * 32, coord(rng) * 32, coord(rng) * 32};
        const TriangleSetup t = make_triangle(x, y);
        if (std::int64_t(t.x_fx8[1] - t.x_fx8[0]) * (t.y_fx8[2] - t.y_fx8[0]) !=
            std::int64_t(t.x_fx8[2] - t.x_fx8[0]) * (t.y_fx8[1] - t.y_fx8[0])) {
          return t;
        }
      }
    };
    const TriangleSetup a = random_triangle(), b = random_triangle();
    const double area = overlap_area(a, b);
    const bool claimed = covrast::detail::interiors_disjoint(a, b);
    INFO("trial " << trial << ": overlap area " << area);
    // Overlaps are areas of whole numbers of (1/2 fx8)^2 or far larger here; 1e-6 separates.
    CHECK(claimed == !(area > 1e-6));
    CHECK(claimed == covrast::detail::interiors_disjoint(b, a));
    (claimed ? disjoint : overlapping) += 1;
    if (covrast::detail::contains_triangle(a, b)) {
      ++contained;
      // b inside a: the overlap is all of b.
      const double area_b =
          0.5 * double(std::int64_t(b.x_fx8[1] - b.x_fx8[0]) * (b.y_fx8[2] - b.y_fx8[0]) -
                       std::int64_t(b.x_fx8[2] - b.x_fx8[0]) * (b.y_fx8[1] - b.y_fx8[0]));
      CHECK(std::fabs(area - area_b) < 1e-6 * std::max(1.0, area_b));
    }
  }
  CHECK(disjoint > 1000);
  CHECK(overlapping > 1000);
  CHECK(contained > 10);
}

namespace {

Scene base_scene(int w, int h) {
  Scene s;
  s.width = w;
  s.height = h;
  s.background_linear = glm::vec3(0.02f, 0.03f, 0.05f);
  s.camera.eye = glm::dvec3(0.3, 0.5, 4.2);
  s.camera.target = glm::dvec3(0, 0, 0);
  s.camera.up = glm::dvec3(0, 1, 0);
  s.camera.fovy_deg = 40;
  s.camera.near = 1.0;
  s.camera.far = 10.0;
  return s;
}

/// A closed UV sphere displaced radially by 1 + amp * sin(a theta) sin(b phi): folds that turn
/// away from the eye near the silhouette, which culling of back faces exposes.
std::shared_ptr<MeshData> folded_sphere(int rings, int segments, double amp) {
  auto m = covrast::test::uv_sphere(rings, segments);
  for (glm::vec3& p : m->positions) {
    const double r = std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z);
    if (r == 0) continue;
    const double theta = std::acos(std::clamp(p.y / r, -1.0, 1.0)), phi = std::atan2(p.z, p.x);
    const double k = 1.0 + amp * std::sin(7 * theta) * std::sin(9 * phi);
    p *= float(k);
  }
  return m;
}

/// A fan of `blades` triangles around one vertex, turning `turns` times around it: a
/// surface whose same-facing triangles overlap though each shares vertices with the others.
std::shared_ptr<MeshData> winding_fan(int blades, double turns) {
  auto m = std::make_shared<MeshData>();
  m->source = "winding fan";
  m->positions.push_back(glm::vec3(0, 0, 0));
  for (int i = 0; i <= blades; ++i) {
    const double a = 2 * kPi * turns * i / blades;
    const double r = 1.2 + 0.15 * i / blades;
    m->positions.push_back(
        glm::vec3(float(r * std::cos(a)), float(r * std::sin(a)), float(0.4 * i / blades)));
  }
  for (int i = 0; i < blades; ++i) {
    m->indices.insert(m->indices.end(), {0u, std::uint32_t(i + 1), std::uint32_t(i + 2)});
  }
  return m;
}

covrast::RenderResult render(const Scene& s, ModeKind mode, bool cull = true) {
  RenderOptions o;
  o.mode.kind = mode;
  o.threads = 1;
  o.cull_hidden_backfaces = cull;
  o.want_depth = true;
  return covrast::render(s, o);
}

/// How far the logs' resolve may lie from the per-sample list resolve [8-bit sRGB codes]: the
/// two differ where a fragment loses samples but no overlap (the list then proves it whole
/// exactly and keeps its area) and in how a share without samples is filled.
constexpr int kLogToleranceSrgb8 = 3;

/// The coverage render with every exact-area path on (the default), and with only the
/// per-sample list resolve (sums, disjoint-set branches and whole-tile/block paths off).
struct BothResolves {
  covrast::RenderResult fast, masks;
};
BothResolves both_resolves(const Scene& s, bool cull = true, bool list_only = true) {
  covrast::detail::testing::CoverageHooks& hooks = covrast::detail::testing::coverage_hooks;
  // The exact clipping of mixed pixels is held to the reference elsewhere (it is exact where
  // the masks estimate); here the paths that add areas are held to the masks.
  const covrast::test::ScopedHook no_clipping(hooks.no_clipping, true);
  BothResolves r{[&] {
                   const covrast::test::ScopedHook list(hooks.list_only, list_only);
                   return render(s, ModeKind::Coverage, cull);
                 }(),
                 {}};
  const covrast::test::ScopedHook masks_only(hooks.mask_resolve, true);
  const covrast::test::ScopedHook pixels_only(hooks.pixel_path_only, true);
  r.masks = render(s, ModeKind::Coverage, cull);
  return r;
}

std::vector<Scene> exactness_scenes() {
  std::vector<Scene> scenes;
  {
    Scene s = base_scene(160, 120);  // folds, triangles near pixel size
    covrast::test::add_instance(s, folded_sphere(60, 120, 0.12), glm::vec3(1),
                                ColorSource::PerTriangle);
    scenes.push_back(s);
  }
  {
    Scene s = base_scene(96, 72);  // dense: many triangles per pixel
    covrast::test::add_instance(s, folded_sphere(90, 180, 0.2), glm::vec3(1),
                                ColorSource::PerTriangle);
    scenes.push_back(s);
  }
  {
    Scene s = base_scene(120, 90);  // a surface winding twice around one vertex
    covrast::test::add_instance(s, winding_fan(40, 2.0), glm::vec3(1), ColorSource::PerTriangle);
    scenes.push_back(s);
  }
  return scenes;
}

}  // namespace

TEST_CASE("coverage resolve: exact-area paths match the per-sample list resolve",
          "[coverage][exact]") {
  int scene_index = 0;
  for (const Scene& s : exactness_scenes()) {
    for (bool cull : {true, false}) {
      const BothResolves r = both_resolves(s, cull);
      const covrast::CompareResult c = covrast::compare_images(r.fast.color, r.masks.color);
      INFO("scene " << scene_index << (cull ? " culled" : " not culled") << ": max diff "
                    << c.max_diff_srgb8 << ", pixels over 1: " << c.pixels_over_1 << ", overflows "
                    << r.fast.stats.fragment_overflows);
      // Overflowing pixels (the dense sphere's poles gather ~180 triangles in a pixel, folds
      // stack several layers) merge within their disjoint set or turn into samples; both
      // renders do the same there, so this bound covers them too.
      CHECK(c.max_diff_srgb8 <= 1);
      // The exact-area paths ran in the fast render and not in the per-sample one, which
      // resolved every pixel with fragments by its samples.
      const covrast::CoverageResolvePaths &fast = r.fast.stats.resolve_paths,
                                          &masks = r.masks.stats.resolve_paths;
      CHECK(fast.layer_sums + fast.disjoint + fast.front_layer > 1000);
      CHECK(masks.layer_sums + masks.disjoint + masks.front_layer == 0);
      CHECK(masks.samples + masks.clipped > fast.samples + fast.clipped);
    }
    ++scene_index;
  }
}

TEST_CASE("coverage resolve: the pixels' logs match the per-sample list resolve",
          "[coverage][exact]") {
  // Proven layers add exact areas as the list's sums do; mixed pixels take sample masks
  // front to back, the list's per-sample visibility found another way: the same winners per
  // sample, and the exact area where a fragment keeps all its samples.
  int scene_index = 0;
  for (const Scene& s : exactness_scenes()) {
    const BothResolves r = both_resolves(s, true, false);
    const covrast::CompareResult c = covrast::compare_images(r.fast.color, r.masks.color);
    const covrast::CoverageResolvePaths& paths = r.fast.stats.resolve_paths;
    INFO("scene " << scene_index << ": max diff " << c.max_diff_srgb8
                  << ", pixels over 1: " << c.pixels_over_1 << ", proven " << paths.proven_layer
                  << ", masked " << paths.masked);
    CHECK(c.max_diff_srgb8 <= kLogToleranceSrgb8);
    CHECK(double(c.pixels_over_1) <= 0.002 * double(s.width * s.height));
    CHECK(paths.proven_layer + paths.masked > 1000);
    CHECK(paths.masked > 0);
    ++scene_index;
  }
}

TEST_CASE("coverage mode: a surface folded over itself is not added up as one layer",
          "[coverage][exact]") {
  // Each blade of the fan shares the centre with every other and an edge with its
  // neighbours, and the second turn lies over the first: adding their areas would mix the
  // turns' colours and double-count coverage. Against the 64 x 64-sample reference, coverage
  // must be as good as 256-sample supersampling.
  Scene s = base_scene(120, 90);
  covrast::test::add_instance(s, winding_fan(40, 2.0), glm::vec3(1), ColorSource::PerTriangle);
  const auto coverage = render(s, ModeKind::Coverage);
  const auto reference = render(s, ModeKind::Reference);
  RenderOptions o;
  o.mode.kind = ModeKind::Ssaa;
  o.mode.samples = 16;
  o.threads = 1;
  const auto ssaa = covrast::render(s, o);
  const covrast::CompareResult cov = covrast::compare_images(coverage.color, reference.color);
  const covrast::CompareResult sup = covrast::compare_images(ssaa.color, reference.color);
  INFO("coverage: max " << cov.max_diff_srgb8 << " rmse " << cov.rmse_linear << "; ssaa:16: max "
                        << sup.max_diff_srgb8 << " rmse " << sup.rmse_linear);
  CHECK(cov.max_diff_srgb8 <= sup.max_diff_srgb8);
  CHECK(cov.rmse_linear <= sup.rmse_linear);
}

TEST_CASE("coverage mode: copies of one triangle stacked on each other cost one",
          "[coverage][exact]") {
  Scene s = base_scene(64, 48);
  auto m = std::make_shared<MeshData>();
  m->source = "stacked";
  m->positions = {glm::vec3(-1.1f, -0.7f, 0), glm::vec3(1.3f, -0.9f, 0), glm::vec3(0.1f, 1.2f, 0)};
  for (int copy = 0; copy < 3000; ++copy) m->indices.insert(m->indices.end(), {0u, 1u, 2u});
  covrast::test::add_instance(s, m, glm::vec3(0.8f, 0.3f, 0.1f));
  Scene one = s;
  auto single = std::make_shared<MeshData>(*m);
  single->indices.resize(3);
  one.meshes[0].mesh = single;
  const auto stacked = render(s, ModeKind::Coverage), alone = render(one, ModeKind::Coverage);
  CHECK(stacked.stats.fragment_overflows == 0);
  CHECK(covrast::compare_images(stacked.color, alone.color).max_diff_srgb8 == 0);
}

TEST_CASE("coverage modes: window depth stays in [0, 1] for slivers", "[coverage][exact]") {
  // Long, steep slivers: their planes, evaluated at pixel centres outside them, leave [0, 1].
  Scene s = base_scene(64, 64);
  auto m = std::make_shared<MeshData>();
  m->source = "slivers";
  for (int i = 0; i < 40; ++i) {
    const float x = -1.5f + 0.075f * i;
    const std::uint32_t b = std::uint32_t(m->positions.size());
    m->positions.push_back(glm::vec3(x, -1.5f, 2.9f));
    m->positions.push_back(glm::vec3(x + 0.0004f, 1.5f, -6.0f));
    m->positions.push_back(glm::vec3(x + 0.002f, -1.5f, 2.9f));
    m->indices.insert(m->indices.end(), {b, b + 1, b + 2});
  }
  covrast::test::add_instance(s, m, glm::vec3(0.5f), ColorSource::PerTriangle);
  for (ModeKind mode : {ModeKind::Coverage, ModeKind::CoverageBlend, ModeKind::Aliased}) {
    const auto r = render(s, mode, false);
    const auto [lo, hi] = std::minmax_element(r.depth.depth.begin(), r.depth.depth.end());
    INFO("mode " << int(mode) << ": depth in [" << *lo << ", " << *hi << "]");
    CHECK(*lo >= 0.0f);
    CHECK(*hi <= 1.0f);
  }
}

TEST_CASE("mesh topology: convex meshes are recognised, others are not", "[coverage][exact]") {
  auto analysed = [](std::shared_ptr<MeshData> m) {
    covrast::analyze_mesh_topology(*m);
    return m;
  };
  CHECK(analysed(covrast::test::uv_sphere(24, 48))->convex);
  // The same sphere dented (a fold), open (one triangle removed), and as two copies in one
  // mesh: closed or not, none is convex.
  CHECK_FALSE(analysed(folded_sphere(24, 48, 0.12))->convex);
  auto open = covrast::test::uv_sphere(24, 48);
  open->indices.resize(open->indices.size() - 3);
  CHECK_FALSE(analysed(open)->convex);
  auto twice = covrast::test::uv_sphere(12, 24);
  const std::size_t n = twice->positions.size();
  for (std::size_t i = 0; i < n; ++i) twice->positions.push_back(twice->positions[i] + 3.0f);
  const std::size_t k = twice->indices.size();
  for (std::size_t i = 0; i < k; ++i)
    twice->indices.push_back(twice->indices[i] + std::uint32_t(n));
  const auto both = analysed(twice);
  CHECK(both->closed_orientation != 0);
  CHECK_FALSE(both->convex);
}
