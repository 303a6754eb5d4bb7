// Coverage mode: the per-sample depth test's scalar twin (sample_depth.hpp), the formula
// sample by sample; sample_depth.cpp must give the same bits on every SIMD target.
#include "raster/coverage/sample_depth.hpp"

namespace covrast::detail {

SampleMask depth_test_samples_scalar(const PixelPlane& plane, const SampleMask& owned,
                                     std::uint64_t primitive, double* best_z,
                                     std::uint64_t* best_primitive) {
  SampleMask won = SampleMask::none();
  for_each_sample(owned, [&](int s) {
    const double z = plane.z0 + plane.dzdx * kSampleOffsetX[std::size_t(s)] +
                     plane.dzdy * kSampleOffsetY[std::size_t(s)];
    if (z < best_z[s] || (z == best_z[s] && primitive < best_primitive[s])) {
      best_z[s] = z;
      best_primitive[s] = primitive;
      won.word[s >> 6] |= std::uint64_t(1) << (s & 63);
    }
  });
  return won;
}

}  // namespace covrast::detail
