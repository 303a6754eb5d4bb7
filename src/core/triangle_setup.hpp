// Geometry stage output: one screen-space triangle, ready for binning and raster.
//
// Every later stage computes from the snapped fixed-point vertices (x_fx8, y_fx8), so two
// triangles that share an edge see bit-identical edge data, whatever tile, thread or SIMD
// target processes them. Fixed point: 24.8 (1/256 pixel), pixel (x, y) covers
// [x, x+1] x [y, y+1], y down, row 0 at the top.
#pragma once

#include <covrast/shading.hpp>

#include <glm/glm.hpp>

#include <algorithm>
#include <cstdint>

namespace covrast::detail {

inline constexpr int kSubpixelBits = 8;
inline constexpr std::int32_t kSubpixelOne = 1 << kSubpixelBits;  ///< 1 pixel in fx8 units

/// Clipped screen positions stay within [-kGuardBandPx, size + kGuardBandPx]: large enough
/// that clipping against the guard band is rare, small enough that edge functions of
/// 24.8 coordinates fit comfortably in int64 (|coordinate| < 2^24 fx8 units).
inline constexpr double kGuardBandPx = 16384.0;

inline constexpr std::uint32_t kNoTriangle = 0xffffffffu;

struct ShadingRecord;  // shading/shading_inputs.hpp

struct TriangleSetup {
  /// Vertices in 24.8 fixed point, ordered so that the doubled signed area
  /// (x1-x0)(y2-y0) - (x2-x0)(y1-y0) is positive (clockwise on screen, y down).
  std::int32_t x_fx8[3];
  std::int32_t y_fx8[3];
  /// Window depth plane (0 = near, 1 = far): z(x, y) = z0 + dzdx (x - x0) + dzdy (y - y0),
  /// x, y in pixels, (x0, y0) = vertex 0. Window z/w is affine in screen space.
  double z0;
  double dzdx;
  double dzdy;
  float inv_w[3];           ///< 1 / clip w per vertex, for perspective-correct attributes
  glm::vec3 color[3];       ///< linear light per vertex (all equal when flat)
  std::uint32_t primitive;  ///< global triangle index in submission order (draw order)
  std::uint32_t surface;    ///< mesh instance index: fragments of one surface may merge
  /// Lit triangles only: what shade() needs besides the colours (world-space positions and
  /// normals, material, lights), written by the front end; null = unlit, colour as is.
  const ShadingRecord* shading = nullptr;
  bool front_facing;  ///< counter-clockwise in NDC (OpenGL convention)
  bool flat_color;    ///< color[0] == color[1] == color[2] and unlit
  /// Of a convex mesh under an affine model matrix: triangles of one surface and facing with
  /// this flag never overlap on screen (the A-buffer skips their overlap test).
  bool convex_surface;
  /// Opaque unless the material says otherwise. Non-opaque triangles always have a
  /// ShadingRecord, which holds what their alpha is made of.
  AlphaMode alpha_mode;

  double depth_at(double x_px, double y_px) const {
    return z0 + dzdx * (x_px - x_fx8[0] * (1.0 / kSubpixelOne)) +
           dzdy * (y_px - y_fx8[0] * (1.0 / kSubpixelOne));
  }
};

// Two cache lines at most: the tile loop prefetches exactly two lines per triangle.
static_assert(sizeof(TriangleSetup) <= 128);
// The alpha mode lives in the padding after the flags: opaque scenes move no more bytes.
static_assert(sizeof(TriangleSetup) == 120);

/// Pixel bounds [x0, x1) x [y0, y1).
struct PixelRect {
  int x0 = 0;
  int y0 = 0;
  int x1 = 0;
  int y1 = 0;
  bool empty() const { return x0 >= x1 || y0 >= y1; }
  /// Pixels in the rectangle (0 when empty).
  std::uint64_t pixel_count() const {
    return empty() ? 0 : std::uint64_t(x1 - x0) * std::uint64_t(y1 - y0);
  }
};

/// Pixels that a triangle with these vertices [fx8, any order] can touch: floor of the
/// minimum to ceil of the maximum.
inline PixelRect touched_pixels(const std::int32_t (&x_fx8)[3], const std::int32_t (&y_fx8)[3]) {
  // Pairwise min/max (the initializer-list forms compile to a loop with branches).
  const std::int32_t minx = std::min(x_fx8[0], std::min(x_fx8[1], x_fx8[2]));
  const std::int32_t maxx = std::max(x_fx8[0], std::max(x_fx8[1], x_fx8[2]));
  const std::int32_t miny = std::min(y_fx8[0], std::min(y_fx8[1], y_fx8[2]));
  const std::int32_t maxy = std::max(y_fx8[0], std::max(y_fx8[1], y_fx8[2]));
  // Arithmetic shift = floor division by 256 for negative values too.
  return PixelRect{minx >> kSubpixelBits, miny >> kSubpixelBits,
                   (maxx + kSubpixelOne - 1) >> kSubpixelBits,
                   (maxy + kSubpixelOne - 1) >> kSubpixelBits};
}

/// Pixels that the triangle's area can touch.
inline PixelRect touched_pixels(const TriangleSetup& t) { return touched_pixels(t.x_fx8, t.y_fx8); }

/// touched_pixels clamped to the image, in 16 bits (image sides are at most 16384 px):
/// all that binning needs, 8 bytes per triangle instead of the whole setup.
struct PixelBounds16 {
  std::uint16_t x0, y0, x1, y1;  ///< [x0, x1) x [y0, y1), never empty
};

inline PixelRect intersect(const PixelRect& a, const PixelRect& b) {
  return PixelRect{std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1),
                   std::min(a.y1, b.y1)};
}

}  // namespace covrast::detail
