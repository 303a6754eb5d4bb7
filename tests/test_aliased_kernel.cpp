// Tests of the aliased mode's depth-test kernel (src/raster/aliased/aliased_kernel.hpp): on
// every Highway target compiled and supported here, the SIMD kernel gives the scalar twin's
// depth and owner bits for random triangles over a tile, including triangles far larger than
// the tile, slivers, planes level with what the tile holds, and rectangles clipped by the
// tile; and it leaves the buffers' padding as it found it.
#include "core/triangle_setup.hpp"
#include "raster/aliased/aliased_kernel.hpp"

#include <catch2/catch.hpp>

#include "test_targets.hpp"

#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using covrast::detail::AliasedTile;
using covrast::detail::kAliasedBufferPadding;
using covrast::detail::kSubpixelOne;
using covrast::detail::PixelRect;
using covrast::detail::TriangleSetup;

constexpr int kTilePx = 64;

/// A triangle in the set-up's orientation (positive doubled area) with a depth plane.
TriangleSetup oriented_triangle(const std::int32_t (&x)[3], const std::int32_t (&y)[3], double z0,
                                double dzdx, double dzdy) {
  TriangleSetup t{};
  for (int i = 0; i < 3; ++i) {
    t.x_fx8[i] = x[i];
    t.y_fx8[i] = y[i];
  }
  if (std::int64_t(x[1] - x[0]) * (y[2] - y[0]) - std::int64_t(x[2] - x[0]) * (y[1] - y[0]) < 0) {
    std::swap(t.x_fx8[1], t.x_fx8[2]);
    std::swap(t.y_fx8[1], t.y_fx8[2]);
  }
  t.z0 = z0;
  t.dzdx = dzdx;
  t.dzdy = dzdy;
  return t;
}

/// A tile's depth and owner buffers with their padding.
struct TileBuffers {
  std::vector<double> depth;
  std::vector<std::uint64_t> owner;
  explicit TileBuffers(std::size_t pixels)
      : depth(pixels + kAliasedBufferPadding), owner(pixels + kAliasedBufferPadding) {}
  AliasedTile view(const PixelRect& rect) {
    return AliasedTile{rect, depth.data(), owner.data(), std::size_t(kTilePx)};
  }
  bool operator==(const TileBuffers& o) const {
    return std::memcmp(depth.data(), o.depth.data(), depth.size() * sizeof(double)) == 0 &&
           owner == o.owner;
  }
};

}  // namespace

TEST_CASE("aliased kernel: every SIMD target gives the scalar twin's bits", "[aliased]") {
  std::mt19937 rng(0xa11a5edu);
  auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<>(lo, hi)(rng);
  };
  auto pick = [&](int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); };
  const PixelRect tile_rect{128, 64, 128 + kTilePx, 64 + kTilePx};
  constexpr std::size_t kPixels = std::size_t(kTilePx) * kTilePx;
  auto level = [](int k) { return double(float((1 + k) / 10.0)); };

  // Start buffers: a depth per pixel (float values as the kernel stores them, or +inf) and
  // an owner; the padding holds values the kernel must write back unchanged.
  TileBuffers start(kPixels);
  for (std::size_t i = 0; i < start.depth.size(); ++i) {
    // Half on eight float levels, so that planes flat at a level tie with many pixels.
    const int kind = pick(4);
    start.depth[i] = kind == 0   ? std::numeric_limits<double>::infinity()
                     : kind == 1 ? double(float(uniform(0.0, 1.0)))
                                 : level(pick(8));
    start.owner[i] = std::uint64_t(rng()) << 32 | rng();
  }
  std::vector<std::pair<TriangleSetup, PixelRect>> jobs;
  for (int n = 0; n < 500; ++n) {
    // Sizes from a sliver to many tiles; positions around and inside the tile [fx8].
    const double size_px = std::vector<double>{0.3, 2.0, 9.0, 40.0, 300.0}[std::size_t(pick(5))];
    const double cx = uniform(tile_rect.x0 - 8, tile_rect.x1 + 8);
    const double cy = uniform(tile_rect.y0 - 8, tile_rect.y1 + 8);
    std::int32_t x[3], y[3];
    for (int i = 0; i < 3; ++i) {
      x[i] = std::int32_t((cx + uniform(-size_px, size_px)) * kSubpixelOne);
      y[i] = std::int32_t((cy + uniform(-size_px, size_px)) * kSubpixelOne);
    }
    if (std::int64_t(x[1] - x[0]) * (y[2] - y[0]) == std::int64_t(x[2] - x[0]) * (y[1] - y[0])) {
      continue;  // the set-up drops degenerate triangles
    }
    // Half the planes flat at a level (ties), the others sloped, mostly behind the nearer
    // levels so that those survive to meet the flat planes.
    const bool flat = pick(2) == 0;
    const double z0 = flat ? level(pick(8)) : uniform(0.3, 1);
    const double slope = flat ? 0.0 : 1e-3;
    const TriangleSetup t =
        oriented_triangle(x, y, z0, uniform(-slope, slope), uniform(-slope, slope));
    PixelRect r = covrast::detail::intersect(touched_pixels(t), tile_rect);
    if (pick(4) == 0 && !r.empty()) r.x1 = r.x0 + 1 + pick(r.x1 - r.x0);  // clipped further
    if (!r.empty()) jobs.emplace_back(t, r);
  }
  REQUIRE(jobs.size() > 300);

  // All jobs in order into one tile (later ones see what earlier ones wrote), per kernel.
  auto run = [&](covrast::detail::RasterAliasedFn kernel) {
    TileBuffers b = start;
    for (std::size_t k = 0; k < jobs.size(); ++k) {
      kernel(jobs[k].first, jobs[k].second, b.view(tile_rect), 1000 + k);
    }
    return b;
  };
  const TileBuffers scalar = run(&covrast::detail::raster_aliased_scalar);
  // The jobs change the tile: the comparison is not between two untouched copies.
  std::size_t written = 0;
  for (std::size_t i = 0; i < kPixels; ++i) written += scalar.owner[i] != start.owner[i];
  CHECK(written > kPixels / 2);
  for (std::size_t i = kPixels; i < start.depth.size(); ++i) {
    CHECK(scalar.owner[i] == start.owner[i]);
  }
  int targets = 0;
  covrast::test::for_each_target([&](std::int64_t) {
    const TileBuffers simd = run(covrast::detail::raster_aliased_simd());
    std::ostringstream first;
    for (std::size_t i = 0; i < simd.depth.size() && first.str().empty(); ++i) {
      if (std::memcmp(&simd.depth[i], &scalar.depth[i], sizeof(double)) != 0 ||
          simd.owner[i] != scalar.owner[i]) {
        first << "first difference at element " << i << ": depth " << simd.depth[i] << " vs "
              << scalar.depth[i] << ", owner " << simd.owner[i] << " vs " << scalar.owner[i];
      }
    }
    INFO(first.str());
    CHECK(simd == scalar);
    ++targets;
  });
  CHECK(targets >= 1);
}
