// Raster stage, coverage mode: the per-pixel fragment log and its proof (pixel_log.hpp).
#include "raster/coverage/pixel_log.hpp"

#include "core/checks.hpp"
#include "raster/coverage/coverage_kernel.hpp"
#include "raster/coverage/fragment_shading.hpp"

#include <algorithm>
#include <cmath>

namespace covrast::detail {
namespace {

/// SplitMix64's finaliser (Steele, Lea and Flood, "Fast splittable pseudorandom number
/// generators", 2014): every input bit moves every output bit.
std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

std::uint64_t point_bits(std::int64_t x_fx8, std::int64_t y_fx8) {
  return std::uint64_t(std::uint32_t(x_fx8)) << 32 | std::uint32_t(y_fx8);
}

}  // namespace

void EdgeCrossingKeys::set(const TriangleSetup& t) {
  triangle_ = &t;
  // Twice the signed area: > 0 when the vertices turn counter-clockwise in (x, y).
  const std::int64_t area2 = std::int64_t(t.x_fx8[1] - t.x_fx8[0]) * (t.y_fx8[2] - t.y_fx8[0]) -
                             std::int64_t(t.x_fx8[2] - t.x_fx8[0]) * (t.y_fx8[1] - t.y_fx8[0]);
  for (int i = 0; i < 3; ++i) {
    const int j = i == 2 ? 0 : i + 1;
    const std::int64_t xi = t.x_fx8[i], yi = t.y_fx8[i], xj = t.x_fx8[j], yj = t.y_fx8[j];
    Edge& e = edge_[i];
    e.x0_fx8 = xi;
    e.y0_fx8 = yi;
    e.dx_fx8 = xj - xi;
    e.dy_fx8 = yj - yi;
    e.min_x_fx8 = std::min(xi, xj);
    e.max_x_fx8 = std::max(xi, xj);
    e.min_y_fx8 = std::min(yi, yj);
    e.max_y_fx8 = std::max(yi, yj);
    // The edge from its lesser to its greater end point; a counter-clockwise triangle lies on
    // the left of each of its edges as it runs i -> j.
    const bool forward = xi < xj || (xi == xj && yi < yj);
    const std::uint64_t lesser = forward ? point_bits(xi, yi) : point_bits(xj, yj);
    const std::uint64_t greater = forward ? point_bits(xj, yj) : point_bits(xi, yi);
    const std::uint64_t hash = mix64(lesser ^ mix64(greater + 0x9e3779b97f4a7c15ull));
    const bool on_left = forward == (area2 > 0);
    e.key = on_left ? hash : std::uint64_t(0) - hash;
  }
}

std::uint64_t EdgeCrossingKeys::crossing_sum(int x, int y) const {
  const std::int64_t px0 = std::int64_t(x) * kSubpixelOne, px1 = px0 + kSubpixelOne;
  const std::int64_t py0 = std::int64_t(y) * kSubpixelOne, py1 = py0 + kSubpixelOne;
  std::uint64_t sum = 0;
  for (const Edge& e : edge_) {
    if (e.min_x_fx8 >= px1 || e.max_x_fx8 <= px0 || e.min_y_fx8 >= py1 || e.max_y_fx8 <= py0) {
      continue;
    }
    // The edge function dx (y - y0) - dy (x - x0) at the four corners.
    const std::int64_t e00 = e.dx_fx8 * (py0 - e.y0_fx8) - e.dy_fx8 * (px0 - e.x0_fx8);
    const std::int64_t step_x = -e.dy_fx8 * kSubpixelOne, step_y = e.dx_fx8 * kSubpixelOne;
    const std::int64_t e10 = e00 + step_x, e01 = e00 + step_y, e11 = e10 + step_y;
    const std::int64_t lo = std::min(std::min(e00, e10), std::min(e01, e11));
    const std::int64_t hi = std::max(std::max(e00, e10), std::max(e01, e11));
    if (lo < 0 && hi > 0) sum += e.key;
  }
  return sum;
}

std::uint64_t PixelLog::crossing_key(const TriangleSetup& t, std::uint32_t coverage, int x, int y) {
  if (coverage == std::uint32_t(kCoverageOne)) return 0;  // no edge in the pixel
  if (keys_.triangle() != &t) keys_.set(t);
  return keys_.crossing_sum(x, y);
}

PixelLog::PixelLog(std::size_t pixels)
    : state_(pixels, LogState::Off),
      count_(pixels),
      head_(pixels),
      tail_(pixels),
      coverage_sum_(pixels),
      near_z_(pixels),
      convex_(pixels),
      key_sum_(pixels),
      far_(pixels),
      hidden_from_(pixels) {}

void PixelLog::clear_entries() {
  entries_.clear();
  keys_.forget();  // a later tile may hold another triangle at the same address
}

void PixelLog::append(std::size_t pixel, int x, int y, const TriangleSetup& t,
                      std::uint32_t coverage, double centre_z, double reach) {
  COVRAST_CHECK(count_[pixel] < kMaxLoggedFragments, "a pixel logs at most kMaxLoggedFragments");
  const std::uint32_t index = std::uint32_t(entries_.size());
  // The reach rounded up to float, so that the range it gives still holds the plane.
  float reach_up = float(reach);
  if (double(reach_up) < reach) reach_up = std::nextafter(reach_up, INFINITY);
  entries_.push_back(LoggedFragment{&t, centre_z, reach_up, coverage, kLogEnd});
  const int n = count_[pixel];
  if (n == 0) {
    head_[pixel] = index;
    coverage_sum_[pixel] = 0;
    near_z_[pixel] = INFINITY;
    convex_[pixel] = convex_key(t);
    key_sum_[pixel] = 0;
    far_[pixel] = -INFINITY;
    hidden_from_[pixel] = INFINITY;
  } else {
    entries_[tail_[pixel]].next = index;
  }
  tail_[pixel] = index;
  count_[pixel] = std::uint8_t(n + 1);
  if (state_[pixel] != LogState::Open) {
    // After a proven layer: something in front of it. The sums start again for a nearer one.
    if (state_[pixel] == LogState::Proven) restart_sums(pixel);
    state_[pixel] = LogState::Mixed;
    prove_later_layer(pixel, x, y, t, coverage, centre_z + reach);
    return;
  }
  coverage_sum_[pixel] += coverage;
  const bool was_convex = convex_[pixel] != kNotConvex;
  if (convex_[pixel] != convex_key(t)) convex_[pixel] = kNotConvex;
  near_z_[pixel] = std::min(near_z_[pixel], float(centre_z));
  if (convex_[pixel] == kNotConvex) {
    // The keys are needed from the first fragment that is not of the one convex facing on;
    // then those of the fragments before it as well (their triangles are read again).
    if (was_convex && n > 0) {
      std::uint32_t e = head_[pixel];
      for (int i = 0; i < n; ++i, e = entries_[e].next) {
        key_sum_[pixel] += crossing_key(*entries_[e].triangle, entries_[e].coverage, x, y);
      }
    }
    key_sum_[pixel] += crossing_key(t, coverage, x, y);
  }
  far_[pixel] = std::max(far_[pixel], centre_z + reach);
  if (coverage_sum_[pixel] < std::uint32_t(kCoverageOne)) return;
  if (sums_prove_layer(pixel)) {
    state_[pixel] = LogState::Proven;
    hidden_from_[pixel] = far_[pixel];
  } else {
    state_[pixel] = LogState::Mixed;
    restart_sums(pixel);
  }
}

bool PixelLog::sums_prove_layer(std::size_t pixel) const {
  // Pieces of one facing of a convex surface do not overlap (TriangleSetup::convex_surface):
  // reaching the pixel, they cover it, as the list's open set closes. Otherwise the header's
  // proof: a zero key sum and less than 1.5 pixels of area.
  return convex_[pixel] != kNotConvex ||
         (key_sum_[pixel] == 0 && coverage_sum_[pixel] < 3 * std::uint32_t(kCoverageOne) / 2);
}

void PixelLog::restart_sums(std::size_t pixel) {
  coverage_sum_[pixel] = 0;
  key_sum_[pixel] = 0;
  far_[pixel] = -INFINITY;
}

void PixelLog::prove_later_layer(std::size_t pixel, int x, int y, const TriangleSetup& t,
                                 std::uint32_t coverage, double far) {
  const std::uint64_t key = crossing_key(t, coverage, x, y);
  const std::uint32_t convex = convex_key(t);
  if (coverage_sum_[pixel] == 0) {
    convex_[pixel] = convex;  // the run's first fragment
  } else if (convex_[pixel] != convex) {
    convex_[pixel] = kNotConvex;
  }
  coverage_sum_[pixel] += coverage;
  key_sum_[pixel] += key;
  far_[pixel] = std::max(far_[pixel], far);
  if (coverage_sum_[pixel] < std::uint32_t(kCoverageOne)) return;
  if (sums_prove_layer(pixel)) {
    // The run since the last restart tiles the pixel: nothing behind its farthest depth shows.
    hidden_from_[pixel] = std::min(hidden_from_[pixel], far_[pixel]);
    restart_sums(pixel);
    return;
  }
  // No proof: the next run starts with this fragment, which may begin a layer.
  convex_[pixel] = convex;
  coverage_sum_[pixel] = coverage;
  key_sum_[pixel] = key;
  far_[pixel] = far;
}

PixelLog::LayerColor PixelLog::layer_color(std::size_t pixel, int x, int y) const {
  // The running sums of a layer, as the list's open set keeps them (the same order and bits).
  LayerColor sums{{0.0, 0.0, 0.0}, near_z_[pixel]};
  for_each(pixel, [&](const LoggedFragment& f) {
    const glm::vec3 c = shade_fragment(*f.triangle, x, y);
    sums.rgb[0] += double(f.coverage) * c.r;
    sums.rgb[1] += double(f.coverage) * c.g;
    sums.rgb[2] += double(f.coverage) * c.b;
  });
  return sums;
}

std::size_t PixelLog::scratch_bytes() const {
  return state_.size() *
             (sizeof(LogState) + sizeof(std::uint8_t) + 3 * sizeof(std::uint32_t) +
              sizeof(std::uint64_t) + 2 * sizeof(double) + sizeof(float) + sizeof(std::uint32_t)) +
         entries_.capacity() * sizeof(LoggedFragment);
}

}  // namespace covrast::detail
