// Post-process stage, FXAA: the scalar twins of the row kernels (fxaa_kernel.hpp), one pixel
// at a time. Written from the published description of FXAA 3.11 (fxaa.hpp, docs/fxaa.md).
#include "color/srgb.hpp"
#include "post/fxaa_kernel.hpp"

#include "color/srgb8.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <span>

namespace covrast::detail {
namespace {

/// Luma at a pixel, clamped to the frame (a texture's clamp-to-edge addressing).
float luma_at(const FxaaFrame& frame, int x, int y) {
  x = std::clamp(x, 0, frame.width - 1);
  y = std::clamp(y, 0, frame.height - 1);
  return frame.luma[std::size_t(y) * frame.width + x];
}

/// Bilinear luma at (u, v) [pixels], pixel (x, y)'s centre at (x, y): what a GPU's filtered
/// fetch returns, with exact weights instead of 8-bit ones.
float luma_bilinear(const FxaaFrame& frame, float u, float v) {
  const float x0 = std::floor(u), y0 = std::floor(v);
  const float fx = u - x0, fy = v - y0;
  const int ix = int(x0), iy = int(y0);
  const float top = (1.0f - fx) * luma_at(frame, ix, iy) + fx * luma_at(frame, ix + 1, iy);
  const float bottom =
      (1.0f - fx) * luma_at(frame, ix, iy + 1) + fx * luma_at(frame, ix + 1, iy + 1);
  return (1.0f - fy) * top + fy * bottom;
}

/// The 3x3 luma block around a pixel; n is the row above (y - 1), w the column to the left.
struct Neighbourhood {
  float m, n, s, w, e;
  float nw, ne, sw, se;
};

/// The cross first (the contrast test needs only it), the corners once a pixel passes.
Neighbourhood cross(const FxaaFrame& frame, int x, int y) {
  Neighbourhood l{};
  l.m = luma_at(frame, x, y);
  l.n = luma_at(frame, x, y - 1);
  l.s = luma_at(frame, x, y + 1);
  l.w = luma_at(frame, x - 1, y);
  l.e = luma_at(frame, x + 1, y);
  return l;
}

void add_corners(const FxaaFrame& frame, int x, int y, Neighbourhood& l) {
  l.nw = luma_at(frame, x - 1, y - 1);
  l.ne = luma_at(frame, x + 1, y - 1);
  l.sw = luma_at(frame, x - 1, y + 1);
  l.se = luma_at(frame, x + 1, y + 1);
}

/// Step 1: the local contrast test on the cross; the range of its lumas when the pixel passes,
/// else 0. (A flat cross has range 0: skipped even when both thresholds are 0.)
float passing_range(float m, float n, float s, float w, float e, const FxaaParams& params) {
  const float max_luma = std::max(std::max(std::max(m, n), std::max(s, w)), e);
  const float range = max_luma - std::min(std::min(std::min(m, n), std::min(s, w)), e);
  const float needed = std::max(params.edge_threshold_min, max_luma * params.edge_threshold);
  return range > 0.0f && range >= needed ? range : 0.0f;
}

/// Step 2: an edge along x (horizontal) when the second differences across rows, weighted
/// 1-2-1 over the three columns, are at least those across columns:
///   horz = |nw + sw - 2w| + 2 |n + s - 2m| + |ne + se - 2e|
///   vert = |nw + ne - 2n| + 2 |w + e - 2m| + |sw + se - 2s|
bool edge_is_horizontal(const Neighbourhood& l) {
  const float horz = std::fabs(l.nw + l.sw - 2.0f * l.w) +
                     2.0f * std::fabs(l.n + l.s - 2.0f * l.m) + std::fabs(l.ne + l.se - 2.0f * l.e);
  const float vert = std::fabs(l.nw + l.ne - 2.0f * l.n) +
                     2.0f * std::fabs(l.w + l.e - 2.0f * l.m) + std::fabs(l.sw + l.se - 2.0f * l.s);
  return horz >= vert;
}

/// Step 3: the sub-pixel weight. The 3x3 low-pass (edges 2, corners 1, centre 0, sum 12)
/// against the centre, relative to the cross's range, through the smoothstep c^2 (3 - 2c),
/// squared, times subpix. A pixel unlike all its neighbours (a dot, a 1-pixel line) gets
/// much; a straight step edge little ((7/27)^2 * subpix = 0.050 for subpix 0.75).
float subpixel_weight(const Neighbourhood& l, float range, float subpix) {
  const float lowpass =
      (2.0f * (l.n + l.s + l.w + l.e) + (l.nw + l.ne + l.sw + l.se)) * (1.0f / 12.0f);
  const float c = std::min(1.0f, std::fabs(lowpass - l.m) / range);
  const float smooth = c * c * (3.0f - 2.0f * c);
  return smooth * smooth * subpix;
}

/// Step 4's search in one direction along the edge. `sample` returns the luma minus the
/// edge's mean at a distance [pixels]; the search stops where it leaves the mean by at
/// least `limit`, else runs through all steps and ends at their sum.
struct SearchEnd {
  float distance;  ///< from the pixel centre [pixels]
  float luma;      ///< the last sample minus the edge's mean
};

template <class Sample>
SearchEnd search_edge(std::span<const float> steps, float limit, Sample sample) {
  SearchEnd end{steps[0], sample(steps[0])};
  for (std::size_t k = 1; k < steps.size(); ++k) {
    if (std::fabs(end.luma) >= limit) return end;
    end.distance += steps[k];
    if (k + 1 < steps.size()) end.luma = sample(end.distance);
  }
  return end;
}

/// sRGB byte -> linear light, for the blend (IEC 61966-2-1, computed once in double). Built
/// at start-up (no guard on every call); nothing filters during static initialisation.
std::array<float, 256> make_srgb8_linear() {
  std::array<float, 256> t{};
  for (int k = 0; k < 256; ++k) {
    const double e = k / 255.0;
    t[k] = float(srgb_decode(e));
  }
  return t;
}
const std::array<float, 256> g_srgb8_linear = make_srgb8_linear();

/// Step 5: out = (1 - w) centre + w neighbour, in linear light (what a filtered fetch from an
/// sRGB texture at the offset position returns), then the exact 8-bit encode. Weight 0 leaves
/// `out` as it is (it holds the centre's bytes).
void blend_pixel(const FxaaFrame& frame, int x, int y, const FxaaBlend& blend, std::uint8_t* out) {
  if (blend.weight == 0.0f) return;
  const std::uint8_t* centre = frame.rgb + 3 * (std::size_t(y) * frame.width + x);
  // The neighbour is inside the frame (clamped, as the luma fetches are).
  const int ox = std::clamp(x + blend.dx, 0, frame.width - 1);
  const int oy = std::clamp(y + blend.dy, 0, frame.height - 1);
  const std::uint8_t* other = frame.rgb + 3 * (std::size_t(oy) * frame.width + ox);
  for (int c = 0; c < 3; ++c) {
    const float mixed =
        (1.0f - blend.weight) * g_srgb8_linear[centre[c]] + blend.weight * g_srgb8_linear[other[c]];
    out[c] = encode_srgb8(mixed);
  }
}

void luma_row_scalar(const std::uint8_t* rgb, int width, float* luma) {
  for (int x = 0; x < width; ++x, rgb += 3) {
    // Integer weights, then one division: white is exactly 1, and the value is exact to
    // float rounding whatever the compiler.
    const int weighted = 299 * rgb[0] + 587 * rgb[1] + 114 * rgb[2];
    luma[x] = float(weighted) / 255000.0f;
  }
}

void filter_rows_scalar(const FxaaFrame& frame, const FxaaParams& params, int y_begin, int y_end,
                        std::uint8_t* out) {
  const int width = frame.width;
  for (int y = y_begin; y < y_end; ++y) {
    // Most pixels fail the contrast test, most of them with a flat cross: test them here on
    // the luma rows (clamped at the frame's border), the others go through fxaa_blend_scalar.
    const float* above = frame.luma + std::size_t(std::max(y - 1, 0)) * width;
    const float* row = frame.luma + std::size_t(y) * width;
    const float* below = frame.luma + std::size_t(std::min(y + 1, frame.height - 1)) * width;
    std::uint8_t* out_row = out + 3 * std::size_t(y) * width;
    for (int x = 0; x < width; ++x) {
      const int left = std::max(x - 1, 0), right = std::min(x + 1, width - 1);
      const float m = row[x];
      if (m == above[x] && m == below[x] && m == row[left] && m == row[right]) continue;
      if (passing_range(m, above[x], below[x], row[left], row[right], params) == 0.0f) continue;
      blend_pixel(frame, x, y, fxaa_blend_scalar(frame, params, x, y),
                  out_row + 3 * std::size_t(x));
    }
  }
}

}  // namespace

const float* fxaa_srgb8_linear() { return g_srgb8_linear.data(); }

FxaaBlend fxaa_blend_scalar(const FxaaFrame& frame, const FxaaParams& params, int x, int y) {
  Neighbourhood l = cross(frame, x, y);
  const float range = passing_range(l.m, l.n, l.s, l.w, l.e, params);
  if (range == 0.0f) return {};
  add_corners(frame, x, y, l);

  const bool horizontal = edge_is_horizontal(l);
  const float subpix = subpixel_weight(l, range, params.subpix);
  // Across the edge: the neighbour before (n or w) or after (s or e) the pixel; take the
  // side with the larger luma step.
  const float before = horizontal ? l.n : l.w, after = horizontal ? l.s : l.e;
  const bool to_before = std::fabs(before - l.m) >= std::fabs(after - l.m);
  const float gradient = std::max(std::fabs(before - l.m), std::fabs(after - l.m));
  const float side = to_before ? -1.0f : 1.0f;
  const float edge_mean = 0.5f * ((to_before ? before : after) + l.m);

  // Step 4: search both ways along the edge, half a pixel towards that side, where the
  // bilinear fetch reads the mean of the two pixels across the edge.
  const auto sample = [&](float along) {
    const float u = horizontal ? float(x) + along : float(x) + 0.5f * side;
    const float v = horizontal ? float(y) + 0.5f * side : float(y) + along;
    return luma_bilinear(frame, u, v) - edge_mean;
  };
  const float limit = 0.25f * gradient;
  const std::span<const float> steps(params.steps, std::size_t(params.step_count));
  const SearchEnd back = search_edge(steps, limit, [&](float d) { return sample(-d); });
  const SearchEnd ahead = search_edge(steps, limit, sample);

  // The nearer end decides. Its span is good when the luma there lies on the other side of
  // the edge's mean than the pixel's own luma (the edge turns towards this pixel's side):
  // then the pixel is blended by 0.5 - distance / span length, a linear ramp over the span.
  const bool centre_below = l.m - edge_mean < 0.0f;
  const bool back_nearer = back.distance < ahead.distance;
  const SearchEnd& nearer = back_nearer ? back : ahead;
  const bool good_span = (nearer.luma < 0.0f) != centre_below;
  const float span_offset = 0.5f - nearer.distance / (back.distance + ahead.distance);
  const float weight = std::max(good_span ? span_offset : 0.0f, subpix);
  const int step = to_before ? -1 : 1;
  return {horizontal ? 0 : step, horizontal ? step : 0, weight};
}

FxaaKernels fxaa_kernels_scalar() { return {&luma_row_scalar, &filter_rows_scalar}; }

}  // namespace covrast::detail
