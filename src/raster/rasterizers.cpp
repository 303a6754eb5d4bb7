// Raster stage: the tile rasterizer of a render mode.
#include "raster/rasterizers.hpp"

#include <covrast/error.hpp>

namespace covrast::detail {

std::unique_ptr<TileRasterizer> make_tile_rasterizer(const RenderMode& mode, int tile_px) {
  switch (mode.kind) {
    case ModeKind::Aliased:
    case ModeKind::Fxaa:  // the pipeline runs FXAA on the finished aliased frame
      return make_aliased_rasterizer(tile_px);
    case ModeKind::Coverage:
      return make_coverage_rasterizer(tile_px, false);
    case ModeKind::CoverageBlend:
      return make_coverage_rasterizer(tile_px, true);
    case ModeKind::Ssaa:
    case ModeKind::SsaaGrid:
    case ModeKind::SsaaCmj:
      return make_ssaa_rasterizer(tile_px, mode);
    case ModeKind::Msaa:
      return make_msaa_rasterizer(tile_px, mode.samples);
    case ModeKind::Reference:
      return make_reference_rasterizer(tile_px);
  }
  throw InputError("mode '" + to_string(mode) + "' is not available in this build yet");
}

}  // namespace covrast::detail
