// Textures (docs/textures.md): building the linear-light mip chain once at scene load
// (make_texture) and sampling it (texture_sampling.hpp). Double precision throughout, no
// contraction: the same bits in every mode, tile, thread and compiler.
#include "core/texture_sampling.hpp"

#include <covrast/error.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace covrast {
namespace {

/// IEC 61966-2-1 decoding of the 256 8-bit codes: c <= 0.04045 ? c / 12.92 :
/// ((c + 0.055) / 1.055)^2.4, c = code / 255.
std::array<float, 256> srgb_decode_table() {
  std::array<float, 256> table{};
  for (int code = 0; code < 256; ++code) {
    const double c = code / 255.0;
    table[std::size_t(code)] = float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
  }
  return table;
}

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

/// Level k + 1 of a chain: the box filter of `source` (the mean over each footprint).
TextureLevel downsample(const TextureLevel& source) {
  TextureLevel level;
  level.width = std::max(1, source.width / 2);
  level.height = std::max(1, source.height / 2);
  level.texels.resize(std::size_t(level.width) * std::size_t(level.height));
  for (int j = 0; j < level.height; ++j) {
    const Footprint fy = footprint(j, source.height);
    for (int i = 0; i < level.width; ++i) {
      const Footprint fx = footprint(i, source.width);
      glm::dvec4 sum(0.0);
      for (int y = fy.first; y < fy.first + fy.count; ++y) {
        for (int x = fx.first; x < fx.first + fx.count; ++x) sum += glm::dvec4(source.at(x, y));
      }
      level.texels[std::size_t(j) * std::size_t(level.width) + std::size_t(i)] =
          glm::vec4(sum / double(fx.count * fy.count));
    }
  }
  return level;
}

}  // namespace

std::shared_ptr<const Texture> make_texture(std::string name, int width, int height,
                                            const std::vector<std::uint8_t>& rgba8, bool srgb) {
  if (width <= 0 || height <= 0 || rgba8.size() != std::size_t(width) * std::size_t(height) * 4) {
    throw InputError(name + ": texture size does not match its texels");
  }
  static const std::array<float, 256> kSrgb = srgb_decode_table();
  auto texture = std::make_shared<Texture>();
  texture->name = std::move(name);
  TextureLevel base;
  base.width = width;
  base.height = height;
  base.texels.resize(std::size_t(width) * std::size_t(height));
  for (std::size_t t = 0; t < base.texels.size(); ++t) {
    const std::uint8_t* p = &rgba8[4 * t];
    const auto channel = [&](int c) { return srgb ? kSrgb[p[c]] : float(p[c] / 255.0); };
    base.texels[t] = glm::vec4(channel(0), channel(1), channel(2), float(p[3] / 255.0));
  }
  texture->levels.push_back(std::move(base));
  while (texture->levels.back().width > 1 || texture->levels.back().height > 1) {
    texture->levels.push_back(downsample(texture->levels.back()));
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

glm::dvec4 sample_level(const TextureLevel& level, const TextureSampler& sampler,
                        const glm::dvec2& uv, TextureFilter filter) {
  const double x = uv.x * level.width, y = uv.y * level.height;
  if (filter == TextureFilter::Nearest) {
    return glm::dvec4(level.at(wrap_texel(texel_floor(x), level.width, sampler.wrap_s),
                               wrap_texel(texel_floor(y), level.height, sampler.wrap_t)));
  }
  // Bilinear around (x - 0.5, y - 0.5): texel centres are at half-integers.
  const long long x0 = texel_floor(x - 0.5), y0 = texel_floor(y - 0.5);
  const double fx = (x - 0.5) - double(x0), fy = (y - 0.5) - double(y0);
  const int xa = wrap_texel(x0, level.width, sampler.wrap_s);
  const int xb = wrap_texel(x0 + 1, level.width, sampler.wrap_s);
  const int ya = wrap_texel(y0, level.height, sampler.wrap_t);
  const int yb = wrap_texel(y0 + 1, level.height, sampler.wrap_t);
  const glm::dvec4 top =
      glm::dvec4(level.at(xa, ya)) * (1.0 - fx) + glm::dvec4(level.at(xb, ya)) * fx;
  const glm::dvec4 bottom =
      glm::dvec4(level.at(xa, yb)) * (1.0 - fx) + glm::dvec4(level.at(xb, yb)) * fx;
  return top * (1.0 - fy) + bottom * fy;
}

}  // namespace

glm::dvec4 sample_texture(const Texture& texture, const TextureSampler& sampler,
                          const glm::dvec2& uv, double lod) {
  if (texture.levels.empty()) return glm::dvec4(1.0);  // refused by check_scene; no crash
  const int last = int(texture.levels.size()) - 1;
  if (!(lod > 0.0) || sampler.mip == MipFilter::None || last == 0) {
    const TextureFilter filter = lod > 0.0 ? sampler.min : sampler.mag;
    return sample_level(texture.levels[0], sampler, uv, filter);
  }
  if (sampler.mip == MipFilter::Nearest) {
    // OpenGL 4.6, 8.14.3: level ceil(lod + 1/2) - 1, clamped to the chain.
    const double chosen = std::ceil(lod + 0.5) - 1.0;
    const int level = chosen >= last ? last : int(chosen);
    return sample_level(texture.levels[std::size_t(level)], sampler, uv, sampler.min);
  }
  if (lod >= last) return sample_level(texture.levels[std::size_t(last)], sampler, uv, sampler.min);
  const int d1 = int(std::floor(lod));
  const double weight = lod - d1;
  const glm::dvec4 a = sample_level(texture.levels[std::size_t(d1)], sampler, uv, sampler.min);
  const glm::dvec4 b = sample_level(texture.levels[std::size_t(d1 + 1)], sampler, uv, sampler.min);
  return a * (1.0 - weight) + b * weight;
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
