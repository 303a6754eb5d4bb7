// Raster stage, sample-based modes: the tile and band loop around the sample kernels
// (sample_raster.hpp, sample_kernel.hpp).
#include "raster/samples/sample_raster.hpp"

#include "color/srgb8.hpp"
#include "core/edge_function.hpp"
#include "shading/composite.hpp"
#include "shading/shading.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <limits>

namespace covrast::detail {
namespace {

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
int round_up(int a, int b) { return (a + b - 1) / b * b; }

}  // namespace

std::uint32_t quantize_color(float linear) {
  if (!(linear > 0.0f)) return 0;  // also NaN
  if (linear >= 1.0f) return std::uint32_t(1) << kColorFractionBits;
  return std::uint32_t(double(linear) * kColorOne + 0.5);
}

void make_group_pattern(const SamplePattern& pattern, GroupPattern& gp) {
  const int s = pattern.size();
  // P = S when S divides 16 (G = 16 / S pixels share a group), else S rounded up to 16.
  gp.samples = s;
  gp.stride = kGroupLaneBlock % s == 0 ? s : round_up(s, kGroupLaneBlock);
  gp.group_px = gp.stride < kGroupLaneBlock ? kGroupLaneBlock / gp.stride : 1;
  gp.lanes = gp.group_px * gp.stride;
  gp.ox_min = gp.oy_min = std::numeric_limits<std::int32_t>::max();
  gp.ox_max = gp.oy_max = std::numeric_limits<std::int32_t>::min();
  for (int l = 0; l < gp.lanes; ++l) {
    const int px = l / gp.stride, k = l % gp.stride;
    const bool real = k < s;
    const std::int32_t ox = real ? px * kSubpixelOne + pattern.x[k] : 0;
    const std::int32_t oy = real ? pattern.y[k] : 0;
    gp.ox_fx8[l] = ox;
    gp.oy_fx8[l] = oy;
    gp.ox_px[l] = float(ox) / float(kSubpixelOne);  // exact: small multiples of 2^-8
    gp.oy_px[l] = float(oy) / float(kSubpixelOne);
    gp.valid[l] = real ? ~std::int32_t(0) : 0;
    if (real) {
      gp.ox_min = std::min(gp.ox_min, ox);
      gp.ox_max = std::max(gp.ox_max, ox);
      gp.oy_min = std::min(gp.oy_min, oy);
      gp.oy_max = std::max(gp.oy_max, oy);
    }
  }
}

bool make_raster_job(const GroupPattern& gp, const TriangleSetup& t, const PixelRect& r,
                     RasterJob& job) {
  const int group_px = gp.group_px;
  const TriangleEdges edges(t);
  // Group extent X = G * 256 [fx8]; see sample_kernel.hpp for the int32 bound.
  const std::int64_t extent = std::int64_t(group_px) * kSubpixelOne;
  bool fits = true;
  const int gx0 = floor_div(r.x0, group_px) * group_px;
  for (int e = 0; e < 3; ++e) {
    const EdgeFunction& ef = edges.e[e];
    if ((std::abs(ef.dx) + std::abs(ef.dy)) * extent >= kEdgeClamp) fits = false;
    // Extremes of c = dx * oy - dy * ox over the box of the pattern's offsets.
    const std::int64_t a0 = ef.dx * gp.oy_min, a1 = ef.dx * gp.oy_max;
    const std::int64_t b0 = -ef.dy * gp.ox_min, b1 = -ef.dy * gp.ox_max;
    job.c_min[e] = std::min(a0, a1) + std::min(b0, b1);
    job.c_max[e] = std::max(a0, a1) + std::max(b0, b1);
    job.step_x[e] = ef.step_x(extent);
    job.step_y[e] = ef.step_y(kSubpixelOne);
    job.f[e] = ef.at(std::int64_t(gx0) * kSubpixelOne, std::int64_t(r.y0) * kSubpixelOne);
  }
  for (int e = 0; e < 3; ++e) {
    job.dx[e] = fits ? std::int32_t(edges.e[e].dx) : 0;
    job.dy[e] = fits ? std::int32_t(edges.e[e].dy) : 0;
  }
  job.gx0 = gx0;
  job.y0 = r.y0;
  job.groups = (r.x1 - gx0 + group_px - 1) / group_px;
  job.rows = r.y1 - r.y0;
  job.dzdx_f = float(t.dzdx);
  job.dzdy_f = float(t.dzdy);
  job.z0 = t.z0;
  job.dzdx = t.dzdx;
  job.dzdy = t.dzdy;
  job.vx = t.x_fx8[0] * (1.0 / kSubpixelOne);
  job.vy = t.y_fx8[0] * (1.0 / kSubpixelOne);
  job.rgb = nullptr;
  job.shade_fn = nullptr;
  job.shade_context = nullptr;
  return fits;
}

SampleRasterizer::SampleRasterizer(int tile_px, const SamplePattern& pattern, ShadingRate rate,
                                   const SampleKernels& kernels, std::size_t band_budget_bytes)
    : tile_px_(tile_px),
      rate_(rate),
      kernels_(kernels),
      pattern_(std::make_unique<GroupPattern>()),
      tri_(std::make_unique<GroupTriangle>()),
      pixel_pattern_(pattern) {
  make_group_pattern(pattern, *pattern_);
  const GroupPattern& gp = *pattern_;
  // A tile's groups run from rect.x0 rounded down to G to rect.x1 rounded up to G.
  buffer_px_ = gp.group_px == 1 ? tile_px : round_up(tile_px, gp.group_px) + gp.group_px;
  row_lanes_ = std::size_t(buffer_px_) * std::size_t(gp.stride);
  const std::size_t row_bytes = row_lanes_ * (sizeof(float) + 3 * sizeof(std::uint32_t));
  band_rows_ = int(std::clamp<std::size_t>(band_budget_bytes / row_bytes, 1, std::size_t(tile_px)));
  const std::size_t lanes = std::size_t(band_rows_) * row_lanes_;
  depth_ = hwy::AllocateAligned<float>(lanes);
  r_ = hwy::AllocateAligned<std::uint32_t>(lanes);
  g_ = hwy::AllocateAligned<std::uint32_t>(lanes);
  b_ = hwy::AllocateAligned<std::uint32_t>(lanes);
  sums_.resize(3 * std::size_t(buffer_px_));
  min_depth_.resize(std::size_t(buffer_px_));
  linear_.resize(std::size_t(tile_px) * tile_px);
  pixel_depth_.resize(std::size_t(tile_px) * tile_px);
}

SampleRasterizer::~SampleRasterizer() = default;

void SampleRasterizer::begin_tile(const PixelRect& rect, const FrameTarget& target) {
  rect_ = rect;
  buffer_x0_ = floor_div(rect.x0, pattern_->group_px) * pattern_->group_px;
  want_depth_ = target.depth != nullptr;
  background_q_[0] = quantize_color(target.background_linear.r);
  background_q_[1] = quantize_color(target.background_linear.g);
  background_q_[2] = quantize_color(target.background_linear.b);
  immediate_ = rect.y1 - rect.y0 <= band_rows_;
  pending_.clear();
  blend_.clear();
  if (immediate_) start_band(rect.y0, rect.y1);
}

void SampleRasterizer::draw(const TriangleSetup& t) {
  const PixelRect r = intersect(touched_pixels(t), rect_);
  if (r.empty()) return;
  if (t.alpha_mode == AlphaMode::Blend) {
    blend_.push_back(Pending{&t, r});  // composited per sample before the resolve
    return;
  }
  if (immediate_) {
    rasterize(t, r);
  } else {
    pending_.push_back(Pending{&t, r});
  }
}

void SampleRasterizer::end_tile(const FrameTarget& target) {
  resolve_tile(target);
  write_tile(target, rect_, linear_.data(), want_depth_ ? pixel_depth_.data() : nullptr, tile_px_);
}

void SampleRasterizer::resolve_tile(const FrameTarget&) {
  if (immediate_) {
    resolve_band();
    return;
  }
  // Bucket the recorded triangles by band (a counting sort that keeps draw order), then
  // replay band after band.
  const int height = rect_.y1 - rect_.y0;
  const int bands = (height + band_rows_ - 1) / band_rows_;
  band_begin_.assign(std::size_t(bands) + 1, 0);
  for (const Pending& p : pending_) {
    const int b0 = (p.rect.y0 - rect_.y0) / band_rows_,
              b1 = (p.rect.y1 - 1 - rect_.y0) / band_rows_;
    for (int b = b0; b <= b1; ++b) ++band_begin_[std::size_t(b) + 1];
  }
  for (int b = 0; b < bands; ++b) band_begin_[std::size_t(b) + 1] += band_begin_[std::size_t(b)];
  band_items_.resize(band_begin_[std::size_t(bands)]);
  band_cursor_.assign(band_begin_.begin(), band_begin_.end() - 1);
  for (std::uint32_t i = 0; i < pending_.size(); ++i) {
    const Pending& p = pending_[i];
    const int b0 = (p.rect.y0 - rect_.y0) / band_rows_,
              b1 = (p.rect.y1 - 1 - rect_.y0) / band_rows_;
    for (int b = b0; b <= b1; ++b) band_items_[band_cursor_[std::size_t(b)]++] = i;
  }
  for (int b = 0; b < bands; ++b) {
    const int y0 = rect_.y0 + b * band_rows_, y1 = std::min(y0 + band_rows_, rect_.y1);
    const auto raster_start = std::chrono::steady_clock::now();
    start_band(y0, y1);
    for (std::uint32_t k = band_begin_[std::size_t(b)]; k < band_begin_[std::size_t(b) + 1]; ++k) {
      const Pending& p = pending_[band_items_[k]];
      PixelRect r = p.rect;
      r.y0 = std::max(r.y0, y0);
      r.y1 = std::min(r.y1, y1);
      rasterize(*p.triangle, r);
    }
    deferred_raster_ms_ +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - raster_start)
            .count();
    resolve_band();
  }
}

std::size_t SampleRasterizer::scratch_bytes() const {
  const std::size_t lanes = std::size_t(band_rows_) * row_lanes_;
  return lanes * (sizeof(float) + 3 * sizeof(std::uint32_t)) + sizeof(GroupPattern) +
         sizeof(GroupTriangle) + sums_.capacity() * sizeof(std::uint32_t) +
         min_depth_.capacity() * sizeof(float) + linear_.capacity() * sizeof(glm::vec3) +
         pixel_depth_.capacity() * sizeof(float) + pending_.capacity() * sizeof(Pending) +
         (band_begin_.capacity() + band_items_.capacity() + band_cursor_.capacity()) *
             sizeof(std::uint32_t);
}

void SampleRasterizer::start_band(int y0, int y1) {
  band_y0_ = y0;
  band_y1_ = y1;
  kernels_.clear(depth_.get(), std::size_t(y1 - y0) * row_lanes_);
}

void SampleRasterizer::rasterize(const TriangleSetup& t, const PixelRect& r) {
  const GroupPattern& gp = *pattern_;
  const int group_px = gp.group_px;
  RasterJob job;
  const bool fits = make_raster_job(gp, t, r, job);
  const int gx0 = job.gx0;
  std::uint32_t rgb[3];
  const std::uint32_t* flat_rgb = nullptr;
  if (t.flat_color) {
    rgb[0] = quantize_color(t.color[0].r);
    rgb[1] = quantize_color(t.color[0].g);
    rgb[2] = quantize_color(t.color[0].b);
    flat_rgb = rgb;
  }
  const std::size_t stride = std::size_t(gp.stride);
  // MASK triangles take the int64 path on every group: it tests the alpha sample by sample.
  const bool mask = t.alpha_mode == AlphaMode::Mask;
  if (fits && !mask) {
    job.rgb = flat_rgb;
    ShadeContext context{this, &t};
    job.shade_fn = &SampleRasterizer::shade_trampoline;
    job.shade_context = &context;
    const std::size_t lane =
        (std::size_t(r.y0 - band_y0_) * std::size_t(buffer_px_) + std::size_t(gx0 - buffer_x0_)) *
        stride;
    job.first =
        GroupSamples{depth_.get() + lane, r_.get() + lane, g_.get() + lane, b_.get() + lane};
    job.row_lanes = row_lanes_;
    kernels_.raster(gp, job, *tri_);
    return;
  }
  // An edge too long for int32 lanes: classify here, and test partly covered groups with
  // int64 arithmetic (sample_wide).
  bool set_up = false;
  std::int64_t f_row[3] = {job.f[0], job.f[1], job.f[2]};
  for (int y = r.y0; y < r.y1; ++y) {
    std::int64_t f[3] = {f_row[0], f_row[1], f_row[2]};
    std::size_t lane =
        (std::size_t(y - band_y0_) * std::size_t(buffer_px_) + std::size_t(gx0 - buffer_x0_)) *
        stride;
    for (int gx = gx0; gx < r.x1; gx += group_px, lane += std::size_t(gp.lanes)) {
      bool all_inside = true, none = false;
      for (int e = 0; e < 3; ++e) {
        none |= f[e] + job.c_max[e] < 0;
        all_inside &= f[e] + job.c_min[e] >= 0;
      }
      const std::int64_t f_here[3] = {f[0], f[1], f[2]};
      for (int e = 0; e < 3; ++e) f[e] += job.step_x[e];
      if (none) continue;
      if (!set_up) {
        kernels_.setup(gp, job.dx, job.dy, false, job.dzdx_f, job.dzdy_f, *tri_);
        set_up = true;
      }
      const float z_base = float(t.depth_at(gx, y));
      const GroupSamples out{depth_.get() + lane, r_.get() + lane, g_.get() + lane,
                             b_.get() + lane};
      std::uint64_t written[kMaxGroupLanes / 64] = {0, 0, 0, 0};
      std::uint64_t* written_ptr = flat_rgb != nullptr ? nullptr : written;
      bool any;
      if (all_inside && !mask) {
        any = kernels_.sample(gp, *tri_, nullptr, z_base, flat_rgb, out, written_ptr);
      } else {
        any = false;
        sample_wide(t, f_here, z_base, flat_rgb, out, written, gx, y);
        for (std::uint64_t w : written) any |= w != 0;
      }
      if (any && flat_rgb == nullptr) shade_written(t, gx, y, written, out);
    }
    for (int e = 0; e < 3; ++e) f_row[e] += job.step_y[e];
  }
}

void SampleRasterizer::sample_wide(const TriangleSetup& t, const std::int64_t f[3], float z_base,
                                   const std::uint32_t* rgb, const GroupSamples& out,
                                   std::uint64_t* written, int gx, int y) {
  // The int64 twin of the kernel for triangles with an edge too long for int32 lanes;
  // it only runs on partly covered groups, i.e. along such a triangle's edges.
  const GroupPattern& gp = *pattern_;
  const TriangleEdges edges(t);
  for (int l = 0; l < gp.lanes; ++l) {
    if (gp.valid[l] == 0) continue;
    bool inside = true;
    for (int e = 0; e < 3; ++e) {
      const std::int64_t c = edges.e[e].dx * gp.oy_fx8[l] - edges.e[e].dy * gp.ox_fx8[l];
      inside &= f[e] + c >= 0;
    }
    const float z = z_base + tri_->dz[l];
    if (!inside || !(z < out.depth[l])) continue;
    if (t.alpha_mode == AlphaMode::Mask && !mask_keeps_lane(t, gx, y, l)) continue;
    out.depth[l] = z;
    if (rgb != nullptr) {
      out.r[l] = rgb[0];
      out.g[l] = rgb[1];
      out.b[l] = rgb[2];
    }
    written[l / 64] |= std::uint64_t(1) << (l % 64);
  }
}

bool SampleRasterizer::mask_keeps_lane(const TriangleSetup& t, int gx, int y, int l) const {
  const GroupPattern& gp = *pattern_;
  if (rate_ == ShadingRate::PerPixel) {
    // msaa: the alpha of the pixel's one shading point, the centre clamped into the triangle.
    return mask_keeps(t, gx + l / gp.stride + 0.5, y + 0.5, true);
  }
  return mask_keeps(t, gx + gp.ox_fx8[l] * (1.0 / kSubpixelOne),
                    y + gp.oy_fx8[l] * (1.0 / kSubpixelOne), false);
}

void SampleRasterizer::composite_band() {
  // Per sample of every pixel that a BLEND triangle touches: the BLEND triangles covering it
  // in front of its opaque depth, nearest first (level ones by primitive index), composited
  // over its colour, or the background's (docs/transparency.md). A sample that only BLEND
  // triangles cover gets the largest finite depth, so that the resolve reads its colour; the
  // pixel depth output clamps it to 1, as the background's.
  const GroupPattern& gp = *pattern_;
  const double inv = 1.0 / kSubpixelOne;
  std::vector<const Pending*> layers;
  std::vector<std::pair<float, const TriangleSetup*>> stack;
  for (int y = band_y0_; y < band_y1_; ++y) {
    for (int x = rect_.x0; x < rect_.x1; ++x) {
      layers.clear();
      for (const Pending& p : blend_) {
        if (x >= p.rect.x0 && x < p.rect.x1 && y >= p.rect.y0 && y < p.rect.y1) {
          layers.push_back(&p);
        }
      }
      if (layers.empty()) continue;
      const int gx = floor_div(x, gp.group_px) * gp.group_px;
      const int first = (x - gx) * gp.stride;
      const std::size_t base =
          (std::size_t(y - band_y0_) * std::size_t(buffer_px_) + std::size_t(gx - buffer_x0_)) *
          std::size_t(gp.stride);
      for (int l = first; l < first + gp.samples; ++l) {
        const std::int64_t sx = std::int64_t(gx) * kSubpixelOne + gp.ox_fx8[l];
        const std::int64_t sy = std::int64_t(y) * kSubpixelOne + gp.oy_fx8[l];
        float& depth = depth_[base + std::size_t(l)];
        stack.clear();
        for (const Pending* p : layers) {
          const TriangleEdges edges(*p->triangle);
          if ((edges.e[0].at(sx, sy) | edges.e[1].at(sx, sy) | edges.e[2].at(sx, sy)) < 0) continue;
          const float z = float(p->triangle->depth_at(sx * inv, sy * inv));
          if (z < depth) stack.emplace_back(z, p->triangle);
        }
        if (stack.empty()) continue;
        std::sort(stack.begin(), stack.end(), [](const auto& a, const auto& b) {
          return nearer_first(a.first, *a.second, b.first, *b.second);
        });
        std::uint32_t* rgb[3] = {&r_[base + std::size_t(l)], &g_[base + std::size_t(l)],
                                 &b_[base + std::size_t(l)]};
        const bool empty = !(depth < std::numeric_limits<float>::infinity());
        FrontToBack layers_over;
        for (const auto& layer : stack) {
          layers_over.add(rate_ == ShadingRate::PerPixel
                              ? shade_rgba(*layer.second, x + 0.5, y + 0.5, true)
                              : shade_rgba(*layer.second, sx * inv, sy * inv, false));
        }
        glm::dvec3 behind;
        for (int k = 0; k < 3; ++k) behind[k] = (empty ? background_q_[k] : *rgb[k]) / kColorOne;
        const glm::dvec3 c = layers_over.over(behind);
        for (int k = 0; k < 3; ++k) *rgb[k] = quantize_color(float(c[k]));
        if (empty) depth = std::numeric_limits<float>::max();
      }
    }
  }
}

void SampleRasterizer::shade_trampoline(void* context, int gx, int y, const std::uint64_t* written,
                                        const GroupSamples& group) {
  const ShadeContext& c = *static_cast<const ShadeContext*>(context);
  c.self->shade_written(*c.triangle, gx, y, written, group);
}

void SampleRasterizer::shade_written(const TriangleSetup& t, int gx, int y,
                                     const std::uint64_t* written, const GroupSamples& out) {
  const GroupPattern& gp = *pattern_;
  auto is_written = [&](int l) { return (written[l / 64] >> (l % 64)) & 1; };
  const double inv = 1.0 / kSubpixelOne;
  for (int px = 0; px < gp.group_px; ++px) {
    const int first = px * gp.stride, end = first + gp.samples;
    if (rate_ == ShadingRate::PerSample) {
      for (int l = first; l < end; ++l) {
        if (!is_written(l)) continue;
        const int s = l - first;
        const glm::vec3 c = shade(t, gx + px + pixel_pattern_.x[std::size_t(s)] * inv,
                                  y + pixel_pattern_.y[std::size_t(s)] * inv, false);
        out.r[l] = quantize_color(c.r);
        out.g[l] = quantize_color(c.g);
        out.b[l] = quantize_color(c.b);
      }
      continue;
    }
    // Per pixel: one colour at the centre for every sample this triangle won.
    bool any = false;
    for (int l = first; l < end && !any; ++l) any = is_written(l);
    if (!any) continue;
    const glm::vec3 c = shade(t, gx + px + 0.5, y + 0.5, true);
    const std::uint32_t q[3] = {quantize_color(c.r), quantize_color(c.g), quantize_color(c.b)};
    for (int l = first; l < end; ++l) {
      if (!is_written(l)) continue;
      out.r[l] = q[0];
      out.g[l] = q[1];
      out.b[l] = q[2];
    }
  }
}

void SampleRasterizer::resolve_band() {
  if (!blend_.empty()) composite_band();
  const GroupPattern& gp = *pattern_;
  const int pixels = rect_.x1 - rect_.x0;
  const double scale = 1.0 / (double(gp.samples) * kColorOne);  // exact for S = 2^k
  for (int y = band_y0_; y < band_y1_; ++y) {
    const std::size_t lane =
        (std::size_t(y - band_y0_) * std::size_t(buffer_px_) + std::size_t(rect_.x0 - buffer_x0_)) *
        std::size_t(gp.stride);
    const GroupSamples in{depth_.get() + lane, r_.get() + lane, g_.get() + lane, b_.get() + lane};
    kernels_.resolve(gp, pixels, in, background_q_, sums_.data(),
                     want_depth_ ? min_depth_.data() : nullptr);
    glm::vec3* out = &linear_[std::size_t(y - rect_.y0) * std::size_t(tile_px_)];
    for (int p = 0; p < pixels; ++p) {
      out[p] = glm::vec3(float(sums_[3 * std::size_t(p)] * scale),
                         float(sums_[3 * std::size_t(p) + 1] * scale),
                         float(sums_[3 * std::size_t(p) + 2] * scale));
    }
    if (want_depth_) {
      std::copy(min_depth_.begin(), min_depth_.begin() + pixels,
                pixel_depth_.begin() + std::ptrdiff_t(y - rect_.y0) * tile_px_);
    }
  }
}

}  // namespace covrast::detail
