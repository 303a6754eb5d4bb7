// Geometry stage, triangle set-up: a TriangleSetup from three snapped vertices, a pure
// function of its arguments. Everything after snapping computes from the 24.8 vertices, so two
// triangles that share an edge get bit-identical edge data. Inline, in a header: it runs in
// the chunk loops of frontend.cpp for every triangle that passes the culls, and as a call
// there it made the set-up of sphere_grid.json about 7% slower (stage/setup_chunk in
// benchmarks/bench_kernels.cpp).
#pragma once

#include "geometry/frontend_stages.hpp"

namespace covrast::detail {

/// The set-up of one triangle from its three snapped vertices in submission order, written in
/// place into `t`: vertices reordered to positive area (v1 and v2 swapped when `front`), the
/// depth plane, 1 / w, colours in the same order, the flags; an unlit triangle
/// (`unlit_tone_mapping` not null) has its colours tone-mapped. Lit triangles get their
/// ShadingRecord afterwards (set_up_shading).
[[gnu::always_inline]] inline void set_up_triangle(const SnappedVertex& v0, const SnappedVertex& v1,
                                                   const SnappedVertex& v2, const glm::vec3& color0,
                                                   const glm::vec3& color1, const glm::vec3& color2,
                                                   bool front, bool flat, bool convex_surface,
                                                   std::uint32_t primitive, std::uint32_t surface,
                                                   const ToneMapping* unlit_tone_mapping,
                                                   TriangleSetup& t) {
  // Reorder to positive area.
  const SnappedVertex& s0 = v0;
  const SnappedVertex& s1 = front ? v2 : v1;
  const SnappedVertex& s2 = front ? v1 : v2;
  t.x_fx8[0] = s0.x_fx8;
  t.x_fx8[1] = s1.x_fx8;
  t.x_fx8[2] = s2.x_fx8;
  t.y_fx8[0] = s0.y_fx8;
  t.y_fx8[1] = s1.y_fx8;
  t.y_fx8[2] = s2.y_fx8;
  // Depth plane from the snapped positions: with d_k = s_k - s_0 in pixels,
  // z(x, y) = z0 + dzdx (x - x0) + dzdy (y - y0), where (Cramer's rule)
  // dzdx = (dz1 dy2 - dz2 dy1) / det, dzdy = (dx1 dz2 - dx2 dz1) / det, det = dx1 dy2 - dx2 dy1.
  const double inv_one = 1.0 / kSubpixelOne;
  const double dx1 = (s1.x_fx8 - s0.x_fx8) * inv_one, dy1 = (s1.y_fx8 - s0.y_fx8) * inv_one;
  const double dx2 = (s2.x_fx8 - s0.x_fx8) * inv_one, dy2 = (s2.y_fx8 - s0.y_fx8) * inv_one;
  const double dz1 = s1.z_window - s0.z_window;
  const double dz2 = s2.z_window - s0.z_window;
  const double det = dx1 * dy2 - dx2 * dy1;
  t.z0 = s0.z_window;
  // Both slopes in one two-lane division (the same IEEE quotients as two scalar ones, at
  // half the divider time on this hot path).
  const Double2 numerator = {dz1 * dy2 - dz2 * dy1, dx1 * dz2 - dx2 * dz1};
  const Double2 slope = numerator / Double2{det, det};
  t.dzdx = slope[0];
  t.dzdy = slope[1];
  t.inv_w[0] = s0.inv_w;
  t.inv_w[1] = s1.inv_w;
  t.inv_w[2] = s2.inv_w;
  t.color[0] = color0;
  t.color[1] = front ? color2 : color1;
  t.color[2] = front ? color1 : color2;
  t.primitive = primitive;
  t.surface = surface;
  t.front_facing = front;
  t.flat_color = flat;
  t.convex_surface = convex_surface;
  t.shading = nullptr;
  t.alpha_mode = AlphaMode::Opaque;
  if (unlit_tone_mapping != nullptr && !unlit_tone_mapping->is_identity()) {
    // Unlit colours are tone-mapped at the vertices (exact for uniform and per-triangle
    // colours; lit ones are tone-mapped where shade_lit makes them).
    for (glm::vec3& c : t.color) c = glm::vec3(tone_map(*unlit_tone_mapping, glm::dvec3(c)));
  }
}

}  // namespace covrast::detail
