// Raster stage, coverage modes: per triangle, the coverage kernel fills the triangle's
// span of a tile-local alpha plane (8.8 coverage per pixel, column group by column group:
// a top partial run, an interior run of full pixels with no per-pixel math, a bottom
// partial run); then each covered pixel goes to
//  - coverage:       the A-buffer (resolve/abuffer.hpp), which resolves it without seams;
//  - coverage-blend: the literal seed, alpha-blended over the frame buffer with one depth
//                    per pixel (kept to show what the A-buffer fixes).
#include "color/srgb8.hpp"
#include "core/testing_hooks.hpp"
#include "core/tile_raster.hpp"
#include "raster/coverage/abuffer.hpp"
#include "raster/coverage/coverage_kernel.hpp"
#include "raster/coverage/fragment_shading.hpp"
#include "raster/rasterizers.hpp"
#include "shading/shading.hpp"

#include <algorithm>
#include <bit>
#include <climits>
#include <limits>
#include <memory>
#include <vector>

namespace covrast::detail {
namespace {

// Aligned column groups lie in one A-buffer block (draw).
static_assert(kColumnGroup == kAbufferBlockPx);

class CoverageRasterizer final : public TileRasterizer {
 public:
  CoverageRasterizer(int tile_px, bool blend)
      : tile_px_(tile_px),
        blend_(blend),
        plane_stride_(std::size_t(tile_px) + kColumnGroup),
        plane_(std::size_t(tile_px) * plane_stride_),
        abuffer_(blend ? 1 : tile_px) {
    if (blend_) {
      color_.resize(std::size_t(tile_px) * tile_px);
      depth_.resize(std::size_t(tile_px) * tile_px);
    }
  }

  void begin_tile(const PixelRect& rect, const FrameTarget& target) override {
    rect_ = rect;
    background_ = target.background_linear;
    if (blend_) {
      std::fill(depth_.begin(), depth_.end(), std::numeric_limits<float>::infinity());
      std::fill(color_.begin(), color_.end(), glm::vec3(-1.0f));
    } else {
      abuffer_.begin_tile(rect);
    }
    previous_ = nullptr;
  }

  void draw(const TriangleSetup& t) override {
    const PixelRect r = intersect(touched_pixels(t), rect_);
    if (r.empty()) return;
    if (!blend_) {
      // A copy of the triangle drawn just before (same vertices and depth plane) is level
      // with it everywhere and later, so it shows nowhere: duplicate faces of CAD exports
      // and stacked copies cost one comparison each.
      // Only an opaque one hides the copy (a MASK or BLEND one may let it show).
      if (previous_ != nullptr && same_geometry(*previous_, t)) return;
      if (t.alpha_mode == AlphaMode::Opaque) previous_ = &t;
    }
    bool skip_decided = false;
    // The fast paths are for opaque triangles: one whose every pixel would drop its fragment
    // as hidden (no kernel, no fragments: on dense meshes a quarter to two thirds of them),
    // and the tile and block paths for one covering the pixels entirely.
    if (!blend_ && fast_paths_ && t.alpha_mode == AlphaMode::Opaque) {
      if (abuffer_.hides_rect(t, r)) {
        ++hidden_draws_;
        return;
      }
      if (abuffer_.add_covering_tile(t, r)) return;
      // Only a triangle at least a block wide and high can cover a whole block.
      if (r.x1 - r.x0 >= 8 && r.y1 - r.y0 >= 8) skip_decided = abuffer_.add_covering_blocks(t, r);
    }
    // Per (triangle, tile) and after the skips above, not once at set-up: a triangle meets
    // 1.03-1.22 tiles on the report's dense scenes, while the hidden skip alone spares it for
    // 45% of ReciprocatingSaw's bin entries (640x360, --stats).
    const CoverageTriangle tri = make_coverage_triangle(t);
    // With decided blocks, column groups line up with the blocks, so that a row of a group
    // lies in one block (columns left of the triangle get zero coverage).
    const int g0 = skip_decided ? rect_.x0 + (r.x0 - rect_.x0) / kColumnGroup * kColumnGroup : r.x0;
    std::uint16_t* const out = plane_.data() + std::size_t(r.y0 - rect_.y0) * plane_stride_;
    for (int g = g0; g < r.x1; g += kColumnGroup) {
      const int lanes = std::min(kColumnGroup, r.x1 - g);
      // Top partial run, interior run, bottom partial run of the group, in the plane.
      const GroupRows rows = cover_group_(tri, g, lanes, r.y0, r.y1, out, plane_stride_);
      if (rows.empty()) continue;
      const int first = rows.first, end = rows.end;
      consume(t, g, lanes, first, end, skip_decided);
    }
  }

  void end_tile(const FrameTarget& target) override {
    if (!blend_) {
      abuffer_.resolve(target);
      return;
    }
    for (auto& c : color_) {
      if (c.r < 0.0f) c = target.background_linear;
    }
    write_tile(target, rect_, color_.data(), depth_.data(), tile_px_);
  }

  std::size_t scratch_bytes() const override {
    return plane_.size() * sizeof(std::uint16_t) + color_.size() * sizeof(glm::vec3) +
           depth_.size() * sizeof(float) + abuffer_.scratch_bytes();
  }
  std::uint64_t overflow_count() const override { return abuffer_.overflow_count(); }
  std::uint64_t hidden_draw_count() const override { return hidden_draws_; }
  CoverageResolvePaths take_resolve_paths() override { return abuffer_.take_resolve_paths(); }

 private:
  /// Hands the group's covered pixels (rows [first, end), columns [g, g + lanes)) on.
  void consume(const TriangleSetup& t, int g, int lanes, int first, int end, bool skip_decided) {
    // The depth plane at the pixel centres, split as TriangleSetup::depth_at evaluates it,
    // (z0 + dzdx (x - vx)) + dzdy (y - vy), so that the sum is the same bits.
    const double vx = t.x_fx8[0] * (1.0 / kSubpixelOne), vy = t.y_fx8[0] * (1.0 / kSubpixelOne);
    double column_z[kColumnGroup];
    for (int lane = 0; lane < lanes; ++lane)
      column_z[lane] = t.z0 + t.dzdx * ((g + lane + 0.5) - vx);
    for (int y = first; y < end; ++y) {
      // Aligned groups: the row lies in one block, decided as a whole.
      if (skip_decided && abuffer_.block_decided(g, y)) continue;
      const std::uint16_t* row = plane_.data() + std::size_t(y - rect_.y0) * plane_stride_;
      // The covered lanes as bits: one loop exit to predict per row, not a branch per lane.
      unsigned covered = 0;
      for (int lane = 0; lane < lanes; ++lane) covered |= unsigned(row[lane] != 0) << lane;
      if (covered == 0) continue;
      if (!blend_) {
        abuffer_.prepare_row(g + std::countr_zero(covered), g + std::bit_width(covered), y);
      }
      const double row_z = t.dzdy * ((y + 0.5) - vy);
      for (; covered != 0; covered &= covered - 1) {
        const int lane = std::countr_zero(covered);
        const std::uint32_t coverage = row[lane];
        const int x = g + lane;
        if (t.alpha_mode != AlphaMode::Opaque) {
          alpha_fragment(t, x, y, coverage, column_z[lane] + row_z);
          continue;
        }
        if (!blend_) {
          abuffer_.add(x, y, &t, coverage, column_z[lane] + row_z);
          continue;
        }
        // The seed's compositing: one depth per pixel, blend with the 8-bit alpha.
        const double cx = x + 0.5, cy = y + 0.5;
        const std::size_t i = std::size_t(y - rect_.y0) * tile_px_ + (x - rect_.x0);
        const float z = float(t.depth_at(cx, cy));
        if (!(z < depth_[i])) continue;
        const float alpha = coverage_to_alpha8(coverage) / 255.0f;
        glm::vec3 dst = color_[i].r < 0.0f ? background_ : color_[i];
        color_[i] = alpha * shade(t, cx, cy, true) + (1.0f - alpha) * dst;
        depth_[i] = z;
      }
    }
  }

  /// A fragment of a MASK or BLEND triangle. Coverage mode: a MASK fragment whose alpha is
  /// surely on one side of the cutoff is kept as an opaque fragment or dropped; one that
  /// straddles it goes, with BLEND's, to the A-buffer's transparent list, whose resolve gives
  /// it the share that passes as its alpha (mask_share). Coverage-blend (the seed): MASK kept where
  /// the alpha at the pixel centre clamped into the triangle passes, then opaque; BLEND blended
  /// over the frame buffer in draw order with alpha8 x alpha, without writing the depth, as a GPU
  /// would.
  void alpha_fragment(const TriangleSetup& t, int x, int y, std::uint32_t coverage,
                      double centre_z) {
    if (!blend_) {
      const MaskVerdict verdict = mask_verdict(t, x, y);  // Keep for BLEND
      if (t.alpha_mode == AlphaMode::Blend || verdict == MaskVerdict::Straddles) {
        abuffer_.add_transparent(x, y, &t, coverage, centre_z);
      } else if (verdict == MaskVerdict::Keep) {
        abuffer_.add(x, y, &t, coverage, centre_z);
      }
      return;
    }
    const double cx = x + 0.5, cy = y + 0.5;
    if (t.alpha_mode == AlphaMode::Mask && !mask_keeps(t, cx, cy, true)) return;
    const std::size_t i = std::size_t(y - rect_.y0) * tile_px_ + (x - rect_.x0);
    const float z = float(t.depth_at(cx, cy));
    if (!(z < depth_[i])) return;
    const ShadedColor c = shade_rgba(t, cx, cy, true);
    const float alpha =
        coverage_to_alpha8(coverage) / 255.0f *
        (t.alpha_mode == AlphaMode::Blend ? float(std::clamp(c.alpha, 0.0, 1.0)) : 1.0f);
    const glm::vec3 dst = color_[i].r < 0.0f ? background_ : color_[i];
    // A transmissive layer also passes filter x alpha of what is behind (0 for the others).
    color_[i] = alpha * c.rgb + (1.0f - alpha) * dst + alpha * c.filter * dst;
    if (t.alpha_mode == AlphaMode::Mask) depth_[i] = z;
  }

  static bool same_geometry(const TriangleSetup& a, const TriangleSetup& b) {
    return std::equal(a.x_fx8, a.x_fx8 + 3, b.x_fx8) && std::equal(a.y_fx8, a.y_fx8 + 3, b.y_fx8) &&
           a.z0 == b.z0 && a.dzdx == b.dzdx && a.dzdy == b.dzdy;
  }

  int tile_px_;
  bool blend_;
  /// The per-group set-up and kernel: the SIMD one, or its scalar twin for a test that
  /// compares the two (testing::CoverageHooks::scalar_kernel).
  CoverGroupFn cover_group_ = testing::coverage_hooks.scalar_kernel.load(std::memory_order_relaxed)
                                  ? cover_group_scalar
                                  : cover_group_simd;
  /// The A-buffer's whole-tile and whole-block paths, on unless a test compares them with
  /// pixel-by-pixel adds (testing::CoverageHooks::pixel_path_only).
  bool fast_paths_ = !testing::coverage_hooks.pixel_path_only.load(std::memory_order_relaxed);
  const TriangleSetup* previous_ = nullptr;  ///< the tile's last drawn triangle (not blend)
  std::uint64_t hidden_draws_ = 0;           ///< triangles skipped by hides_rect, ever
  std::size_t plane_stride_;
  PixelRect rect_;
  std::vector<std::uint16_t> plane_;  ///< the alpha plane: 8.8 coverage per pixel of the span
  ABufferTile abuffer_;
  std::vector<glm::vec3> color_;  ///< coverage-blend: linear colour, r < 0 = background
  std::vector<float> depth_;      ///< coverage-blend: one depth per pixel
  glm::vec3 background_{0.0f};
};

}  // namespace

std::unique_ptr<TileRasterizer> make_coverage_rasterizer(int tile_px, bool blend) {
  return std::make_unique<CoverageRasterizer>(tile_px, blend);
}

}  // namespace covrast::detail
