// Binning stage implementation: a two-pass counting sort of (tile, triangle) pairs.
#include "binning/tile_bins.hpp"

#include <algorithm>

namespace covrast::detail {
namespace {

/// Tiles overlapped by the triangle's touched-pixel rectangle, clamped to the grid.
struct TileSpan {
  int tx0, ty0, tx1, ty1;  ///< [tx0, tx1) x [ty0, ty1)
};

TileSpan tiles_touched(const TileGrid& grid, const TriangleSetup& t) {
  PixelRect r = intersect(touched_pixels(t), PixelRect{0, 0, grid.width_px, grid.height_px});
  if (r.empty()) return {0, 0, 0, 0};
  return {r.x0 / grid.tile_px, r.y0 / grid.tile_px, (r.x1 - 1) / grid.tile_px + 1,
          (r.y1 - 1) / grid.tile_px + 1};
}

}  // namespace

void bin_chunk(const TileGrid& grid, std::span<const TriangleSetup> triangles, ChunkBins& bins,
               std::vector<std::uint32_t>& cursor) {
  const int tiles = grid.tile_count();
  bins.tile_begin.assign(std::size_t(tiles) + 1, 0);
  // Pass 1: count entries per tile (shifted by one for the prefix sum).
  for (const TriangleSetup& t : triangles) {
    TileSpan s = tiles_touched(grid, t);
    for (int ty = s.ty0; ty < s.ty1; ++ty) {
      for (int tx = s.tx0; tx < s.tx1; ++tx) ++bins.tile_begin[std::size_t(ty) * grid.tiles_x + tx + 1];
    }
  }
  for (int i = 0; i < tiles; ++i) bins.tile_begin[i + 1] += bins.tile_begin[i];
  bins.triangle_index.resize(bins.tile_begin[tiles]);
  // Pass 2: place triangle indices; ascending within a tile because we scan in order.
  cursor.assign(bins.tile_begin.begin(), bins.tile_begin.end() - 1);
  for (std::uint32_t i = 0; i < triangles.size(); ++i) {
    TileSpan s = tiles_touched(grid, triangles[i]);
    for (int ty = s.ty0; ty < s.ty1; ++ty) {
      for (int tx = s.tx0; tx < s.tx1; ++tx) {
        bins.triangle_index[cursor[std::size_t(ty) * grid.tiles_x + tx]++] = i;
      }
    }
  }
}

}  // namespace covrast::detail
