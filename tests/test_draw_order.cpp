// Coverage mode's draw order (binning/tile_bins.hpp, sort_nearest_first; docs/coverage.md,
// "Draw order"): each tile's triangles nearest first, ties in submission order. Checked: the
// order itself on hand-made set-ups; on a rendered stack of spheres, that coverage's bytes do
// not depend on the order they are submitted in (submitted back to front, the old draw order
// gave other bytes), and that what lies behind skips the area kernel even when it is
// submitted first.
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include "binning/tile_bins.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "test_meshes.hpp"

using covrast::detail::TriangleSetup;

namespace {

/// A set-up triangle over pixels (0, 0)-(8, 8) whose depth plane is z0 at vertex 0 and
/// changes by dzdx per pixel across.
TriangleSetup setup_at(double z0, double dzdx, std::uint32_t primitive) {
  TriangleSetup t{};
  const std::int32_t one = covrast::detail::kSubpixelOne;
  const std::int32_t xs[3] = {0, 8 * one, 0}, ys[3] = {0, 0, 8 * one};
  std::copy(xs, xs + 3, t.x_fx8);
  std::copy(ys, ys + 3, t.y_fx8);
  t.z0 = z0;
  t.dzdx = dzdx;
  t.dzdy = 0.0;
  t.primitive = primitive;
  return t;
}

/// Spheres of radius 1 along the view axis at distinct depths, each its own colour, in
/// `order` (indices into the depths), over a 160 x 96 frame seen from (0, 0, 8).
covrast::Scene sphere_stack(const std::vector<int>& order) {
  covrast::Scene scene;
  scene.width = 160;
  scene.height = 96;
  scene.camera.eye = {0.0, 0.0, 8.0};
  scene.camera.target = {0.0, 0.0, 0.0};
  scene.camera.fovy_deg = 40.0;
  scene.camera.near = 1.0;
  scene.camera.far = 30.0;
  const auto sphere = covrast::test::uv_sphere(40, 80);
  for (const int k : order) {
    const glm::vec3 colour(0.1f + 0.12f * k, 0.9f - 0.1f * k, 0.3f + 0.05f * k);
    covrast::test::add_instance(scene, sphere, colour);
    // Each sphere a little to the right of and behind the one before: they overlap on screen.
    scene.meshes.back().model = glm::dmat4(1.0);
    scene.meshes.back().model[3] = glm::dvec4(0.35 * k - 1.2, 0.1 * k, -1.5 * k, 1.0);
  }
  return scene;
}

}  // namespace

TEST_CASE("coverage's draw order: nearest first by the plane at the vertices, ties as submitted",
          "[coverage][binning]") {
  // Depths at the nearest vertex: a 0.5 (flat), b 0.3 (flat), c 0.2 (tilted: 0.6 at vertex 0,
  // falling 0.05 a pixel, so 0.2 at x = 8), d 0.3 (flat, a tie with b, submitted after it).
  const TriangleSetup a = setup_at(0.5, 0.0, 0), b = setup_at(0.3, 0.0, 1),
                      c = setup_at(0.6, -0.05, 2), d = setup_at(0.3, 0.0, 3);
  std::vector<const TriangleSetup*> order = {&a, &b, &c, &d};
  covrast::detail::sort_nearest_first(order);
  CHECK(order == std::vector<const TriangleSetup*>{&c, &b, &d, &a});
  // The same set submitted in another order: the same order but for the tie.
  std::vector<const TriangleSetup*> again = {&d, &a, &c, &b};
  covrast::detail::sort_nearest_first(again);
  CHECK(again == std::vector<const TriangleSetup*>{&c, &d, &b, &a});
}

TEST_CASE("coverage: spheres at distinct depths give the same bytes in either submission order",
          "[coverage][binning]") {
  const covrast::Scene far_first = sphere_stack({5, 4, 3, 2, 1, 0});
  const covrast::Scene near_first = sphere_stack({0, 1, 2, 3, 4, 5});
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode("coverage");
  options.threads = 2;
  options.want_depth = true;
  for (const int tile : {16, 64}) {
    INFO("tile " << tile);
    options.tile = tile;
    const covrast::RenderResult back_to_front = covrast::render(far_first, options);
    const covrast::RenderResult front_to_back = covrast::render(near_first, options);
    CHECK(back_to_front.color.rgb == front_to_back.color.rgb);
    CHECK(back_to_front.depth.depth == front_to_back.depth.depth);
    // Drawn nearest first, the spheres behind are skipped before the kernel where the ones in
    // front hide them, though they were submitted first.
    INFO("hidden " << back_to_front.stats.hidden_bin_entries << " of "
                   << back_to_front.stats.bin_entries);
    CHECK(back_to_front.stats.hidden_bin_entries > back_to_front.stats.bin_entries / 5);
  }
}
