// Raster stage, reference mode: the ground truth for quality figures. 64 x 64 correlated
// multi-jittered samples per pixel (positions on a 2^-20 pixel grid, fixed seed), exact
// per-sample coverage in double precision from the snapped vertices with the top-left tie
// rule, per-sample depth in double (nearest wins, ties keep the earlier triangle),
// per-sample shading and a box-filter resolve in double, then 8-bit sRGB.
//
// Exactness: with E0 = E(pixel corner) (an integer in fx8^2 units, converted to px^2) and
// c_s = dx oy_s - dy ox_s (dx, dy multiples of 2^-8 px below 2^17, ox, oy multiples of
// 2^-20 in [0, 1)), each product is exact in double (<= 45 significant bits) and so is
// c_s (a multiple of 2^-28 below 2^18). A sample is only tested when the pixel is partly
// covered by the edge, where |E0| <= |dx| + |dy| < 2^18, so E0 + c_s, a multiple of 2^-28
// below 2^19, is exact too (47 bits): the sign test and the tie E = 0 are exact.
//
// The tile is processed one pixel at a time (the pixel's 4096 samples stay in L1/L2):
// draw() records the triangles, end_tile() buckets them by row and replays, per pixel,
// the row's triangles that touch the pixel, in draw order.
#pragma once

#include "core/tile_raster.hpp"
#include "raster/samples/sample_pattern.hpp"

#include <cstdint>
#include <vector>

namespace covrast::detail {

class ReferenceRasterizer final : public TileRasterizer {
 public:
  explicit ReferenceRasterizer(int tile_px);

  void begin_tile(const PixelRect& rect, const FrameTarget& target) override;
  void draw(const TriangleSetup& triangle) override;
  void end_tile(const FrameTarget& target) override;
  std::size_t scratch_bytes() const override;

  /// What end_tile does before encoding: pixel (x, y) of the tile gets the linear colour
  /// linear()[(y - y0) * tile_px + (x - x0)], in double.
  void resolve_tile(const FrameTarget& target);
  const glm::dvec3* linear() const { return linear_.data(); }

 private:
  struct Pending {
    const TriangleSetup* triangle;
    PixelRect rect;
  };
  /// Depth-tests an opaque or MASK triangle at pixel (x, y)'s samples.
  void sample_pixel(const TriangleSetup& t, std::uint32_t index, int x, int y);
  /// inside_[s]: sample s of pixel (x, y) lies in `t` (top-left rule); false when none can.
  bool inside_samples(const TriangleSetup& t, int x, int y);
  /// Pixel (x, y) with BLEND triangles (blend_): per sample, the ones in front of the nearest
  /// opaque sample composited front to back over it (docs/transparency.md); the box filter of
  /// that, and the nearest opaque depth in `nearest`.
  glm::dvec3 composite_pixel(int x, int y, double& nearest);

  int tile_px_;
  std::vector<double> ox_;  ///< sample offsets from the pixel corner [pixels]
  std::vector<double> oy_;
  std::vector<double> depth_;              ///< per sample of the current pixel
  std::vector<std::uint32_t> winner_;      ///< index into pending_, or kNoTriangle
  std::vector<std::uint8_t> inside_;       ///< per sample: inside the triangle being drawn
  std::vector<std::uint32_t> flat_count_;  ///< resolve: samples won per flat triangle
  std::vector<std::uint32_t> touched_;     ///< resolve: flat triangles in order of first win
  std::vector<Pending> pending_;
  std::vector<std::uint32_t> blend_;  ///< the current pixel's BLEND triangles (pending_ index)
  std::vector<double> layer_z_;       ///< composite_pixel: per BLEND triangle and sample
  std::vector<std::uint32_t> row_begin_;
  std::vector<std::uint32_t> row_items_;
  std::vector<std::uint32_t> row_cursor_;
  std::vector<glm::dvec3> linear_;
  std::vector<glm::vec3> linear_float_;
  std::vector<float> pixel_depth_;
  PixelRect rect_;
  glm::dvec3 background_{0.0};
  bool want_depth_ = false;
};

}  // namespace covrast::detail
