// Raster stage, aliased mode: one sample at each pixel centre, top-left fill rule,
// z-buffer (nearest wins, equal depth keeps the earlier triangle), perspective-correct
// vertex colours.
//
// Speed, for scenes of small triangles (sphere_grid: ~7 px each):
// - The depth test runs a row of lanes at a time in a Highway kernel (this file is compiled
//   for every Highway target and the best is picked at run time), with a scalar twin that
//   does the same one pixel at a time. Both evaluate the int64 edge functions and the
//   double depth plane exactly as before, point by point (the plane directly at each
//   pixel centre, never incrementally), then round depth to float: every target gives the
//   same bits.
// - Shading is deferred: a pixel records which triangle last won its depth test, and
//   end_tile shades each pixel once, for that triangle, at the same point (x + 0.5, y + 0.5):
//   the colour the winning triangle would have written when it won.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/aliased/aliased.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#ifndef COVRAST_RASTER_ALIASED_SHARED_
#define COVRAST_RASTER_ALIASED_SHARED_

#include "core/edge_function.hpp"
#include "core/shading.hpp"
#include "core/srgb8.hpp"
#include "core/tile_raster.hpp"
#include "raster/rasterizers.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace covrast::detail {
namespace {

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
inline AliasedJob make_job(const TriangleSetup& t, const PixelRect& r, const AliasedTile& tile,
                           std::uint64_t id) {
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

/// The scalar twin: pixel by pixel, the arithmetic each SIMD lane does.
void raster_aliased_scalar(const TriangleSetup& t, const PixelRect& r, const AliasedTile& tile,
                           std::uint64_t id) {
  const AliasedJob job = make_job(t, r, tile, id);
  std::int64_t row[3] = {job.e[0], job.e[1], job.e[2]};
  for (int j = 0; j < job.height; ++j) {
    const double zy = job.dzdy * ((job.y0 + j + 0.5) - job.vy);
    double* depth = job.depth + std::size_t(j) * job.stride;
    std::uint64_t* owner = job.owner + std::size_t(j) * job.stride;
    std::int64_t e0 = row[0], e1 = row[1], e2 = row[2];
    for (int i = 0; i < job.width; ++i) {
      if ((e0 | e1 | e2) >= 0) {
        const double px = (job.x0 + i) + 0.5;
        const float z = float(job.z0 + job.dzdx * (px - job.vx) + zy);
        if (z < depth[i]) {
          depth[i] = z;
          owner[i] = job.id;
        }
      }
      e0 += job.step_x[0];
      e1 += job.step_x[1];
      e2 += job.step_x[2];
    }
    for (int k = 0; k < 3; ++k) row[k] += job.step_y[k];
  }
}

}  // namespace
}  // namespace covrast::detail

#endif  // COVRAST_RASTER_ALIASED_SHARED_

HWY_BEFORE_NAMESPACE();
namespace covrast::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// The SIMD kernel: column groups of N lanes (N = lanes of int64), and in each group the
/// rows top to bottom. Lanes past the rectangle's right end are never inside; their
/// depth and owner are read and written back unchanged (the tile buffers are padded).
void RasterAliased(const TriangleSetup& t, const PixelRect& r, const AliasedTile& tile,
                   std::uint64_t id_value) {
  // Built here, in registers: read through a pointer, the stores through depth and owner
  // could alias the job and force its fields to be reloaded on every row.
  const AliasedJob job = make_job(t, r, tile, id_value);
  const hn::ScalableTag<std::int64_t> di;
  const hn::RebindToUnsigned<decltype(di)> du;
  const hn::RebindToFloat<decltype(di)> df;
  const hn::Rebind<float, decltype(df)> df32;
  const std::size_t n = hn::Lanes(di);
  // Lane offsets k * step_x of each edge, k = 0 .. N-1, from the bits of k (there is no
  // 64-bit multiply on every target; building them in memory stalls on store forwarding).
  const auto lane = hn::Iota(di, 0);
  auto off0 = hn::Zero(di), off1 = hn::Zero(di), off2 = hn::Zero(di);
  for (std::int64_t bit = 1; bit < std::int64_t(n); bit *= 2) {
    const auto has = hn::TestBit(lane, hn::Set(di, bit));
    off0 = hn::Add(off0, hn::IfThenElseZero(has, hn::Set(di, job.step_x[0] * bit)));
    off1 = hn::Add(off1, hn::IfThenElseZero(has, hn::Set(di, job.step_x[1] * bit)));
    off2 = hn::Add(off2, hn::IfThenElseZero(has, hn::Set(di, job.step_x[2] * bit)));
  }
  const auto sy0 = hn::Set(di, job.step_y[0]);
  const auto sy1 = hn::Set(di, job.step_y[1]);
  const auto sy2 = hn::Set(di, job.step_y[2]);
  const auto zero = hn::Zero(di);
  const auto id = hn::Set(du, job.id);
  const auto iota = hn::Iota(df, 0.0);
  for (int gx = 0; gx < job.width; gx += int(n)) {
    const auto valid = hn::FirstN(di, std::size_t(job.width - gx));
    auto v0 = hn::Add(hn::Set(di, job.e[0] + gx * job.step_x[0]), off0);
    auto v1 = hn::Add(hn::Set(di, job.e[1] + gx * job.step_x[1]), off1);
    auto v2 = hn::Add(hn::Set(di, job.e[2] + gx * job.step_x[2]), off2);
    // z0 + dzdx (px - vx) with px = x + 0.5 per lane (small integers and halves: exact).
    const auto px = hn::Add(hn::Add(hn::Set(df, double(job.x0 + gx)), iota), hn::Set(df, 0.5));
    const auto zx = hn::Add(hn::Set(df, job.z0),
                            hn::Mul(hn::Set(df, job.dzdx), hn::Sub(px, hn::Set(df, job.vx))));
    double* depth = job.depth + gx;
    std::uint64_t* owner = job.owner + gx;
    // Every row of the rectangle, empty or not: a test-and-branch per row mispredicts
    // more than the masked work costs.
    for (int j = 0; j < job.height; ++j, depth += job.stride, owner += job.stride) {
      // Outside some edge <=> a sign bit in the OR of the three.
      const auto outside = hn::Lt(hn::Or(hn::Or(v0, v1), v2), zero);
      const double zy = job.dzdy * ((job.y0 + j + 0.5) - job.vy);
      // Rounded to float as the scalar float(z); in range wherever it is used (inside the
      // triangle z lies between its vertices' depths), where every target's DemoteTo is
      // the IEEE conversion.
      const auto z = hn::PromoteTo(df, hn::DemoteTo(df32, hn::Add(zx, hn::Set(df, zy))));
      const auto old = hn::LoadU(df, depth);
      const auto pass = hn::RebindMask(
          df, hn::AndNot(outside, hn::And(valid, hn::RebindMask(di, hn::Lt(z, old)))));
      hn::StoreU(hn::IfThenElse(pass, z, old), df, depth);
      hn::StoreU(hn::IfThenElse(hn::RebindMask(du, pass), id, hn::LoadU(du, owner)), du, owner);
      v0 = hn::Add(v0, sy0);
      v1 = hn::Add(v1, sy1);
      v2 = hn::Add(v2, sy2);
    }
  }
}

}  // namespace covrast::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace covrast::detail {

HWY_EXPORT(RasterAliased);

namespace {

/// Elements past the last tile pixel that a kernel may read and write back unchanged: at
/// least the lanes of the widest vector of 64-bit lanes of any target, minus one (2048-bit
/// SVE/RVV: 32). A literal: HWY_MAX_BYTES here is the last compiled target's, not the widest.
constexpr std::size_t kBufferPadding = 64;

RasterAliasedFn chosen_kernel() {
  // Look the target up once per rasterizer, not per triangle; HWY_DYNAMIC_DISPATCH's first
  // table entry is an initialising trampoline, so make the choice first.
  hwy::ChosenTarget& chosen = hwy::GetChosenTarget();
  if (!chosen.IsInitialized()) chosen.Update(hwy::SupportedTargets());
  return HWY_DISPATCH_TABLE(RasterAliased)[chosen.GetIndex()];
}

/// What a pixel's owner holds: for a flat triangle its final 8-bit sRGB colour, tagged in
/// bit 0 (bits 8..31 = r, g, b); otherwise the triangle's address (8-byte aligned, so bit 0
/// is clear), to shade the pixel from at the end of the tile.
constexpr std::uint64_t kFlatTag = 1;
static_assert(alignof(TriangleSetup) % 2 == 0, "triangle addresses must leave bit 0 free");

std::uint64_t flat_owner(const std::uint8_t code[3]) {
  return kFlatTag | std::uint64_t(code[0]) << 8 | std::uint64_t(code[1]) << 16 |
         std::uint64_t(code[2]) << 24;
}

void write_codes(std::uint64_t owner, std::uint8_t* dst) {
  dst[0] = std::uint8_t(owner >> 8);
  dst[1] = std::uint8_t(owner >> 16);
  dst[2] = std::uint8_t(owner >> 24);
}

class AliasedRasterizer final : public TileRasterizer {
 public:
  AliasedRasterizer(int tile_px, RasterAliasedFn kernel)
      : stride_(tile_px),
        kernel_(kernel),
        depth_(std::size_t(tile_px) * tile_px + kBufferPadding),
        owner_(std::size_t(tile_px) * tile_px + kBufferPadding) {}

  void begin_tile(const PixelRect& rect, const FrameTarget&) override {
    rect_ = rect;
    // Owners need no clearing: they are read only where a depth was written.
    std::fill(depth_.begin(), depth_.end(), std::numeric_limits<double>::infinity());
  }

  void draw(const TriangleSetup& t) override {
    // The triangles of a tile come in ascending order, often neighbours in memory: start
    // loading the one two ahead (a hint only: prefetches never fault).
    const auto here = reinterpret_cast<std::uintptr_t>(&t);
    __builtin_prefetch(reinterpret_cast<const void*>(here + 2 * sizeof(TriangleSetup)));
    __builtin_prefetch(reinterpret_cast<const void*>(here + 2 * sizeof(TriangleSetup) + 64));
    const PixelRect r = intersect(touched_pixels(t), rect_);
    if (r.empty()) return;
    std::uint64_t id = std::uint64_t(here);
    if (t.flat_color) {
      // shade() of a flat triangle is color[0] everywhere: encode it now, once per run of
      // triangles of one colour.
      if (!(t.color[0] == flat_color_)) {
        flat_color_ = t.color[0];
        const std::uint8_t code[3] = {encode_srgb8(flat_color_.r), encode_srgb8(flat_color_.g),
                                      encode_srgb8(flat_color_.b)};
        flat_owner_ = flat_owner(code);
      }
      id = flat_owner_;
    }
    kernel_(t, r, AliasedTile{rect_, depth_.data(), owner_.data(), std::size_t(stride_)}, id);
  }

  void end_tile(const FrameTarget& target) override {
    // Encodes to 8-bit sRGB: flat triangles' codes are in the owners already; a shaded
    // pixel reuses the last codes while its colour repeats. Either way the bytes of
    // encoding every pixel's colour.
    std::uint8_t bg[3];
    for (int k = 0; k < 3; ++k) bg[k] = encode_srgb8(target.background_linear[k]);
    const int width = rect_.x1 - rect_.x0;
    const double* depth_row = depth_.data();
    const std::uint64_t* owner_row = owner_.data();
    for (int y = rect_.y0; y < rect_.y1; ++y, depth_row += stride_, owner_row += stride_) {
      std::uint8_t* dst = target.color->pixel(rect_.x0, y);
      glm::vec3 last_color(-1.0f);
      std::uint8_t code[3] = {0, 0, 0};
      for (int i = 0; i < width; ++i, dst += 3) {
        const std::uint64_t owner = owner_row[i];
        if (depth_row[i] == std::numeric_limits<double>::infinity()) {
          dst[0] = bg[0];
          dst[1] = bg[1];
          dst[2] = bg[2];
        } else if (owner & kFlatTag) {
          write_codes(owner, dst);
        } else {
          const auto& t = *reinterpret_cast<const TriangleSetup*>(std::uintptr_t(owner));
          const int x = rect_.x0 + i;
          const glm::vec3 c = shade(t, x + 0.5, y + 0.5, false);
          if (c != last_color) {
            last_color = c;
            code[0] = encode_srgb8(c.r);
            code[1] = encode_srgb8(c.g);
            code[2] = encode_srgb8(c.b);
          }
          dst[0] = code[0];
          dst[1] = code[1];
          dst[2] = code[2];
        }
      }
      if (target.depth != nullptr) {
        float* out = &target.depth->depth[std::size_t(y) * target.depth->width + rect_.x0];
        for (int i = 0; i < width; ++i) out[i] = std::min(float(depth_row[i]), 1.0f);
      }
    }
  }

  std::size_t scratch_bytes() const override {
    return depth_.size() * sizeof(double) + owner_.size() * sizeof(std::uint64_t);
  }

 private:
  int stride_;
  RasterAliasedFn kernel_;
  PixelRect rect_;
  /// Depth per pixel: float values (as the depth test rounds them), held in doubles so the
  /// kernels compare and blend them in their 64-bit lanes without narrowing conversions.
  std::vector<double> depth_;
  std::vector<std::uint64_t> owner_;  ///< per pixel, see kFlatTag
  /// The last flat colour encoded, and its owner value (NaN: none yet).
  glm::vec3 flat_color_{std::numeric_limits<float>::quiet_NaN()};
  std::uint64_t flat_owner_ = 0;
};

}  // namespace

std::unique_ptr<TileRasterizer> make_aliased_rasterizer(int tile_px) {
  return std::make_unique<AliasedRasterizer>(tile_px, chosen_kernel());
}

/// The same mode on the scalar twin of the kernel, for tests that compare the two (declare
/// it where needed; it has no header of its own).
std::unique_ptr<TileRasterizer> make_aliased_rasterizer_scalar(int tile_px) {
  return std::make_unique<AliasedRasterizer>(tile_px, &raster_aliased_scalar);
}

}  // namespace covrast::detail
#endif  // HWY_ONCE
