// Raster stage, sample-based modes (ssaa, ssaa-grid, msaa): the per-sample inner loops.
//
// A rasterizer walks a triangle over "groups": G horizontally adjacent pixels of one row
// whose samples are contiguous in the tile's sample buffers (pixel-major, P sample slots
// per pixel, S <= P of them real). A group holds L = G * P lanes, a multiple of 16, so
// every SIMD target splits it into whole vectors. For lane l at offset (ox_l, oy_l) [fx8]
// from the group origin (gx, gy), each edge function is
//
//   E(origin + o_l) + bias = F + c_l,   F = E(origin) + bias,   c_l = dx * oy_l - dy * ox_l
//
// and the lane is inside when all three are >= 0 (edge_function.hpp, top-left rule).
//
// Exactness in int32: with ox < G * 256 =: X and oy < 256, |c_l| <= (|dx| + |dy|) X =: M.
// The rasterizer classifies each group first with int64 F: it skips the group when some
// F + max c < 0 (no lane inside) and skips an edge's test when F + min c >= 0 (every lane
// inside). A tested edge therefore has -M <= F < M, so when M < 2^29 = kEdgeClamp both F
// and F + c_l (|.| < 2^30) fit int32 exactly. Triangles with a longer edge take a scalar
// int64 path for their partly covered groups (rare: |dx| + |dy| >= 8192 / G pixels).
//
// Depth is float: z_l = float(depth at the group origin) + dz_l, dz_l = float(dzdx) ox_l +
// float(dzdy) oy_l [pixels], evaluated as separate IEEE multiplies and adds (no FMA), so
// every target gives the same bits. Colour is fixed point: round(clamp(c, 0, 1) * 2^22)
// per channel, so the box-filter sums of up to 256 samples are exact uint32 integers and
// their order does not matter.
#pragma once

#include <cstddef>
#include <cstdint>

namespace covrast::detail {

/// Most lanes in one group (16 x 16 samples of one pixel).
inline constexpr int kMaxGroupLanes = 256;
/// Lanes per group are a multiple of this; SIMD code never uses more int32 lanes.
inline constexpr int kGroupLaneBlock = 16;
/// Bound of |F| and |c| on the int32 path (see above).
inline constexpr std::int32_t kEdgeClamp = std::int32_t(1) << 29;
/// c of padding lanes on edge 0: F + c < 0 for every F <= kEdgeClamp, so never inside.
inline constexpr std::int32_t kPaddingOffset = -(kEdgeClamp + 1);
/// Fixed-point colour: 1.0 = 2^22, so 256 samples sum to at most 2^30: the sum fits a
/// signed int32 too, which matters because some targets reduce lanes with signed adds.
inline constexpr int kColorFractionBits = 22;
inline constexpr double kColorOne = double(1 << kColorFractionBits);

/// The sample layout of one group, fixed per rasterizer.
struct GroupPattern {
  int samples = 0;   ///< S: real samples per pixel
  int stride = 0;    ///< P: sample slots per pixel (S, or S rounded up to 16)
  int group_px = 0;  ///< G: pixels per group
  int lanes = 0;     ///< L = G * P
  /// Lane offsets from the group origin [fx8] and [pixels]; padding lanes hold 0.
  alignas(64) std::int32_t ox_fx8[kMaxGroupLanes];
  alignas(64) std::int32_t oy_fx8[kMaxGroupLanes];
  alignas(64) float ox_px[kMaxGroupLanes];
  alignas(64) float oy_px[kMaxGroupLanes];
  /// ~0 for real samples, 0 for padding.
  alignas(64) std::int32_t valid[kMaxGroupLanes];
  /// Bounding box of the real lanes' offsets [fx8].
  std::int32_t ox_min = 0, ox_max = 0, oy_min = 0, oy_max = 0;
};

/// Per-triangle lane constants.
struct GroupTriangle {
  alignas(64) std::int32_t c[3][kMaxGroupLanes];  ///< edge offsets c_l (edge 0 kills padding)
  alignas(64) float dz[kMaxGroupLanes];           ///< depth offsets dz_l
};

/// One group's slice of the sample buffers (L lanes each, 64-byte aligned).
struct GroupSamples {
  float* depth;
  std::uint32_t* r;
  std::uint32_t* g;
  std::uint32_t* b;
};

/// Fills `tri`: c (only when `with_edges`, i.e. every |dx| + |dy| fits the int32 bound)
/// and dz.
using SetupGroupFn = void (*)(const GroupPattern& pattern, const std::int32_t dx[3],
                              const std::int32_t dy[3], bool with_edges, float dzdx, float dzdy,
                              GroupTriangle& tri);

/// Depth-tests the group's lanes that are inside: all real lanes when `f` is null, else
/// lanes with f[e] + c[e][l] >= 0 for e = 0, 1, 2 (f[e] in [-kEdgeClamp, kEdgeClamp]).
/// A lane with z_l < depth[l] (nearest wins, ties keep the earlier triangle) gets depth
/// z_l and, when `rgb` is not null, the fixed-point colour rgb[0..2]. When `written` is
/// not null (L / 64 words, zeroed by the caller), bit l is set for every lane written.
/// Returns whether any lane was written.
using SampleGroupFn = bool (*)(const GroupPattern& pattern, const GroupTriangle& tri,
                               const std::int32_t* f, float z_base, const std::uint32_t* rgb,
                               const GroupSamples& out, std::uint64_t* written);

/// Called for every group where a triangle without a flat colour won lanes (bit l of
/// `written` set), so that the rasterizer shades them (shading.hpp).
using ShadeWrittenFn = void (*)(void* context, int gx, int y, const std::uint64_t* written,
                                const GroupSamples& group);

/// One triangle over a rectangle of groups: the whole per-triangle loop in one call, for
/// triangles whose edges fit the int32 bound. Per group, with int64 F: skip it when some
/// F + c_max < 0; test no edge when every F + c_min >= 0; else test the lanes with
/// f = min(F, kEdgeClamp) as in SampleGroupFn. The lane constants are set up (into
/// `scratch`) at the first group that is not skipped.
struct RasterJob {
  int gx0 = 0;     ///< x of the first group [px], a multiple of G
  int y0 = 0;      ///< first row [px]
  int groups = 0;  ///< groups per row
  int rows = 0;
  std::int64_t f[3];       ///< F = E + bias at (gx0, y0) [fx8^2]
  std::int64_t step_x[3];  ///< change of F from one group to the next
  std::int64_t step_y[3];  ///< change of F from one row to the next
  std::int64_t c_min[3];   ///< bounds of c over the group's lanes
  std::int64_t c_max[3];
  std::int32_t dx[3];  ///< edge vectors [fx8]
  std::int32_t dy[3];
  float dzdx_f;  ///< depth slopes for dz
  float dzdy_f;
  /// Depth plane as in TriangleSetup::depth_at: z(x, y) = z0 + dzdx (x - vx) + dzdy (y - vy);
  /// z_base = float(z(gx, y)) at each group origin.
  double z0, dzdx, dzdy, vx, vy;
  const std::uint32_t* rgb;  ///< flat colour, or null: then shade_fn is called
  ShadeWrittenFn shade_fn;
  void* shade_context;
  GroupSamples first;     ///< lanes of group (gx0, y0)
  std::size_t row_lanes;  ///< lanes from one buffer row to the next
};
using RasterTriangleFn = void (*)(const GroupPattern& pattern, const RasterJob& job,
                                  GroupTriangle& scratch);

/// Box-filter sums of `pixels` consecutive pixels: sums[3 p + k] = sum over the S real
/// samples of channel k, where a sample whose depth is +infinity (never written since the
/// band was cleared) counts as `background`; and, when `min_depth` is not null, the
/// nearest sample depth.
using ResolvePixelsFn = void (*)(const GroupPattern& pattern, int pixels, const GroupSamples& in,
                                 const std::uint32_t background[3], std::uint32_t* sums,
                                 float* min_depth);

/// Sets `count` depths (a multiple of 16, 64-byte aligned) to +infinity. Colours are not
/// cleared: the resolve reads them only where the depth says a triangle was written.
using ClearDepthFn = void (*)(float* depth, std::size_t count);

struct SampleKernels {
  SetupGroupFn setup;
  SampleGroupFn sample;
  RasterTriangleFn raster;
  ResolvePixelsFn resolve;
  ClearDepthFn clear;
};

/// Highway dynamic dispatch: the best target of this CPU (or the forced one).
SampleKernels sample_kernels_simd();
/// The scalar twins: the same arithmetic one lane at a time (sample_kernel_scalar.cpp).
SampleKernels sample_kernels_scalar();

}  // namespace covrast::detail
