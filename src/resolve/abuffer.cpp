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

/// Adjacent pieces of a conforming tessellation share a vertex (an edge, or a fan's centre).
/// A fold of one mesh over itself shares none with what it covers, or, folded over a shared
/// edge, has the opposite facing.
bool share_vertex(const TriangleSetup& a, const TriangleSetup& b) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (a.x_fx8[i] == b.x_fx8[j] && a.y_fx8[i] == b.y_fx8[j]) return true;
    }
  }
  return false;
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
  opaque_z_.resize(n);
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

/// order_of, decided in most cases from the planes' difference at the pixel centre and a
/// bound on how far it can move towards a corner: |d(corner) - d(centre)| <=
/// (|ddz/dx| + |ddz/dy|) / 2. Near ties it falls back to the exact corner comparison.
DepthOrder ABufferTile::order_against_opaque(const TriangleSetup& t, double t_centre_z,
                                             std::size_t pixel, int x, int y) const {
  const TriangleSetup& o = *opaque_[pixel];
  const double d = t_centre_z - opaque_z_[pixel];
  const double reach = 0.5 * (std::fabs(t.dzdx - o.dzdx) + std::fabs(t.dzdy - o.dzdy));
  constexpr double kMargin = 1e-12;  // far above the rounding of z in [0, 1]
  if (d + reach < -kMargin) return DepthOrder::InFront;
  if (d - reach > kMargin) return DepthOrder::Behind;
  return order_of(t, o, x, y);
}

void ABufferTile::add(int x, int y, const TriangleSetup* t, std::uint32_t coverage) {
  const std::size_t pixel = std::size_t(y - rect_.y0) * stride_ + (x - rect_.x0);
  const double centre_z = t->depth_at(x + 0.5, y + 0.5);
  if (opaque_[pixel] == nullptr) {
    if (coverage == std::uint32_t(kCoverageOne)) {
      opaque_[pixel] = t;
      opaque_z_[pixel] = centre_z;
      return;
    }
  } else {
    switch (order_against_opaque(*t, centre_z, pixel, x, y)) {
      case DepthOrder::InFront:
        // A fully covered pixel is an ordinary depth test.
        if (coverage == std::uint32_t(kCoverageOne)) {
          opaque_[pixel] = t;
          opaque_z_[pixel] = centre_z;
          return;
        }
        break;
      case DepthOrder::Behind:
        return;  // hidden everywhere in the pixel
      case DepthOrder::Crossing:
        break;  // kept as a fragment, resolved per sample
    }
  }
  add_fragment(pixel, x, y, t, coverage);
}

void ABufferTile::merge_into(Fragment& f, std::uint32_t coverage, std::uint64_t mask,
                             glm::vec3 color, int x, int y) {
  if (!f.merged) {
    f.mask = sample_mask(*f.triangle, x, y);
    f.color = shade(*f.triangle, x + 0.5, y + 0.5, true);
    f.weight = f.coverage;
    f.merged = true;
  }
  f.mask |= mask;
  // Running coverage-weighted mean of the pieces' colours.
  const std::uint32_t weight = f.weight + coverage;
  if (weight > 0) {
    f.color = (f.color * float(f.weight) + color * float(coverage)) / float(weight);
  }
  f.weight = weight;
  f.coverage = std::min<std::uint32_t>(f.coverage + coverage, kCoverageOne);
}

bool ABufferTile::handle_overflow(std::size_t pixel, int x, int y, const TriangleSetup* t,
                                  std::uint32_t coverage) {
  ++overflows_;
  // 1. Drop fragments that the opaque surface now hides everywhere.
  if (const TriangleSetup* opaque = opaque_[pixel]; opaque != nullptr) {
    std::uint32_t kept = kEnd, last = kEnd;
    int n = 0;
    for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
      if (order_of(*pool_[f].triangle, *opaque, x, y) == DepthOrder::Behind) continue;
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
    if (n < kMaxFragmentsPerPixel) return false;
  }
  // 2. Merge the new fragment into an adjacent fragment of its surface, else any of it.
  std::uint32_t same = kEnd;
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    const TriangleSetup& o = *pool_[f].triangle;
    if (!same_surface(o, *t)) continue;
    if (share_vertex(o, *t)) {
      same = f;
      break;
    }
    if (same == kEnd) same = f;
  }
  if (same != kEnd) {
    merge_into(pool_[same], coverage, sample_mask(*t, x, y), shade(*t, x + 0.5, y + 0.5, true), x,
               y);
    return true;
  }
  // 3. Merge two fragments of one surface already in the list, freeing a slot.
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    std::uint32_t prev = f;
    for (std::uint32_t g = pool_[f].next; g != kEnd; prev = g, g = pool_[g].next) {
      if (!same_surface(*pool_[f].triangle, *pool_[g].triangle)) continue;
      Fragment& victim = pool_[g];
      merge_into(pool_[f], victim.merged ? victim.weight : victim.coverage,
                 victim.merged ? victim.mask : sample_mask(*victim.triangle, x, y),
                 victim.merged ? victim.color : shade(*victim.triangle, x + 0.5, y + 0.5, true), x,
                 y);
      pool_[prev].next = victim.next;
      if (tail_[pixel] == g) tail_[pixel] = prev;
      --count_[pixel];
      return false;
    }
  }
  // 4. Sixteen different surfaces in one pixel: keep the larger areas.
  std::uint32_t smallest = head_[pixel];
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    if (pool_[f].coverage < pool_[smallest].coverage) smallest = f;
  }
  if (coverage > pool_[smallest].coverage) {
    pool_[smallest].triangle = t;
    pool_[smallest].coverage = coverage;
    pool_[smallest].merged = false;
  }
  return true;
}

void ABufferTile::add_fragment(std::size_t pixel, int x, int y, const TriangleSetup* t,
                               std::uint32_t coverage) {
  if (count_[pixel] >= kMaxFragmentsPerPixel && handle_overflow(pixel, x, y, t, coverage)) {
    return;
  }
  std::uint32_t index = std::uint32_t(pool_.size());
  pool_.push_back(Fragment{t, kEnd, coverage, 0, glm::vec3(0.0f), 0, false});
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
  depth =
      opaque != nullptr ? float(opaque->depth_at(cx, cy)) : std::numeric_limits<float>::infinity();
  if (head_[pixel] == kEnd) return behind;

  const DepthRange opaque_range =
      opaque != nullptr ? depth_range(*opaque, x, y) : DepthRange{kFar, kFar};
  const TriangleSetup* tri[kMaxFragmentsPerPixel];
  std::uint32_t cov[kMaxFragmentsPerPixel];
  DepthRange range[kMaxFragmentsPerPixel];
  int group[kMaxFragmentsPerPixel];
  // A group is one layer of one surface: fragments of the same mesh instance and facing,
  // connected through shared vertices. Its pieces do not overlap, so their exact areas add.
  std::uint64_t merged_mask[kMaxFragmentsPerPixel];
  bool merged[kMaxFragmentsPerPixel];
  glm::vec3 merged_color[kMaxFragmentsPerPixel];
  int n = 0;
  bool crossing = false;  // some fragment's plane crosses the opaque one in this pixel
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    const TriangleSetup* t = pool_[f].triangle;
    // Range over the pixel from the centre: z(centre) -+ (|dz/dx| + |dz/dy|) / 2.
    const double centre_z = t->depth_at(cx, cy);
    const double reach = 0.5 * (std::fabs(t->dzdx) + std::fabs(t->dzdy));
    const DepthRange r{centre_z - reach, centre_z + reach};
    if (opaque != nullptr) {
      DepthOrder order = r.max < opaque_range.min    ? DepthOrder::InFront
                         : r.min >= opaque_range.max ? DepthOrder::Behind
                                                     : order_of(*t, *opaque, x, y);
      if (order == DepthOrder::Behind) continue;  // hidden: the opaque surface came later
      if (order == DepthOrder::Crossing) crossing = true;
    }
    tri[n] = t;
    cov[n] = pool_[f].coverage;
    range[n] = r;
    merged[n] = pool_[f].merged;
    merged_color[n] = pool_[f].color;
    merged_mask[n] = pool_[f].mask;
    depth = std::min(depth, float(centre_z));
    ++n;
  }
  if (n == 0) return behind;

  // Union-find over at most 16 fragments, then per-group sums and depth ranges.
  int parent[kMaxFragmentsPerPixel];
  for (int i = 0; i < n; ++i) parent[i] = i;
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      // A merged fragment already stands for adjacent pieces of its surface.
      if (same_surface(*tri[i], *tri[j]) &&
          (merged[i] || merged[j] || share_vertex(*tri[i], *tri[j]))) {
        parent[root(j)] = root(i);
      }
    }
  }
  struct Group {
    std::uint32_t coverage;
    DepthRange range;
  } groups[kMaxFragmentsPerPixel];
  int group_of_root[kMaxFragmentsPerPixel];
  int group_count = 0;
  for (int i = 0; i < n; ++i) group_of_root[i] = -1;
  for (int i = 0; i < n; ++i) {
    int r = root(i);
    if (group_of_root[r] < 0) {
      group_of_root[r] = group_count;
      groups[group_count++] = Group{0, range[i]};
    }
    Group& g = groups[group_of_root[r]];
    group[i] = group_of_root[r];
    g.coverage += cov[i];
    g.range.min = std::min(g.range.min, range[i].min);
    g.range.max = std::max(g.range.max, range[i].max);
  }

  double weight[kMaxFragmentsPerPixel];
  int front = 0;  // the group nearest at its nearest point
  for (int g = 1; g < group_count; ++g) {
    if (groups[g].range.min < groups[front].range.min) front = g;
  }
  bool front_separate = !crossing;
  for (int g = 0; g < group_count; ++g) {
    if (g != front && !(groups[front].range.max < groups[g].range.min)) front_separate = false;
  }
  if (front_separate &&
      (group_count == 1 || groups[front].coverage >= std::uint32_t(kCoverageOne))) {
    // One surface in front of everything else in this pixel: its exact areas add, and when
    // they fill the pixel nothing behind shows. (Weights are normalised below if > 1.)
    for (int i = 0; i < n; ++i) {
      weight[i] = group[i] == front ? double(cov[i]) / kCoverageOne : 0.0;
    }
  } else {
    // Visibility per sub-pixel sample, with per-sample depth from each plane.
    std::uint64_t mask[kMaxFragmentsPerPixel];
    int won[kMaxFragmentsPerPixel] = {};
    double winner_z[64];
    for (int i = 0; i < n; ++i) mask[i] = merged[i] ? merged_mask[i] : sample_mask(*tri[i], x, y);
    for (int s = 0; s < 64; ++s) {
      const double sx = x + ((s & 7) + 0.5) / 8.0, sy = y + ((s >> 3) + 0.5) / 8.0;
      int best = -1;
      double best_z =
          opaque != nullptr ? opaque->depth_at(sx, sy) : std::numeric_limits<double>::infinity();
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
      winner_z[s] = best_z;
    }
    for (int i = 0; i < n; ++i) {
      int samples = std::popcount(mask[i]);
      double share;
      if (samples > 0) {
        share = double(won[i]) / samples;
      } else {
        // Too small to own a sample: spread it over the pixel, and count the samples where
        // its plane would be nearer than what won them.
        int nearer = 0;
        for (int s = 0; s < 64; ++s) {
          const double sx = x + ((s & 7) + 0.5) / 8.0, sy = y + ((s >> 3) + 0.5) / 8.0;
          nearer += tri[i]->depth_at(sx, sy) < winner_z[s];
        }
        share = nearer / 64.0;
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
    const glm::vec3 c = merged[i] ? merged_color[i] : shade(*tri[i], cx, cy, true);
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
  return opaque_.size() *
             (sizeof(void*) + 2 * sizeof(std::uint32_t) + 1 + sizeof(glm::vec3) + sizeof(float)) +
         pool_.capacity() * sizeof(Fragment);
}

}  // namespace covrast::detail
