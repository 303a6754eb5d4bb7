// Raster stage, ssaa:N, ssaa-grid:N and ssaa-cmj:N: N x N samples per pixel with per-sample
// coverage, depth and shading, box-filter resolve (sample_raster.hpp). This file holds the
// sample patterns: ssaa:N uses the ordered grid, which has the lowest edge error of the
// patterns measured (docs/supersampling.md); the correlated multi-jittered generator of
// ssaa-cmj:N is shared with the reference mode.
#include "core/tile_raster.hpp"
#include "raster/rasterizers.hpp"
#include "raster/samples/sample_pattern.hpp"
#include "raster/samples/sample_raster.hpp"

#include <covrast/error.hpp>

#include <string>

namespace covrast::detail {
namespace {

/// Seed of the ssaa-cmj pattern (any fixed value; this one gives sample 0 a central-ish spot).
constexpr std::uint32_t kSsaaSeed = 0x5eed0001u;

// Kensler, "Correlated Multi-Jittered Sampling", Pixar Technical Memo 13-01 (2013):
// a hashed permutation of [0, l) (cycle-walking on the next power of two) and a hashed
// 32-bit value.
std::uint32_t permute(std::uint32_t i, std::uint32_t l, std::uint32_t p) {
  std::uint32_t w = l - 1;
  w |= w >> 1;
  w |= w >> 2;
  w |= w >> 4;
  w |= w >> 8;
  w |= w >> 16;
  do {
    i ^= p;
    i *= 0xe170893du;
    i ^= p >> 16;
    i ^= (i & w) >> 4;
    i ^= p >> 8;
    i *= 0x0929eb3fu;
    i ^= p >> 23;
    i ^= (i & w) >> 1;
    i *= 1u | p >> 27;
    i *= 0x6935fa69u;
    i ^= (i & w) >> 11;
    i *= 0x74dcb303u;
    i ^= (i & w) >> 2;
    i *= 0x9e501cc3u;
    i ^= (i & w) >> 2;
    i *= 0xc860a3dfu;
    i &= w;
    i ^= i >> 5;
  } while (i >= l);
  return (i + p) % l;
}

std::uint32_t hash_bits(std::uint32_t i, std::uint32_t p) {
  i ^= p;
  i ^= i >> 17;
  i ^= i >> 10;
  i *= 0xb36534e5u;
  i ^= i >> 12;
  i ^= i >> 21;
  i *= 0x93fc4795u;
  i ^= 0xdf6e307fu;
  i ^= i >> 17;
  i *= 1u | p >> 18;
  return i;
}

}  // namespace

SamplePattern cmj_pattern(int n, std::int32_t unit, std::uint32_t seed) {
  const std::int64_t fine = std::int64_t(n) * n;
  // a(k) = floor(k unit / n^2): fine cell k is [a(k), a(k + 1)), non-empty as unit >= n^2.
  auto cell_start = [&](std::int64_t k) { return std::int32_t(k * unit / fine); };
  SamplePattern pattern;
  pattern.unit = unit;
  pattern.x.resize(std::size_t(fine));
  pattern.y.resize(std::size_t(fine));
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const std::uint32_t s = std::uint32_t(j * n + i);
      const std::uint32_t sx = permute(std::uint32_t(i), std::uint32_t(n), seed * 0xa511e9b3u);
      const std::uint32_t sy = permute(std::uint32_t(j), std::uint32_t(n), seed * 0x63d83595u);
      const std::int64_t kx = std::int64_t(i) * n + sy, ky = std::int64_t(j) * n + sx;
      const std::int32_t x0 = cell_start(kx), x1 = cell_start(kx + 1);
      const std::int32_t y0 = cell_start(ky), y1 = cell_start(ky + 1);
      // Jitter inside the fine cell: floor(h / 2^32 * width), h a 32-bit hash.
      const std::uint64_t hx = hash_bits(s, seed * 0xa399d265u);
      const std::uint64_t hy = hash_bits(s, seed * 0x711ad6a5u);
      pattern.x[s] = x0 + std::int32_t((hx * std::uint64_t(x1 - x0)) >> 32);
      pattern.y[s] = y0 + std::int32_t((hy * std::uint64_t(y1 - y0)) >> 32);
    }
  }
  return pattern;
}

SamplePattern ssaa_pattern(int n) { return ssaa_grid_pattern(n); }

SamplePattern ssaa_cmj_pattern(int n) { return cmj_pattern(n, kSubpixelOne, kSsaaSeed); }

SamplePattern ssaa_grid_pattern(int n) {
  SamplePattern pattern;
  pattern.unit = kSubpixelOne;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      // round((i + 0.5) 256 / n) = floor(((2i + 1) 256 + n) / (2n))
      pattern.x.push_back(((2 * i + 1) * kSubpixelOne + n) / (2 * n));
      pattern.y.push_back(((2 * j + 1) * kSubpixelOne + n) / (2 * n));
    }
  }
  return pattern;
}

std::unique_ptr<TileRasterizer> make_ssaa_rasterizer(int tile_px, const RenderMode& mode) {
  const int n = mode.samples;
  if (n < 1 || n > 16) {
    throw InputError("ssaa: N = " + std::to_string(n) + " out of range: must be 1..16");
  }
  const SamplePattern pattern = mode.kind == ModeKind::SsaaGrid  ? ssaa_grid_pattern(n)
                                : mode.kind == ModeKind::SsaaCmj ? ssaa_cmj_pattern(n)
                                                                 : ssaa_pattern(n);
  return std::make_unique<SampleRasterizer>(tile_px, pattern, ShadingRate::PerSample,
                                            sample_kernels_simd());
}

}  // namespace covrast::detail
