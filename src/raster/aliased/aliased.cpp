// Raster stage, aliased mode: one sample at each pixel centre, top-left fill rule,
// z-buffer (nearest wins, equal depth keeps the earlier triangle), perspective-correct
// vertex colours.
//
// Speed, for scenes of small triangles (sphere_grid: ~7 px each):
// - The depth test runs a row of lanes at a time in a Highway kernel (aliased_kernel.hpp),
//   with a scalar twin that does the same one pixel at a time; both give the same bits.
// - Shading is deferred: a pixel records which triangle last won its depth test, and
//   end_tile shades each pixel once, for that triangle, at the same point (x + 0.5, y + 0.5):
//   the colour the winning triangle would have written when it won.
#include "color/srgb.hpp"
#include "color/srgb8.hpp"
#include "core/tile_raster.hpp"
#include "raster/aliased/aliased_kernel.hpp"
#include "raster/rasterizers.hpp"
#include "shading/composite.hpp"
#include "shading/shading.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace covrast::detail {
namespace {

/// What a pixel's owner holds: for a flat triangle its final 8-bit sRGB colour, tagged in
/// bit 0 (bits 8..31 = r, g, b); otherwise the triangle's address (8-byte aligned, so bit 0
/// is clear), to shade the pixel from at the end of the tile.
constexpr std::uint64_t kFlatTag = 1;
static_assert(alignof(TriangleSetup) % 2 == 0, "triangle addresses must leave bit 0 free");

std::uint64_t flat_owner(const std::uint8_t code[3]) {
  return kFlatTag | std::uint64_t(code[0]) << 8 | std::uint64_t(code[1]) << 16 |
         std::uint64_t(code[2]) << 24;
}

/// The linear value of an 8-bit sRGB code (IEC 61966-2-1): encode_srgb8 of it gives the code
/// back, so a pixel that no BLEND triangle covers keeps its bytes.
double decode_srgb8(std::uint8_t code) { return srgb8_decode_table()[code]; }

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
        depth_(std::size_t(tile_px) * tile_px + kAliasedBufferPadding),
        owner_(std::size_t(tile_px) * tile_px + kAliasedBufferPadding) {}

  void begin_tile(const PixelRect& rect, const FrameTarget&) override {
    rect_ = rect;
    blend_.clear();
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
    if (t.alpha_mode == AlphaMode::Blend) {
      blend_.push_back(&t);  // composited at the end of the tile, in depth order
      return;
    }
    if (t.alpha_mode == AlphaMode::Mask) {
      raster_mask(t, r, id);
      return;
    }
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
    if (!blend_.empty()) composite_blend(target);
  }

  /// A MASK triangle: the scalar twin's test (aliased_kernel_scalar.cpp) with the alpha test
  /// at the sample (the pixel centre) before the depth test.
  void raster_mask(const TriangleSetup& t, const PixelRect& r, std::uint64_t id) {
    const AliasedJob job = make_aliased_job(
        t, r, AliasedTile{rect_, depth_.data(), owner_.data(), std::size_t(stride_)}, id);
    std::int64_t row[3] = {job.e[0], job.e[1], job.e[2]};
    for (int j = 0; j < job.height; ++j) {
      const double py = job.y0 + j + 0.5;
      const double zy = job.dzdy * (py - job.vy);
      double* depth = job.depth + std::size_t(j) * job.stride;
      std::uint64_t* owner = job.owner + std::size_t(j) * job.stride;
      for (int i = 0; i < job.width; ++i) {
        const std::int64_t e0 = row[0] + i * job.step_x[0], e1 = row[1] + i * job.step_x[1],
                           e2 = row[2] + i * job.step_x[2];
        if ((e0 | e1 | e2) < 0) continue;
        const double px = (job.x0 + i) + 0.5;
        const float z = float(job.z0 + job.dzdx * (px - job.vx) + zy);
        if (z < depth[i] && mask_keeps(t, px, py, false)) {
          depth[i] = z;
          owner[i] = job.id;
        }
      }
      for (int k = 0; k < 3; ++k) row[k] += job.step_y[k];
    }
  }

  /// BLEND triangles, per pixel centre: the ones that cover it in front of the opaque depth,
  /// sorted nearest first (level ones by primitive index), composited over the opaque colour
  /// (docs/transparency.md); the depth stays the opaque one.
  void composite_blend(const FrameTarget& target) {
    std::vector<std::pair<float, const TriangleSetup*>> stack;
    for (int y = rect_.y0; y < rect_.y1; ++y) {
      for (int x = rect_.x0; x < rect_.x1; ++x) {
        const std::size_t i = std::size_t(y - rect_.y0) * stride_ + std::size_t(x - rect_.x0);
        const PixelRect one{x, y, x + 1, y + 1};
        stack.clear();
        for (const TriangleSetup* t : blend_) {
          const PixelRect r = intersect(touched_pixels(*t), one);
          if (r.empty()) continue;
          const AliasedJob job = make_aliased_job(
              *t, r, AliasedTile{rect_, depth_.data(), owner_.data(), std::size_t(stride_)}, 0);
          if ((job.e[0] | job.e[1] | job.e[2]) < 0) continue;
          const float z =
              float(job.z0 + job.dzdx * ((x + 0.5) - job.vx) + job.dzdy * ((y + 0.5) - job.vy));
          if (z < depth_[i]) stack.emplace_back(z, t);
        }
        if (stack.empty()) continue;
        std::sort(stack.begin(), stack.end(), [](const auto& a, const auto& b) {
          return nearer_first(a.first, *a.second, b.first, *b.second);
        });
        std::uint8_t* dst = target.color->pixel(x, y);
        glm::dvec3 behind(target.background_linear);
        if (depth_[i] != std::numeric_limits<double>::infinity()) {
          const std::uint64_t owner = owner_[i];
          if (owner & kFlatTag) {
            // The flat colour's 8-bit code, decoded (the owner keeps no linear colour).
            for (int k = 0; k < 3; ++k) behind[k] = decode_srgb8(dst[k]);
          } else {
            const auto& o = *reinterpret_cast<const TriangleSetup*>(std::uintptr_t(owner));
            behind = glm::dvec3(shade(o, x + 0.5, y + 0.5, false));
          }
        }
        FrontToBack layers_over;
        for (const auto& layer : stack) {
          layers_over.add(shade_rgba(*layer.second, x + 0.5, y + 0.5, false));
        }
        const glm::dvec3 c = layers_over.over(behind);
        for (int k = 0; k < 3; ++k) dst[k] = encode_srgb8(float(c[k]));
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
  std::vector<std::uint64_t> owner_;         ///< per pixel, see kFlatTag
  std::vector<const TriangleSetup*> blend_;  ///< the tile's BLEND triangles
  /// The last flat colour encoded, and its owner value (NaN: none yet).
  glm::vec3 flat_color_{std::numeric_limits<float>::quiet_NaN()};
  std::uint64_t flat_owner_ = 0;
};

}  // namespace

std::unique_ptr<TileRasterizer> make_aliased_rasterizer(int tile_px) {
  return std::make_unique<AliasedRasterizer>(tile_px, raster_aliased_simd());
}

}  // namespace covrast::detail
