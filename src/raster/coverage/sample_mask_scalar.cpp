// Coverage mode: the scalar twin and reference of the 256-sample sub-pixel mask
// (sample_mask.hpp): the three int64 edge functions at each sample, from their definition.
#include "core/edge_function.hpp"
#include "raster/coverage/sample_mask.hpp"

namespace covrast::detail {

SampleMask pixel_sample_mask_scalar(const TriangleSetup& t, int x, int y) {
  const TriangleEdges edges(t);
  const std::int64_t px0 = std::int64_t(x) * kMaskUnitsPerPixel;
  const std::int64_t py0 = std::int64_t(y) * kMaskUnitsPerPixel;
  SampleMask mask = SampleMask::none();
  for (int k = 0; k < kMaskSamples; ++k) {
    const std::int64_t px = px0 + kMaskSampleX_fx9[std::size_t(k)];
    const std::int64_t py = py0 + kMaskSampleY_fx9[std::size_t(k)];
    bool inside = true;
    for (const EdgeFunction& e : edges.e) {
      inside = inside && e.dx * (py - 2 * e.y0) - e.dy * (px - 2 * e.x0) + e.bias >= 0;
    }
    if (inside) mask.word[k >> 6] |= std::uint64_t(1) << (k & 63);
  }
  return mask;
}

}  // namespace covrast::detail
