// Textures (docs/textures.md): building the 8-bit mip chain, filtered in linear light, once at
// scene load (make_texture) and sampling it (texture_sampling.hpp), each texel decoded to
// linear light by a 256-entry table. Double precision throughout, no contraction: the same
// bits in every mode, tile, thread and compiler.
#include "color/srgb.hpp"
#include "texture/level_cuts.hpp"
#include "texture/texture_sampling.hpp"

#include <covrast/error.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace covrast {
namespace {

/// One encoding of a stored channel: code / 255 (linear slots, and alpha always) or sRGB (the
/// RGB of sRGB slots). `linear` holds the 256 codes in linear light (sampling); `threshold`
/// the 255 linear values where the nearest code changes, threshold[k] = decode((k + 0.5) /
/// 255), with threshold[255] = +inf as a sentinel (building the mips: a value's code is the
/// number of thresholds at or below it, i.e. round(255 encode(value)) in the encoded domain,
/// halves up). `start[i]` is the code of i / kBuckets, where the threshold steps begin.
struct ChannelCode {
  static constexpr int kBuckets = 4096;  // under one sRGB code per bucket (slope 12.92 x 255)
  std::array<double, 256> linear{};
  std::array<double, 256> threshold{};
  std::array<std::uint8_t, kBuckets + 1> start{};
  template <class Decode>
  explicit ChannelCode(const Decode& decode) {
    for (int code = 0; code < 256; ++code) linear[std::size_t(code)] = decode(code / 255.0);
    for (int k = 0; k < 255; ++k) threshold[std::size_t(k)] = decode((k + 0.5) / 255.0);
    threshold[255] = std::numeric_limits<double>::infinity();
    for (int i = 0, code = 0; i <= kBuckets; ++i) {
      while (threshold[std::size_t(code)] <= double(i) / kBuckets) ++code;
      start[std::size_t(i)] = std::uint8_t(code);
    }
  }
  /// The nearest code of a linear value: a bucket look-up, then a step or two (no search).
  std::uint8_t encode(double value) const {
    if (!(value > 0.0)) return 0;
    if (value >= 1.0) return 255;
    // i / kBuckets <= value for i = floor(value kBuckets): exact power-of-2 scaling.
    int code = start[std::size_t(value * kBuckets)];
    while (threshold[std::size_t(code)] <= value) ++code;
    return std::uint8_t(code);
  }
};

/// Built once at start-up (no guard on every texel fetch, as a function-local static would
/// need); nothing builds or samples a texture during static initialisation.
const ChannelCode g_unit([](double c) { return c; });
const ChannelCode g_srgb(detail::srgb_decode);

/// Decodes stored texels: RGB through the texture's encoding, alpha as code / 255.
struct TexelDecoder {
  const double* rgb;
  explicit TexelDecoder(bool srgb) : rgb(srgb ? g_srgb.linear.data() : g_unit.linear.data()) {}
  glm::dvec4 operator()(const std::uint8_t* p) const {
    return glm::dvec4(rgb[p[0]], rgb[p[1]], rgb[p[2]], g_unit.linear[p[3]]);
  }
};

/// The source texels that texel `i` of the next level averages along one side of `n`
/// texels (next side m = max(1, floor(n / 2))): 2i and 2i + 1, and 2i + 2 for the last texel
/// of an odd side; a side of 1 keeps its one texel.
struct Footprint {
  int first;
  int count;
};
Footprint footprint(int i, int n) {
  if (n == 1) return {0, 1};
  const int m = n / 2;
  return {2 * i, (n % 2 == 1 && i == m - 1) ? 3 : 2};
}

/// A mip level in linear light before rounding, 4 doubles a texel: the next level is filtered
/// from these exact means, not from the rounded codes, and they are dropped once it is built.
struct LinearLevel {
  int width = 0;
  int height = 0;
  std::vector<glm::dvec4> texels;
};

/// The box filter of a width x height source whose texel (x, y) is `fetch(x, y)` in linear
/// light: the mean over each footprint, summed in double.
template <class Fetch>
LinearLevel box_filter(int width, int height, const Fetch& fetch) {
  LinearLevel level;
  level.width = std::max(1, width / 2);
  level.height = std::max(1, height / 2);
  level.texels.resize(std::size_t(level.width) * std::size_t(level.height));
  for (int j = 0; j < level.height; ++j) {
    const Footprint fy = footprint(j, height);
    for (int i = 0; i < level.width; ++i) {
      const Footprint fx = footprint(i, width);
      glm::dvec4 sum(0.0);
      for (int y = fy.first; y < fy.first + fy.count; ++y) {
        for (int x = fx.first; x < fx.first + fx.count; ++x) sum += fetch(x, y);
      }
      // A 2x2 box: x 0.25 is the same IEEE result as / 4 (a power of two), and cheaper.
      const int count = fx.count * fy.count;
      level.texels[std::size_t(j) * std::size_t(level.width) + std::size_t(i)] =
          count == 4 ? sum * 0.25 : sum / double(count);
    }
  }
  return level;
}

/// A linear level stored: each channel as its nearest code (RGB in sRGB when `srgb`).
TextureLevel encode_level(const LinearLevel& source, bool srgb) {
  const ChannelCode& rgb = srgb ? g_srgb : g_unit;
  TextureLevel level;
  level.width = source.width;
  level.height = source.height;
  level.rgba8.assign(TextureLevel::bytes(level.width, level.height), 0);
  for (int y = 0; y < level.height; ++y) {
    for (int x = 0; x < level.width; ++x) {
      const glm::dvec4& v =
          source.texels[std::size_t(y) * std::size_t(level.width) + std::size_t(x)];
      std::uint8_t* out = level.at(x, y);
      for (int c = 0; c < 3; ++c) out[c] = rgb.encode(v[c]);
      out[3] = g_unit.encode(v.a);
    }
  }
  return level;
}

}  // namespace

TextureLevel TextureLevel::from_rows(int width, int height, const std::vector<std::uint8_t>& rows) {
  TextureLevel level;
  level.width = width;
  level.height = height;
  level.rgba8.assign(bytes(width, height), 0);
  // Row by row, one block's run of up to 8 texels at a time (contiguous in both layouts).
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* row = &rows[std::size_t(y) * std::size_t(width) * 4];
    for (int x = 0; x < width; x += kBlockSide) {
      const int run = std::min(kBlockSide, width - x);
      std::copy(row + std::size_t(x) * 4, row + std::size_t(x + run) * 4, level.at(x, y));
    }
  }
  return level;
}

glm::dvec4 Texture::linear(int level, int x, int y) const {
  return TexelDecoder(srgb)(levels[std::size_t(level)].at(x, y));
}

std::shared_ptr<const Texture> make_texture(std::string name, int width, int height,
                                            std::vector<std::uint8_t> rgba8, bool srgb) {
  if (width <= 0 || height <= 0 || rgba8.size() != std::size_t(width) * std::size_t(height) * 4) {
    throw InputError(name + ": texture size does not match its texels");
  }
  auto texture = std::make_shared<Texture>();
  texture->name = std::move(name);
  texture->srgb = srgb;
  texture->levels.push_back(TextureLevel::from_rows(width, height, rgba8));
  std::vector<std::uint8_t>().swap(rgba8);  // the decoded rows are no longer needed
  if (width == 1 && height == 1) return texture;
  const TexelDecoder decode(srgb);
  const TextureLevel& base = texture->levels[0];
  LinearLevel above =
      box_filter(width, height, [&](int x, int y) { return decode(base.at(x, y)); });
  for (;;) {
    texture->levels.push_back(encode_level(above, srgb));
    if (above.width == 1 && above.height == 1) break;
    const std::size_t stride = std::size_t(above.width);
    above = box_filter(above.width, above.height, [&](int x, int y) {
      return above.texels[std::size_t(y) * stride + std::size_t(x)];
    });
  }
  return texture;
}

namespace detail {

int wrap_texel(long long i, int size, TextureWrap wrap) {
  if (i >= 0 && i < size) return int(i);  // inside: every mode agrees, no division
  switch (wrap) {
    case TextureWrap::ClampToEdge:
      return int(std::clamp<long long>(i, 0, size - 1));
    case TextureWrap::MirroredRepeat: {
      const long long period = 2LL * size;
      const long long k = ((i % period) + period) % period;
      return int(k < size ? k : period - 1 - k);
    }
    case TextureWrap::Repeat:
    default:
      // One period off (a bilinear neighbour across the seam, UVs just past 0 or 1): the
      // same remainder without a 64-bit division.
      if (i >= -size && i < 0) return int(i + size);
      if (i >= size && i < 2LL * size) return int(i - size);
      return int(((i % size) + size) % size);
  }
}

double texture_lod(const Texture& texture, const glm::dvec2& duv_dx, const glm::dvec2& duv_dy) {
  if (texture.levels.empty()) return 0.0;
  const double w = texture.levels[0].width, h = texture.levels[0].height;
  const double rx = std::sqrt(duv_dx.x * w * (duv_dx.x * w) + duv_dx.y * h * (duv_dx.y * h));
  const double ry = std::sqrt(duv_dy.x * w * (duv_dy.x * w) + duv_dy.y * h * (duv_dy.y * h));
  const double rho = std::max(rx, ry);
  if (!(rho > 0.0)) return -std::numeric_limits<double>::infinity();  // also NaN
  return std::log2(rho);
}

namespace {

/// One level filtered at `uv`, each fetched texel decoded to linear light (`decode`) before it
/// is weighted: the filter works in linear light.
glm::dvec4 sample_level(const TextureLevel& level, const TexelDecoder& decode,
                        const TextureSampler& sampler, const glm::dvec2& uv, TextureFilter filter) {
  const double x = uv.x * level.width, y = uv.y * level.height;
  if (filter == TextureFilter::Nearest) {
    return decode(level.at(wrap_texel(texel_floor(x), level.width, sampler.wrap_s),
                           wrap_texel(texel_floor(y), level.height, sampler.wrap_t)));
  }
  // Bilinear around (x - 0.5, y - 0.5): texel centres are at half-integers.
  const long long x0 = texel_floor(x - 0.5), y0 = texel_floor(y - 0.5);
  const double fx = (x - 0.5) - double(x0), fy = (y - 0.5) - double(y0);
  const int xa = wrap_texel(x0, level.width, sampler.wrap_s);
  const int xb = wrap_texel(x0 + 1, level.width, sampler.wrap_s);
  const int ya = wrap_texel(y0, level.height, sampler.wrap_t);
  const int yb = wrap_texel(y0 + 1, level.height, sampler.wrap_t);
  const glm::dvec4 top = decode(level.at(xa, ya)) * (1.0 - fx) + decode(level.at(xb, ya)) * fx;
  const glm::dvec4 bottom = decode(level.at(xa, yb)) * (1.0 - fx) + decode(level.at(xb, yb)) * fx;
  return top * (1.0 - fy) + bottom * fy;
}

}  // namespace

namespace {

/// The levels a lookup at `lod` reads, their filter and blend (OpenGL 4.6, 8.14.3): `first`
/// alone when `second` is -1, else first x (1 - weight) + second x weight.
struct LevelChoice {
  int first = 0;
  int second = -1;
  double weight = 0.0;
  TextureFilter filter = TextureFilter::Linear;
};

LevelChoice choose_levels(const Texture& texture, const TextureSampler& sampler, double lod) {
  const int last = int(texture.levels.size()) - 1;
  if (!(lod > 0.0) || sampler.mip == MipFilter::None || last == 0) {
    return {0, -1, 0.0, lod > 0.0 ? sampler.min : sampler.mag};
  }
  if (sampler.mip == MipFilter::Nearest) {
    // Level ceil(lod + 1/2) - 1, clamped to the chain.
    const double chosen = std::ceil(lod + 0.5) - 1.0;
    return {chosen >= last ? last : int(chosen), -1, 0.0, sampler.min};
  }
  if (lod >= last) return {last, -1, 0.0, sampler.min};
  const int d1 = int(std::floor(lod));
  return {d1, d1 + 1, lod - d1, sampler.min};
}

}  // namespace

glm::dvec4 sample_texture(const Texture& texture, const TextureSampler& sampler,
                          const glm::dvec2& uv, double lod) {
  if (texture.levels.empty()) return glm::dvec4(1.0);  // refused by check_scene; no crash
  const TexelDecoder decode(texture.srgb);
  const LevelChoice c = choose_levels(texture, sampler, lod);
  const glm::dvec4 a =
      sample_level(texture.levels[std::size_t(c.first)], decode, sampler, uv, c.filter);
  if (c.second < 0) return a;
  const glm::dvec4 b =
      sample_level(texture.levels[std::size_t(c.second)], decode, sampler, uv, c.filter);
  return a * (1.0 - c.weight) + b * c.weight;
}

namespace {

/// The texels the cells of an average read: (64 + 1) x (1 + 1) at most, for the bilinear
/// filter.
constexpr int kMaxTexels = 130;

/// Texel values g_0..g_{n-1} along one axis (`stride` apart) rewritten in place as the
/// coefficients of a basis with one kink per inner node k = s0 + 1, s0 + 2, ...:
///   order 0 (NEAREST, steps):  g(s) = g_0 + sum_{x >= 1} (g_x - g_{x-1}) step(s - s0 - x)
///   order 1 (LINEAR, ramps):   g(s) = g_0 + (g_1 - g_0)(s - s0)
///                                     + sum_{x >= 2} (g_x - 2 g_{x-1} + g_{x-2}) r(s - s0 - x + 1)
/// with r(d) = max(0, d): what the filter between texel centres is on [s0, s0 + n - 1].
/// From the far end, so each difference reads the values before they change.
void to_kink_basis(glm::dvec4* g, int n, int stride, int order) {
  if (order == 0) {
    for (int x = n - 1; x >= 1; --x) g[x * stride] -= g[(x - 1) * stride];
    return;
  }
  for (int x = n - 1; x >= 2; --x) {
    g[x * stride] = g[x * stride] - 2.0 * g[(x - 1) * stride] + g[(x - 2) * stride];
  }
  if (n >= 2) g[stride] -= g[0];
}

/// The texels a filter of order 0 (NEAREST) or 1 (LINEAR) reads over the cells `cuts` reach,
/// decoded, row by row (columns + order per row, rows + order rows; first i0, j0), wrapped as
/// sample_level wraps them.
struct TexelBlock {
  int n = 0, m = 0;  ///< texels per row, rows of texels
  glm::dvec4 texel[kMaxTexels];
};

void read_block(const TextureLevel& level, const TexelDecoder& decode,
                const TextureSampler& sampler, const LevelPolygon& at, int order,
                TexelBlock& block) {
  block.n = at.columns + order;
  block.m = at.rows + order;
  int column[kMaxTexels];  // wrapped once per block, not once per texel
  for (int x = 0; x < block.n; ++x) column[x] = wrap_texel(at.i0 + x, level.width, sampler.wrap_s);
  for (int y = 0; y < block.m; ++y) {
    const int row = wrap_texel(at.j0 + y, level.height, sampler.wrap_t);
    for (int x = 0; x < block.n; ++x)
      block.texel[y * block.n + x] = decode(level.at(column[x], row));
  }
}

/// The mean of one level over `uv`, filtered NEAREST (order 0) or LINEAR (order 1), exactly.
/// In s, t (level_cuts.hpp) the filter over the cells the polygon's bounds reach is the texel
/// block rewritten by to_kink_basis along both axes, times products A_x(s) B_y(t) of the
/// basis functions. Each product's integral over the polygon P is a moment of a piece of P:
/// with S_k = P n {s >= k} and T_l = P n {t >= l},
///   steps:  int_P step(s - k) step(t - l) = M_1(S_k n T_l)
///   ramps:  int_P r(s - k) r(t - l) = M_ab(S_k n T_l) about (k, l),
///           int_P r(s - k) (t - t0) = M_ab(S_k) about (k, t0), and so on,
/// so the pieces are P cut by at most two half-planes: one per inner node on each axis and one
/// per pair, where clipping every cell would cut four per cell. `cuts` (DirectCuts or
/// LevelCuts, level_cuts.hpp) cuts the pieces; the texels decide which are needed. Nothing
/// when P has no area or its bounds reach more than kMaxCells cells.
template <int kOrder, class Cuts>
std::optional<glm::dvec4> level_average(const TextureLevel& level, const TexelDecoder& decode,
                                        const TextureSampler& sampler, Cuts& cuts) {
  const LevelPolygon& at = cuts.at();
  if (!at.fits) return std::nullopt;
  TexelBlock block;
  read_block(level, decode, sampler, at, kOrder, block);
  const int columns = at.columns, rows = at.rows, n = block.n, m = block.m;
  glm::dvec4* c = block.texel;
  for (int y = 0; y < m; ++y) to_kink_basis(c + y * n, n, 1, kOrder);
  for (int x = 0; x < n; ++x) to_kink_basis(c + x, m, n, kOrder);
  // Piece (ps, pt) is P cut at s >= i0 + ps (ps > 0) and t >= j0 + pt (pt > 0); the pieces
  // shrink as ps or pt grows, so the first empty one ends its loop. A cut piece whose
  // coefficients are all zero (the texels are constant, or linear for LINEAR, across its
  // node) adds nothing, exactly, and is not cut.
  const auto zero = [](const glm::dvec4& v) { return v == glm::dvec4(0.0); };
  const auto column_is_zero = [&](int x) {
    for (int y = 0; y < m; ++y) {
      if (!zero(c[y * n + x])) return false;
    }
    return true;
  };
  const Moments& whole = at.whole;
  const double area = whole.m1;
  if (!(std::fabs(area) > 1e-12)) return std::nullopt;
  if (kOrder == 0 && n * m == 1) return c[0];  // inside one texel: its value
  glm::dvec4 sum(0.0);
  for (int ps = 0; ps < columns; ++ps) {
    const int x = ps + kOrder;  // the basis function of the cut at s = i0 + ps
    if (ps > 0 && column_is_zero(x)) continue;
    if (ps > 0 && cuts.column(ps) == nullptr) break;
    for (int pt = 0; pt < rows; ++pt) {
      const int y = pt + kOrder;
      if (pt > 0 && zero(c[y * n + x]) && (ps > 0 || zero(c[y * n]))) continue;
      const Moments* q = ps == 0 && pt == 0 ? &whole : cuts.piece(ps, pt);
      if (q == nullptr) break;
      if constexpr (kOrder == 0) {
        sum += c[y * n + x] * q->m1;
      } else {
        // The ramp basis functions on this piece: x = 1 ((s - i0) on P) or ps + 1
        // (r(s - i0 - ps)), and the constant x = 0 on P alone; the same for y.
        sum += c[y * n + x] * q->mab;
        if (ps == 0) sum += c[y * n] * q->mb;
        if (pt == 0) sum += c[x] * q->ma;
        if (ps == 0 && pt == 0) sum += c[0] * q->m1;
      }
    }
  }
  return sum / area;
}

/// level_average with the filter's order, on `memo`'s cuts when there is one.
std::optional<glm::dvec4> level_average(const TextureLevel& level, const TexelDecoder& decode,
                                        const TextureSampler& sampler, const ConvexPolygon& uv,
                                        TextureFilter filter, LevelCutsMemo* memo) {
  const int order = filter == TextureFilter::Nearest ? 0 : 1;
  const auto average = [&](auto& cuts) {
    return order == 0 ? level_average<0>(level, decode, sampler, cuts)
                      : level_average<1>(level, decode, sampler, cuts);
  };
  if (memo != nullptr) return average(memo->get(level.width, level.height, uv, order));
  DirectCuts cuts(level.width, level.height, uv, order);
  return average(cuts);
}

/// The smallest and largest alpha of the texels `filter` reads over `uv` on `level`.
std::optional<AlphaRange> level_alpha_range(const TextureLevel& level, const TexelDecoder& decode,
                                            const TextureSampler& sampler, const ConvexPolygon& uv,
                                            TextureFilter filter) {
  const int order = filter == TextureFilter::Nearest ? 0 : 1;
  LevelPolygon at;
  at.set_cells(level.width, level.height, uv, order);
  if (!at.fits) return std::nullopt;
  TexelBlock block;
  read_block(level, decode, sampler, at, order, block);
  AlphaRange range{HUGE_VAL, -HUGE_VAL};
  for (int k = 0; k < block.n * block.m; ++k) {
    range.low = std::min(range.low, block.texel[k].a);
    range.high = std::max(range.high, block.texel[k].a);
  }
  return range;
}

}  // namespace

std::optional<AlphaRange> area_alpha_range(const Texture& texture, const TextureSampler& sampler,
                                           const ConvexPolygon& uv, double lod) {
  if (texture.levels.empty()) return std::nullopt;
  const TexelDecoder decode(texture.srgb);
  const LevelChoice c = choose_levels(texture, sampler, lod);
  std::optional<AlphaRange> a =
      level_alpha_range(texture.levels[std::size_t(c.first)], decode, sampler, uv, c.filter);
  if (c.second < 0 || !a) return a;
  const std::optional<AlphaRange> b =
      level_alpha_range(texture.levels[std::size_t(c.second)], decode, sampler, uv, c.filter);
  if (!b) return std::nullopt;
  return AlphaRange{std::min(a->low, b->low), std::max(a->high, b->high)};
}

std::optional<glm::dvec4> area_average(const Texture& texture, const TextureSampler& sampler,
                                       const ConvexPolygon& uv, double lod, LevelCutsMemo* memo) {
  if (texture.levels.empty()) return std::nullopt;
  const TexelDecoder decode(texture.srgb);
  const LevelChoice c = choose_levels(texture, sampler, lod);  // as sample_texture reads them
  const std::optional<glm::dvec4> a =
      level_average(texture.levels[std::size_t(c.first)], decode, sampler, uv, c.filter, memo);
  if (c.second < 0 || !a) return a;
  const std::optional<glm::dvec4> b =
      level_average(texture.levels[std::size_t(c.second)], decode, sampler, uv, c.filter, memo);
  if (!b) return std::nullopt;
  return *a * (1.0 - c.weight) + *b * c.weight;
}

glm::dvec2 transform_duv(const TextureTransform& t, const glm::dvec2& d) {
  const double x = d.x * t.scale.x, y = d.y * t.scale.y;
  if (t.rotation == 0.0) return glm::dvec2(x, y);  // the common case: no trigonometry
  const double c = std::cos(t.rotation), s = std::sin(t.rotation);
  return glm::dvec2(c * x + s * y, -s * x + c * y);
}

glm::dvec2 transform_uv(const TextureTransform& t, const glm::dvec2& uv) {
  return transform_duv(t, uv) + t.offset;
}

}  // namespace detail
}  // namespace covrast
