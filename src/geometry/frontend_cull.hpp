// Geometry stage, the per-triangle culls (frontend.hpp, passes_culls): zero area after
// snapping, wholly outside the image, a hidden back face, a back face of a single-sided
// material; the per-instance decisions they apply are in frontend_cull.cpp. Inline, in a
// header: they run in the chunk loops of frontend.cpp for every triangle, and as a call there
// (with the set-up) they made the set-up of sphere_grid.json about 17% slower
// (stage/setup_chunk in benchmarks/bench_kernels.cpp).
#pragma once

#include "geometry/frontend_stages.hpp"

namespace covrast::detail {

[[gnu::always_inline]] inline bool GeometryFrontEnd::passes_culls(
    const SnappedVertex& v0, const SnappedVertex& v1, const SnappedVertex& v2,
    std::uint32_t primitive, Sink& sink, KeptTriangle& kept) const {
  const std::int64_t ax = v1.x_fx8 - v0.x_fx8, ay = v1.y_fx8 - v0.y_fx8;
  const std::int64_t bx = v2.x_fx8 - v0.x_fx8, by = v2.y_fx8 - v0.y_fx8;
  const std::int64_t area2 = ax * by - bx * ay;
  if (area2 == 0) {
    ++sink.counters.culled;
    return false;
  }
  // Reject triangles wholly outside the image.
  const PixelRect r =
      touched_pixels({v0.x_fx8, v1.x_fx8, v2.x_fx8}, {v0.y_fx8, v1.y_fx8, v2.y_fx8});
  if (r.x1 <= 0 || r.y1 <= 0 || r.x0 >= width_px_ || r.y0 >= height_px_) {
    ++sink.counters.culled;
    return false;
  }
  // CCW in NDC (y up) is negative area with y down. Checked after the image test, so that
  // backface_culled counts exactly the triangles that culling keeps from binning.
  const bool front = area2 < 0;
  const unsigned facing = front ? kDropCounterClockwise : kDropClockwise;
  if ((sink.drop_facing & facing) != 0) {
    ++sink.counters.culled;
    ++sink.counters.backface_culled;
    return false;
  }
  // glTF 2.0, 3.9.5: the back faces of a single-sided material are not drawn.
  if ((sink.cull_facing & facing) != 0 &&
      (sink.single_sided == nullptr || sink.single_sided[primitive - sink.first_primitive] != 0)) {
    ++sink.counters.culled;
    return false;
  }
  kept.pixels = r;
  kept.front = front;
  return true;
}

}  // namespace covrast::detail
