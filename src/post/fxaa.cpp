// Post-process stage: FXAA 3.11, quality variant; the steps and their formulas are in
// fxaa.hpp and docs/fxaa.md. Written from the published description of the algorithm.
#include "post/fxaa.hpp"

#include "core/srgb8.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace covrast::detail {
namespace {

/// FXAA 3.11's quality presets: the search steps along an edge [pixels]. The last, long step
/// is where the search assumes the edge ends when it has not found the end by then.
struct Preset {
  int id;
  std::array<float, 12> steps;
  int step_count;
};
constexpr std::array<Preset, 17> kPresets{{
    {10, {1.5f, 3.0f, 12.0f}, 3},
    {11, {1.0f, 1.5f, 3.0f, 12.0f}, 4},
    {12, {1.0f, 1.5f, 2.0f, 4.0f, 12.0f}, 5},
    {13, {1.0f, 1.5f, 2.0f, 2.0f, 4.0f, 12.0f}, 6},
    {14, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 4.0f, 12.0f}, 7},
    {15, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 12.0f}, 8},
    {20, {1.5f, 2.0f, 8.0f}, 3},
    {21, {1.0f, 1.5f, 2.0f, 8.0f}, 4},
    {22, {1.0f, 1.5f, 2.0f, 2.0f, 8.0f}, 5},
    {23, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 8.0f}, 6},
    {24, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 3.0f, 8.0f}, 7},
    {25, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 8},
    {26, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 9},
    {27, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 10},
    {28, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 11},
    {29, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 12},
    {39, {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 12},
}};

/// Luma at a pixel, clamped to the frame (a texture's clamp-to-edge addressing).
float luma_at(const LumaPlane& plane, int x, int y) {
  x = std::clamp(x, 0, plane.width - 1);
  y = std::clamp(y, 0, plane.height - 1);
  return plane.luma[std::size_t(y) * plane.width + x];
}

/// Bilinear luma at (u, v) [pixels], pixel (x, y)'s centre at (x, y): what a GPU's filtered
/// fetch returns, with exact weights instead of 8-bit ones.
float luma_bilinear(const LumaPlane& plane, float u, float v) {
  const float x0 = std::floor(u), y0 = std::floor(v);
  const float fx = u - x0, fy = v - y0;
  const int ix = int(x0), iy = int(y0);
  const float top = (1.0f - fx) * luma_at(plane, ix, iy) + fx * luma_at(plane, ix + 1, iy);
  const float bottom =
      (1.0f - fx) * luma_at(plane, ix, iy + 1) + fx * luma_at(plane, ix + 1, iy + 1);
  return (1.0f - fy) * top + fy * bottom;
}

/// The 3x3 luma block around a pixel; n is the row above (y - 1), w the column to the left.
struct Neighbourhood {
  float m, n, s, w, e;
  float nw, ne, sw, se;
};

/// The cross first (the contrast test needs only it), the corners once a pixel passes.
Neighbourhood cross(const LumaPlane& plane, int x, int y) {
  Neighbourhood l{};
  l.m = luma_at(plane, x, y);
  l.n = luma_at(plane, x, y - 1);
  l.s = luma_at(plane, x, y + 1);
  l.w = luma_at(plane, x - 1, y);
  l.e = luma_at(plane, x + 1, y);
  return l;
}

void add_corners(const LumaPlane& plane, int x, int y, Neighbourhood& l) {
  l.nw = luma_at(plane, x - 1, y - 1);
  l.ne = luma_at(plane, x + 1, y - 1);
  l.sw = luma_at(plane, x - 1, y + 1);
  l.se = luma_at(plane, x + 1, y + 1);
}

/// Step 1: the local contrast test on the cross; the range of its lumas when the pixel passes,
/// else 0. (A flat cross has range 0: skipped even when both thresholds are 0.)
float passing_range(float m, float n, float s, float w, float e, const FxaaOptions& options) {
  const float max_luma = std::max(std::max(std::max(m, n), std::max(s, w)), e);
  const float range = max_luma - std::min(std::min(std::min(m, n), std::min(s, w)), e);
  const float needed = std::max(options.edge_threshold_min, max_luma * options.edge_threshold);
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

/// sRGB byte -> linear light, for the blend (IEC 61966-2-1, computed once in double).
const std::array<float, 256>& srgb8_linear() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int k = 0; k < 256; ++k) {
      const double e = k / 255.0;
      t[k] = float(e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

/// Step 5: out = (1 - w) centre + w neighbour, in linear light (what a filtered fetch from an
/// sRGB texture at the offset position returns), then the exact 8-bit encode.
void blend_pixel(const Image& input, int x, int y, const FxaaBlend& blend, std::uint8_t* out) {
  const std::uint8_t* centre = input.pixel(x, y);
  if (blend.weight == 0.0f) {
    std::copy(centre, centre + 3, out);
    return;
  }
  const std::array<float, 256>& linear = srgb8_linear();
  // The neighbour is inside the frame (clamped, as the luma fetches are).
  const std::uint8_t* other = input.pixel(std::clamp(x + blend.dx, 0, input.width - 1),
                                          std::clamp(y + blend.dy, 0, input.height - 1));
  for (int c = 0; c < 3; ++c) {
    const float mixed = (1.0f - blend.weight) * linear[centre[c]] + blend.weight * linear[other[c]];
    out[c] = encode_srgb8(mixed);
  }
}

}  // namespace

std::span<const float> fxaa_search_steps(int quality_preset) {
  for (const Preset& p : kPresets) {
    if (p.id == quality_preset) return {p.steps.data(), std::size_t(p.step_count)};
  }
  return {};
}

float fxaa_luma(const std::uint8_t* rgb) {
  // Integer weights, then one division: white is exactly 1, and the value is exact to
  // float rounding whatever the compiler.
  const int weighted = 299 * rgb[0] + 587 * rgb[1] + 114 * rgb[2];
  return float(weighted) / 255000.0f;
}

void fxaa_luma_rows(const Image& image, LumaPlane& plane, int y_begin, int y_end) {
  for (int y = y_begin; y < y_end; ++y) {
    for (int x = 0; x < image.width; ++x) {
      plane.luma[std::size_t(y) * image.width + x] = fxaa_luma(image.pixel(x, y));
    }
  }
}

FxaaBlend fxaa_pixel_blend(const LumaPlane& plane, int x, int y, const FxaaOptions& options,
                           std::span<const float> steps) {
  Neighbourhood l = cross(plane, x, y);
  const float range = passing_range(l.m, l.n, l.s, l.w, l.e, options);
  if (range == 0.0f) return {};
  add_corners(plane, x, y, l);

  const bool horizontal = edge_is_horizontal(l);
  const float subpix = subpixel_weight(l, range, options.subpix);
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
    return luma_bilinear(plane, u, v) - edge_mean;
  };
  const float limit = 0.25f * gradient;
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

void fxaa_rows(const Image& input, const LumaPlane& plane, const FxaaOptions& options,
               Image& output, int y_begin, int y_end) {
  const std::span<const float> steps = fxaa_search_steps(options.quality_preset);
  for (int y = y_begin; y < y_end; ++y) {
    // Most pixels fail the contrast test, most of them with a flat cross: test them here on
    // the luma rows (clamped at the frame's border), the others go through fxaa_pixel_blend.
    const float* above = &plane.luma[std::size_t(std::max(y - 1, 0)) * plane.width];
    const float* row = &plane.luma[std::size_t(y) * plane.width];
    const float* below = &plane.luma[std::size_t(std::min(y + 1, plane.height - 1)) * plane.width];
    // Start from the input row; only the pixels FXAA blends are rewritten.
    std::copy(input.pixel(0, y), input.pixel(0, y) + 3 * std::size_t(input.width),
              output.pixel(0, y));
    for (int x = 0; x < input.width; ++x) {
      const int left = std::max(x - 1, 0), right = std::min(x + 1, input.width - 1);
      const float m = row[x];
      if (m == above[x] && m == below[x] && m == row[left] && m == row[right]) continue;
      if (passing_range(m, above[x], below[x], row[left], row[right], options) == 0.0f) continue;
      blend_pixel(input, x, y, fxaa_pixel_blend(plane, x, y, options, steps), output.pixel(x, y));
    }
  }
}

Image fxaa(const Image& input, const FxaaOptions& options) {
  if (fxaa_search_steps(options.quality_preset).empty()) {
    throw InputError("unknown FXAA quality preset " + std::to_string(options.quality_preset));
  }
  LumaPlane plane{input.width, input.height, std::vector<float>(input.rgb.size() / 3)};
  fxaa_luma_rows(input, plane, 0, input.height);
  Image output{input.width, input.height, std::vector<std::uint8_t>(input.rgb.size())};
  fxaa_rows(input, plane, options, output, 0, input.height);
  return output;
}

}  // namespace covrast::detail
