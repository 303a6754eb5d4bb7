// The exact visible areas of a pixel's fragments (raster/coverage/visible_parts.hpp): held to
// analytic values, to a brute-force point count, and to the tie rule of the samples.
#include "core/testing_hooks.hpp"
#include "core/triangle_setup.hpp"
#include "raster/coverage/visible_parts.hpp"

#include <covrast/compare.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include "test_hooks.hpp"
#include "test_meshes.hpp"
#include "test_splits.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <vector>

namespace {

using covrast::detail::TriangleSetup;
using covrast::detail::visible_areas;

constexpr std::int32_t kOne = covrast::detail::kSubpixelOne;  // one pixel in 24.8 fixed point

/// A triangle of 24.8 vertices (reordered to the set-up's orientation) whose window depth is
/// z(x, y) = z0 + dzdx x + dzdy y [pixels], with primitive index `primitive`.
TriangleSetup triangle(std::int32_t x0, std::int32_t y0, std::int32_t x1, std::int32_t y1,
                       std::int32_t x2, std::int32_t y2, double z0, double dzdx, double dzdy,
                       std::uint32_t primitive) {
  TriangleSetup t{};
  const std::int64_t area = std::int64_t(x1 - x0) * (y2 - y0) - std::int64_t(x2 - x0) * (y1 - y0);
  if (area < 0) {
    std::swap(x1, x2);
    std::swap(y1, y2);
  }
  t.x_fx8[0] = x0, t.x_fx8[1] = x1, t.x_fx8[2] = x2;
  t.y_fx8[0] = y0, t.y_fx8[1] = y1, t.y_fx8[2] = y2;
  t.dzdx = dzdx;
  t.dzdy = dzdy;
  t.z0 = z0 + dzdx * (double(x0) / kOne) + dzdy * (double(y0) / kOne);  // the plane at vertex 0
  t.primitive = primitive;
  return t;
}

/// A triangle that covers pixel (0, 0) and its neighbours with the plane given.
TriangleSetup covering(double z0, double dzdx, double dzdy, std::uint32_t primitive) {
  return triangle(-4 * kOne, -4 * kOne, 8 * kOne, -4 * kOne, -4 * kOne, 8 * kOne, z0, dzdx, dzdy,
                  primitive);
}

bool inside(const TriangleSetup& t, double px, double py) {
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const double xi = double(t.x_fx8[i]) / kOne, yi = double(t.y_fx8[i]) / kOne;
    const double xj = double(t.x_fx8[j]) / kOne, yj = double(t.y_fx8[j]) / kOne;
    if ((xj - xi) * (py - yi) - (yj - yi) * (px - xi) < 0.0) return false;
  }
  return true;
}

/// Visible areas in pixel (0, 0) by counting an n x n grid of points: at each, the nearest
/// fragment that covers it (level: the lower primitive), the opaque surface covering all.
std::vector<double> counted_areas(const std::vector<TriangleSetup>& tris,
                                  const TriangleSetup* opaque, int n) {
  std::vector<double> area(tris.size(), 0.0);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double px = (i + 0.5) / n, py = (j + 0.5) / n;
      int best = -1;
      double best_z = opaque != nullptr ? opaque->depth_at(px, py) : 1e300;
      std::uint32_t best_primitive = opaque != nullptr ? opaque->primitive : 0xffffffffu;
      for (std::size_t k = 0; k < tris.size(); ++k) {
        if (!inside(tris[k], px, py)) continue;
        const double z = tris[k].depth_at(px, py);
        if (z < best_z || (z == best_z && tris[k].primitive < best_primitive)) {
          best = int(k);
          best_z = z;
          best_primitive = tris[k].primitive;
        }
      }
      if (best >= 0) area[std::size_t(best)] += 1.0 / (double(n) * n);
    }
  }
  return area;
}

std::vector<double> exact_areas(const std::vector<TriangleSetup>& tris,
                                const TriangleSetup* opaque) {
  std::vector<const TriangleSetup*> ptr;
  for (const TriangleSetup& t : tris) ptr.push_back(&t);
  std::vector<double> area(tris.size(), -1.0);
  REQUIRE(visible_areas(int(tris.size()), ptr.data(), opaque, 0, 0, area.data()));
  return area;
}

}  // namespace

TEST_CASE("visible parts: two planes crossing split the pixel along their line",
          "[coverage][clipping]") {
  // z_a = 0.5 + 0.1 (x - 0.25) and z_b = 0.5: a is nearer where x < 0.25, over a quarter of
  // the pixel; b over the rest. Both cover the pixel.
  const std::vector<TriangleSetup> tris = {covering(0.5 - 0.025, 0.1, 0.0, 1),
                                           covering(0.5, 0.0, 0.0, 2)};
  const std::vector<double> area = exact_areas(tris, nullptr);
  CHECK(area[0] == Approx(0.25).margin(1e-12));
  CHECK(area[1] == Approx(0.75).margin(1e-12));
  // The same against an opaque surface: the opaque plane takes what neither shows.
  const TriangleSetup opaque = covering(0.5 - 0.05, 0.0, 0.1, 0);  // nearer where y < 0.5
  const std::vector<double> over = exact_areas(tris, &opaque);
  // a shows where x < 0.25 and y > x + 0.25 (nearer than the opaque plane there):
  // the integral of 1 - (x + 0.25) over x in [0, 0.25].
  CHECK(over[0] == Approx(0.25 * 0.75 - 0.5 * 0.25 * 0.25).margin(1e-12));
  // b shows where x > 0.25 and y > 0.5.
  CHECK(over[1] == Approx(0.75 * 0.5).margin(1e-12));
}

TEST_CASE("visible parts: identical planes give their overlap to the earlier primitive",
          "[coverage][clipping]") {
  // Two copies of one triangle (the samples' rule: level keeps the lower primitive), and a
  // third, smaller, on the same plane drawn before both.
  const TriangleSetup big =
      triangle(-kOne, -kOne, 2 * kOne, -kOne, -kOne, 2 * kOne, 0.4, 0.01, 0.02, 7);
  TriangleSetup copy = big;
  copy.primitive = 3;
  const TriangleSetup small =
      triangle(0, 0, kOne / 2, 0, 0, kOne / 2, 0.4, 0.01, 0.02, 1);  // a corner, area 1/8
  const std::vector<double> area = exact_areas({big, copy, small}, nullptr);
  CHECK(area[0] == 0.0);                                // primitive 7: hidden by its copy
  CHECK(area[1] == Approx(0.5 - 0.125).margin(1e-12));  // its part (x + y <= 1) less small's
  CHECK(area[2] == Approx(0.125).margin(1e-12));
}

TEST_CASE("visible parts: a plane that is not finite leaves the pixel to the samples",
          "[coverage][clipping]") {
  // The set-up of a degenerate triangle far out in the guard band can give NaN slopes (the
  // fuzzer found one): no order of depths exists, and the clipping declines the pixel.
  const TriangleSetup a = covering(0.5, 0.0, 0.0, 1);
  TriangleSetup b = covering(0.4, 0.0, 0.0, 2);
  b.dzdx = std::numeric_limits<double>::quiet_NaN();
  const TriangleSetup* tris[2] = {&a, &b};
  double area[2];
  CHECK_FALSE(visible_areas(2, tris, nullptr, 0, 0, area));
  CHECK_FALSE(visible_areas(1, tris, &b, 0, 0, area));  // as the opaque surface
  b.dzdx = 0.0;
  b.dzdy = std::numeric_limits<double>::infinity();
  CHECK_FALSE(visible_areas(2, tris, nullptr, 0, 0, area));
  CHECK(visible_areas(1, tris, nullptr, 0, 0, area));
  CHECK(area[0] == Approx(1.0).margin(1e-12));
}

TEST_CASE("visible parts: a tessellation of the pixel keeps every piece", "[coverage][clipping]") {
  // Four triangles fanned around the pixel centre, tilted differently (a folded-free mesh):
  // disjoint, each shows whole, and together they fill the pixel.
  const std::int32_t c = kOne / 2, o = 0, e = kOne;
  const std::vector<TriangleSetup> fan = {
      triangle(c, c, o, o, e, o, 0.50, 0.02, 0.00, 4),
      triangle(c, c, e, o, e, e, 0.51, -0.01, 0.03, 5),
      triangle(c, c, e, e, o, e, 0.49, 0.00, -0.02, 6),
      triangle(c, c, o, e, o, o, 0.52, 0.04, 0.01, 7),
  };
  const std::vector<double> area = exact_areas(fan, nullptr);
  double sum = 0.0;
  for (double a : area) {
    CHECK(a == Approx(0.25).margin(1e-12));
    sum += a;
  }
  CHECK(sum == Approx(1.0).margin(1e-12));
}

TEST_CASE("visible parts: random stacks agree with a brute-force count", "[coverage][clipping]") {
  // Up to eight triangles around pixel (0, 0), planes tilted at random, crossing each other
  // and an optional opaque plane; vertices in 24.8 fixed point. A 512 x 512 point count is
  // within a few thousandths of each visible area (the grid's step along every boundary).
  std::mt19937 rng(20261207);
  std::uniform_int_distribution<std::int32_t> coord(-kOne, 2 * kOne);
  std::uniform_real_distribution<double> depth(0.3, 0.7), slope(-0.2, 0.2);
  std::uniform_int_distribution<int> count(1, 8);
  int compared = 0, shown_in_part = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<TriangleSetup> tris;
    const int n = count(rng);
    for (int k = 0; k < n; ++k) {
      const std::uint32_t primitive = std::uint32_t(k + 1);
      TriangleSetup t = triangle(coord(rng), coord(rng), coord(rng), coord(rng), coord(rng),
                                 coord(rng), depth(rng), slope(rng), slope(rng), primitive);
      tris.push_back(t);
    }
    const bool with_opaque = trial % 3 == 0;
    const TriangleSetup opaque = covering(depth(rng), slope(rng), slope(rng), 0);
    const std::vector<double> exact = exact_areas(tris, with_opaque ? &opaque : nullptr);
    const std::vector<double> counted = counted_areas(tris, with_opaque ? &opaque : nullptr, 512);
    double sum = 0.0;
    for (std::size_t k = 0; k < tris.size(); ++k) {
      INFO("trial " << trial << ", fragment " << k << " of " << n);
      CHECK(exact[k] >= 0.0);
      CHECK(exact[k] == Approx(counted[k]).margin(4e-3));
      sum += exact[k];
      ++compared;
      shown_in_part += exact[k] > 0.01 && exact[k] < 0.99;
    }
    CHECK(sum <= 1.0 + 1e-12);
  }
  CHECK(compared > 150);
  CHECK(shown_in_part > 50);  // the test saw many partly hidden fragments, not only extremes
}

namespace {

/// `copies` copies of one triangle, each moved as a whole by a pseudo-random offset of up to
/// +-jitter in x and y and +-jitter / 4 in depth (the generator's stacked_offset, smaller):
/// many large fragments per pixel, nearly coincident, each hiding the others' edges.
std::shared_ptr<covrast::MeshData> jittered_stack(int copies, float jitter) {
  auto m = std::make_shared<covrast::MeshData>();
  m->source = "jittered stack";
  std::mt19937 rng(4242);
  std::uniform_real_distribution<float> d(-1.0f, 1.0f);
  const glm::vec3 corner[3] = {{-11.0f, -8.5f, 0.0f}, {12.5f, -5.5f, 0.0f}, {-1.5f, 9.5f, 0.0f}};
  for (int k = 0; k < copies; ++k) {
    const glm::vec3 offset(jitter * d(rng), jitter * d(rng), 0.25f * jitter * d(rng));
    const auto base = std::uint32_t(m->positions.size());
    for (const glm::vec3& c : corner) m->positions.push_back(c + offset);
    m->indices.insert(m->indices.end(), {base, base + 1, base + 2});
  }
  return m;
}

}  // namespace

TEST_CASE("visible parts: a jittered stack resolves exactly, the same on every split",
          "[coverage][clipping]") {
  covrast::Scene s = covrast::test::pixel_scene(32, 24);
  s.background_linear = glm::vec3(0.05f, 0.1f, 0.2f);
  covrast::test::add_instance(s, jittered_stack(300, 0.8f), glm::vec3(1),
                              covrast::ColorSource::PerTriangle);
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode("coverage");
  const covrast::RenderResult base = covrast::test::expect_same_bytes_for_every_split(s, options);
  const covrast::CoverageResolvePaths& paths = base.stats.resolve_paths;
  INFO("clipped " << paths.clipped << ", masked " << paths.masked << ", samples " << paths.samples
                  << ", overflowed " << paths.overflowed);
  CHECK(paths.clipped > 40);
  // Against the 64x64-sample reference, and against the same render with the masks and
  // samples alone: the clipping halves the error (in the masks' render the deep lists turn
  // into samples; here most drop what they hide instead). What error is left is in the logs
  // of more than six fragments, which the masks resolve (coverage.md, section 2); 256-sample
  // supersampling has about 1.35x this RMSE here.
  const covrast::Image reference = covrast::test::render_mode(s, "reference");
  const covrast::CompareResult coverage = covrast::compare_images(base.color, reference);
  const covrast::test::ScopedHook no_clipping(covrast::detail::testing::coverage_hooks.no_clipping,
                                              true);
  const covrast::RenderResult sampled = covrast::render(s, options);
  const covrast::CompareResult masks = covrast::compare_images(sampled.color, reference);
  INFO("clipped: rmse " << coverage.rmse_linear << ", max " << coverage.max_diff_srgb8
                        << "; masks and samples: rmse " << masks.rmse_linear << ", max "
                        << masks.max_diff_srgb8 << ", overflowed "
                        << sampled.stats.resolve_paths.overflowed);
  CHECK(coverage.rmse_linear <= 0.6 * masks.rmse_linear);
  CHECK(coverage.max_diff_srgb8 <= masks.max_diff_srgb8);
  CHECK(4 * paths.overflowed < sampled.stats.resolve_paths.overflowed);
}
