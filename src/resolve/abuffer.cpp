// Resolve stage, coverage mode: the A-buffer; see abuffer.hpp.
#include "resolve/abuffer.hpp"

#include "raster/coverage_kernel.hpp"
#include "raster/edge_function.hpp"
#include "raster/shading.hpp"
#include "resolve/srgb8.hpp"

#include <bit>
#include <limits>

namespace covrast::detail {
namespace {

/// Window depth of a triangle's plane at the four corners of pixel (x, y), always from the
/// same operations so that every comparison below sees the same numbers.
struct CornerDepths {
  double z[4];
  double min() const { return std::min(std::min(z[0], z[1]), std::min(z[2], z[3])); }
  double max() const { return std::max(std::max(z[0], z[1]), std::max(z[2], z[3])); }
};

CornerDepths corner_depths(const TriangleSetup& t, int x, int y) {
  const double z = t.depth_at(x, y);
  return {{z, z + t.dzdx, z + t.dzdy, (z + t.dzdx) + t.dzdy}};
}

struct DepthRange {
  double min;
  double max;
};
constexpr double kFar = std::numeric_limits<double>::infinity();

DepthRange depth_range(const TriangleSetup& t, int x, int y) {
  CornerDepths c = corner_depths(t, x, y);
  return {c.min(), c.max()};
}

/// How plane `t` lies against plane `other` over pixel (x, y). Both are affine, so their
/// difference is extreme at the corners: nearer at all four corners is in front; farther or
/// equal at all four is behind (equal depth keeps the earlier triangle); else they cross.
enum class DepthOrder { InFront, Behind, Crossing };

DepthOrder order_of(const TriangleSetup& t, const TriangleSetup& other, int x, int y) {
  CornerDepths a = corner_depths(t, x, y), b = corner_depths(other, x, y);
  if (a.max() < b.min()) return DepthOrder::InFront;
  if (a.min() >= b.max()) return DepthOrder::Behind;
  int nearer = 0;
  for (int k = 0; k < 4; ++k) nearer += a.z[k] < b.z[k];
  if (nearer == 4) return DepthOrder::InFront;
  if (nearer == 0) return DepthOrder::Behind;
  return DepthOrder::Crossing;
}

bool same_surface(const TriangleSetup& a, const TriangleSetup& b) {
  return a.surface == b.surface && a.front_facing == b.front_facing;
}

/// Samples of an 8x8 grid at ((i + 0.5) / 8, (j + 0.5) / 8) inside pixel (x, y), bit
/// j * 8 + i, that the triangle owns under the top-left rule.
std::uint64_t sample_mask(const TriangleSetup& t, int x, int y) {
  TriangleEdges edges(t);
  constexpr std::int64_t kStep = kSubpixelOne / 8;  // 32 fx8 units
  const std::int64_t sx = std::int64_t(x) * kSubpixelOne + kStep / 2;
  const std::int64_t sy = std::int64_t(y) * kSubpixelOne + kStep / 2;
  std::uint64_t mask = 0;
  std::int64_t row[3], dx[3], dy[3];
  for (int e = 0; e < 3; ++e) {
    row[e] = edges.e[e].at(sx, sy);
    dx[e] = edges.e[e].step_x(kStep);
    dy[e] = edges.e[e].step_y(kStep);
  }
  for (int j = 0; j < 8; ++j) {
    std::int64_t e0 = row[0], e1 = row[1], e2 = row[2];
    for (int i = 0; i < 8; ++i) {
      if ((e0 | e1 | e2) >= 0) mask |= std::uint64_t(1) << (j * 8 + i);
      e0 += dx[0];
      e1 += dx[1];
      e2 += dx[2];
    }
    for (int e = 0; e < 3; ++e) row[e] += dy[e];
  }
  return mask;
}

}  // namespace

ABufferTile::ABufferTile(int tile_px) : stride_(tile_px) {
  std::size_t n = std::size_t(tile_px) * tile_px;
  opaque_.resize(n);
  head_.resize(n);
  tail_.resize(n);
  count_.resize(n);
  color_.resize(n);
  depth_.resize(n);
}

void ABufferTile::begin_tile(const PixelRect& rect) {
  rect_ = rect;
  std::fill(opaque_.begin(), opaque_.end(), nullptr);
  std::fill(head_.begin(), head_.end(), kEnd);
  std::fill(count_.begin(), count_.end(), 0);
  pool_.clear();
}

void ABufferTile::add(int x, int y, const TriangleSetup* t, std::uint32_t coverage) {
  const std::size_t pixel = std::size_t(y - rect_.y0) * stride_ + (x - rect_.x0);
  const TriangleSetup* opaque = opaque_[pixel];
  if (coverage == std::uint32_t(kCoverageOne)) {
    // Fast path: a fully covered pixel is an ordinary depth test, unless the planes cross.
    if (opaque == nullptr) {
      opaque_[pixel] = t;
      return;
    }
    switch (order_of(*t, *opaque, x, y)) {
      case DepthOrder::InFront:
        opaque_[pixel] = t;
        return;
      case DepthOrder::Behind:
        return;
      case DepthOrder::Crossing:
        break;
    }
  } else if (opaque != nullptr && order_of(*t, *opaque, x, y) == DepthOrder::Behind) {
    return;  // hidden everywhere in the pixel
  }
  add_fragment(pixel, x, y, t, coverage);
}

void ABufferTile::add_fragment(std::size_t pixel, int x, int y, const TriangleSetup* t,
                               std::uint32_t coverage) {
  if (count_[pixel] >= kMaxFragmentsPerPixel) {
    ++overflows_;
    // 1. Drop fragments that the opaque surface now hides everywhere.
    const TriangleSetup* opaque = opaque_[pixel];
    std::uint32_t kept = kEnd, last = kEnd;
    int n = 0;
    for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
      if (opaque != nullptr &&
          order_of(*pool_[f].triangle, *opaque, x, y) == DepthOrder::Behind) {
        continue;
      }
      if (last == kEnd) {
        kept = f;
      } else {
        pool_[last].next = f;
      }
      last = f;
      ++n;
    }
    if (last != kEnd) pool_[last].next = kEnd;
    head_[pixel] = kept;
    tail_[pixel] = last;
    count_[pixel] = std::uint8_t(n);
    if (n >= kMaxFragmentsPerPixel) {
      // 2. Merge into the oldest fragment of the same surface and facing.
      for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
        const TriangleSetup& o = *pool_[f].triangle;
        if (o.surface == t->surface && o.front_facing == t->front_facing) {
          pool_[f].coverage = std::min<std::uint32_t>(pool_[f].coverage + coverage, kCoverageOne);
          return;
        }
      }
      // 3. Keep the nearest: replace the farthest fragment if the new one is nearer.
      const double cx = x + 0.5, cy = y + 0.5;
      std::uint32_t farthest = head_[pixel];
      for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
        if (pool_[f].triangle->depth_at(cx, cy) > pool_[farthest].triangle->depth_at(cx, cy)) {
          farthest = f;
        }
      }
      if (t->depth_at(cx, cy) < pool_[farthest].triangle->depth_at(cx, cy)) {
        pool_[farthest].triangle = t;
        pool_[farthest].coverage = coverage;
      }
      return;
    }
  }
  std::uint32_t index = std::uint32_t(pool_.size());
  pool_.push_back(Fragment{t, kEnd, coverage});
  if (head_[pixel] == kEnd) {
    head_[pixel] = index;
  } else {
    pool_[tail_[pixel]].next = index;
  }
  tail_[pixel] = index;
  ++count_[pixel];
}

glm::vec3 ABufferTile::resolve_pixel(std::size_t pixel, int x, int y, glm::vec3 background,
                                     float& depth) {
  const double cx = x + 0.5, cy = y + 0.5;
  const TriangleSetup* opaque = opaque_[pixel];
  const glm::vec3 behind = opaque != nullptr ? shade(*opaque, cx, cy, true) : background;
  depth = opaque != nullptr ? float(opaque->depth_at(cx, cy))
                            : std::numeric_limits<float>::infinity();
  if (head_[pixel] == kEnd) return behind;

  const DepthRange opaque_range =
      opaque != nullptr ? depth_range(*opaque, x, y) : DepthRange{kFar, kFar};
  const TriangleSetup* tri[kMaxFragmentsPerPixel];
  std::uint32_t cov[kMaxFragmentsPerPixel];
  DepthRange range[kMaxFragmentsPerPixel];
  int group[kMaxFragmentsPerPixel];
  // Fragments of one layer of one surface form a group: in one pixel they are adjacent
  // pieces of a tessellation, and their exact areas add.
  struct Group {
    const TriangleSetup* key;
    std::uint32_t coverage;
    DepthRange range;
  } groups[kMaxFragmentsPerPixel];
  int n = 0, group_count = 0;
  bool crossing = false;  // some fragment's plane crosses the opaque one in this pixel
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    const TriangleSetup* t = pool_[f].triangle;
    DepthRange r = depth_range(*t, x, y);
    if (opaque != nullptr) {
      DepthOrder order = r.max < opaque_range.min   ? DepthOrder::InFront
                         : r.min >= opaque_range.max ? DepthOrder::Behind
                                                     : order_of(*t, *opaque, x, y);
      if (order == DepthOrder::Behind) continue;  // hidden: the opaque surface came later
      if (order == DepthOrder::Crossing) crossing = true;
    }
    // A group is one layer: the same surface, and depth ranges that meet (adjacent pieces of
    // a tessellation share an edge inside the pixel, so their ranges overlap). Two parts of
    // one mesh at different depths (a fold in front of the back) are different layers.
    int g = 0;
    while (g < group_count &&
           !(same_surface(*groups[g].key, *t) &&
             !(r.max < groups[g].range.min || groups[g].range.max < r.min))) {
      ++g;
    }
    if (g == group_count) groups[group_count++] = Group{t, 0, r};
    groups[g].coverage += pool_[f].coverage;
    groups[g].range.min = std::min(groups[g].range.min, r.min);
    groups[g].range.max = std::max(groups[g].range.max, r.max);
    tri[n] = t;
    cov[n] = pool_[f].coverage;
    range[n] = r;
    group[n] = g;
    depth = std::min(depth, float(t->depth_at(cx, cy)));
    ++n;
  }
  if (n == 0) return behind;

  double weight[kMaxFragmentsPerPixel];
  int front = 0;  // the group nearest at its nearest point
  for (int g = 1; g < group_count; ++g) {
    if (groups[g].range.min < groups[front].range.min) front = g;
  }
  bool front_separate = !crossing;
  for (int g = 0; g < group_count; ++g) {
    if (g != front && !(groups[front].range.max < groups[g].range.min)) front_separate = false;
  }
  if (front_separate && (group_count == 1 || groups[front].coverage >= std::uint32_t(kCoverageOne))) {
    // One surface in front of everything else in this pixel: its exact areas add, and when
    // they fill the pixel nothing behind shows. (Weights are normalised below if > 1.)
    for (int i = 0; i < n; ++i) {
      weight[i] = group[i] == front ? double(cov[i]) / kCoverageOne : 0.0;
    }
  } else {
    // Visibility per sub-pixel sample, with per-sample depth from each plane.
    std::uint64_t mask[kMaxFragmentsPerPixel];
    int won[kMaxFragmentsPerPixel] = {};
    for (int i = 0; i < n; ++i) mask[i] = sample_mask(*tri[i], x, y);
    for (int s = 0; s < 64; ++s) {
      const double sx = x + ((s & 7) + 0.5) / 8.0, sy = y + ((s >> 3) + 0.5) / 8.0;
      int best = -1;
      double best_z = opaque != nullptr ? opaque->depth_at(sx, sy)
                                        : std::numeric_limits<double>::infinity();
      std::uint32_t best_primitive = opaque != nullptr ? opaque->primitive : kNoTriangle;
      for (int i = 0; i < n; ++i) {
        if (!(mask[i] >> s & 1)) continue;
        double z = tri[i]->depth_at(sx, sy);
        // Nearest wins; equal depth keeps the earlier triangle.
        if (z < best_z || (z == best_z && tri[i]->primitive < best_primitive)) {
          best = i;
          best_z = z;
          best_primitive = tri[i]->primitive;
        }
      }
      if (best >= 0) ++won[best];
    }
    for (int i = 0; i < n; ++i) {
      int samples = std::popcount(mask[i]);
      double share;
      if (samples > 0) {
        share = double(won[i]) / samples;
      } else {
        // Too small to own a sample: visible if it is in front of the opaque surface.
        share = opaque == nullptr || range[i].min < opaque_range.min ? 1 : 0;
      }
      weight[i] = double(cov[i]) / kCoverageOne * share;
    }
  }
  double total = 0;
  for (int i = 0; i < n; ++i) total += weight[i];
  const double scale = total > 1.0 ? 1.0 / total : 1.0;
  const double rest = total > 1.0 ? 0.0 : 1.0 - total;
  double r = rest * behind.r, g = rest * behind.g, b = rest * behind.b;
  for (int i = 0; i < n; ++i) {
    if (weight[i] == 0) continue;
    glm::vec3 c = shade(*tri[i], cx, cy, true);
    double w = weight[i] * scale;
    r += w * c.r;
    g += w * c.g;
    b += w * c.b;
  }
  return glm::vec3(float(r), float(g), float(b));
}

void ABufferTile::resolve(const FrameTarget& target) {
  for (int y = rect_.y0; y < rect_.y1; ++y) {
    for (int x = rect_.x0; x < rect_.x1; ++x) {
      std::size_t pixel = std::size_t(y - rect_.y0) * stride_ + (x - rect_.x0);
      color_[pixel] = resolve_pixel(pixel, x, y, target.background_linear, depth_[pixel]);
    }
  }
  write_tile(target, rect_, color_.data(), depth_.data(), stride_);
}

std::size_t ABufferTile::scratch_bytes() const {
  return opaque_.size() * (sizeof(void*) + 2 * sizeof(std::uint32_t) + 1 + sizeof(glm::vec3) +
                           sizeof(float)) +
         pool_.capacity() * sizeof(Fragment);
}

}  // namespace covrast::detail
