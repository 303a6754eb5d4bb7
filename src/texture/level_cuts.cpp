// The geometry of an exact texture average on one level, cut directly or kept for the next
// texture on the same polygon (level_cuts.hpp).
#include "texture/level_cuts.hpp"

#include <algorithm>
#include <cstring>

namespace covrast::detail {

Moments moments(const ConvexPolygon& q, double s0, double t0) {
  Moments m;
  for (int i = 0; i < q.n; ++i) {
    const int j = i + 1 == q.n ? 0 : i + 1;
    const double ai = q.x[i] - s0, bi = q.y[i] - t0, aj = q.x[j] - s0, bj = q.y[j] - t0;
    const double c = ai * bj - aj * bi;
    m.m1 += c;
    m.ma += (ai + aj) * c;
    m.mb += (bi + bj) * c;
    m.mab += (2.0 * ai * bi + ai * bj + aj * bi + 2.0 * aj * bj) * c;
  }
  m.m1 *= 1.0 / 2.0;
  m.ma *= 1.0 / 6.0;
  m.mb *= 1.0 / 6.0;
  m.mab *= 1.0 / 24.0;
  return m;
}

void LevelPolygon::set(int width, int height, const ConvexPolygon& uv, int order) {
  set_cells(width, height, uv, order);
  whole = fits ? moments(p, double(i0), double(j0)) : Moments{};
}

void LevelPolygon::set_cells(int width, int height, const ConvexPolygon& uv, int order) {
  p.n = uv.n;
  double s_min = HUGE_VAL, t_min = HUGE_VAL, s_max = -HUGE_VAL, t_max = -HUGE_VAL;
  for (int i = 0; i < uv.n; ++i) {
    p.x[i] = uv.x[i] * width - 0.5 * order;
    p.y[i] = uv.y[i] * height - 0.5 * order;
    s_min = std::min(s_min, p.x[i]);
    s_max = std::max(s_max, p.x[i]);
    t_min = std::min(t_min, p.y[i]);
    t_max = std::max(t_max, p.y[i]);
  }
  i0 = texel_floor(s_min);
  j0 = texel_floor(t_min);
  const long long i1 = texel_floor(s_max), j1 = texel_floor(t_max);
  fits = p.n >= 3 && i1 - i0 < kMaxCells && j1 - j0 < kMaxCells &&
         (i1 - i0 + 1) * (j1 - j0 + 1) <= kMaxCells;
  columns = fits ? int(i1 - i0) + 1 : 0;
  rows = fits ? int(j1 - j0) + 1 : 0;
}

void LevelCuts::reset(int width, int height, const ConvexPolygon& uv, int order) {
  uv_.n = uv.n;
  std::memcpy(uv_.x, uv.x, sizeof(double) * std::size_t(uv.n));
  std::memcpy(uv_.y, uv.y, sizeof(double) * std::size_t(uv.n));
  width_ = width;
  height_ = height;
  order_ = order;
  at_.set(width, height, uv, order);
  std::fill_n(column_state_.begin(), at_.columns, kUnknown);
  std::fill_n(piece_state_.begin(), at_.columns * at_.rows, kUnknown);
}

bool LevelCuts::matches(int width, int height, const ConvexPolygon& uv, int order) const {
  // Bits, not values: the geometry is a function of the bits (and NaN never equals itself).
  return width == width_ && height == height_ && order == order_ && uv.n == uv_.n &&
         std::memcmp(uv.x, uv_.x, sizeof(double) * std::size_t(uv.n)) == 0 &&
         std::memcmp(uv.y, uv_.y, sizeof(double) * std::size_t(uv.n)) == 0;
}

const ConvexPolygon* LevelCuts::cut_and_keep_column(int ps) {
  const bool cut = detail::cut_column(at_, ps, column_[std::size_t(ps)]);
  column_state_[std::size_t(ps)] = cut ? kCut : kEmpty;
  return cut ? &column_[std::size_t(ps)] : nullptr;
}

const Moments* LevelCuts::cut_and_keep_piece(int ps, int pt) {
  const ConvexPolygon* column = ps == 0 ? &at_.p : this->column(ps);
  COVRAST_CHECK(column != nullptr, "a piece of a column that is not empty");
  const std::size_t k = std::size_t(ps * at_.rows + pt);
  const bool cut = detail::cut_piece(at_, *column, ps, pt, piece_[k]);
  piece_state_[k] = cut ? kCut : kEmpty;
  return cut ? &piece_[k] : nullptr;
}

LevelCutsMemo& LevelCutsMemo::of_this_thread() {
  thread_local LevelCutsMemo memo;
  return memo;
}

LevelCuts& LevelCutsMemo::get(int width, int height, const ConvexPolygon& uv, int order) {
  for (int i = 1; i <= kEntries; ++i) {
    LevelCuts& entry = entries_[std::size_t((next_ + kEntries - i) % kEntries)];
    if (entry.matches(width, height, uv, order)) {
      ++hits_;
      return entry;
    }
  }
  ++misses_;
  LevelCuts& entry = entries_[std::size_t(next_)];
  next_ = (next_ + 1) % kEntries;
  entry.reset(width, height, uv, order);
  return entry;
}

}  // namespace covrast::detail
