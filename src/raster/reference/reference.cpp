// Raster stage, reference mode (reference.hpp): slow on purpose, exact by construction.
#include "raster/reference/reference.hpp"
#include "raster/rasterizers.hpp"

#include "color/srgb8.hpp"
#include "core/edge_function.hpp"
#include "shading/composite.hpp"
#include "shading/shading.hpp"

#include <algorithm>
#include <limits>

namespace covrast::detail {
namespace {

/// Seed of the reference pattern (any fixed value, different from the ssaa one).
constexpr std::uint32_t kReferenceSeed = 0x5eed0040u;

}  // namespace

SamplePattern reference_pattern() {
  return cmj_pattern(kReferenceGrid, kReferenceUnit, kReferenceSeed);
}

ReferenceRasterizer::ReferenceRasterizer(int tile_px) : tile_px_(tile_px) {
  const SamplePattern pattern = reference_pattern();
  for (int s = 0; s < pattern.size(); ++s) {
    ox_.push_back(double(pattern.x[std::size_t(s)]) / kReferenceUnit);  // exact
    oy_.push_back(double(pattern.y[std::size_t(s)]) / kReferenceUnit);
  }
  depth_.resize(ox_.size());
  inside_.resize(ox_.size());
  winner_.resize(ox_.size());
  linear_.resize(std::size_t(tile_px) * tile_px);
  linear_float_.resize(linear_.size());
  pixel_depth_.resize(linear_.size());
}

void ReferenceRasterizer::begin_tile(const PixelRect& rect, const FrameTarget& target) {
  rect_ = rect;
  background_ = glm::dvec3(target.background_linear);
  want_depth_ = target.depth != nullptr;
  pending_.clear();
}

void ReferenceRasterizer::draw(const TriangleSetup& t) {
  const PixelRect r = intersect(touched_pixels(t), rect_);
  if (!r.empty()) pending_.push_back(Pending{&t, r});
}

void ReferenceRasterizer::end_tile(const FrameTarget& target) {
  resolve_tile(target);
  for (std::size_t i = 0; i < linear_.size(); ++i) linear_float_[i] = glm::vec3(linear_[i]);
  write_tile(target, rect_, linear_float_.data(), want_depth_ ? pixel_depth_.data() : nullptr,
             tile_px_);
}

std::size_t ReferenceRasterizer::scratch_bytes() const {
  return (ox_.capacity() + oy_.capacity() + depth_.capacity()) * sizeof(double) +
         (winner_.capacity() + flat_count_.capacity() + touched_.capacity()) *
             sizeof(std::uint32_t) +
         inside_.capacity() + pending_.capacity() * sizeof(Pending) +
         (row_begin_.capacity() + row_items_.capacity() + row_cursor_.capacity()) *
             sizeof(std::uint32_t) +
         linear_.capacity() * sizeof(glm::dvec3) + linear_float_.capacity() * sizeof(glm::vec3) +
         pixel_depth_.capacity() * sizeof(float);
}

void ReferenceRasterizer::resolve_tile(const FrameTarget&) {
  // Bucket the triangles by row, keeping draw order.
  const int rows = rect_.y1 - rect_.y0;
  row_begin_.assign(std::size_t(rows) + 1, 0);
  for (const Pending& p : pending_) {
    for (int y = p.rect.y0; y < p.rect.y1; ++y) ++row_begin_[std::size_t(y - rect_.y0) + 1];
  }
  for (int r = 0; r < rows; ++r) row_begin_[std::size_t(r) + 1] += row_begin_[std::size_t(r)];
  row_items_.resize(row_begin_[std::size_t(rows)]);
  flat_count_.assign(pending_.size(), 0);
  row_cursor_.assign(row_begin_.begin(), row_begin_.end() - 1);
  for (std::uint32_t i = 0; i < pending_.size(); ++i) {
    const Pending& p = pending_[i];
    for (int y = p.rect.y0; y < p.rect.y1; ++y) {
      row_items_[row_cursor_[std::size_t(y - rect_.y0)]++] = i;
    }
  }
  const std::size_t count = ox_.size();
  for (int y = rect_.y0; y < rect_.y1; ++y) {
    const std::size_t row = std::size_t(y - rect_.y0);
    for (int x = rect_.x0; x < rect_.x1; ++x) {
      const std::size_t i = row * std::size_t(tile_px_) + std::size_t(x - rect_.x0);
      bool touched = false;
      for (std::uint32_t k = row_begin_[row]; k < row_begin_[row + 1] && !touched; ++k) {
        const Pending& p = pending_[row_items_[k]];
        touched = x >= p.rect.x0 && x < p.rect.x1;
      }
      if (!touched) {
        linear_[i] = background_;
        pixel_depth_[i] = std::numeric_limits<float>::infinity();
        continue;
      }
      std::fill(depth_.begin(), depth_.end(), std::numeric_limits<double>::infinity());
      std::fill(winner_.begin(), winner_.end(), kNoTriangle);
      blend_.clear();
      for (std::uint32_t k = row_begin_[row]; k < row_begin_[row + 1]; ++k) {
        const Pending& p = pending_[row_items_[k]];
        if (x < p.rect.x0 || x >= p.rect.x1) continue;
        if (p.triangle->alpha_mode == AlphaMode::Blend) {
          blend_.push_back(row_items_[k]);  // composited after the opaque samples
        } else {
          sample_pixel(*p.triangle, row_items_[k], x, y);
        }
      }
      if (!blend_.empty()) {
        double nearest = std::numeric_limits<double>::infinity();
        linear_[i] = composite_pixel(x, y, nearest);
        pixel_depth_[i] = float(nearest);
        continue;
      }
      // Box filter in double; each sample shaded at its own position. A flat triangle
      // shades the same everywhere, so its samples are counted and weighted once.
      glm::dvec3 sum(0.0);
      double nearest = std::numeric_limits<double>::infinity();
      std::uint32_t background_count = 0;
      touched_.clear();
      for (std::size_t s = 0; s < count; ++s) {
        const std::uint32_t w = winner_[s];
        if (w == kNoTriangle) {
          ++background_count;
          continue;
        }
        nearest = std::min(nearest, depth_[s]);
        const TriangleSetup& t = *pending_[w].triangle;
        if (t.flat_color) {
          if (flat_count_[w]++ == 0) touched_.push_back(w);
          continue;
        }
        sum += glm::dvec3(shade(t, x + ox_[s], y + oy_[s], false));
      }
      sum += background_ * double(background_count);
      for (std::uint32_t w : touched_) {
        sum += glm::dvec3(pending_[w].triangle->color[0]) * double(flat_count_[w]);
        flat_count_[w] = 0;
      }
      linear_[i] = sum / double(count);
      pixel_depth_[i] = float(nearest);
    }
  }
}

glm::dvec3 ReferenceRasterizer::composite_pixel(int x, int y, double& nearest) {
  const std::size_t count = ox_.size();
  const std::size_t layers = blend_.size();
  // Per transparent triangle and sample: its depth where it covers the sample in front of the
  // nearest opaque one, else +inf.
  layer_z_.assign(layers * count, std::numeric_limits<double>::infinity());
  for (std::size_t b = 0; b < layers; ++b) {
    const TriangleSetup& t = *pending_[blend_[b]].triangle;
    if (!inside_samples(t, x, y)) continue;
    const double z0 = t.depth_at(x, y);
    for (std::size_t s = 0; s < count; ++s) {
      const double z = z0 + (t.dzdx * ox_[s] + t.dzdy * oy_[s]);
      if (inside_[s] != 0 && z < depth_[s]) layer_z_[b * count + s] = z;
    }
  }
  glm::dvec3 sum(0.0);
  std::vector<std::pair<double, std::size_t>> stack;
  for (std::size_t s = 0; s < count; ++s) {
    const double sx = x + ox_[s], sy = y + oy_[s];
    glm::dvec3 behind = background_;
    if (const std::uint32_t w = winner_[s]; w != kNoTriangle) {
      nearest = std::min(nearest, depth_[s]);
      behind = glm::dvec3(shade(*pending_[w].triangle, sx, sy, false));
    }
    stack.clear();
    for (std::size_t b = 0; b < layers; ++b) {
      if (layer_z_[b * count + s] < std::numeric_limits<double>::infinity()) {
        stack.emplace_back(layer_z_[b * count + s], b);
      }
    }
    std::sort(stack.begin(), stack.end(), [&](const auto& a, const auto& b) {
      return nearer_first(a.first, *pending_[blend_[a.second]].triangle, b.first,
                          *pending_[blend_[b.second]].triangle);
    });
    FrontToBack layers_over;
    for (const auto& layer : stack) {
      layers_over.add(shade_rgba(*pending_[blend_[layer.second]].triangle, sx, sy, false));
    }
    sum += layers_over.over(behind);
  }
  return sum / double(count);
}

void ReferenceRasterizer::sample_pixel(const TriangleSetup& t, std::uint32_t index, int x, int y) {
  if (!inside_samples(t, x, y)) return;
  const std::size_t count = ox_.size();
  if (t.alpha_mode == AlphaMode::Mask) {
    // Kept where the alpha at the sample passes the cutoff (a texture-driven edge, per sample).
    for (std::size_t s = 0; s < count; ++s) {
      if (inside_[s] != 0) inside_[s] = mask_keeps(t, x + ox_[s], y + oy_[s], false);
    }
  }
  const double z0 = t.depth_at(x, y);
  for (std::size_t s = 0; s < count; ++s) {
    const double z = z0 + (t.dzdx * ox_[s] + t.dzdy * oy_[s]);
    const bool wins = inside_[s] != 0 && z < depth_[s];
    depth_[s] = wins ? z : depth_[s];
    winner_[s] = wins ? index : winner_[s];
  }
}

bool ReferenceRasterizer::inside_samples(const TriangleSetup& t, int x, int y) {
  const TriangleEdges edges(t);
  constexpr double kFx8Squared = 1.0 / (double(kSubpixelOne) * kSubpixelOne);
  double e0[3], dx[3], dy[3];
  bool top_left[3];
  int partial[3], partial_count = 0;
  for (int e = 0; e < 3; ++e) {
    const EdgeFunction& ef = edges.e[e];
    // E at the pixel's corner without the tie bias: an integer below 2^50 (exact in
    // double), scaled to px^2 by a power of two.
    const std::int64_t raw =
        ef.at(std::int64_t(x) * kSubpixelOne, std::int64_t(y) * kSubpixelOne) - ef.bias;
    e0[e] = double(raw) * kFx8Squared;
    dx[e] = double(ef.dx) / kSubpixelOne;
    dy[e] = double(ef.dy) / kSubpixelOne;
    top_left[e] = ef.bias == 0;
    // c = dx oy - dy ox over [0, 1)^2 lies in [c_min, c_max]; one rounding of e0 + c
    // keeps its sign, so these tests are exact too.
    const double c_min = std::min(0.0, dx[e]) + std::min(0.0, -dy[e]);
    const double c_max = std::max(0.0, dx[e]) + std::max(0.0, -dy[e]);
    if (e0[e] + c_max < 0.0) return false;  // no sample inside this edge
    if (!(e0[e] + c_min > 0.0)) partial[partial_count++] = e;
  }
  const std::size_t count = ox_.size();
  // Branch-free passes (the compiler vectorises them): the edges first, then depth.
  std::fill(inside_.begin(), inside_.end(), std::uint8_t(1));
  for (int k = 0; k < partial_count; ++k) {
    const int e = partial[k];
    const double a = e0[e], ex = dx[e], ey = dy[e];
    if (top_left[e]) {
      for (std::size_t s = 0; s < count; ++s) inside_[s] &= a + (ex * oy_[s] - ey * ox_[s]) >= 0.0;
    } else {
      for (std::size_t s = 0; s < count; ++s) inside_[s] &= a + (ex * oy_[s] - ey * ox_[s]) > 0.0;
    }
  }
  return true;
}

std::unique_ptr<TileRasterizer> make_reference_rasterizer(int tile_px) {
  return std::make_unique<ReferenceRasterizer>(tile_px);
}

}  // namespace covrast::detail
