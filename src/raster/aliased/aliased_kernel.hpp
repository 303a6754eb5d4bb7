// Raster stage, aliased mode: the depth-test kernel. One sample at each pixel centre of a
// triangle's rectangle in the tile, top-left fill rule:
//
//   inside(x, y) <=> E_i(x + 1/2, y + 1/2) + bias_i >= 0 for the three edges (int64, exact),
//   z(x, y) = float(z0 + dzdx ((x + 1/2) - vx) + dzdy ((y + 1/2) - vy)),
//
// the plane evaluated at each pixel centre directly (never incrementally), left term first,
// then rounded to float; where inside and z < depth, depth = z and owner = id (nearest wins,
// equal depth keeps the earlier triangle). Contract: the SIMD kernel (aliased_kernel.cpp,
// one source for every Highway target) gives the scalar twin's (aliased_kernel_scalar.cpp)
// depth and owner bits exactly, for every target; tests/test_aliased_kernel.cpp checks it.
// It may read and write back unchanged up to kAliasedBufferPadding elements past the last
// pixel of the tile buffers, which must be padded so.
#pragma once

#include "core/edge_function.hpp"
#include "core/triangle_setup.hpp"

#include <cstddef>
#include <cstdint>

namespace covrast::detail {

/// Elements past the last tile pixel that a kernel may read and write back unchanged: at
/// least the lanes of the widest vector of 64-bit lanes of any target, minus one (2048-bit
/// SVE/RVV: 32). A literal: HWY_MAX_BYTES is the last compiled target's, not the widest.
inline constexpr std::size_t kAliasedBufferPadding = 64;

/// One triangle clipped to a tile: everything the depth-test kernels need.
struct AliasedJob {
  int x0, y0;              ///< first pixel [px, frame coordinates]
  int width, height;       ///< pixels of the rectangle to test (> 0)
  std::int64_t e[3];       ///< E + bias of each edge at the centre of pixel (x0, y0) [fx8^2]
  std::int64_t step_x[3];  ///< change of E + bias from a pixel to its right neighbour
  std::int64_t step_y[3];  ///< change of E + bias from a row to the next (down)
  /// Depth plane as in TriangleSetup::depth_at:
  ///   z(x, y) = z0 + dzdx (x - vx) + dzdy (y - vy), evaluated left to right.
  double z0, dzdx, dzdy, vx, vy;
  double* depth;         ///< tile depth at pixel (x0, y0): float values, or +infinity
  std::uint64_t* owner;  ///< tile owner at pixel (x0, y0)
  std::size_t stride;    ///< pixels from one tile row to the next
  std::uint64_t id;      ///< stored into owner where the triangle wins
};

/// A rasterizer's tile buffers.
struct AliasedTile {
  PixelRect rect;        ///< the tile's pixels
  double* depth;         ///< float values, or +infinity where nothing was drawn
  std::uint64_t* owner;  ///< see kFlatTag
  std::size_t stride;    ///< pixels from one row to the next
};

/// The job of triangle `t` over `r` (its touched pixels within the tile, not empty).
inline AliasedJob make_aliased_job(const TriangleSetup& t, const PixelRect& r,
                                   const AliasedTile& tile, std::uint64_t id) {
  const TriangleEdges edges(t);
  constexpr std::int64_t kHalf = kSubpixelOne / 2;
  const std::int64_t cx = std::int64_t(r.x0) * kSubpixelOne + kHalf;
  const std::int64_t cy = std::int64_t(r.y0) * kSubpixelOne + kHalf;
  AliasedJob job;
  job.x0 = r.x0;
  job.y0 = r.y0;
  job.width = r.x1 - r.x0;
  job.height = r.y1 - r.y0;
  for (int i = 0; i < 3; ++i) {
    job.e[i] = edges.e[i].at(cx, cy);
    job.step_x[i] = edges.e[i].step_x(kSubpixelOne);
    job.step_y[i] = edges.e[i].step_y(kSubpixelOne);
  }
  job.z0 = t.z0;
  job.dzdx = t.dzdx;
  job.dzdy = t.dzdy;
  job.vx = t.x_fx8[0] * (1.0 / kSubpixelOne);
  job.vy = t.y_fx8[0] * (1.0 / kSubpixelOne);
  const std::size_t offset =
      std::size_t(r.y0 - tile.rect.y0) * tile.stride + std::size_t(r.x0 - tile.rect.x0);
  job.depth = tile.depth + offset;
  job.owner = tile.owner + offset;
  job.stride = tile.stride;
  job.id = id;
  return job;
}

/// Depth-tests triangle `t` over `r` and records `id` as the owner where it wins.
using RasterAliasedFn = void (*)(const TriangleSetup& t, const PixelRect& r,
                                 const AliasedTile& tile, std::uint64_t id);

/// The scalar twin and reference: pixel by pixel, the arithmetic each SIMD lane does.
void raster_aliased_scalar(const TriangleSetup& t, const PixelRect& r, const AliasedTile& tile,
                           std::uint64_t id);

/// The SIMD kernel of the target Highway dispatches to now (best supported, or forced with
/// testing::force_simd_target), looked up once: a rasterizer keeps the pointer.
RasterAliasedFn raster_aliased_simd();

}  // namespace covrast::detail
