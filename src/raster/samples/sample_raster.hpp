// Raster stage, sample-based modes (ssaa, ssaa-grid, msaa): one rasterizer parameterised
// by its sample pattern and shading rate.
//
// Per tile it keeps, for every sample, a float depth and a fixed-point linear colour
// (sample_kernel.hpp), pixel-major. The tile is rasterized in horizontal bands whose
// sample buffers fit `band_budget_bytes` (2 MiB by default): when the
// whole tile fits, triangles are rasterized as they arrive; otherwise draw() only records
// them and end_tile() replays each band's triangles, in draw order, band after band.
// Resolve: the box filter, i.e. the mean linear colour over the pixel's samples, then
// 8-bit sRGB.
#pragma once

#include "core/tile_raster.hpp"
#include "raster/samples/sample_kernel.hpp"
#include "raster/samples/sample_pattern.hpp"

#include <hwy/aligned_allocator.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace covrast::detail {

enum class ShadingRate {
  PerSample,  ///< ssaa: shade() at every sample position
  PerPixel,   ///< msaa: shade() once per pixel and triangle, at the centre, clamped inside
};

/// Default band budget for the four sample buffers together: a whole 64-pixel tile in one
/// band up to 16 samples per pixel, 8 bands of 8 rows at 256. Measured on the 500k-triangle
/// scene, 2 MiB bands beat L2-sized (512 KiB) ones: fewer re-walks of the triangle list.
inline constexpr std::size_t kDefaultBandBudgetBytes = std::size_t(2048) << 10;

class SampleRasterizer final : public TileRasterizer {
 public:
  /// `pattern` must use unit 256 and hold 1..256 samples.
  SampleRasterizer(int tile_px, const SamplePattern& pattern, ShadingRate rate,
                   const SampleKernels& kernels,
                   std::size_t band_budget_bytes = kDefaultBandBudgetBytes);
  ~SampleRasterizer() override;

  void begin_tile(const PixelRect& rect, const FrameTarget& target) override;
  void draw(const TriangleSetup& triangle) override;
  void end_tile(const FrameTarget& target) override;
  std::size_t scratch_bytes() const override;
  double deferred_raster_ms() const override { return deferred_raster_ms_; }

  /// What end_tile does before encoding: rasterizes what is pending and resolves the
  /// tile. Afterwards pixel (x, y) of the tile has linear colour
  /// linear()[(y - y0) * tile_px + (x - x0)] (and depth() likewise when depth is wanted).
  void resolve_tile(const FrameTarget& target);
  const glm::vec3* linear() const { return linear_.data(); }
  const float* depth() const { return pixel_depth_.data(); }
  int band_rows() const { return band_rows_; }

 private:
  struct Pending {
    const TriangleSetup* triangle;
    PixelRect rect;
  };
  struct ShadeContext {
    SampleRasterizer* self;
    const TriangleSetup* triangle;
  };
  static void shade_trampoline(void* context, int gx, int y, const std::uint64_t* written,
                               const GroupSamples& group);
  void start_band(int y0, int y1);
  void rasterize(const TriangleSetup& t, const PixelRect& r);
  /// (gx, y): the group's first pixel, for the alpha test of MASK triangles.
  void sample_wide(const TriangleSetup& t, const std::int64_t f[3], float z_base,
                   const std::uint32_t* rgb, const GroupSamples& out, std::uint64_t* written,
                   int gx, int y);
  /// Whether MASK triangle `t` keeps lane l of the group at (gx, y): its alpha at the lane's
  /// shading point (ssaa: the sample; msaa: the pixel centre clamped into t) >= the cutoff.
  bool mask_keeps_lane(const TriangleSetup& t, int gx, int y, int l) const;
  /// Composites the tile's BLEND triangles into the band's samples (before the resolve).
  void composite_band();
  void shade_written(const TriangleSetup& t, int gx, int y, const std::uint64_t* written,
                     const GroupSamples& out);
  void resolve_band();

  int tile_px_;
  ShadingRate rate_;
  SampleKernels kernels_;
  std::unique_ptr<GroupPattern> pattern_;
  std::unique_ptr<GroupTriangle> tri_;
  SamplePattern pixel_pattern_;  ///< the S per-pixel offsets [fx8]
  int buffer_px_;                ///< pixels per buffer row, a multiple of G
  int band_rows_;
  std::size_t row_lanes_;  ///< buffer_px_ * P
  hwy::AlignedFreeUniquePtr<float[]> depth_;
  hwy::AlignedFreeUniquePtr<std::uint32_t[]> r_, g_, b_;
  std::vector<std::uint32_t> sums_;
  std::vector<float> min_depth_;
  std::vector<glm::vec3> linear_;
  std::vector<float> pixel_depth_;
  std::vector<Pending> pending_;
  std::vector<Pending> blend_;       ///< the tile's BLEND triangles, in draw order
  double deferred_raster_ms_ = 0.0;  ///< replaying pending_ in end_tile, summed over tiles
  std::vector<std::uint32_t> band_begin_;
  std::vector<std::uint32_t> band_items_;
  std::vector<std::uint32_t> band_cursor_;

  PixelRect rect_;
  int buffer_x0_ = 0;  ///< absolute x of buffer column 0: rect_.x0 rounded down to G
  int band_y0_ = 0;
  int band_y1_ = 0;
  bool immediate_ = true;
  bool want_depth_ = false;
  std::uint32_t background_q_[3] = {0, 0, 0};
};

/// The group layout of a pixel pattern: P = S when S divides 16 (G = 16 / S pixels share a
/// group), else S rounded up to 16 (G = 1); padding lanes have offset 0 and valid 0.
void make_group_pattern(const SamplePattern& pattern, GroupPattern& out);

/// The per-triangle part of the RasterJob for pixels `r` (groups from x = floor(r.x0 / G) * G,
/// rows from r.y0): edge values, steps and bounds, depth plane. Returns false when an edge is
/// too long for the int32 lanes (dx and dy are then 0). rgb, shade_fn, shade_context, first
/// and row_lanes are left to the caller.
bool make_raster_job(const GroupPattern& gp, const TriangleSetup& t, const PixelRect& r,
                     RasterJob& job);

/// Fixed-point linear colour of sample_kernel.hpp: round(clamp(c, 0, 1) * 2^22).
std::uint32_t quantize_color(float linear);

}  // namespace covrast::detail
