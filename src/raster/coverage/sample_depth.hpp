// Coverage mode: the per-sample depth test of one triangle against the 256 samples of a
// pixel, used where the A-buffer resolves a pixel by its samples (abuffer_visibility.cpp) and
// where an overflowed pixel keeps them (abuffer_samples.cpp).
//
// For every sample s set in `owned` (the triangle's sample mask, sample_mask.hpp):
//
//   z_s = (z0 + dzdx * X_s) + dzdy * Y_s                      (double, in this order, no FMA)
//   won <=> z_s < best_z[s]  or  (z_s == best_z[s] and primitive < best_primitive[s])
//
// with (X_s, Y_s) the sample's offset from the pixel's top-left corner [px] (kSampleOffsetX,
// kSampleOffsetY) and z0 the plane at that corner. A won sample takes best_z[s] = z_s and
// best_primitive[s] = primitive; the others are untouched. Nearer wins, and at equal depth the
// earlier triangle (lower primitive index): a total order, so the winners do not depend on
// the order triangles are tested in. Returns the mask of the samples won.
//
// depth_test_samples_simd is one Highway source (sample_depth.cpp) dispatched to the best
// target; depth_test_samples_scalar (sample_depth_scalar.cpp) is its twin, the formula sample
// by sample over the owned samples only. depth_test_samples takes the twin for masks of fewer
// than kSparseMaskSamples samples, where visiting only those is cheaper, and the vectors
// otherwise. The SIMD lanes do the same IEEE operations per sample (a multiply, an add, a
// multiply, an add, -ffp-contract=off), so the bits are the same on every target
// (tests/test_sample_depth.cpp checks it on each).
#pragma once

#include "raster/coverage/sample_mask.hpp"

#include <cstdint>

namespace covrast::detail {

/// A depth plane over one pixel: z at the pixel's top-left corner and its slopes [1/px].
struct PixelPlane {
  double z0, dzdx, dzdy;
};

/// Below this many owned samples depth_test_samples runs the twin (measured on
/// ReciprocatingSaw, whose sub-pixel triangles own a few samples each, and DamagedHelmet).
inline constexpr int kSparseMaskSamples = 64;

SampleMask depth_test_samples(const PixelPlane& plane, const SampleMask& owned,
                              std::uint64_t primitive, double* best_z,
                              std::uint64_t* best_primitive);

SampleMask depth_test_samples_simd(const PixelPlane& plane, const SampleMask& owned,
                                   std::uint64_t primitive, double* best_z,
                                   std::uint64_t* best_primitive);

SampleMask depth_test_samples_scalar(const PixelPlane& plane, const SampleMask& owned,
                                     std::uint64_t primitive, double* best_z,
                                     std::uint64_t* best_primitive);

}  // namespace covrast::detail
