// Raster stage, aliased mode: one sample at each pixel centre, top-left fill rule,
// z-buffer (nearest wins, equal depth keeps the earlier triangle), perspective-correct
// vertex colours.
#include "raster/edge_function.hpp"
#include "raster/shading.hpp"
#include "raster/tile_raster.hpp"
#include "resolve/srgb8.hpp"

#include <limits>
#include <vector>

namespace covrast::detail {
namespace {

class AliasedRasterizer final : public TileRasterizer {
public:
  explicit AliasedRasterizer(int tile_px)
      : stride_(tile_px),
        color_(std::size_t(tile_px) * tile_px),
        depth_(std::size_t(tile_px) * tile_px) {}

  void begin_tile(const PixelRect& rect, const FrameTarget&) override {
    rect_ = rect;
    std::fill(depth_.begin(), depth_.end(), std::numeric_limits<float>::infinity());
  }

  void draw(const TriangleSetup& t) override {
    PixelRect r = intersect(touched_pixels(t), rect_);
    if (r.empty()) return;
    TriangleEdges edges(t);
    constexpr std::int64_t kHalf = kSubpixelOne / 2;
    const std::int64_t cx0 = std::int64_t(r.x0) * kSubpixelOne + kHalf;
    std::int64_t cy = std::int64_t(r.y0) * kSubpixelOne + kHalf;
    std::int64_t row_e[3], step_x[3];
    for (int i = 0; i < 3; ++i) {
      row_e[i] = edges.e[i].at(cx0, cy);
      step_x[i] = edges.e[i].step_x(kSubpixelOne);
    }
    for (int y = r.y0; y < r.y1; ++y, cy += kSubpixelOne) {
      std::int64_t e0 = row_e[0], e1 = row_e[1], e2 = row_e[2];
      float* depth_row = &depth_[std::size_t(y - rect_.y0) * stride_ - rect_.x0];
      glm::vec3* color_row = &color_[std::size_t(y - rect_.y0) * stride_ - rect_.x0];
      for (int x = r.x0; x < r.x1; ++x) {
        if ((e0 | e1 | e2) >= 0) {
          double px = x + 0.5, py = y + 0.5;
          float z = float(t.depth_at(px, py));
          if (z < depth_row[x]) {
            depth_row[x] = z;
            color_row[x] = shade(t, px, py, false);
          }
        }
        e0 += step_x[0];
        e1 += step_x[1];
        e2 += step_x[2];
      }
      for (int i = 0; i < 3; ++i) row_e[i] += edges.e[i].step_y(kSubpixelOne);
    }
  }

  void end_tile(const FrameTarget& target) override {
    for (int y = rect_.y0; y < rect_.y1; ++y) {
      for (int x = rect_.x0; x < rect_.x1; ++x) {
        std::size_t i = std::size_t(y - rect_.y0) * stride_ + (x - rect_.x0);
        if (depth_[i] == std::numeric_limits<float>::infinity()) {
          color_[i] = target.background_linear;
        }
      }
    }
    write_tile(target, rect_, color_.data(), depth_.data(), stride_);
  }

  std::size_t scratch_bytes() const override {
    return color_.size() * sizeof(glm::vec3) + depth_.size() * sizeof(float);
  }

private:
  int stride_;
  PixelRect rect_;
  std::vector<glm::vec3> color_;
  std::vector<float> depth_;
};

}  // namespace

std::unique_ptr<TileRasterizer> make_aliased_rasterizer(int tile_px) {
  return std::make_unique<AliasedRasterizer>(tile_px);
}

}  // namespace covrast::detail
