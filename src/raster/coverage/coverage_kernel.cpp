// Raster stage, coverage mode: the SIMD column set-up and kernel, one source compiled for
// every Highway target and picked at run time: SetupColumnGroup and CoverageRows
// separately, and CoverGroup, the two fused for one column group (the product's path: one
// dispatch per group, the set-up kept in registers for the rows). They give the bits of
// setup_column_group_scalar and coverage_rows_scalar (coverage_setup.cpp): the set-up
// mirrors it operation for operation (no FMA, round to nearest even, true division), and
// the row math (EdgeTerm) reorders only where the result is provably the same bits (see
// there); tests/test_coverage_kernel.cpp checks every target this CPU has.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/coverage/coverage_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "raster/coverage/coverage_kernel.hpp"

#include <climits>
#include <type_traits>

HWY_BEFORE_NAMESPACE();
namespace covrast::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The set-up runs on doubles, at most half a group per vector (the columns past the
// triangle's are skipped in such chunks: most small triangles span at most 4 columns); its
// float results have the same lane count (DH). The rows run on float vectors of at most
// one group (DF): two DH vectors combined, or DH itself where it holds as many lanes.
using DD = hn::CappedTag<double, kColumnGroup / 2>;
using DH = hn::Rebind<float, DD>;
inline constexpr bool kCombine =
    hn::MaxLanes(DH()) < hn::MaxLanes(hn::CappedTag<float, kColumnGroup>());
using DF = std::conditional_t<kCombine, hn::Twice<DH>, DH>;
using VD = hn::Vec<DD>;
using VH = hn::Vec<DH>;
using VF = hn::Vec<DF>;
using DI = hn::RebindToSigned<DF>;
using VI = hn::Vec<DI>;

/// The group's rows as the union over its columns (double lanes, reduced at the end).
struct RowBounds {
  VD first, end, interior_begin, interior_end;
};

/// One edge of one chunk of columns, as setup_column computes it (lanes whose piece is
/// empty hold exact zeros): t_left, t_right, width_q, |t_right - t_left| and base_row.
struct ChunkEdge {
  VH tl, tr, wq, adt;
  VD base;
};

/// setup_column (coverage_setup.cpp) on the columns [col + j, col + j + Lanes(DD)): the
/// same double operations in the same order (separate Mul/Add, no FMA), then the row
/// bookkeeping as lane-wise min/max. Lanes whose piece of an edge is empty (xl >= xr, or a
/// lane past `lanes`) get exact zeros and contribute the identities INT_MAX / INT_MIN,
/// exactly as the scalar loop skips them. Row numbers stay in double until the end: they
/// are integers far inside int32, so min/max are exact.
HWY_INLINE void SetupChunk(const CoverageTriangle& tri, int col, int lanes, std::size_t j,
                           ChunkEdge (&out)[3], RowBounds& rows) {
  const DD dd;
  const DH dh;
  const auto one = hn::Set(dd, 1.0);
  const auto qone = hn::Set(dd, double(kCoverageOne));
  const auto int_max = hn::Set(dd, double(INT_MAX));
  const auto int_min = hn::Set(dd, double(INT_MIN));
  const auto cl = hn::Iota(dd, double(col) + double(j));  // exact: small integers
  const auto cr = hn::Add(cl, one);
  const auto inside = hn::Lt(cl, hn::Set(dd, double(col + lanes)));
  // ac is the top edge when sign < 0, else ab and bc are.
  const bool ac_top = tri.sign < 0;
  // Per edge: the row band's first row (floor of the upper end), one past its last row
  // (ceil of the lower end), both INT_MAX / INT_MIN where the piece is empty.
  VD band_first[3], band_end[3], column_end = int_min;
  auto column_first = int_max;
  for (int e = 0; e < 3; ++e) {
    const CoverageEdge& edge = tri.edge[e];
    const auto x0 = hn::Set(dd, edge.x0), x1 = hn::Set(dd, edge.x1);
    const auto y0 = hn::Set(dd, edge.y0), slope = hn::Set(dd, edge.slope);
    const auto xl = hn::Max(cl, x0), xr = hn::Min(cr, x1);
    const auto valid = hn::And(hn::Lt(xl, xr), inside);
    const auto yl =
        hn::IfThenElse(hn::Eq(xl, x0), y0, hn::Add(y0, hn::Mul(hn::Sub(xl, x0), slope)));
    const auto yr = hn::IfThenElse(hn::Eq(xr, x1), hn::Set(dd, edge.y1),
                                   hn::Add(y0, hn::Mul(hn::Sub(xr, x0), slope)));
    const auto base = hn::Floor(hn::Min(yl, yr));
    const auto ceil_max = hn::Ceil(hn::Max(yl, yr));
    ChunkEdge& o = out[e];
    o.tl = hn::DemoteTo(dh, hn::IfThenElseZero(valid, hn::Sub(yl, base)));
    o.tr = hn::DemoteTo(dh, hn::IfThenElseZero(valid, hn::Sub(yr, base)));
    o.wq = hn::DemoteTo(dh, hn::IfThenElseZero(valid, hn::Mul(qone, hn::Sub(xr, xl))));
    o.adt = hn::Abs(hn::Sub(o.tr, o.tl));
    o.base = hn::IfThenElseZero(valid, base);
    band_first[e] = hn::IfThenElse(valid, base, int_max);
    band_end[e] = hn::IfThenElse(valid, ceil_max, int_min);
    column_first = hn::Min(column_first, band_first[e]);
    // The band covers at least one row: max(band_end, band_first + 1).
    column_end =
        hn::Max(column_end, hn::IfThenElse(valid, hn::Max(ceil_max, hn::Add(base, one)), int_min));
  }
  // Interior: below every top edge's band, above every bottom edge's band.
  const auto interior_begin = ac_top ? band_end[0] : hn::Max(band_end[1], band_end[2]);
  const auto interior_end =
      hn::Max(interior_begin, ac_top ? hn::Min(band_first[1], band_first[2]) : band_first[0]);
  // Columns no edge touches hold the identities of min/max here, as the scalar loop skips
  // them: first = INT_MAX, end = INT_MIN, interior_begin = INT_MIN, interior_end = INT_MAX.
  rows.first = hn::Min(rows.first, column_first);
  rows.end = hn::Max(rows.end, column_end);
  rows.interior_begin = hn::Max(rows.interior_begin, interior_begin);
  rows.interior_end = hn::Min(rows.interior_end, interior_end);
}

HWY_INLINE RowBounds EmptyRowBounds() {
  const DD dd;
  const auto int_max = hn::Set(dd, double(INT_MAX));
  const auto int_min = hn::Set(dd, double(INT_MIN));
  return RowBounds{int_max, int_min, int_min, int_max};
}

HWY_INLINE GroupRows ReduceRows(const RowBounds& rows, int row_min, int row_max) {
  const DD dd;
  return clip_group_rows(int(hn::GetLane(hn::MinOfLanes(dd, rows.first))),
                         int(hn::GetLane(hn::MaxOfLanes(dd, rows.end))),
                         int(hn::GetLane(hn::MaxOfLanes(dd, rows.interior_begin))),
                         int(hn::GetLane(hn::MinOfLanes(dd, rows.interior_end))), row_min, row_max);
}

/// One edge of one row's columns, prepared for EdgeTerm: the piece's ends relative to
/// base_row sorted (lo_t <= hi_t), and width_q, |slope_q| with the edge's sign in the
/// coverage folded in.
struct RowEdge {
  VF lo_t, hi_t, wq, slope;
};

#if HWY_ARCH_X86 && HWY_TARGET <= HWY_SSSE3
// cvtps2dq rounds to nearest even (the default MXCSR mode, which std::nearbyint uses too).
HWY_INLINE __m128i RoundToInt32(__m128 v) { return _mm_cvtps_epi32(v); }
#if HWY_TARGET <= HWY_AVX2
HWY_INLINE __m256i RoundToInt32(__m256 v) { return _mm256_cvtps_epi32(v); }
#endif
#endif

/// hn::NearestInt without its fix-up of values outside int32, which EdgeTerm's areas never
/// are: |area| <= |width_q| <= 65280 in the simple branch, else |width_q| / |dt| times
/// |H(hi) - H(lo)| <= |dt| + 6 ulp, the ulps bounding the rounding of lo, hi and H, so
/// |area| < 65280 * (1 + 12 * 1024) < 2^30 (|t|, |k| < 2^24: ulp <= 2; |dt| >= 1 / 1024).
HWY_INLINE VI RoundArea(VF area) {
#if HWY_ARCH_X86 && HWY_TARGET <= HWY_SSSE3
  return VI{RoundToInt32(area.raw)};
#else
  return hn::NearestInt(area);
#endif
}

/// `m` * q_e of coverage_rows_scalar, m = +1 or -1 the edge's sign in
/// coverage = sign * (q_ac - q_ab - q_bc), for rows at k = r - base_row (exact integers).
/// The same bits as the scalar twin, with fewer operations:
///  - lo = lo_t - k, hi = hi_t - k are min(a, b), max(a, b): rounding is monotone.
///  - (H(hi) - H(lo)) * |slope_q| is (H(b) - H(a)) * slope_q: swapping a and b negates
///    both factors exactly (and wq / |dt| is |wq / dt|, wq >= 0); mid is symmetric.
///  - m * area, with m folded into wq and |slope_q|, rounds to m * q: negation is exact
///    and round-to-nearest-even is symmetric.
///  - the scalar test `hi <= 0` is dropped: then H(hi) = H(lo) = 0 and mid = 0, so both
///    branches give a zero area.
HWY_INLINE VI EdgeTerm(const RowEdge& edge, VF k) {
  const DF df;
  const auto zero = hn::Zero(df);
  const auto one = hn::Set(df, 1.0f);
  const auto half = hn::Set(df, 0.5f);
  // lo, hi = the edge's y at the piece ends relative to row r, sorted.
  const auto lo = hn::Sub(edge.lo_t, k);
  const auto hi = hn::Sub(edge.hi_t, k);
  const auto simple = hn::Or(hn::Or(hn::Ge(lo, one), hn::And(hn::Ge(lo, zero), hn::Le(hi, one))),
                             hn::Lt(hn::Sub(hi, lo), hn::Set(df, kFlatEdgeEps)));
  const auto mid = hn::Min(hn::Max(hn::Mul(hn::Add(lo, hi), half), zero), one);
  const auto clo = hn::Min(hn::Max(lo, zero), one);
  const auto chi = hn::Min(hn::Max(hi, zero), one);
  // H(t) = clamp(t, 0, 1)^2 / 2 + max(t - 1, 0)
  const auto hlo = hn::Add(hn::Mul(hn::Mul(clo, clo), half), hn::Max(hn::Sub(lo, one), zero));
  const auto hhi = hn::Add(hn::Mul(hn::Mul(chi, chi), half), hn::Max(hn::Sub(hi, one), zero));
  const auto area =
      hn::IfThenElse(simple, hn::Mul(edge.wq, mid), hn::Mul(hn::Sub(hhi, hlo), edge.slope));
  return RoundArea(area);
}

/// Edge e's factor m (as a sign bit to xor in): ac counts with `sign`, ab and bc against.
HWY_INLINE VF EdgeSignBit(int e, int sign) {
  const DF df;
  return hn::Set(df, (e == 0) == (sign > 0) ? 0.0f : -0.0f);
}

/// Stores the coverage of rows [row_begin, row_end) of one chunk of columns, out at row
/// row_begin, except rows [fill_begin, fill_end) (inside [row_begin, row_end]; none when
/// fill_begin >= row_end), which get `fill`: the interior run.
HWY_INLINE void ChunkRows(const RowEdge (&edge)[3], const VF (&base)[3], int row_begin, int row_end,
                          int fill_begin, int fill_end, hn::Vec<hn::Rebind<std::uint16_t, DF>> fill,
                          std::uint16_t* out, std::size_t stride) {
  const DF df;
  const DI di;
  const hn::Rebind<std::uint16_t, DF> du16;
  const auto one = hn::Set(df, 1.0f);
  const auto full = hn::Set(di, kCoverageOne);
  // k = r - base_row, kept in float and stepped by 1 (or over the fill): exact, rows and
  // base rows are integers below 2^23 (24.8 fixed point), so |k| < 2^24.
  const auto row = hn::Set(df, float(row_begin));
  VF k[3] = {hn::Sub(row, base[0]), hn::Sub(row, base[1]), hn::Sub(row, base[2])};
  for (int r = row_begin; r < row_end; ++r, out += stride) {
    if (r == fill_begin) {
      for (; r < fill_end; ++r, out += stride) hn::StoreU(fill, du16, out);
      const auto step = hn::Set(df, float(fill_end - fill_begin));
      for (int e = 0; e < 3; ++e) k[e] = hn::Add(k[e], step);
      if (r == row_end) break;
    }
    const auto cov =
        hn::Add(hn::Add(EdgeTerm(edge[0], k[0]), EdgeTerm(edge[1], k[1])), EdgeTerm(edge[2], k[2]));
    // clamp(cov, 0, kCoverageOne): the demotion saturates negative values to 0.
    hn::StoreU(hn::DemoteTo(du16, hn::Min(cov, full)), du16, out);
    for (int e = 0; e < 3; ++e) k[e] = hn::Add(k[e], one);
  }
}

/// One vector of the rows from the set-up's: `lo` itself, or `lo` and `hi` joined where a
/// double vector holds half as many lanes (the call is unqualified so that targets without
/// Combine never look it up).
template <class D, class V>
HWY_INLINE hn::Vec<D> Join(D d, V hi, V lo) {
  if constexpr (std::is_same_v<V, hn::Vec<D>>) {
    (void)d;
    (void)hi;
    return lo;
  } else {
    return Combine(d, hi, lo);
  }
}

/// RowEdge from the set-up's values (t_left, t_right, width_q, |t_right - t_left|).
HWY_INLINE RowEdge MakeRowEdge(VF tl, VF tr, VF wq, VF adt, VF sign_bit) {
  const DF df;
  const auto slope = hn::IfThenElseZero(hn::Ge(adt, hn::Set(df, kFlatEdgeEps)), hn::Div(wq, adt));
  return RowEdge{hn::Min(tl, tr), hn::Max(tl, tr), hn::Xor(wq, sign_bit), hn::Xor(slope, sign_bit)};
}

void CoverageRows(const CoverageColumns& columns, int col, int row_begin, int row_end, int sign,
                  std::uint16_t* out, std::size_t stride) {
  const DF df;
  const DI di;
  for (std::size_t j = 0; j < std::size_t(kColumnGroup); j += hn::Lanes(df)) {
    const std::size_t c = std::size_t(col) + j;
    RowEdge edge[3];
    VF base[3];
    for (int e = 0; e < 3; ++e) {
      const auto sign_bit = EdgeSignBit(e, sign);
      const auto wq = hn::LoadU(df, &columns.width_q[e][c]);
      const auto tl = hn::LoadU(df, &columns.t_left[e][c]);
      const auto tr = hn::LoadU(df, &columns.t_right[e][c]);
      // |slope_q| pairs with the sorted ends because slope_q has the sign of
      // t_right - t_left (wq / (t_right - t_left), wq >= 0), as the set-up stores it.
      const auto slope = hn::Abs(hn::LoadU(df, &columns.slope_q[e][c]));
      edge[e] = RowEdge{hn::Min(tl, tr), hn::Max(tl, tr), hn::Xor(wq, sign_bit),
                        hn::Xor(slope, sign_bit)};
      base[e] = hn::ConvertTo(df, hn::LoadU(di, &columns.base_row[e][c]));
    }
    ChunkRows(edge, base, row_begin, row_end, row_end, row_end,
              hn::Zero(hn::Rebind<std::uint16_t, DF>()), out + j, stride);
  }
}

GroupRows SetupColumnGroup(const CoverageTriangle& tri, int col, int lanes, int row_min,
                           int row_max, CoverageColumns& columns) {
  const DD dd;
  const DH dh;
  const hn::Rebind<std::int32_t, DD> di;
  const auto eps = hn::Set(dh, kFlatEdgeEps);
  RowBounds rows = EmptyRowBounds();
  for (std::size_t j = 0; j < std::size_t(kColumnGroup); j += hn::Lanes(dd)) {
    ChunkEdge edge[3];
    SetupChunk(tri, col, lanes, j, edge, rows);
    for (int e = 0; e < 3; ++e) {
      const ChunkEdge& o = edge[e];
      // The float division is a true division, as the scalar twin's.
      const auto dt = hn::Sub(o.tr, o.tl);
      hn::StoreU(o.tl, dh, &columns.t_left[e][j]);
      hn::StoreU(o.tr, dh, &columns.t_right[e][j]);
      hn::StoreU(o.wq, dh, &columns.width_q[e][j]);
      hn::StoreU(hn::IfThenElseZero(hn::Ge(o.adt, eps), hn::Div(o.wq, dt)), dh,
                 &columns.slope_q[e][j]);
      hn::StoreU(hn::DemoteTo(di, o.base), di, &columns.base_row[e][j]);
    }
  }
  return ReduceRows(rows, row_min, row_max);
}

GroupRows CoverGroup(const CoverageTriangle& tri, int col, int lanes, int row_min, int row_max,
                     std::uint16_t* out, std::size_t stride) {
  const DD dd;
  const DH dh;
  const DF df;
  const DI di;
  const hn::Rebind<std::uint16_t, DF> du16;
  constexpr std::size_t kChunkLanes = hn::MaxLanes(DF());
  constexpr std::size_t kChunks = std::size_t(kColumnGroup) / kChunkLanes;
  // The whole group's set-up first (its rows are needed before any row), kept in registers.
  RowBounds bounds = EmptyRowBounds();
  RowEdge edge[kChunks][3];
  VF base[kChunks][3], width_ac[kChunks];
  for (std::size_t c = 0; c < kChunks; ++c) {
    // Chunks past `lanes` are zeros without rows, as SetupChunk would make them.
    const ChunkEdge none = {hn::Zero(dh), hn::Zero(dh), hn::Zero(dh), hn::Zero(dh), hn::Zero(dd)};
    ChunkEdge lo[3] = {none, none, none}, hi[3] = {none, none, none};
    const std::size_t j = c * kChunkLanes;
    if (j < std::size_t(lanes)) SetupChunk(tri, col, lanes, j, lo, bounds);
    if (kCombine && j + hn::Lanes(dd) < std::size_t(lanes)) {
      SetupChunk(tri, col, lanes, j + hn::Lanes(dd), hi, bounds);
    }
    for (int e = 0; e < 3; ++e) {
      const VF tl = Join(df, hi[e].tl, lo[e].tl), tr = Join(df, hi[e].tr, lo[e].tr);
      const VF wq = Join(df, hi[e].wq, lo[e].wq), adt = Join(df, hi[e].adt, lo[e].adt);
      edge[c][e] = MakeRowEdge(tl, tr, wq, adt, EdgeSignBit(e, tri.sign));
      // exact: |base| < 2^23
      base[c][e] = Join(df, hn::DemoteTo(dh, hi[e].base), hn::DemoteTo(dh, lo[e].base));
      if (e == 0) width_ac[c] = wq;
    }
  }
  const GroupRows rows = ReduceRows(bounds, row_min, row_max);
  if (rows.empty()) return rows;
  // The interior run, if any, is filled with the long edge's width_q.
  const bool interior = rows.interior_begin < rows.interior_end;
  const int fill_begin = interior ? rows.interior_begin : rows.end;
  const int fill_end = interior ? rows.interior_end : rows.end;
  for (std::size_t c = 0; c < kChunks; ++c) {
    ChunkRows(edge[c], base[c], rows.first, rows.end, fill_begin, fill_end,
              hn::DemoteTo(du16, hn::ConvertTo(di, width_ac[c])),
              out + std::size_t(rows.first - row_min) * stride + c * kChunkLanes, stride);
  }
  return rows;
}

}  // namespace covrast::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace covrast::detail {

HWY_EXPORT(CoverageRows);
HWY_EXPORT(SetupColumnGroup);
HWY_EXPORT(CoverGroup);

GroupRows setup_column_group(const CoverageTriangle& tri, int col, int lanes, int row_min,
                             int row_max, CoverageColumns& columns) {
  return HWY_DYNAMIC_DISPATCH(SetupColumnGroup)(tri, col, lanes, row_min, row_max, columns);
}

void coverage_rows_simd(const CoverageColumns& columns, int col, int row_begin, int row_end,
                        int sign, std::uint16_t* out, std::size_t stride) {
  HWY_DYNAMIC_DISPATCH(CoverageRows)(columns, col, row_begin, row_end, sign, out, stride);
}

GroupRows cover_group_simd(const CoverageTriangle& tri, int col, int lanes, int row_min,
                           int row_max, std::uint16_t* out, std::size_t stride) {
  return HWY_DYNAMIC_DISPATCH(CoverGroup)(tri, col, lanes, row_min, row_max, out, stride);
}

}  // namespace covrast::detail
#endif
