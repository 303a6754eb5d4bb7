// Tests of the 16x16 sub-pixel sample mask of the coverage resolve (src/resolve/sample_mask.hpp):
// masks computed by hand (ties of the top-left rule on sample columns and rows, a tiny
// triangle around one sample, two triangles sharing a diagonal through samples), the scalar
// reference against a direct per-sample evaluation, and every Highway target compiled and
// supported here against the scalar reference, bit for bit, on 200,000 random
// (triangle, pixel) pairs.
#include "core/edge_function.hpp"
#include "core/triangle_setup.hpp"
#include "raster/coverage/sample_mask.hpp"

#include <hwy/targets.h>

#include <catch2/catch.hpp>

#include "test_targets.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using covrast::detail::force_sample_mask_target;
using covrast::detail::kMaskGridSide;
using covrast::detail::kMaskSamples;
using covrast::detail::kSubpixelOne;
using covrast::detail::pixel_sample_mask;
using covrast::detail::pixel_sample_mask_scalar;
using covrast::detail::SampleMask;
using covrast::detail::TriangleEdges;
using covrast::detail::TriangleSetup;

using MaskFn = SampleMask (*)(const TriangleSetup&, int, int);

TriangleSetup make_triangle(std::int32_t x0, std::int32_t y0, std::int32_t x1, std::int32_t y1,
                            std::int32_t x2, std::int32_t y2) {
  TriangleSetup t{};
  t.x_fx8[0] = x0;
  t.y_fx8[0] = y0;
  t.x_fx8[1] = x1;
  t.y_fx8[1] = y1;
  t.x_fx8[2] = x2;
  t.y_fx8[2] = y2;
  return t;
}

/// Position of sample k (0..15) of pixel p along one axis [fx8]: p + (k + 0.5) / 16 pixels.
constexpr std::int32_t sample_fx8(int p, int k) { return p * kSubpixelOne + 8 + 16 * k; }

/// The mask of the samples (i, j) for which `inside(i, j)` holds: bit j * 16 + i.
template <class Inside>
SampleMask grid_mask(Inside inside) {
  SampleMask mask = SampleMask::none();
  for (int j = 0; j < kMaskGridSide; ++j) {
    for (int i = 0; i < kMaskGridSide; ++i) {
      const int s = j * kMaskGridSide + i;
      if (inside(i, j)) mask.word[s / 64] |= std::uint64_t(1) << (s % 64);
    }
  }
  return mask;
}

/// The mask from the edge functions evaluated at every sample directly (no stepping).
SampleMask direct_mask(const TriangleSetup& t, int x, int y) {
  const TriangleEdges edges(t);
  return grid_mask([&](int i, int j) {
    const std::int64_t px = std::int64_t(sample_fx8(x, i)), py = std::int64_t(sample_fx8(y, j));
    bool inside = true;
    for (const auto& e : edges.e) inside = inside && e.at(px, py) >= 0;
    return inside;
  });
}

/// Edges whose 256 samples in pixel (x, y) are neither all inside nor all outside.
int crossing_edges(const TriangleSetup& t, int x, int y) {
  const TriangleEdges edges(t);
  int crossing = 0;
  for (const auto& e : edges.e) {
    const int inside = grid_mask([&](int i, int j) {
                         return e.at(sample_fx8(x, i), sample_fx8(y, j)) >= 0;
                       }).count();
    crossing += inside > 0 && inside < kMaskSamples;
  }
  return crossing;
}

/// The mask as 64 hex digits, sample 255 first.
std::string hex(const SampleMask& m) {
  char buf[80];
  std::snprintf(
      buf, sizeof(buf), "0x%016llx%016llx%016llx%016llx",
      static_cast<unsigned long long>(m.word[3]), static_cast<unsigned long long>(m.word[2]),
      static_cast<unsigned long long>(m.word[1]), static_cast<unsigned long long>(m.word[0]));
  return buf;
}

std::string describe(const TriangleSetup& t, int x, int y) {
  std::ostringstream s;
  s << "(" << t.x_fx8[0] << ", " << t.y_fx8[0] << ") (" << t.x_fx8[1] << ", " << t.y_fx8[1] << ") ("
    << t.x_fx8[2] << ", " << t.y_fx8[2] << ") [fx8], pixel (" << x << ", " << y << ")";
  return s.str();
}

/// Runs `check(name, fn)` with the scalar reference and with pixel_sample_mask forced to
/// each usable target in turn; restores the best target afterwards.
void for_each_implementation(const std::function<void(const std::string&, MaskFn)>& check) {
  const std::vector<std::int64_t> targets =
      covrast::test::usable_targets(covrast::detail::sample_mask_targets());
  REQUIRE(!targets.empty());
  check("scalar", pixel_sample_mask_scalar);
  for (std::int64_t target : targets) {
    force_sample_mask_target(target);
    REQUIRE(std::string(covrast::detail::sample_mask_target_name()) == hwy::TargetName(target));
    check(hwy::TargetName(target), pixel_sample_mask);
  }
  force_sample_mask_target(0);
}

TEST_CASE("sample mask: hand-computed masks and top-left ties", "[coverage]") {
  // Sample k of a pixel lies at (2k + 1) / 32 along each axis: 1/32, 3/32, ..., 31/32.
  const SampleMask left_columns = grid_mask([](int i, int) { return i < 8; });
  const SampleMask right_columns = grid_mask([](int i, int) { return i >= 8; });
  const SampleMask top_rows = grid_mask([](int, int j) { return j < 8; });
  const SampleMask bottom_rows = grid_mask([](int, int j) { return j >= 8; });
  // The grid's layout, spelled out: columns 0..7 are the low byte of every 16-bit row.
  for (std::uint64_t w : left_columns.word) REQUIRE(w == 0x00FF00FF00FF00FFull);
  for (int j = 0; j < kMaskGridSide; ++j) {
    REQUIRE(left_columns.row(j) == 0x00FFu);
    REQUIRE(bottom_rows.row(j) == (j >= 8 ? 0xFFFFu : 0u));
  }
  // Rows 0..7 are words 0 and 1.
  REQUIRE(top_rows.word[0] == ~0ull);
  REQUIRE(top_rows.word[1] == ~0ull);
  REQUIRE(top_rows.word[2] == 0);
  REQUIRE(top_rows.word[3] == 0);
  constexpr std::int32_t kBig = 32 * kSubpixelOne;  // 32 px

  for_each_implementation([&](const std::string& name, MaskFn mask) {
    INFO(name);
    {
      // Left half of pixel (10, 20), its right edge on the line x = 10.5 (vertical, A -> B
      // goes down: a right edge, bias -1). x = 0.5 = 16/32 lies between sample columns 7
      // (15/32) and 8 (17/32): no sample is on the line, the top-left rule has nothing to
      // decide, and exactly columns 0..7 are inside in all 16 rows.
      const std::int32_t line = 10 * kSubpixelOne + kSubpixelOne / 2;
      const std::int32_t mid = 20 * kSubpixelOne + kSubpixelOne / 2;
      const TriangleSetup left =
          make_triangle(line, mid - kBig / 2, line, mid + kBig / 2, line - kBig, mid);
      CHECK(hex(mask(left, 10, 20)) == hex(left_columns));
      CHECK(mask(left, 9, 20) == SampleMask::all());    // the whole pixel to the left
      CHECK(mask(left, 11, 20) == SampleMask::none());  // the pixel to the right
    }
    {
      // The line moved to x = 10 + 17/32, through sample column 8 (between two columns of
      // an 8x8 grid). The triangle on the left has it as a right edge (A -> B downwards,
      // dy > 0: bias -1): the samples on the line are not its own, it keeps columns 0..7.
      // The triangle on the right shares the edge as B -> A (upwards, dy < 0: a left edge,
      // bias 0) and owns column 8: columns 8..15. Each sample exactly once: disjoint, and
      // together the whole pixel.
      const std::int32_t line = sample_fx8(10, 8);
      const std::int32_t mid = 20 * kSubpixelOne + kSubpixelOne / 2;
      const std::int32_t ay = mid - kBig / 2, by = mid + kBig / 2;
      const TriangleSetup left = make_triangle(line, ay, line, by, line - kBig, mid);
      const TriangleSetup right = make_triangle(line, by, line, ay, line + kBig, mid);
      CHECK(hex(mask(left, 10, 20)) == hex(left_columns));
      CHECK(hex(mask(right, 10, 20)) == hex(right_columns));
    }
    {
      // The same with the line through the last column (x = 10 + 31/32): the left triangle
      // keeps columns 0..14, the right one owns column 15 alone.
      const std::int32_t line = sample_fx8(10, 15);
      const std::int32_t mid = 20 * kSubpixelOne + kSubpixelOne / 2;
      const std::int32_t ay = mid - kBig / 2, by = mid + kBig / 2;
      const TriangleSetup left = make_triangle(line, ay, line, by, line - kBig, mid);
      const TriangleSetup right = make_triangle(line, by, line, ay, line + kBig, mid);
      CHECK(hex(mask(left, 10, 20)) == hex(grid_mask([](int i, int) { return i < 15; })));
      CHECK(hex(mask(right, 10, 20)) == hex(grid_mask([](int i, int) { return i == 15; })));
    }
    {
      // A horizontal edge through sample row 8 (y = 20 + 17/32). Below it, the edge runs
      // A -> B to the right (dy == 0, dx > 0: a top edge, bias 0): the triangle below owns
      // row 8, rows 8..15. Above, the same edge runs B -> A to the left (not a top edge):
      // rows 0..7 only.
      const std::int32_t line = sample_fx8(20, 8);
      const std::int32_t mid = 10 * kSubpixelOne + kSubpixelOne / 2;
      const TriangleSetup below =
          make_triangle(mid - kBig, line, mid + kBig, line, mid, line + kBig);
      const TriangleSetup above =
          make_triangle(mid + kBig, line, mid - kBig, line, mid, line - kBig);
      CHECK(hex(mask(below, 10, 20)) == hex(bottom_rows));
      CHECK(hex(mask(above, 10, 20)) == hex(top_rows));
    }
    {
      // A triangle 6 x 5 fx8 units around sample (i, j) = (13, 11) of pixel (-3, 7), far
      // smaller than the 16-unit sample spacing: that one sample, bit 11 * 16 + 13 = 189
      // (bit 61 of word 2).
      const std::int32_t sx = sample_fx8(-3, 13), sy = sample_fx8(7, 11);
      const TriangleSetup tiny = make_triangle(sx - 3, sy - 2, sx + 3, sy - 2, sx, sy + 3);
      SampleMask one = SampleMask::none();
      one.word[2] = std::uint64_t(1) << 61;
      CHECK(hex(mask(tiny, -3, 7)) == hex(one));
      CHECK(mask(tiny, -2, 7) == SampleMask::none());
      // The same shape around the pixel centre (16/32, 16/32) lies between samples: no bit.
      const std::int32_t cx = -3 * kSubpixelOne + 128, cy = 7 * kSubpixelOne + 128;
      const TriangleSetup between = make_triangle(cx - 3, cy - 2, cx + 3, cy - 2, cx, cy + 3);
      CHECK(mask(between, -3, 7) == SampleMask::none());
    }
    {
      // The square [8/32, 24/32]^2 of pixel (5, -2) holds samples i, j = 4..11 (its sides
      // lie between sample lines). Split along its diagonal from (8/32, 8/32) to
      // (24/32, 24/32), which passes through the samples (k, k), k = 4..11. Upper-right
      // triangle (y < x) P0 -> P1 -> P2: the diagonal is P2 -> P0, going up (dy < 0): a left
      // edge, so it owns the diagonal: i >= j. Lower-left P0 -> P2 -> P3: the diagonal goes
      // down (dy > 0), not top-left: i < j.
      const std::int32_t x0 = 5 * kSubpixelOne + 64, x1 = 5 * kSubpixelOne + 192;
      const std::int32_t y0 = -2 * kSubpixelOne + 64, y1 = -2 * kSubpixelOne + 192;
      const TriangleSetup upper_right = make_triangle(x0, y0, x1, y0, x1, y1);
      const TriangleSetup lower_left = make_triangle(x0, y0, x1, y1, x0, y1);
      auto in_square = [](int i, int j) { return i >= 4 && i <= 11 && j >= 4 && j <= 11; };
      const SampleMask ur = mask(upper_right, 5, -2), ll = mask(lower_left, 5, -2);
      CHECK(hex(ur) == hex(grid_mask([&](int i, int j) { return in_square(i, j) && i >= j; })));
      CHECK(hex(ll) == hex(grid_mask([&](int i, int j) { return in_square(i, j) && i < j; })));
      CHECK((ur & ll) == SampleMask::none());
      CHECK(hex(ur | ll) == hex(grid_mask(in_square)));
      CHECK((ur | ll).count() == 64);
    }
  });
}

/// Random (triangle, pixel) pairs that stress the exactness: triangles of every size,
/// slivers, horizontal and vertical edges, vertices on sample positions, pixel borders and
/// half pixels, coordinates up to +-32768 px; pixels at vertices, on edges, inside the
/// bounding box and anywhere.
class CaseGenerator {
 public:
  explicit CaseGenerator(std::uint64_t seed) : rng_(seed) {}

  std::int64_t uniform(std::int64_t lo, std::int64_t hi) {
    return std::uniform_int_distribution<std::int64_t>(lo, hi)(rng_);
  }

  /// Moves a coordinate onto a lattice now and then: pixel border, sample, half pixel.
  std::int32_t snap(std::int64_t v) {
    const std::int64_t pixel = v >> 8;  // floor
    switch (uniform(0, 5)) {
      case 0:
        return std::int32_t(pixel * kSubpixelOne);
      case 1:
        return std::int32_t(pixel * kSubpixelOne + 8 + 16 * uniform(0, kMaskGridSide - 1));
      case 2:
        return std::int32_t(pixel * kSubpixelOne + 128);
      default:
        return std::int32_t(v);
    }
  }

  /// A triangle whose vertices lie within +-range_fx8.
  TriangleSetup triangle(std::int64_t range_fx8) {
    const std::int64_t cx = uniform(-range_fx8, range_fx8), cy = uniform(-range_fx8, range_fx8);
    const std::int64_t sizes[] = {8, 40, 256, 1024, 16384, std::int64_t(1) << 20, range_fx8};
    const std::int64_t r = sizes[uniform(0, 6)];
    std::int64_t v[6];
    switch (uniform(0, 3)) {
      case 0: {  // anything of size r
        for (int k = 0; k < 3; ++k) {
          v[2 * k] = snap(cx + uniform(-r, r));
          v[2 * k + 1] = snap(cy + uniform(-r, r));
        }
        break;
      }
      case 1: {  // sliver: c close to the segment ab
        const std::int64_t ax = cx, ay = cy;
        const std::int64_t bx = cx + uniform(-r, r), by = cy + uniform(-r, r);
        const std::int64_t t = uniform(0, 1024);
        v[0] = snap(ax);
        v[1] = snap(ay);
        v[2] = snap(bx);
        v[3] = snap(by);
        v[4] = ax + (bx - ax) * t / 1024 + uniform(-3, 3);
        v[5] = ay + (by - ay) * t / 1024 + uniform(-3, 3);
        break;
      }
      default: {  // right triangle with a horizontal and a vertical edge
        const std::int64_t x = snap(cx), y = snap(cy);
        std::int64_t w = uniform(-r, r), h = uniform(-r, r);
        if (uniform(0, 1) == 0) {  // on the sample or pixel lattice
          const std::int64_t unit = uniform(0, 1) == 0 ? 16 : kSubpixelOne;
          w = w / unit * unit;
          h = h / unit * unit;
        }
        const std::int64_t corner[6] = {x, y, x + w, y, x, y + h};
        std::copy(corner, corner + 6, v);
        break;
      }
    }
    for (std::int64_t& c : v) c = std::clamp(c, -range_fx8, range_fx8);
    // Positive doubled area as the setup makes it; a few of either orientation kept.
    const std::int64_t area2 = (v[2] - v[0]) * (v[5] - v[1]) - (v[4] - v[0]) * (v[3] - v[1]);
    if (area2 < 0 && uniform(0, 49) != 0) {
      std::swap(v[2], v[4]);
      std::swap(v[3], v[5]);
    }
    return make_triangle(std::int32_t(v[0]), std::int32_t(v[1]), std::int32_t(v[2]),
                         std::int32_t(v[3]), std::int32_t(v[4]), std::int32_t(v[5]));
  }

  /// A pixel for `t`: kind 0 at a vertex (or next to it), 1 on an edge, 2 in the bounding
  /// box, 3 anywhere within +-range_px.
  std::pair<int, int> pixel(const TriangleSetup& t, int kind, std::int64_t range_px) {
    switch (kind) {
      case 0: {
        const int k = int(uniform(0, 2));
        const int dx = uniform(0, 3) == 0 ? int(uniform(-1, 1)) : 0;
        const int dy = uniform(0, 3) == 0 ? int(uniform(-1, 1)) : 0;
        return {(t.x_fx8[k] >> 8) + dx, (t.y_fx8[k] >> 8) + dy};
      }
      case 1: {
        const int a = int(uniform(0, 2)), b = (a + 1) % 3;
        const std::int64_t s = uniform(0, 1 << 16);
        const std::int64_t px = t.x_fx8[a] + (std::int64_t(t.x_fx8[b]) - t.x_fx8[a]) * s / 65536;
        const std::int64_t py = t.y_fx8[a] + (std::int64_t(t.y_fx8[b]) - t.y_fx8[a]) * s / 65536;
        return {int(px >> 8), int(py >> 8)};
      }
      case 2: {
        const auto [x0, x1] = std::minmax({t.x_fx8[0], t.x_fx8[1], t.x_fx8[2]});
        const auto [y0, y1] = std::minmax({t.y_fx8[0], t.y_fx8[1], t.y_fx8[2]});
        return {int(uniform(x0 >> 8, x1 >> 8)), int(uniform(y0 >> 8, y1 >> 8))};
      }
      default:
        return {int(uniform(-range_px, range_px)), int(uniform(-range_px, range_px))};
    }
  }

 private:
  std::mt19937_64 rng_;
};

struct Case {
  TriangleSetup t;
  int x, y;
};

TEST_CASE("sample mask: every SIMD target equals the scalar reference", "[coverage]") {
  // +-32768 px: an image side of 16384 px plus the 16384 px guard band on either side.
  constexpr std::int64_t kRangePx = 32768;
  constexpr int kTriangles = 50000, kPixelsPerTriangle = 4;
  CaseGenerator gen(0x5a3b1e0fu);
  std::vector<Case> cases;
  cases.reserve(std::size_t(kTriangles) * kPixelsPerTriangle + 8000);
  for (int n = 0; n < kTriangles; ++n) {
    const TriangleSetup t = gen.triangle(kRangePx * kSubpixelOne);
    for (int k = 0; k < kPixelsPerTriangle; ++k) {
      const auto [x, y] = gen.pixel(t, k, kRangePx);
      cases.push_back({t, x, y});
    }
  }
  // Edges too long for the int32 lanes (vertices up to +-2^29 fx8, far beyond the guard
  // band): they take the scalar path and must still agree.
  const std::size_t wide_begin = cases.size();
  for (int n = 0; n < 2000; ++n) {
    const TriangleSetup t = gen.triangle(std::int64_t(1) << 29);
    for (int k = 0; k < kPixelsPerTriangle; ++k) {
      const auto [x, y] = gen.pixel(t, k % 2, 0);
      cases.push_back({t, x, y});
    }
  }
  REQUIRE(cases.size() >= 200000);

  // The reference against a direct evaluation at each sample, and what the cases exercise:
  // how many edges cross the sample grid (the SIMD lanes run only for crossing edges).
  std::vector<SampleMask> reference(cases.size());
  std::size_t direct_mismatch = 0, partial = 0, full = 0, empty = 0;
  std::size_t by_crossing[4] = {};
  std::string first_direct;
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const Case& k = cases[c];
    reference[c] = pixel_sample_mask_scalar(k.t, k.x, k.y);
    if (reference[c] != direct_mask(k.t, k.x, k.y) && direct_mismatch++ == 0) {
      first_direct = describe(k.t, k.x, k.y);
    }
    if (c >= wide_begin) continue;
    ++by_crossing[crossing_edges(k.t, k.x, k.y)];
    if (reference[c] == SampleMask::none()) {
      ++empty;
    } else if (reference[c] == SampleMask::all()) {
      ++full;
    } else {
      ++partial;
    }
  }
  INFO(first_direct);
  CHECK(direct_mismatch == 0);
  INFO("crossing edges 0/1/2/3: " << by_crossing[0] << " " << by_crossing[1] << " "
                                  << by_crossing[2] << " " << by_crossing[3] << "; masks empty "
                                  << empty << ", full " << full << ", partial " << partial);
  CHECK(by_crossing[1] > 20000);
  CHECK(by_crossing[2] > 5000);
  CHECK(by_crossing[3] > 2000);
  CHECK(partial > 50000);
  CHECK(full > 2000);
  CHECK(empty > 20000);

  std::string names;
  for (std::int64_t t : covrast::test::usable_targets(covrast::detail::sample_mask_targets()))
    names += std::string(hwy::TargetName(t)) + " ";
  WARN("sample mask targets compiled and supported here: " << names);
  for_each_implementation([&](const std::string& name, MaskFn mask) {
    INFO(name);
    std::size_t mismatch = 0;
    std::string first;
    for (std::size_t c = 0; c < cases.size(); ++c) {
      const Case& k = cases[c];
      const SampleMask got = mask(k.t, k.x, k.y);
      if (got != reference[c] && mismatch++ == 0) {
        first = describe(k.t, k.x, k.y) + ": " + hex(got) + ", scalar " + hex(reference[c]);
      }
    }
    INFO(first);
    CHECK(mismatch == 0);
  });
  CHECK(pixel_sample_mask(cases[0].t, cases[0].x, cases[0].y) == reference[0]);
}

}  // namespace
