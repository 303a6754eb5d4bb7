// Tests: the per-pixel fragment log of coverage mode (src/raster/coverage/pixel_log.hpp): the
// edge keys that prove a pixel tiled by one layer, the log's states, and what the proven and
// masked resolves give against the fragment list and the 64x64-sample reference.
#include <covrast/compare.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <vector>

#include "core/testing_hooks.hpp"
#include "raster/coverage/coverage_kernel.hpp"
#include "raster/coverage/pixel_log.hpp"
#include "test_hooks.hpp"
#include "test_meshes.hpp"
#include "test_splits.hpp"

using covrast::detail::EdgeCrossingKeys;
using covrast::detail::kCoverageOne;
using covrast::detail::kSubpixelOne;
using covrast::detail::LogState;
using covrast::detail::PixelLog;
using covrast::detail::TriangleSetup;

namespace {

/// A triangle with snapped vertices [fx8] and nothing else set (the keys read only those).
TriangleSetup triangle_fx8(std::int32_t x0, std::int32_t y0, std::int32_t x1, std::int32_t y1,
                           std::int32_t x2, std::int32_t y2) {
  TriangleSetup t{};
  t.x_fx8[0] = x0, t.y_fx8[0] = y0;
  t.x_fx8[1] = x1, t.y_fx8[1] = y1;
  t.x_fx8[2] = x2, t.y_fx8[2] = y2;
  return t;
}

/// A fan of `n` triangles around a centre inside pixel (10, 10), out to a ring of radius 3
/// pixels: together they cover the pixel exactly once. Every other triangle is clockwise when
/// `alternate` (a mesh's winding is not the keys' concern, only which side each lies on).
std::vector<TriangleSetup> fan_over_pixel(int n, bool alternate = false) {
  const double cx = 10.37 * kSubpixelOne, cy = 10.61 * kSubpixelOne, r = 3.0 * kSubpixelOne;
  std::vector<std::int32_t> ring_x, ring_y;
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * std::numbers::pi * (k + 0.3) / n;
    ring_x.push_back(std::int32_t(std::lround(cx + r * std::cos(a))));
    ring_y.push_back(std::int32_t(std::lround(cy + r * std::sin(a))));
  }
  const auto x = std::int32_t(std::lround(cx)), y = std::int32_t(std::lround(cy));
  std::vector<TriangleSetup> fan;
  for (int k = 0; k < n; ++k) {
    const int j = (k + 1) % n;
    fan.push_back(alternate && k % 2 == 1
                      ? triangle_fx8(x, y, ring_x[j], ring_y[j], ring_x[k], ring_y[k])
                      : triangle_fx8(x, y, ring_x[k], ring_y[k], ring_x[j], ring_y[j]));
  }
  return fan;
}

std::uint64_t key_sum(const std::vector<TriangleSetup>& triangles, int x, int y) {
  std::uint64_t sum = 0;
  EdgeCrossingKeys keys;
  for (const TriangleSetup& t : triangles) {
    keys.set(t);
    sum += keys.crossing_sum(x, y);
  }
  return sum;
}

covrast::RenderResult render_coverage(const covrast::Scene& s, bool list_only, int threads = 2,
                                      int tile = 64) {
  const covrast::test::ScopedHook hook(covrast::detail::testing::coverage_hooks.list_only,
                                       list_only);
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode("coverage");
  options.threads = threads;
  options.tile = tile;
  return covrast::render(s, options);
}

}  // namespace

TEST_CASE("pixel log: the edge keys of a pixel's tiling cancel, and nothing else's do",
          "[coverage][log]") {
  for (bool alternate : {false, true}) {
    INFO((alternate ? "alternating winding" : "one winding"));
    std::vector<TriangleSetup> fan = fan_over_pixel(7, alternate);
    CHECK(key_sum(fan, 10, 10) == 0);
    // A piece missing leaves two spokes unmatched.
    std::vector<TriangleSetup> missing(fan.begin() + 1, fan.end());
    CHECK(key_sum(missing, 10, 10) != 0);
    // A piece twice: the pixel is covered twice there.
    std::vector<TriangleSetup> doubled = fan;
    doubled.push_back(fan[3]);
    CHECK(key_sum(doubled, 10, 10) != 0);
  }
  // A piece folded over its neighbour: mirrored through the centre so that it lies on the
  // same side of their shared spoke (centre -> ring point 3) as the neighbour.
  const std::vector<TriangleSetup> fan = fan_over_pixel(7);
  std::vector<TriangleSetup> folded = fan;
  const TriangleSetup& o = fan[3];  // (centre, ring 3, ring 4)
  folded[3] = triangle_fx8(o.x_fx8[0], o.y_fx8[0], o.x_fx8[1], o.y_fx8[1],
                           2 * o.x_fx8[0] - o.x_fx8[2], 2 * o.y_fx8[0] - o.y_fx8[2]);
  CHECK(key_sum(folded, 10, 10) != 0);
  // The neighbouring pixels see only the spokes that cross them, matched as well.
  CHECK(key_sum(fan, 11, 10) == 0);
  CHECK(key_sum(fan, 10, 9) == 0);
  // An edge along the pixel's border crosses no open square: neither pixel counts it.
  const TriangleSetup below = triangle_fx8(2560, 2816, 2816, 2816, 2688, 2900);
  EdgeCrossingKeys keys;
  keys.set(below);
  CHECK(keys.crossing_sum(10, 10) == 0);
}

TEST_CASE("pixel log: a tiling proves a layer, which hides what lies behind it",
          "[coverage][log]") {
  const std::vector<TriangleSetup> fan = fan_over_pixel(6);
  PixelLog log(1);
  log.clear_entries();
  log.start_pixel(0, true);
  // Coverage values that add up to the pixel (the proof reads only their sum and the keys).
  const std::uint32_t piece = std::uint32_t(kCoverageOne) / 6;
  for (int k = 0; k < 5; ++k) {
    log.append(0, 10, 10, fan[std::size_t(k)], piece, 0.5 + 0.01 * k, 0.002);
    CHECK(log.state(0) == LogState::Open);
  }
  log.append(0, 10, 10, fan[5], std::uint32_t(kCoverageOne) - 5 * piece, 0.55, 0.002);
  CHECK(log.state(0) == LogState::Proven);
  CHECK(log.count(0) == 6);
  // The farthest depth a piece reaches: 0.55 + 0.002.
  CHECK(log.hidden_from(0) == 0.55 + 0.002);
  // Anything logged after it lies in front of the layer somewhere: the pixel is mixed.
  log.append(0, 10, 10, fan[0], piece, 0.3, 0.002);
  CHECK(log.state(0) == LogState::Mixed);
  int seen = 0;
  log.for_each(0, [&](const covrast::detail::LoggedFragment& f) {
    CHECK(f.triangle == &fan[std::size_t(seen < 6 ? seen : 0)]);  // arrival order
    ++seen;
  });
  CHECK(seen == 7);

  // Areas that reach the pixel without a zero key sum do not prove it.
  log.start_pixel(0, true);
  for (int k = 0; k < 3; ++k)
    log.append(0, 10, 10, fan[std::size_t(k)], kCoverageOne / 2, 0.5, 0.0);
  CHECK(log.state(0) == LogState::Mixed);
  // Off stays off.
  log.start_pixel(0, false);
  CHECK(log.state(0) == LogState::Off);
}

TEST_CASE("pixel log: a mixed pixel proves a later layer from a run, which hides what is behind",
          "[coverage][log]") {
  const std::vector<TriangleSetup> front = fan_over_pixel(5), layer = fan_over_pixel(6, true);
  const std::uint32_t half = std::uint32_t(kCoverageOne) / 2,
                      sixth = std::uint32_t(kCoverageOne) / 6;
  const auto append_layer = [&](PixelLog& log, double depth) {
    for (int k = 0; k < 6; ++k) {
      const std::uint32_t c = k < 5 ? sixth : std::uint32_t(kCoverageOne) - 5 * sixth;
      log.append(0, 10, 10, layer[std::size_t(k)], c, depth + 0.01 * k, 0.002);
    }
  };
  // The farthest depth the layer's pieces reach, as the log computes it.
  const auto far_of_layer = [](double depth) { return depth + 0.01 * 5 + 0.002; };
  PixelLog log(1);
  log.clear_entries();
  log.start_pixel(0, true);
  // Two halves of a fan reach the pixel without a zero key sum: mixed, nothing proven.
  for (int k = 0; k < 2; ++k) log.append(0, 10, 10, front[std::size_t(k)], half, 0.2, 0.001);
  REQUIRE(log.state(0) == LogState::Mixed);
  CHECK(std::isinf(log.hidden_from(0)));
  // A layer further back tiles the pixel: its farthest depth hides what follows.
  append_layer(log, 0.6);
  CHECK(log.state(0) == LogState::Mixed);
  CHECK(log.hidden_from(0) == far_of_layer(0.6));
  // A nearer layer lowers the bound; a farther one leaves it.
  append_layer(log, 0.9);
  CHECK(log.hidden_from(0) == far_of_layer(0.6));
  append_layer(log, 0.4);
  CHECK(log.hidden_from(0) == far_of_layer(0.4));

  // A run that reaches the pixel without a proof starts again from its last fragment, which
  // here begins a layer: the bound is the layer's alone, not the stray piece's (depth 0.95).
  log.start_pixel(0, true);
  for (int k = 0; k < 2; ++k) log.append(0, 10, 10, front[std::size_t(k)], half, 0.2, 0.001);
  log.append(0, 10, 10, front[3], std::uint32_t(kCoverageOne) - 10, 0.95, 0.001);
  CHECK(std::isinf(log.hidden_from(0)));
  append_layer(log, 0.6);
  CHECK(log.hidden_from(0) == far_of_layer(0.6));

  // Pieces that overlap (the same piece twice) prove nothing, however far they go.
  log.start_pixel(0, true);
  for (int k = 0; k < 2; ++k) log.append(0, 10, 10, front[std::size_t(k)], half, 0.2, 0.001);
  for (int k = 0; k < 8; ++k) log.append(0, 10, 10, layer[0], half, 0.6, 0.002);
  CHECK(std::isinf(log.hidden_from(0)));
  // Pieces of one facing of a convex surface never overlap: reaching the pixel, they prove a
  // layer without the keys (these two halves alone would not).
  log.start_pixel(0, true);
  for (int k = 0; k < 2; ++k) log.append(0, 10, 10, front[std::size_t(k)], half, 0.2, 0.001);
  TriangleSetup convex[2] = {front[2], front[3]};
  for (TriangleSetup& t : convex) t.convex_surface = true, t.surface = 3, t.front_facing = true;
  log.append(0, 10, 10, convex[0], half, 0.7, 0.002);
  log.append(0, 10, 10, convex[1], half, 0.7, 0.002);
  CHECK(log.hidden_from(0) == 0.7 + 0.002);
  // And a proven first layer with a fragment in front: the run starts at that fragment.
  log.start_pixel(0, true);
  append_layer(log, 0.6);
  REQUIRE(log.state(0) == LogState::Proven);
  append_layer(log, 0.3);
  CHECK(log.state(0) == LogState::Mixed);
  CHECK(log.hidden_from(0) == far_of_layer(0.3));
}

TEST_CASE("pixel log: proven layers give the list's bytes, and every path is taken",
          "[coverage][log]") {
  // Two spheres whose triangles are near pixel size. The left one is analysed: convex, its
  // back faces culled, its pieces of one facing taken as disjoint. The right one is not: its
  // back faces are drawn behind its front, and only the edge keys prove its front layer; at
  // its silhouette the two layers meet, and the masks decide.
  covrast::Scene s = covrast::test::pixel_scene(128, 96);
  s.camera.eye = glm::dvec3(0.0, 0.3, 3.2);
  s.camera.fovy_deg = 40.0;
  auto convex = covrast::test::uv_sphere(40, 80);
  covrast::analyze_mesh_topology(*convex);
  covrast::test::add_instance(s, convex, glm::vec3(1), covrast::ColorSource::PerTriangle);
  s.meshes.back().model[3] = glm::dvec4(-0.55, 0.0, 0.0, 1.0);
  covrast::test::add_instance(s, covrast::test::uv_sphere(40, 80), glm::vec3(1),
                              covrast::ColorSource::PerTriangle);
  s.meshes.back().model[3] = glm::dvec4(0.55, 0.0, -0.3, 1.0);
  const covrast::RenderResult clipped = render_coverage(s, false);
  // The log against the list, both with the masks and samples alone (the clipping is exact
  // where they estimate, so it would show as a difference between them).
  const covrast::test::ScopedHook no_clipping(covrast::detail::testing::coverage_hooks.no_clipping,
                                              true);
  const covrast::RenderResult log = render_coverage(s, false);
  const covrast::RenderResult list = render_coverage(s, true);
  const covrast::CoverageResolvePaths& paths = log.stats.resolve_paths;
  INFO("proven " << paths.proven_layer << ", masked " << paths.masked);
  CHECK(paths.proven_layer > 1000);
  CHECK(paths.masked > 50);  // the silhouette over the background
  CHECK(list.stats.resolve_paths.proven_layer + list.stats.resolve_paths.masked == 0);
  // Pixel by pixel: where the log proved a layer the list added the same disjoint areas, so
  // the images differ only at the silhouette, by the masks' share of what the list proves.
  const covrast::CompareResult c = covrast::compare_images(log.color, list.color);
  INFO("against the list: max " << c.max_diff_srgb8 << ", pixels over 1: " << c.pixels_over_1);
  CHECK(c.max_diff_srgb8 <= 1);
  // And both against the 64x64-sample reference.
  covrast::RenderOptions reference;
  reference.mode = covrast::parse_render_mode("reference");
  const covrast::Image ref = covrast::render(s, reference).color;
  const covrast::CompareResult log_ref = covrast::compare_images(log.color, ref);
  const covrast::CompareResult list_ref = covrast::compare_images(list.color, ref);
  INFO("log: rmse " << log_ref.rmse_linear << ", max " << log_ref.max_diff_srgb8 << "; list: rmse "
                    << list_ref.rmse_linear << ", max " << list_ref.max_diff_srgb8);
  CHECK(log_ref.rmse_linear <= 1.05 * list_ref.rmse_linear);
  CHECK(log_ref.max_diff_srgb8 <= list_ref.max_diff_srgb8 + 1);
  // The default render clips the small mixed logs exactly: closer to the reference.
  const covrast::CompareResult clipped_ref = covrast::compare_images(clipped.color, ref);
  INFO("clipped: rmse " << clipped_ref.rmse_linear << ", max " << clipped_ref.max_diff_srgb8
                        << ", pixels " << clipped.stats.resolve_paths.clipped);
  CHECK(clipped.stats.resolve_paths.clipped > 20);
  CHECK(clipped_ref.rmse_linear <= log_ref.rmse_linear);
  CHECK(clipped_ref.max_diff_srgb8 <= log_ref.max_diff_srgb8);
}

TEST_CASE("pixel log: the same bytes for every thread count and tile size", "[coverage][log]") {
  covrast::Scene s = covrast::test::pixel_scene(80, 60);
  s.camera.eye = glm::dvec3(0.4, 0.2, 2.6);
  auto sphere = covrast::test::uv_sphere(30, 60);  // not analysed: back faces drawn too
  covrast::test::add_instance(s, sphere, glm::vec3(1), covrast::ColorSource::PerTriangle);
  const covrast::test::ScopedHook hook(covrast::detail::testing::coverage_hooks.list_only, false);
  const covrast::RenderResult base = covrast::test::expect_same_bytes_for_every_split(
      s, "coverage", covrast::test::every_split({1, 2, 3}, {8, 16, 32}),
      [](const covrast::RenderResult& r, const covrast::RenderResult& b, covrast::test::Split) {
        CHECK(r.stats.resolve_paths.masked == b.stats.resolve_paths.masked);
        CHECK(r.stats.resolve_paths.clipped == b.stats.resolve_paths.clipped);
      });
  // Folds at the silhouette, two layers: the larger mixed logs take the masks, the smaller
  // the clipping.
  CHECK(base.stats.resolve_paths.masked > 50);
  CHECK(base.stats.resolve_paths.clipped > 5);
}
