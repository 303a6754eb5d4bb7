// Tests of the 256-sample sub-pixel mask of the coverage resolve
// (src/raster/coverage/sample_mask.hpp): the lattice's layout (one sample per fine column and
// row), masks computed by hand (axis-aligned edges, a tiny triangle around one sample, two
// triangles sharing a diagonal through a sample), the scalar reference against a direct
// per-sample evaluation, and every Highway target compiled and supported here against the
// scalar reference, bit for bit, on 200,000 random (triangle, pixel) pairs.
#include "core/edge_function.hpp"
#include "core/triangle_setup.hpp"
#include "raster/coverage/sample_mask.hpp"

#include <hwy/targets.h>

#include <catch2/catch.hpp>

#include "test_hooks.hpp"

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

using covrast::detail::kMaskSamples;
using covrast::detail::kMaskSampleX_fx9;
using covrast::detail::kMaskSampleY_fx9;
using covrast::detail::kSubpixelOne;
using covrast::detail::pixel_sample_mask;
using covrast::detail::pixel_sample_mask_scalar;
using covrast::detail::SampleMask;
using covrast::detail::TriangleEdges;
using covrast::detail::TriangleSetup;
using covrast::detail::testing::force_simd_target;

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

/// Sample k of pixel (x, y) [fx9: 1/512 pixel].
std::int64_t sample_x_fx9(int x, int k) {
  return std::int64_t(x) * 512 + kMaskSampleX_fx9[std::size_t(k)];
}
std::int64_t sample_y_fx9(int y, int k) {
  return std::int64_t(y) * 512 + kMaskSampleY_fx9[std::size_t(k)];
}

/// The mask of the samples k of pixel (x, y) whose position (fx9) satisfies `inside`.
template <class Inside>
SampleMask mask_where(int x, int y, Inside inside) {
  SampleMask mask = SampleMask::none();
  for (int k = 0; k < kMaskSamples; ++k) {
    if (inside(sample_x_fx9(x, k), sample_y_fx9(y, k))) {
      mask.word[k / 64] |= std::uint64_t(1) << (k % 64);
    }
  }
  return mask;
}

/// Edge function e at a point in fx9 units, from its definition (2 E, exact: the point is
/// (px / 2, py / 2) in fx8) plus the top-left bias.
std::int64_t edge_at_fx9(const covrast::detail::EdgeFunction& e, std::int64_t px, std::int64_t py) {
  return e.dx * (py - 2 * e.y0) - e.dy * (px - 2 * e.x0) + e.bias;
}

/// The mask from the edge functions evaluated at every sample directly.
SampleMask direct_mask(const TriangleSetup& t, int x, int y) {
  const TriangleEdges edges(t);
  return mask_where(x, y, [&](std::int64_t px, std::int64_t py) {
    bool inside = true;
    for (const auto& e : edges.e) inside = inside && edge_at_fx9(e, px, py) >= 0;
    return inside;
  });
}

/// Edges whose 256 samples in pixel (x, y) are neither all inside nor all outside.
int crossing_edges(const TriangleSetup& t, int x, int y) {
  const TriangleEdges edges(t);
  int crossing = 0;
  for (const auto& e : edges.e) {
    const int inside = mask_where(x, y, [&](std::int64_t px, std::int64_t py) {
                         return edge_at_fx9(e, px, py) >= 0;
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
  const std::vector<std::int64_t> targets = covrast::test::usable_targets();
  REQUIRE(!targets.empty());
  check("scalar", pixel_sample_mask_scalar);
  for (std::int64_t target : targets) {
    const covrast::test::ScopedSimdTarget forced(target);
    REQUIRE(std::string(covrast::detail::testing::simd_target_name()) == hwy::TargetName(target));
    check(hwy::TargetName(target), pixel_sample_mask);
  }
}

TEST_CASE("sample mask: the lattice has one sample in every fine column and row", "[coverage]") {
  std::vector<int> column(256, 0), row(256, 0);
  for (int k = 0; k < kMaskSamples; ++k) {
    const std::int32_t x = kMaskSampleX_fx9[std::size_t(k)], y = kMaskSampleY_fx9[std::size_t(k)];
    REQUIRE(x == 2 * k + 1);
    REQUIRE(y == 2 * (71 * k % 256) + 1);
    ++column[std::size_t(x / 2)];
    ++row[std::size_t(y / 2)];
  }
  CHECK(std::count(column.begin(), column.end(), 1) == 256);
  CHECK(std::count(row.begin(), row.end(), 1) == 256);
}

TEST_CASE("sample mask: hand-computed masks and top-left ties", "[coverage]") {
  constexpr std::int32_t kBig = 32 * kSubpixelOne;  // 32 px
  // Fine column c holds sample c (x = (2c + 1) / 512), fine row r the sample k with
  // 71 k = r (mod 256).
  auto columns_below = [](int c) {
    SampleMask m = SampleMask::none();
    for (int k = 0; k < c; ++k) m.word[k / 64] |= std::uint64_t(1) << (k % 64);
    return m;
  };
  for_each_implementation([&](const std::string& name, MaskFn mask) {
    INFO(name);
    {
      // Left of the vertical line x = 10 + 77/256 in pixel (10, 20): the samples of fine
      // columns 0..76, i.e. k < 77 (bits 0..63 and 64..76). Vertices lie on the 1/256 grid,
      // samples halfway between: no sample is on the line. The triangle on the right, sharing
      // the edge the other way, owns the other 179 samples.
      const std::int32_t line = 10 * kSubpixelOne + 77;
      const std::int32_t mid = 20 * kSubpixelOne + kSubpixelOne / 2;
      const std::int32_t ay = mid - kBig / 2, by = mid + kBig / 2;
      const TriangleSetup left = make_triangle(line, ay, line, by, line - kBig, mid);
      const TriangleSetup right = make_triangle(line, by, line, ay, line + kBig, mid);
      const SampleMask expected = columns_below(77);
      CHECK(expected.word[0] == ~0ull);
      CHECK(expected.word[1] == (std::uint64_t(1) << 13) - 1);
      CHECK(hex(mask(left, 10, 20)) == hex(expected));
      CHECK(mask(right, 10, 20).count() == 256 - 77);
      CHECK((mask(left, 10, 20) & mask(right, 10, 20)) == SampleMask::none());
      CHECK(mask(left, 9, 20) == SampleMask::all());    // the whole pixel to the left
      CHECK(mask(left, 11, 20) == SampleMask::none());  // the pixel to the right
    }
    {
      // Above the horizontal line y = 20 + 200/256: the samples of fine rows 0..199, 200 of
      // them, and exactly those whose y (fx9) is below 400.
      const std::int32_t line = 20 * kSubpixelOne + 200;
      const std::int32_t mid = 10 * kSubpixelOne + kSubpixelOne / 2;
      const TriangleSetup above =
          make_triangle(mid + kBig, line, mid - kBig, line, mid, line - kBig);
      const SampleMask got = mask(above, 10, 20);
      CHECK(got.count() == 200);
      CHECK(hex(got) == hex(mask_where(10, 20, [](std::int64_t, std::int64_t py) {
              return py < 20 * 512 + 400;
            })));
    }
    {
      // A triangle 3 x 3 fx8 units around sample 37 of pixel (-3, 7): that sample alone.
      const int k = 37;
      const std::int32_t sx = -3 * kSubpixelOne + kMaskSampleX_fx9[k] / 2;  // just left of it
      const std::int32_t sy = 7 * kSubpixelOne + kMaskSampleY_fx9[k] / 2;   // just above it
      const TriangleSetup tiny = make_triangle(sx - 1, sy - 1, sx + 2, sy - 1, sx, sy + 2);
      SampleMask one = SampleMask::none();
      one.word[0] = std::uint64_t(1) << k;
      CHECK(hex(mask(tiny, -3, 7)) == hex(one));
      CHECK(mask(tiny, -2, 7) == SampleMask::none());
    }
    {
      // The square [64/256, 192/256]^2 of pixel (5, -2), split along its diagonal from
      // (64, 64) to (192, 192) [fx8], which passes through sample 128 at (128.5, 128.5)
      // (71 * 128 = 128 mod 256). Upper-right triangle P0 -> P1 -> P2: the diagonal is
      // P2 -> P0, going up (dy < 0): a left edge, so it owns the sample on it. Lower-left
      // P0 -> P2 -> P3: the diagonal goes down (dy > 0), not top-left.
      const std::int32_t x0 = 5 * kSubpixelOne + 64, x1 = 5 * kSubpixelOne + 192;
      const std::int32_t y0 = -2 * kSubpixelOne + 64, y1 = -2 * kSubpixelOne + 192;
      const TriangleSetup upper_right = make_triangle(x0, y0, x1, y0, x1, y1);
      const TriangleSetup lower_left = make_triangle(x0, y0, x1, y1, x0, y1);
      const SampleMask ur = mask(upper_right, 5, -2), ll = mask(lower_left, 5, -2);
      const SampleMask square = mask_where(5, -2, [&](std::int64_t px, std::int64_t py) {
        return px > 2 * x0 && px < 2 * x1 && py > 2 * y0 && py < 2 * y1;
      });
      CHECK(ur.has(128));
      CHECK(!ll.has(128));
      CHECK((ur & ll) == SampleMask::none());
      CHECK(hex(ur | ll) == hex(square));
      CHECK(square.count() == 63);  // the lattice's count in this quarter of the pixel
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

  /// Moves a coordinate onto a lattice now and then: pixel border, a sample's column or
  /// row, half pixel.
  std::int32_t snap(std::int64_t v) {
    const std::int64_t pixel = v >> 8;  // floor
    switch (uniform(0, 5)) {
      case 0:
        return std::int32_t(pixel * kSubpixelOne);
      case 1:  // next to a sample: its column (fx8 = k) or row
        return std::int32_t(pixel * kSubpixelOne + uniform(0, kSubpixelOne - 1));
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
  for (std::int64_t t : covrast::test::usable_targets())
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
