// Raster stage, coverage mode: pixels whose fragment list overflowed, kept as depth-tested
// samples at the sample masks' positions (ABufferTile::PixelSamples), and their resolve.
#include "raster/coverage/abuffer.hpp"

#include "raster/coverage/abuffer_planes.hpp"
#include "raster/coverage/fragment_shading.hpp"
#include "raster/coverage/sample_depth.hpp"

#include <algorithm>
#include <limits>

namespace covrast::detail {

bool ABufferTile::overflow_fragment(std::size_t pixel, int x, int y, const TriangleSetup* t,
                                    std::uint32_t coverage, double centre_z) {
  ++overflows_;
  if (layer_[pixel] == Layer::Sampled) {
    if (add_to_samples(pixel, x, y, *t)) bound_by_samples(pixel);
    return true;
  }
  if (open_count_[pixel] != 0 && joins_open_set(pixel, *t) &&
      merge_into_open_set(pixel, x, y, *t, coverage, centre_z)) {
    return true;
  }
  switch (drop_hidden(pixel, x, y, *t)) {
    case Compaction::NewHidden:
      return true;
    case Compaction::Room:
      return false;  // add_fragment stores t
    case Compaction::Full:
      break;
  }
  to_samples(pixel, x, y);
  add_to_samples(pixel, x, y, *t);
  bound_by_samples(pixel);  // once the list and t are all in the samples
  return true;
}

void ABufferTile::to_samples(std::size_t pixel, int x, int y) {
  const std::uint32_t slot = std::uint32_t(samples_.size());
  samples_.emplace_back();
  PixelSamples& samples = samples_.back();
  const TriangleSetup* opaque = opaque_[pixel];
  if (opaque != nullptr) {
    const SamplePlane plane(*opaque, x, y);
    for (int s = 0; s < kMaskSamples; ++s) samples.z[s] = plane.at(s);
  } else {
    std::fill(samples.z, samples.z + kMaskSamples, kFar);
  }
  std::fill(samples.primitive, samples.primitive + kMaskSamples,
            opaque != nullptr ? opaque->primitive : 0);
  std::fill(samples.winner, samples.winner + kMaskSamples, opaque);
  const int opaque_owned = opaque != nullptr ? pixel_sample_mask(*opaque, x, y).count() : 0;
  std::fill(samples.winner_owned, samples.winner_owned + kMaskSamples, std::uint16_t(opaque_owned));
  // The stored fragments, in list order (merged ones by their pieces, which they always know:
  // merges happen only inside the open set), then the list is gone.
  const std::uint32_t head = head_[pixel];
  layer_[pixel] = Layer::Sampled;
  tail_[pixel] = slot;
  count_[pixel] = std::uint8_t(kMaxFragmentsPerPixel);  // every later fragment comes here
  for (std::uint32_t f = head; f != kEnd; f = pool_[f].next) {
    if (!(pool_[f].coverage & kMergedFlag)) {
      add_to_samples(pixel, x, y, *pool_[f].triangle);
      continue;
    }
    const MergedPiece& m = merged_piece(f);  // an open-set member: its pieces, one by one
    for (int k = 0; k < m.pieces; ++k) add_to_samples(pixel, x, y, *m.piece[k]);
  }
  head_[pixel] = kEnd;
  open_count_[pixel] = closed_count_[pixel] = 0;
}

void ABufferTile::bound_by_samples(std::size_t pixel) {
  // The farthest sample depth: a later triangle whose plane lies behind it all over the pixel
  // wins no sample (ties go to the earlier triangle, and later ones come later in the
  // primitive order too), so add() drops it before computing a mask. Four running maxima so
  // that the loop has no carried dependency of one compare per sample.
  const PixelSamples& samples = samples_[tail_[pixel]];
  double far[4] = {samples.z[0], samples.z[1], samples.z[2], samples.z[3]};
  for (int s = 4; s < kMaskSamples; s += 4) {
    for (int k = 0; k < 4; ++k) far[k] = samples.z[s + k] > far[k] ? samples.z[s + k] : far[k];
  }
  const double farthest = std::max(std::max(far[0], far[1]), std::max(far[2], far[3]));
  // The margin keeps the test on the safe side of the rounding of the centre depth, the
  // reach and each sample's plane value.
  occluder_z_[pixel] = std::min(occluder_z_[pixel], farthest + kOccluderMargin);
}

bool ABufferTile::add_to_samples(std::size_t pixel, int x, int y, const TriangleSetup& t) {
  PixelSamples& samples = samples_[tail_[pixel]];
  const SampleMask mask = pixel_sample_mask(t, x, y);
  const SamplePlane plane(t, x, y);
  // The order of sample_weights: nearer wins; at equal depth the earlier triangle.
  const SampleMask won = depth_test_samples(PixelPlane{plane.z0, plane.dzdx, plane.dzdy}, mask,
                                            t.primitive, samples.z, samples.primitive);
  const auto owned = std::uint16_t(mask.count());
  for_each_sample(won, [&](int s) {
    samples.winner[s] = &t;
    samples.winner_owned[s] = owned;
  });
  return won != SampleMask::none();
}

glm::vec3 ABufferTile::resolve_samples(std::size_t pixel, int x, int y, glm::vec3 background,
                                       float& depth, const Transmittance* tr) {
  // Each triangle that won samples shows over its exact area times the share of its own
  // samples that it won (as sample_weights weighs fragments), and the background over its
  // share of the samples. A piece too thin to own a sample drops out, so the triangles'
  // weights are scaled to fill what the background leaves: the pieces of a tessellation
  // still cover the pixel, and no background leaks where none shows.
  const PixelSamples& samples = samples_[tail_[pixel]];
  const TriangleSetup* winner[kMaskSamples];
  int won[kMaskSamples], owned[kMaskSamples];
  int winners = 0, background_won = 0;
  const TriangleSetup* last = nullptr;
  int last_slot = -1;
  depth = std::numeric_limits<float>::infinity();
  for (int s = 0; s < kMaskSamples; ++s) {
    const TriangleSetup* w = samples.winner[s];
    if (w == nullptr) {
      ++background_won;
      continue;
    }
    depth = std::min(depth, float(samples.z[s]));
    if (w != last) {  // winners come in runs: look each run's up once
      last = w;
      last_slot = int(std::find(winner, winner + winners, w) - winner);
      if (last_slot == winners) {
        winner[winners] = w;
        owned[winners] = samples.winner_owned[s];
        won[winners++] = 0;
      }
    }
    ++won[last_slot];
  }
  double weight[kMaskSamples];
  double total = 0.0;
  for (int k = 0; k < winners; ++k) {
    const double area = std::clamp(polygon_area(part_in_pixel(*winner[k], x, y)), 0.0, 1.0);
    weight[k] =
        owned[k] > 0 && area > 0.0 ? area * won[k] / owned[k] : double(won[k]) / kMaskSamples;
    total += weight[k];
  }
  const double background_share = double(background_won) / kMaskSamples;
  const double scale = total > 0.0 ? (1.0 - background_share) / total : 0.0;
  if (tr != nullptr) background *= glm::vec3(tr->of(nullptr));
  double rgb[3] = {background_share * background.r, background_share * background.g,
                   background_share * background.b};
  for (int k = 0; k < winners; ++k) {
    add_kept(rgb, weight[k] * scale, tr, winner[k], shade_fragment(*winner[k], x, y));
  }
  return glm::vec3(float(rgb[0]), float(rgb[1]), float(rgb[2]));
}
}  // namespace covrast::detail
