// Raster stage: the factories of the per-mode tile rasterizers (src/raster/<mode>/), and the
// one that picks by render mode (rasterizers.cpp). The pipeline includes only this header
// and core/tile_raster.hpp of the raster stage.
#pragma once

#include "core/tile_raster.hpp"

#include <covrast/options.hpp>

#include <memory>

namespace covrast::detail {

std::unique_ptr<TileRasterizer> make_tile_rasterizer(const RenderMode& mode, int tile_px);

// Factories of the individual modes (raster/<mode>/*.cpp).
std::unique_ptr<TileRasterizer> make_aliased_rasterizer(int tile_px);
std::unique_ptr<TileRasterizer> make_coverage_rasterizer(int tile_px, bool blend);
/// ssaa:N, ssaa-grid:N and ssaa-cmj:N (mode.kind picks the pattern, mode.samples is N).
std::unique_ptr<TileRasterizer> make_ssaa_rasterizer(int tile_px, const RenderMode& mode);
std::unique_ptr<TileRasterizer> make_msaa_rasterizer(int tile_px, int k);
std::unique_ptr<TileRasterizer> make_reference_rasterizer(int tile_px);

}  // namespace covrast::detail
