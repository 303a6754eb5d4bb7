// Raster stage, sample-based modes: the scalar twins of the SIMD kernels
// (sample_kernel.cpp), one lane at a time with the same operations in the same order.
#include "raster/samples/sample_kernel.hpp"

#include <algorithm>
#include <limits>

namespace covrast::detail {
namespace {

void setup_group_scalar(const GroupPattern& pattern, const std::int32_t dx[3],
                        const std::int32_t dy[3], bool with_edges, float dzdx, float dzdy,
                        GroupTriangle& tri) {
  for (int l = 0; l < pattern.lanes; ++l) {
    const float a = dzdx * pattern.ox_px[l];
    const float b = dzdy * pattern.oy_px[l];
    tri.dz[l] = a + b;
  }
  if (!with_edges) return;
  for (int e = 0; e < 3; ++e) {
    for (int l = 0; l < pattern.lanes; ++l) {
      std::int32_t c = dx[e] * pattern.oy_fx8[l] - dy[e] * pattern.ox_fx8[l];
      if (e == 0 && pattern.valid[l] == 0) c = kPaddingOffset;
      tri.c[e][l] = c;
    }
  }
}

bool sample_group_scalar(const GroupPattern& pattern, const GroupTriangle& tri,
                         const std::int32_t* f, float z_base, const std::uint32_t* rgb,
                         const GroupSamples& out, std::uint64_t* written) {
  bool any = false;
  for (int l = 0; l < pattern.lanes; ++l) {
    const bool inside =
        f != nullptr ? ((f[0] + tri.c[0][l]) | (f[1] + tri.c[1][l]) | (f[2] + tri.c[2][l])) >= 0
                     : pattern.valid[l] != 0;
    const float z = z_base + tri.dz[l];
    if (!inside || !(z < out.depth[l])) continue;
    any = true;
    out.depth[l] = z;
    if (rgb != nullptr) {
      out.r[l] = rgb[0];
      out.g[l] = rgb[1];
      out.b[l] = rgb[2];
    }
    if (written != nullptr) written[l / 64] |= std::uint64_t(1) << (l % 64);
  }
  return any;
}

#include "raster/samples/sample_walk-inl.hpp"  // walk_triangle_groups, scalar

void raster_triangle_scalar(const GroupPattern& pattern, const RasterJob& job, GroupTriangle& tri) {
  walk_triangle_groups(
      pattern, job,
      [&] { setup_group_scalar(pattern, job.dx, job.dy, true, job.dzdx_f, job.dzdy_f, tri); },
      [&](const std::int32_t* f32, float z_base, const GroupSamples& out, std::uint64_t* written) {
        return sample_group_scalar(pattern, tri, f32, z_base, job.rgb, out, written);
      });
}

void resolve_pixels_scalar(const GroupPattern& pattern, int pixels, const GroupSamples& in,
                           const std::uint32_t background[3], std::uint32_t* sums,
                           float* min_depth) {
  const float inf = std::numeric_limits<float>::infinity();
  for (int p = 0; p < pixels; ++p) {
    const std::size_t base = std::size_t(p) * std::size_t(pattern.stride);
    std::uint32_t r = 0, g = 0, b = 0;
    float z = inf;
    for (int s = 0; s < pattern.samples; ++s) {
      const float d = in.depth[base + s];
      const bool empty = !(d < inf);
      r += empty ? background[0] : in.r[base + s];
      g += empty ? background[1] : in.g[base + s];
      b += empty ? background[2] : in.b[base + s];
      z = d < z ? d : z;
    }
    sums[3 * p] = r;
    sums[3 * p + 1] = g;
    sums[3 * p + 2] = b;
    if (min_depth != nullptr) min_depth[p] = z;
  }
}

void clear_depth_scalar(float* depth, std::size_t count) {
  std::fill(depth, depth + count, std::numeric_limits<float>::infinity());
}

}  // namespace

SampleKernels sample_kernels_scalar() {
  return SampleKernels{setup_group_scalar, sample_group_scalar, raster_triangle_scalar,
                       resolve_pixels_scalar, clear_depth_scalar};
}

}  // namespace covrast::detail
