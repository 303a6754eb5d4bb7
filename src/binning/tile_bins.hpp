// Binning stage: which triangles touch which screen tile.
//
// Like llvmpipe's bins, but built without locks: each setup chunk bins its own triangles
// (a counting sort by tile), and a tile reads the chunks in order. Submission order per
// tile is therefore the global draw order, whatever the thread count.
#pragma once

#include "core/triangle_setup.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace covrast::detail {

/// The fixed tile grid of a frame. It depends only on the image size and tile side.
struct TileGrid {
  int width_px = 0;
  int height_px = 0;
  int tile_px = 64;  ///< tile side [pixels]
  int tiles_x = 0;
  int tiles_y = 0;

  TileGrid() = default;
  TileGrid(int width, int height, int tile)
      : width_px(width),
        height_px(height),
        tile_px(tile),
        tiles_x((width + tile - 1) / tile),
        tiles_y((height + tile - 1) / tile) {}
  int tile_count() const { return tiles_x * tiles_y; }
  PixelRect tile_rect(int tile) const {
    int tx = tile % tiles_x, ty = tile / tiles_x;
    return PixelRect{tx * tile_px, ty * tile_px, std::min(width_px, (tx + 1) * tile_px),
                     std::min(height_px, (ty + 1) * tile_px)};
  }
};

/// One chunk's triangles, grouped by tile: the triangles of tile t are
/// triangle_index[tile_begin[t] .. tile_begin[t + 1]), indices into the chunk's setups,
/// ascending.
struct ChunkBins {
  std::vector<std::uint32_t> tile_begin;
  std::vector<std::uint32_t> triangle_index;

  std::span<const std::uint32_t> tile(int t) const {
    return {triangle_index.data() + tile_begin[t], tile_begin[t + 1] - tile_begin[t]};
  }
};

/// Bins one chunk from the clamped pixel bounds that setup stored next to its triangles
/// (bounds[i] belongs to triangle i), without reading the setups. `scratch` is reused between
/// calls to avoid allocation.
void bin_chunk(const TileGrid& grid, std::span<const PixelBounds16> bounds, ChunkBins& bins,
               std::vector<std::uint32_t>& scratch);

/// Coverage mode's draw order for one tile: `triangles` (in submission order) reordered
/// nearest first, by the least window depth of each triangle's plane at its three vertices
/// (the plane is linear, so that is its nearest point) rounded to a float's top 24 bits; equal
/// keys keep submission order, so the order is a total one that every tile and thread count
/// shares.
/// Why nearest first: the A-buffer drops what lies behind a proven layer or closed set as it
/// arrives, and skips a triangle hidden all over its box before its area kernel runs
/// (docs/coverage.md, section 2, "Draw order"); what arrives before its occluder is logged,
/// masked and resolved instead. Its scratch is the calling thread's, reused between calls.
void sort_nearest_first(std::vector<const TriangleSetup*>& triangles);

}  // namespace covrast::detail
