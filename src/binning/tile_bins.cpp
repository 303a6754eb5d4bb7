// Binning stage implementation: a two-pass counting sort of (tile, triangle) pairs.
//
// Pass 1 counts entries per tile and remembers the tile of every triangle that touches a
// single tile (the common case for small triangles: sphere_grid has 1.09 entries per
// triangle); pass 2 places the indices, recomputing the tile span only for the others.
#include "binning/tile_bins.hpp"

#include <algorithm>
#include <cstring>

namespace covrast::detail {
namespace {

/// Tiles overlapped by a pixel rectangle that lies inside the image and is not empty:
/// [tx0, tx1) x [ty0, ty1).
struct TileSpan {
  int tx0, ty0, tx1, ty1;
};

/// Exact floor(x / d) for 0 <= x < 2^16 and 1 <= d <= 2^16, by one multiplication:
/// with m = floor(2^32 / d) + 1 = 2^32 / d + eps (0 < eps <= 1),
///   x * m / 2^32 = x / d + x * eps / 2^32,  and  x * eps / 2^32 < 2^-16 <= 1 / d,
/// which never reaches the next multiple of 1 / d above x / d.
class TileDivider {
 public:
  explicit TileDivider(int tile_px) : m_((std::uint64_t(1) << 32) / std::uint64_t(tile_px) + 1) {}
  int operator()(int x) const { return int((std::uint64_t(x) * m_) >> 32); }

 private:
  std::uint64_t m_;
};

TileSpan tile_span(const TileDivider& div, int x0, int y0, int x1, int y1) {
  return {div(x0), div(y0), div(x1 - 1) + 1, div(y1 - 1) + 1};
}

/// Marks a triangle of scratch that touches more than one tile.
constexpr std::uint32_t kManyTiles = 0xffffffffu;

/// The counting sort, over any source of per-triangle pixel bounds (clamped to the image,
/// or empty).
template <class BoundsOf>
void bin_impl(const TileGrid& grid, std::uint32_t count, BoundsOf bounds_of, ChunkBins& bins,
              std::vector<std::uint32_t>& scratch) {
  const int tiles = grid.tile_count();
  const TileDivider div(grid.tile_px);
  bins.tile_begin.assign(std::size_t(tiles) + 1, 0);
  // scratch[0 .. tiles): per-tile cursor; scratch[tiles + i]: triangle i's only tile, or
  // kManyTiles.
  scratch.resize(std::size_t(tiles) + count);
  std::uint32_t* const cursor = scratch.data();
  std::uint32_t* const single = scratch.data() + tiles;
  // Pass 1: count entries per tile (shifted by one for the prefix sum).
  std::uint32_t* const counts = bins.tile_begin.data() + 1;
  for (std::uint32_t i = 0; i < count; ++i) {
    const PixelRect r = bounds_of(i);
    if (r.empty()) {
      single[i] = kManyTiles;
      continue;
    }
    const TileSpan s = tile_span(div, r.x0, r.y0, r.x1, r.y1);
    if (s.tx1 - s.tx0 == 1 && s.ty1 - s.ty0 == 1) {
      const std::uint32_t tile = std::uint32_t(s.ty0 * grid.tiles_x + s.tx0);
      single[i] = tile;
      ++counts[tile];
      continue;
    }
    single[i] = kManyTiles;
    for (int ty = s.ty0; ty < s.ty1; ++ty) {
      for (int tx = s.tx0; tx < s.tx1; ++tx) ++counts[std::size_t(ty) * grid.tiles_x + tx];
    }
  }
  for (int i = 0; i < tiles; ++i) bins.tile_begin[i + 1] += bins.tile_begin[i];
  bins.triangle_index.resize(bins.tile_begin[tiles]);
  // Pass 2: place triangle indices; ascending within a tile because we scan in order.
  std::copy(bins.tile_begin.begin(), bins.tile_begin.end() - 1, cursor);
  std::uint32_t* const out = bins.triangle_index.data();
  for (std::uint32_t i = 0; i < count; ++i) {
    if (single[i] != kManyTiles) {
      out[cursor[single[i]]++] = i;
      continue;
    }
    const PixelRect r = bounds_of(i);
    if (r.empty()) continue;
    const TileSpan s = tile_span(div, r.x0, r.y0, r.x1, r.y1);
    for (int ty = s.ty0; ty < s.ty1; ++ty) {
      for (int tx = s.tx0; tx < s.tx1; ++tx) out[cursor[std::size_t(ty) * grid.tiles_x + tx]++] = i;
    }
  }
}

}  // namespace

void bin_chunk(const TileGrid& grid, std::span<const PixelBounds16> bounds, ChunkBins& bins,
               std::vector<std::uint32_t>& scratch) {
  bin_impl(
      grid, std::uint32_t(bounds.size()),
      [&](std::uint32_t i) {
        const PixelBounds16 b = bounds[i];
        return PixelRect{b.x0, b.y0, b.x1, b.y1};
      },
      bins, scratch);
}

namespace {

/// The sort key of `t`: the top 24 bits of its nearest depth as a float (>= +0, so the bits
/// order as the values do; about 5 significant decimal digits).
std::uint32_t nearest_depth_key(const TriangleSetup& t) {
  const double s = 1.0 / kSubpixelOne;
  double z = t.depth_at(t.x_fx8[0] * s, t.y_fx8[0] * s);
  z = std::min(z, t.depth_at(t.x_fx8[1] * s, t.y_fx8[1] * s));
  z = std::min(z, t.depth_at(t.x_fx8[2] * s, t.y_fx8[2] * s));
  const float nearest = float(z) > 0.0f ? float(z) : 0.0f;  // -0, NaN: 0
  std::uint32_t bits;
  std::memcpy(&bits, &nearest, sizeof bits);
  return bits >> 8;
}

/// Sorts `keys` (key << 32 | submission index, all distinct) ascending: an LSD radix sort of
/// the 24-bit keys, three stable passes of 8 bits, which gives the same order as comparing the
/// whole values (ties in index order) in linear time; a comparison sort for short tiles.
void sort_keys(std::vector<std::uint64_t>& keys, std::vector<std::uint64_t>& other) {
  if (keys.size() < 256) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  other.resize(keys.size());
  for (int shift = 32; shift < 56; shift += 8) {
    std::uint32_t start[257] = {};
    for (const std::uint64_t k : keys) ++start[((k >> shift) & 0xff) + 1];
    for (int d = 0; d < 256; ++d) start[d + 1] += start[d];
    for (const std::uint64_t k : keys) other[start[(k >> shift) & 0xff]++] = k;
    keys.swap(other);
  }
}

}  // namespace

void sort_nearest_first(std::vector<const TriangleSetup*>& triangles) {
  thread_local std::vector<std::uint64_t> keys;
  keys.clear();
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    keys.push_back(std::uint64_t(nearest_depth_key(*triangles[i])) << 32 | std::uint64_t(i));
  }
  thread_local std::vector<std::uint64_t> other;
  sort_keys(keys, other);
  // The permutation: each key's low half is its triangle's old position.
  thread_local std::vector<const TriangleSetup*> sorted;
  sorted.resize(triangles.size());
  for (std::size_t k = 0; k < keys.size(); ++k) sorted[k] = triangles[keys[k] & 0xffffffffu];
  triangles.swap(sorted);
}

}  // namespace covrast::detail
