// Post-process stage, FXAA: the SIMD row kernels (fxaa_kernel.hpp), one source compiled for
// every Highway target; the best is picked at run time. Each lane does the scalar twin's IEEE
// operations in its order (fxaa_kernel_scalar.cpp), so every target gives the same bits:
//   - luma row: N pixels per vector (LoadInterleaved3 of the bytes, int32 sums, one division);
//   - filter rows: the contrast test on N pixels per vector (plain loads inside a row, clamped
//     gathers at its ends), the passing pixels' (x, y) compressed into a list carried over the
//     band's rows; then the list N candidates per vector: the 3x3 block, direction and
//     sub-pixel weight, both searches along the edge (bilinear fetches by gather, a lane
//     stopping when its own search ends, the vector when all have), the blend in linear light
//     and the exact sRGB encode by gathers from encode_srgb8's tables.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "post/fxaa_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "color/srgb8.hpp"
#include "post/fxaa_kernel.hpp"

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

HWY_BEFORE_NAMESPACE();
namespace covrast::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using VF = hn::Vec<DF>;
using DU = hn::RebindToUnsigned<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using MF = hn::Mask<DF>;

// PixelBytes reads a pixel's bytes as one little-endian word.
static_assert(std::endian::native == std::endian::little);

/// Most float lanes of any target (2048-bit vectors): the slack of the stack buffers below.
constexpr int kMaxLanes = 64;

/// std::max(a, b) and std::min(a, b) lane by lane: a < b ? b : a and b < a ? b : a (the
/// max and min instructions pick differently between +0 and -0).
HWY_INLINE VF StdMax(VF a, VF b) { return hn::IfThenElse(hn::Lt(a, b), b, a); }
HWY_INLINE VF StdMin(VF a, VF b) { return hn::IfThenElse(hn::Lt(b, a), b, a); }

HWY_INLINE VI Clamp(VI v, VI lo, VI hi) { return hn::Min(hn::Max(v, lo), hi); }

/// luma = float(299 r + 587 g + 114 b) / 255000 for N pixels at `rgb`.
HWY_INLINE VF LumaOf(const std::uint8_t* HWY_RESTRICT rgb) {
  const DF df;
  const DI di;
  const hn::Rebind<std::uint8_t, DF> d8;
  hn::Vec<decltype(d8)> r, g, b;
  hn::LoadInterleaved3(d8, rgb, r, g, b);
  const VI weighted = hn::Add(hn::Add(hn::Mul(hn::Set(di, 299), hn::PromoteTo(di, r)),
                                      hn::Mul(hn::Set(di, 587), hn::PromoteTo(di, g))),
                              hn::Mul(hn::Set(di, 114), hn::PromoteTo(di, b)));
  return hn::Div(hn::ConvertTo(df, weighted), hn::Set(df, 255000.0f));
}

void LumaRow(const std::uint8_t* HWY_RESTRICT rgb, int width, float* HWY_RESTRICT luma) {
  const DF df;
  const int n = int(hn::Lanes(df));
  int x = 0;
  for (; x + n <= width; x += n) hn::StoreU(LumaOf(rgb + 3 * std::size_t(x)), df, luma + x);
  if (x < width) {
    // The last pixels through a buffer, so that no load or store leaves the row.
    std::uint8_t bytes[3 * kMaxLanes] = {};
    HWY_ALIGN float out[kMaxLanes];
    const int rest = width - x;
    std::memcpy(bytes, rgb + 3 * std::size_t(x), 3 * std::size_t(rest));
    hn::Store(LumaOf(bytes), df, out);
    std::memcpy(luma + x, out, sizeof(float) * std::size_t(rest));
  }
}

/// Step 1 on N pixels: the range of the cross > 0 and >= max(edge_threshold_min,
/// max * edge_threshold).
HWY_INLINE MF Passes(VF m, VF n, VF s, VF w, VF e, VF edge_threshold_min, VF edge_threshold) {
  const DF df;
  const VF max_luma = StdMax(StdMax(StdMax(m, n), StdMax(s, w)), e);
  const VF range = hn::Sub(max_luma, StdMin(StdMin(StdMin(m, n), StdMin(s, w)), e));
  const VF needed = StdMax(edge_threshold_min, hn::Mul(max_luma, edge_threshold));
  return hn::And(hn::Gt(range, hn::Zero(df)), hn::Ge(range, needed));
}

/// encode_srgb8 lane by lane, from its tables.
HWY_INLINE VI EncodeSrgb8(VF x, const Srgb8EncodeTables& tables) {
  const DF df;
  const DI di;
  const MF inside = hn::And(hn::Gt(x, hn::Zero(df)), hn::Lt(x, hn::Set(df, 1.0f)));
  // Lanes outside (0, 1) look up bucket 0 and are replaced below.
  const VF xin = hn::IfThenElseZero(inside, x);
  VI code = hn::GatherIndex(di, tables.start,
                            hn::ConvertTo(di, hn::Mul(xin, hn::Set(df, float(kSrgb8Buckets)))));
  for (;;) {
    const MF step = hn::And(inside, hn::Le(hn::GatherIndex(df, tables.threshold, code), xin));
    if (hn::AllFalse(df, step)) break;
    code = hn::Sub(code, hn::VecFromMask(di, hn::RebindMask(di, step)));  // + 1 where stepping
  }
  const VI zero = hn::Zero(di);
  return hn::IfThenElse(hn::RebindMask(di, hn::Ge(x, hn::Set(df, 1.0f))), hn::Set(di, 255),
                        hn::IfThenElse(hn::RebindMask(di, inside), code, zero));
}

/// The 3 bytes of each lane's pixel (an index into the frame) in the low 24 bits: one 32-bit
/// gather at byte 3 p, or at 3 p - 1 (then shifted) for the frame's last pixel, so that no
/// read leaves the buffer. The frame has at least 2 pixels (a 1-pixel frame has no
/// candidate: its cross is flat).
HWY_INLINE VU PixelBytes(const FxaaFrame& f, VI pixel) {
  const DI di;
  const DU du;
  const hn::Mask<DI> last = hn::Eq(pixel, hn::Set(di, f.width * f.height - 1));
  const VI offset =
      hn::Sub(hn::Add(hn::Add(pixel, pixel), pixel), hn::IfThenElseZero(last, hn::Set(di, 1)));
  const VU word =
      hn::BitCast(du, hn::GatherOffset(di, reinterpret_cast<const std::int32_t*>(f.rgb), offset));
  return hn::IfThenElse(hn::RebindMask(du, last), hn::ShiftRight<8>(word), word);
}

/// Channel `ch` (0..2) of PixelBytes, as an index.
HWY_INLINE VI Channel(VU bytes, int ch) {
  const DI di;
  const DU du;
  const VU shifted = ch == 0   ? bytes
                     : ch == 1 ? hn::ShiftRight<8>(bytes)
                               : hn::ShiftRight<16>(bytes);
  return hn::BitCast(di, hn::And(shifted, hn::Set(du, 0xFFu)));
}

/// Step 4 for a vector of candidates: the search along the edge, both ways, for its ends,
/// with bilinear samples half a pixel across it (`side` -1: towards n or w), and the blend
/// weight that the nearer end gives, at least `subpix`.
HWY_INLINE VF EdgeEndWeight(const FxaaFrame& f, const FxaaParams& p, VI xs, VI ys, MF valid,
                            MF horizontal, VF side, VF m, VF edge_mean, VF gradient, VF subpix) {
  const DF df;
  const DI di;
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f), half = hn::Set(df, 0.5f);
  const VI izero = hn::Zero(di), ione = hn::Set(di, 1);
  const VI wmax = hn::Set(di, f.width - 1), hmax = hn::Set(di, f.height - 1);
  const VI width = hn::Set(di, f.width);
  const VF xf = hn::ConvertTo(df, xs);
  const VF yf = hn::ConvertTo(df, ys);
  const VF half_side = hn::Mul(half, side);
  const VF u_across = hn::Add(xf, half_side), v_across = hn::Add(yf, half_side);
  // The luma `along` the edge from the pixel, less the edge's mean.
  const auto sample = [&](VF along) HWY_ATTR {
    const VF u = hn::IfThenElse(horizontal, hn::Add(xf, along), u_across);
    const VF v = hn::IfThenElse(horizontal, v_across, hn::Add(yf, along));
    const VF x0 = hn::Floor(u), y0 = hn::Floor(v);
    const VF fx = hn::Sub(u, x0), fy = hn::Sub(v, y0);
    const VI ix = hn::ConvertTo(di, x0), iy = hn::ConvertTo(di, y0);
    const VI col0 = Clamp(ix, izero, wmax), col1 = Clamp(hn::Add(ix, ione), izero, wmax);
    const VI row0 = hn::Mul(Clamp(iy, izero, hmax), width);
    const VI row1 = hn::Mul(Clamp(hn::Add(iy, ione), izero, hmax), width);
    const VF top =
        hn::Add(hn::Mul(hn::Sub(one, fx), hn::GatherIndex(df, f.luma, hn::Add(row0, col0))),
                hn::Mul(fx, hn::GatherIndex(df, f.luma, hn::Add(row0, col1))));
    const VF bottom =
        hn::Add(hn::Mul(hn::Sub(one, fx), hn::GatherIndex(df, f.luma, hn::Add(row1, col0))),
                hn::Mul(fx, hn::GatherIndex(df, f.luma, hn::Add(row1, col1))));
    return hn::Sub(hn::Add(hn::Mul(hn::Sub(one, fy), top), hn::Mul(fy, bottom)), edge_mean);
  };
  const VF limit = hn::Mul(hn::Set(df, 0.25f), gradient);
  VF back_distance = hn::Set(df, p.steps[0]), ahead_distance = back_distance;
  VF back_luma = sample(hn::Neg(back_distance)), ahead_luma = sample(ahead_distance);
  MF back_on = valid, ahead_on = valid;
  for (int k = 1; k < p.step_count; ++k) {
    back_on = hn::AndNot(hn::Ge(hn::Abs(back_luma), limit), back_on);
    ahead_on = hn::AndNot(hn::Ge(hn::Abs(ahead_luma), limit), ahead_on);
    if (hn::AllFalse(df, hn::Or(back_on, ahead_on))) break;
    const VF step = hn::Set(df, p.steps[k]);
    back_distance = hn::IfThenElse(back_on, hn::Add(back_distance, step), back_distance);
    ahead_distance = hn::IfThenElse(ahead_on, hn::Add(ahead_distance, step), ahead_distance);
    if (k + 1 < p.step_count) {
      back_luma = hn::IfThenElse(back_on, sample(hn::Neg(back_distance)), back_luma);
      ahead_luma = hn::IfThenElse(ahead_on, sample(ahead_distance), ahead_luma);
    }
  }
  // The nearer end decides: 0.5 - distance / span where the span is good.
  const MF centre_below = hn::Lt(hn::Sub(m, edge_mean), zero);
  const MF back_nearer = hn::Lt(back_distance, ahead_distance);
  const VF nearer_distance = hn::IfThenElse(back_nearer, back_distance, ahead_distance);
  const VF nearer_luma = hn::IfThenElse(back_nearer, back_luma, ahead_luma);
  const MF good_span = hn::Xor(hn::Lt(nearer_luma, zero), centre_below);
  const VF span_offset =
      hn::Sub(half, hn::Div(nearer_distance, hn::Add(back_distance, ahead_distance)));
  return StdMax(hn::IfThenElseZero(good_span, span_offset), subpix);
}

/// Step 5 for the lanes in `blend`: each pixel mixed with its partner across the edge (one
/// step towards n or w where `to_before`, else s or e; clamped to the frame) by `weight`, in
/// linear light, and written into `out` as 8-bit sRGB.
HWY_INLINE void WriteBlends(const FxaaFrame& f, VI xs, VI ys, MF horizontal, MF to_before,
                            VF weight, MF blend, const Srgb8EncodeTables& tables,
                            std::uint8_t* HWY_RESTRICT out) {
  const DF df;
  const DI di;
  const VI izero = hn::Zero(di), ione = hn::Set(di, 1);
  const VI wmax = hn::Set(di, f.width - 1), hmax = hn::Set(di, f.height - 1);
  const VI width = hn::Set(di, f.width);
  const VI step = hn::IfThenElse(hn::RebindMask(di, to_before), hn::Set(di, -1), ione);
  const VI horizontal_i = hn::VecFromMask(di, hn::RebindMask(di, horizontal));
  const VI ox = Clamp(hn::Add(xs, hn::AndNot(horizontal_i, step)), izero, wmax);
  const VI oy = Clamp(hn::Add(ys, hn::And(horizontal_i, step)), izero, hmax);
  const VI pixel = hn::Add(hn::Mul(ys, width), xs);
  const VU centre = PixelBytes(f, pixel);
  const VU other = PixelBytes(f, hn::Add(hn::Mul(oy, width), ox));
  const float* linear = fxaa_srgb8_linear();
  const VF keep = hn::Sub(hn::Set(df, 1.0f), weight);
  HWY_ALIGN std::int32_t code[3][kMaxLanes];
  for (int ch = 0; ch < 3; ++ch) {
    const VF a = hn::GatherIndex(df, linear, Channel(centre, ch));
    const VF b = hn::GatherIndex(df, linear, Channel(other, ch));
    hn::Store(EncodeSrgb8(hn::Add(hn::Mul(keep, a), hn::Mul(weight, b)), tables), di, code[ch]);
  }
  const int lanes = int(hn::Lanes(df));
  HWY_ALIGN std::int32_t pixel_of[kMaxLanes], write[kMaxLanes];
  hn::Store(pixel, di, pixel_of);
  hn::Store(hn::VecFromMask(di, hn::RebindMask(di, blend)), di, write);
  for (int i = 0; i < lanes; ++i) {
    if (write[i] == 0) continue;
    std::uint8_t* dst = out + 3 * std::size_t(pixel_of[i]);
    dst[0] = std::uint8_t(code[0][i]);
    dst[1] = std::uint8_t(code[1][i]);
    dst[2] = std::uint8_t(code[2][i]);
  }
}

/// Steps 2 to 5 for the candidates (xs, ys) (valid lanes: `valid`; the others hold pixel
/// (0, 0)); `out` is the output frame.
HWY_INLINE void BlendCandidates(const FxaaFrame& f, const FxaaParams& p, VI xs, VI ys, MF valid,
                                const Srgb8EncodeTables& tables, std::uint8_t* HWY_RESTRICT out) {
  const DF df;
  const DI di;
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f), two = hn::Set(df, 2.0f);
  const VF half = hn::Set(df, 0.5f);
  const VI izero = hn::Zero(di), ione = hn::Set(di, 1);
  const VI wmax = hn::Set(di, f.width - 1), hmax = hn::Set(di, f.height - 1);
  const VI width = hn::Set(di, f.width);

  // The 3x3 block, clamped to the frame: the rows' first pixels and the columns.
  const VI row = hn::Mul(ys, width);
  const VI above = hn::Mul(hn::Max(hn::Sub(ys, ione), izero), width);
  const VI below = hn::Mul(hn::Min(hn::Add(ys, ione), hmax), width);
  const VI left = hn::Max(hn::Sub(xs, ione), izero);
  const VI right = hn::Min(hn::Add(xs, ione), wmax);
  const auto at = [&](VI r, VI c) HWY_ATTR { return hn::GatherIndex(df, f.luma, hn::Add(r, c)); };
  const VF m = at(row, xs);
  const VF n = at(above, xs);
  const VF s = at(below, xs);
  const VF w = at(row, left);
  const VF e = at(row, right);
  const VF nw = at(above, left);
  const VF ne = at(above, right);
  const VF sw = at(below, left);
  const VF se = at(below, right);
  const VF range = hn::Sub(StdMax(StdMax(StdMax(m, n), StdMax(s, w)), e),
                           StdMin(StdMin(StdMin(m, n), StdMin(s, w)), e));

  // Step 2: horz = |nw + sw - 2w| + 2 |n + s - 2m| + |ne + se - 2e|, vert likewise.
  const VF horz = hn::Add(hn::Add(hn::Abs(hn::Sub(hn::Add(nw, sw), hn::Mul(two, w))),
                                  hn::Mul(two, hn::Abs(hn::Sub(hn::Add(n, s), hn::Mul(two, m))))),
                          hn::Abs(hn::Sub(hn::Add(ne, se), hn::Mul(two, e))));
  const VF vert = hn::Add(hn::Add(hn::Abs(hn::Sub(hn::Add(nw, ne), hn::Mul(two, n))),
                                  hn::Mul(two, hn::Abs(hn::Sub(hn::Add(w, e), hn::Mul(two, m))))),
                          hn::Abs(hn::Sub(hn::Add(sw, se), hn::Mul(two, s))));
  const MF horizontal = hn::Ge(horz, vert);

  // Step 3: lowpass = (2 (n + s + w + e) + (nw + ne + sw + se)) * (1/12),
  // c = min(1, |lowpass - m| / range), weight = (c c (3 - 2 c))^2 * subpix.
  const VF lowpass = hn::Mul(hn::Add(hn::Mul(two, hn::Add(hn::Add(hn::Add(n, s), w), e)),
                                     hn::Add(hn::Add(hn::Add(nw, ne), sw), se)),
                             hn::Set(df, 1.0f / 12.0f));
  const VF c = StdMin(one, hn::Div(hn::Abs(hn::Sub(lowpass, m)), range));
  const VF smooth = hn::Mul(hn::Mul(c, c), hn::Sub(hn::Set(df, 3.0f), hn::Mul(two, c)));
  const VF subpix = hn::Mul(hn::Mul(smooth, smooth), hn::Set(df, p.subpix));

  // Across the edge: before (n or w) or after (s or e), the larger luma step.
  const VF before = hn::IfThenElse(horizontal, n, w);
  const VF after = hn::IfThenElse(horizontal, s, e);
  const VF step_before = hn::Abs(hn::Sub(before, m));
  const VF step_after = hn::Abs(hn::Sub(after, m));
  const MF to_before = hn::Ge(step_before, step_after);
  const VF gradient = StdMax(step_before, step_after);
  const VF side = hn::IfThenElse(to_before, hn::Set(df, -1.0f), one);
  const VF edge_mean = hn::Mul(half, hn::Add(hn::IfThenElse(to_before, before, after), m));

  const VF weight =
      EdgeEndWeight(f, p, xs, ys, valid, horizontal, side, m, edge_mean, gradient, subpix);
  const MF blend = hn::And(valid, hn::Ne(weight, zero));
  if (hn::AllFalse(df, blend)) return;
  WriteBlends(f, xs, ys, horizontal, to_before, weight, blend, tables, out);
}

void FilterRows(const FxaaFrame& f, const FxaaParams& p, int y_begin, int y_end,
                std::uint8_t* HWY_RESTRICT out) {
  const DF df;
  const DI di;
  const int n = int(hn::Lanes(df));
  const int width = f.width;
  const VF edge_threshold = hn::Set(df, p.edge_threshold);
  const VF edge_threshold_min = hn::Set(df, p.edge_threshold_min);
  const VI izero = hn::Zero(di), ione = hn::Set(di, 1), wmax = hn::Set(di, width - 1);
  const Srgb8EncodeTables tables = srgb8_encode_tables();
  const VI iota = hn::Iota(di, 0);  // built once: Iota goes through memory on some targets

  // The candidates' (x, y), gathered over the rows in chunks of a row; whole vectors of them
  // are blended after each chunk, the rest carried over (fewer partly filled vectors: a row
  // of sphere_grid has a few tens of candidates). Fewer than n are left before a chunk.
  constexpr int kChunk = 256;
  HWY_ALIGN std::int32_t cand_x[kChunk + 2 * kMaxLanes];
  HWY_ALIGN std::int32_t cand_y[kChunk + 2 * kMaxLanes];
  int count = 0;
  for (int y = y_begin; y < y_end; ++y) {
    const float* above = f.luma + std::size_t(std::max(y - 1, 0)) * width;
    const float* row = f.luma + std::size_t(y) * width;
    const float* below = f.luma + std::size_t(std::min(y + 1, f.height - 1)) * width;
    const VI yv = hn::Set(di, y);
    for (int x0 = 0; x0 < width; x0 += kChunk) {
      const int x1 = std::min(x0 + kChunk, width);
      for (int x = x0; x < x1; x += n) {
        const VI xs = hn::Add(iota, hn::Set(di, x));
        VF m, north, south, west, east;
        if (x >= 1 && x + n < width) {
          // Inside the row: every lane's neighbours are in it.
          m = hn::LoadU(df, row + x);
          north = hn::LoadU(df, above + x);
          south = hn::LoadU(df, below + x);
          west = hn::LoadU(df, row + x - 1);
          east = hn::LoadU(df, row + x + 1);
        } else {
          // At the row's ends: clamped gathers (lanes past the end read the last pixel).
          const VI c = hn::Min(xs, wmax);
          m = hn::GatherIndex(df, row, c);
          north = hn::GatherIndex(df, above, c);
          south = hn::GatherIndex(df, below, c);
          west = hn::GatherIndex(df, row, hn::Max(hn::Sub(c, ione), izero));
          east = hn::GatherIndex(df, row, hn::Min(hn::Add(c, ione), wmax));
        }
        const MF pass =
            hn::And(hn::FirstN(df, std::size_t(x1 - x)),
                    Passes(m, north, south, west, east, edge_threshold_min, edge_threshold));
        // Most vectors have no candidate. Compress in a register, then store: the masked
        // compressing store is microcoded on some CPUs (AMD Zen 4), tens of times slower.
        if (hn::AllFalse(df, pass)) continue;
        const auto pass_i = hn::RebindMask(di, pass);
        hn::StoreU(hn::Compress(xs, pass_i), di, cand_x + count);
        hn::StoreU(yv, di, cand_y + count);
        count += int(hn::CountTrue(di, pass_i));
      }
      int k = 0;
      for (; k + n <= count; k += n) {
        BlendCandidates(f, p, hn::LoadU(di, cand_x + k), hn::LoadU(di, cand_y + k),
                        hn::FirstN(df, std::size_t(n)), tables, out);
      }
      std::memmove(cand_x, cand_x + k, sizeof(std::int32_t) * std::size_t(count - k));
      std::memmove(cand_y, cand_y + k, sizeof(std::int32_t) * std::size_t(count - k));
      count -= k;
    }
  }
  if (count > 0) {
    // Lanes past the last candidate read pixel (0, 0) (and are not written).
    hn::StoreU(izero, di, cand_x + count);
    hn::StoreU(izero, di, cand_y + count);
    BlendCandidates(f, p, hn::LoadU(di, cand_x), hn::LoadU(di, cand_y),
                    hn::FirstN(df, std::size_t(count)), tables, out);
  }
}

}  // namespace covrast::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace covrast::detail {

HWY_EXPORT(LumaRow);
HWY_EXPORT(FilterRows);

FxaaKernels fxaa_kernels_simd() {
  // HWY_DYNAMIC_DISPATCH's first table entry is an initialising trampoline, so make the
  // choice first.
  hwy::ChosenTarget& chosen = hwy::GetChosenTarget();
  if (!chosen.IsInitialized()) chosen.Update(hwy::SupportedTargets());
  const std::size_t index = chosen.GetIndex();
  return FxaaKernels{HWY_DISPATCH_TABLE(LumaRow)[index], HWY_DISPATCH_TABLE(FilterRows)[index]};
}

}  // namespace covrast::detail
#endif  // HWY_ONCE
