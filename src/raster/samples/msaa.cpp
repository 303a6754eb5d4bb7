// Raster stage, msaa:K: K samples per pixel at the Direct3D 11 standard positions,
// per-sample coverage and depth (the depth plane evaluated at each sample), shading once
// per pixel and triangle at the pixel centre (barycentrics clamped inside), stored to
// every sample the triangle wins; box-filter resolve in linear light (sample_raster.hpp).
// Per-sample depth is what keeps the edge shared by a near and a far triangle free of the
// background ("black edge" of one-depth-per-pixel MSAA).
#include "core/tile_raster.hpp"
#include "raster/rasterizers.hpp"
#include "raster/samples/sample_pattern.hpp"
#include "raster/samples/sample_raster.hpp"

#include <covrast/error.hpp>

#include <string>

namespace covrast::detail {
namespace {

struct Offset16 {
  int x, y;  ///< from the pixel centre, in 1/16 pixel, y down
};

// D3D11_STANDARD_MULTISAMPLE_PATTERN (Direct3D 11 functional specification, 19.2.4).
constexpr Offset16 kD3D2[] = {{4, 4}, {-4, -4}};
constexpr Offset16 kD3D4[] = {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}};
constexpr Offset16 kD3D8[] = {{1, -3}, {-1, 3},  {5, 1}, {-3, -5},
                              {-5, 5}, {-7, -1}, {3, 7}, {7, -7}};
constexpr Offset16 kD3D16[] = {{1, 1},  {-1, -3}, {-3, 2}, {4, -1}, {-5, -2}, {2, 5},
                               {5, 3},  {3, -5},  {-2, 6}, {0, -7}, {-4, -6}, {-6, 4},
                               {-8, 0}, {7, -4},  {6, 7},  {-7, -8}};

}  // namespace

SamplePattern msaa_pattern(int k) {
  const Offset16* table = nullptr;
  switch (k) {
    case 2:
      table = kD3D2;
      break;
    case 4:
      table = kD3D4;
      break;
    case 8:
      table = kD3D8;
      break;
    case 16:
      table = kD3D16;
      break;
    default:
      throw InputError("msaa: K = " + std::to_string(k) + " not supported: must be 2, 4, 8 or 16");
  }
  SamplePattern pattern;
  pattern.unit = kSubpixelOne;
  for (int s = 0; s < k; ++s) {
    // Centre + offset / 16 pixel = (128 + 16 offset) / 256; -8 lands on the pixel's edge.
    pattern.x.push_back(kSubpixelOne / 2 + 16 * table[s].x);
    pattern.y.push_back(kSubpixelOne / 2 + 16 * table[s].y);
  }
  return pattern;
}

std::unique_ptr<TileRasterizer> make_msaa_rasterizer(int tile_px, int k) {
  return std::make_unique<SampleRasterizer>(tile_px, msaa_pattern(k), ShadingRate::PerPixel,
                                            sample_kernels_simd());
}

}  // namespace covrast::detail
