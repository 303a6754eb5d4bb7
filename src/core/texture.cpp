// Textures (docs/textures.md): building the 8-bit mip chain, filtered in linear light, once at
// scene load (make_texture) and sampling it (texture_sampling.hpp), each texel decoded to
// linear light by a 256-entry table. Double precision throughout, no contraction: the same
// bits in every mode, tile, thread and compiler.
#include "core/srgb.hpp"
#include "core/texture_sampling.hpp"

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

/// A texel coordinate as a wrapped index: NaN and huge values (a UV far outside any
/// sensible range) are pinned first, so the integer conversion is defined.
long long texel_floor(double v) {
  constexpr double kLimit = 1e15;
  if (!(v > -kLimit)) return -static_cast<long long>(kLimit);
  if (!(v < kLimit)) return static_cast<long long>(kLimit);
  return static_cast<long long>(std::floor(v));
}

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

/// The cells of one level the overlap sum may visit: 8 x 8, a footprint of several texels
/// (coverage mode asks on levels whose texels are about a pixel wide).
constexpr long long kMaxCells = 64;

/// nearest_area_average on one level.
std::optional<glm::dvec4> level_area_average(const TextureLevel& level, const TexelDecoder& decode,
                                             const TextureSampler& sampler,
                                             const ConvexPolygon& uv) {
  ConvexPolygon p = uv;
  double x_min = HUGE_VAL, y_min = HUGE_VAL, x_max = -HUGE_VAL, y_max = -HUGE_VAL;
  for (int i = 0; i < p.n; ++i) {
    p.x[i] *= level.width;
    p.y[i] *= level.height;
    x_min = std::min(x_min, p.x[i]);
    x_max = std::max(x_max, p.x[i]);
    y_min = std::min(y_min, p.y[i]);
    y_max = std::max(y_max, p.y[i]);
  }
  const long long x0 = texel_floor(x_min), x1 = texel_floor(x_max);
  const long long y0 = texel_floor(y_min), y1 = texel_floor(y_max);
  if (p.n < 3 || x1 - x0 >= kMaxCells || y1 - y0 >= kMaxCells ||
      (x1 - x0 + 1) * (y1 - y0 + 1) > kMaxCells) {
    return std::nullopt;
  }
  if (x0 == x1 && y0 == y1) {  // inside one texel: its value
    if (!(polygon_area(p) > 1e-12)) return std::nullopt;
    return decode(level.at(wrap_texel(x0, level.width, sampler.wrap_s),
                           wrap_texel(y0, level.height, sampler.wrap_t)));
  }
  // Column strips first, then each strip's rows: two half-planes per strip and two per
  // cell, and only the rows a strip reaches.
  glm::dvec4 sum(0.0);
  double area = 0.0;
  for (long long tx = x0; tx <= x1; ++tx) {
    const ConvexPolygon strip =
        clip_half_plane(clip_half_plane(p, 1.0, 0.0, -double(tx)), -1.0, 0.0, double(tx + 1));
    if (strip.n < 3) continue;
    double strip_y_min = HUGE_VAL, strip_y_max = -HUGE_VAL;
    for (int i = 0; i < strip.n; ++i) {
      strip_y_min = std::min(strip_y_min, strip.y[i]);
      strip_y_max = std::max(strip_y_max, strip.y[i]);
    }
    const long long r0 = std::max(y0, texel_floor(strip_y_min));
    const long long r1 = std::min(y1, texel_floor(strip_y_max));
    const int column = wrap_texel(tx, level.width, sampler.wrap_s);
    for (long long ty = r0; ty <= r1; ++ty) {
      const double part =
          r0 == r1 ? polygon_area(strip)
                   : polygon_area(clip_half_plane(clip_half_plane(strip, 0.0, 1.0, -double(ty)),
                                                  0.0, -1.0, double(ty + 1)));
      if (!(part > 0.0)) continue;
      sum += decode(level.at(column, wrap_texel(ty, level.height, sampler.wrap_t))) * part;
      area += part;
    }
  }
  if (!(area > 1e-12)) return std::nullopt;
  return sum / area;
}

}  // namespace

std::optional<glm::dvec4> nearest_area_average(const Texture& texture,
                                               const TextureSampler& sampler,
                                               const ConvexPolygon& uv, double lod) {
  if (texture.levels.empty()) return std::nullopt;
  const TexelDecoder decode(texture.srgb);
  const LevelChoice c = choose_levels(texture, sampler, lod);  // as sample_texture reads them
  const std::optional<glm::dvec4> a =
      level_area_average(texture.levels[std::size_t(c.first)], decode, sampler, uv);
  if (c.second < 0 || !a) return a;
  const std::optional<glm::dvec4> b =
      level_area_average(texture.levels[std::size_t(c.second)], decode, sampler, uv);
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
