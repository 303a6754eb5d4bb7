// Geometry stage, what its parts share (frontend.cpp runs the stages): the one clip-space
// expression of a model-space position and the one snap of a clip position, which the
// transform (frontend_transform.cpp) and clipping (frontend_clip.cpp) both use, so that a
// vertex gets the same bits whichever computes it; the clip planes and the near and far
// outcode bits; and the hand-overs between the stages: a clipped polygon (frontend_clip.cpp)
// and a triangle that passed the culls (frontend_cull.hpp). Private to the geometry stage.
#pragma once

#include "geometry/frontend.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#if defined(__x86_64__) || defined(_M_X64)
#include <emmintrin.h>
#endif

namespace covrast::detail {

/// Homogeneous plane: inside where dot(plane, position) >= 0.
using ClipPlane = glm::dvec4;

/// Outcode bits of the near and far planes (planes_[0] and planes_[1]).
inline constexpr unsigned kNearFarBits = 1u << 0 | 1u << 1;

/// Two doubles in one SSE2 / NEON register (GCC and Clang vector extension); arithmetic on
/// it is lane-wise IEEE arithmetic, the same results as on each lane alone.
using Double2 = double __attribute__((vector_size(16)));

/// Row r of mvp * (x, y, z, 1): the one expression for a model-space position in clip space.
/// transform_vertices (two vertices at a time, T = Double2, or one, T = double) and
/// clip_triangle both use it, so (with -ffp-contract=off) a vertex gets the same clip
/// position, bit for bit, whichever computes it. The order is glm's for mat4 * vec4,
/// (m0 x + m1 y) + (m2 z + m3 * 1), with m3 * 1 = m3.
template <class T>
inline T clip_row(const glm::dmat4& mvp, int r, T x, T y, T z) {
  return (mvp[0][r] * x + mvp[1][r] * y) + (mvp[2][r] * z + mvp[3][r]);
}

inline glm::dvec4 clip_position(const glm::dmat4& mvp, const glm::vec3& position) {
  const double x = position.x, y = position.y, z = position.z;
  return glm::dvec4(clip_row(mvp, 0, x, y, z), clip_row(mvp, 1, x, y, z), clip_row(mvp, 2, x, y, z),
                    clip_row(mvp, 3, x, y, z));
}

/// std::llrint(v) in the current rounding mode. glibc's x86-64 llrint is the single
/// instruction cvtsd2si (round to nearest even; 0x8000000000000000 for NaN and overflow),
/// but without -fno-math-errno the compiler keeps it an out-of-line call: issued here
/// directly it is the same instruction, inlined. Elsewhere the library call.
inline std::int64_t round_to_int64(double v) {
#if defined(__x86_64__) || defined(_M_X64)
  return _mm_cvtsd_si64(_mm_set_sd(v));
#else
  return std::llrint(v);
#endif
}

/// The viewport transform of a clip position, before rounding: x and y in 24.8 units, window
/// z (not yet clamped) and 1 / w.
template <class T>
struct ScreenPosition {
  T x_fx8, y_fx8, z_window, inv_w;
};
template <class T>
inline ScreenPosition<T> to_screen(T x, T y, T z, T w, double width_px, double height_px) {
  const T inv_w = 1.0 / w;
  return ScreenPosition<T>{(x * inv_w + 1.0) * 0.5 * width_px * double(kSubpixelOne),
                           (1.0 - y * inv_w) * 0.5 * height_px * double(kSubpixelOne),
                           z * inv_w * 0.5 + 0.5, inv_w};
}

/// One screen position rounded to the snapped vertex.
inline SnappedVertex snapped_vertex(double x_fx8, double y_fx8, double z_window, double inv_w) {
  return SnappedVertex{std::int32_t(round_to_int64(x_fx8)), std::int32_t(round_to_int64(y_fx8)),
                       std::clamp(z_window, 0.0, 1.0), float(inv_w)};
}

// Inline, so that transform_vertices writes the snapped vertex in place (a returned copy
// costs a store-forwarding stall per vertex).
inline SnappedVertex GeometryFrontEnd::snap(const glm::dvec4& c) const {
  const ScreenPosition<double> p = to_screen(c.x, c.y, c.z, c.w, width_px_, height_px_);
  return snapped_vertex(p.x_fx8, p.y_fx8, p.z_window, p.inv_w);
}

/// A triangle clipped to the near and far planes and the guard band (clip_triangle): a convex
/// polygon of `count` vertices in order around it, snapped, with their colours and, when the
/// triangle had shading inputs, their ShadeVertex. Each plane adds at most one vertex: 3 + 6,
/// room for 12.
struct ClippedPolygon {
  int count = 0;
  SnappedVertex snapped[12];
  glm::vec3 color[12];
  ShadeVertex shade[12];
};

/// A triangle that passed the per-triangle culls (passes_culls).
struct KeptTriangle {
  PixelRect pixels;  ///< touched_pixels of its snapped vertices, not clamped to the image
  bool front;        ///< counter-clockwise in NDC (TriangleSetup::front_facing)
};

}  // namespace covrast::detail
