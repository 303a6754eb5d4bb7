// Tests of the coverage kernel (src/raster/coverage_kernel.hpp): its 8.8 coverage against the
// exact area of triangle ∩ pixel (a Sutherland-Hodgman clip in double on the snapped vertices),
// bit identity of the SIMD kernel on every target this CPU runs with the scalar twin, and exact
// sums (kCoverageOne) over tessellations. Also the set-up's fast paths against their
// references: the vertex sorting network against std::sort, and the SIMD column set-up on
// every target against its scalar twin (all five arrays, all lanes, the group's rows), and
// the fused group function (set-up and rows in one call, the product's path) on every
// target against the composition of the scalar twins. The helpers drive the kernel the
// way CoverageRasterizer::draw (src/raster/coverage.cpp) does: groups of kColumnGroup
// columns, lanes past the span zeroed, kernel on the partial runs and the piece width on
// the interior.
#include "core/triangle_setup.hpp"
#include "raster/coverage/coverage_kernel.hpp"

#include <hwy/targets.h>

#include <catch2/catch.hpp>

#include "test_hooks.hpp"

#include "test_targets.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using covrast::detail::ColumnRows;
using covrast::detail::CoverageColumns;
using covrast::detail::CoverageRowsFn;
using covrast::detail::CoverageTriangle;
using covrast::detail::CoverGroupFn;
using covrast::detail::kColumnGroup;
using covrast::detail::kCoverageOne;
using covrast::detail::kSubpixelOne;
using covrast::detail::PixelRect;
using covrast::detail::TriangleSetup;

struct Fx8Point {
  std::int32_t x, y;  ///< 24.8 fixed point
};

std::int32_t snap(double px) { return std::int32_t(std::llround(px * kSubpixelOne)); }

std::int64_t doubled_area(Fx8Point a, Fx8Point b, Fx8Point c) {
  return (std::int64_t(b.x) - a.x) * (std::int64_t(c.y) - a.y) -
         (std::int64_t(c.x) - a.x) * (std::int64_t(b.y) - a.y);
}

/// A TriangleSetup in the setup's orientation (positive doubled area); false if degenerate.
bool make_setup(Fx8Point a, Fx8Point b, Fx8Point c, TriangleSetup& t) {
  std::int64_t area2 = doubled_area(a, b, c);
  if (area2 == 0) return false;
  if (area2 < 0) std::swap(b, c);
  const Fx8Point v[3] = {a, b, c};
  t = TriangleSetup{};
  for (int k = 0; k < 3; ++k) {
    t.x_fx8[k] = v[k].x;
    t.y_fx8[k] = v[k].y;
    t.inv_w[k] = 1.0f;
    t.color[k] = glm::vec3(1.0f);
  }
  t.z0 = 0.5;
  t.flat_color = true;
  t.front_facing = true;
  return true;
}

/// Exact area of triangle ∩ pixel square [px, px+1] x [py, py+1]: Sutherland-Hodgman
/// against the four sides, then the shoelace formula, in double relative to the pixel
/// origin (the snapped vertices are multiples of 1/256, exact in double).
double exact_area(const TriangleSetup& t, int px, int py) {
  std::array<double, 12> xs{}, ys{}, nx{}, ny{};
  int n = 3;
  for (int k = 0; k < 3; ++k) {
    xs[k] = (double(t.x_fx8[k]) - double(px) * kSubpixelOne) / kSubpixelOne;
    ys[k] = (double(t.y_fx8[k]) - double(py) * kSubpixelOne) / kSubpixelOne;
  }
  // Half-planes: 0 <= x, x <= 1, 0 <= y, y <= 1 as signed distances d(p) >= 0.
  for (int side = 0; side < 4 && n > 0; ++side) {
    auto dist = [side](double x, double y) {
      switch (side) {
        case 0:
          return x;
        case 1:
          return 1.0 - x;
        case 2:
          return y;
        default:
          return 1.0 - y;
      }
    };
    int m = 0;
    for (int k = 0; k < n; ++k) {
      const int j = (k + 1) % n;
      const double dk = dist(xs[k], ys[k]), dj = dist(xs[j], ys[j]);
      if (dk >= 0) {
        nx[m] = xs[k];
        ny[m] = ys[k];
        ++m;
      }
      if ((dk >= 0) != (dj >= 0)) {
        const double s = dk / (dk - dj);
        nx[m] = xs[k] + s * (xs[j] - xs[k]);
        ny[m] = ys[k] + s * (ys[j] - ys[k]);
        ++m;
      }
    }
    xs = nx;
    ys = ny;
    n = m;
  }
  double area2 = 0;
  for (int k = 0; k < n; ++k) {
    const int j = (k + 1) % n;
    area2 += xs[k] * ys[j] - xs[j] * ys[k];
  }
  return std::fabs(area2) * 0.5;
}

/// 8.8 coverage of one triangle over a window of pixels (zero outside the triangle's box).
struct CoveragePlane {
  PixelRect rect;
  std::vector<std::uint16_t> cov;
  std::uint16_t at(int x, int y) const {
    return cov[std::size_t(y - rect.y0) * std::size_t(rect.x1 - rect.x0) +
               std::size_t(x - rect.x0)];
  }
  std::uint16_t& at(int x, int y) {
    return cov[std::size_t(y - rect.y0) * std::size_t(rect.x1 - rect.x0) +
               std::size_t(x - rect.x0)];
  }
};

enum class RowMode {
  LikeDraw,  ///< kernel on the partial runs only, width_q on the interior run (as draw does)
  AllRows,   ///< kernel on every row of the box, no use of ColumnRows
};

/// Marks kernel output rows that were never written.
constexpr std::uint16_t kPoison = 0xbeef;

struct KernelRun {
  CoveragePlane plane;
  int sign = 0;
  std::uint64_t nonzero_beyond_span = 0;  ///< kernel output != 0 in a zeroed lane
  std::uint64_t rows_mismatch = 0;        ///< groups whose rows differ from the scalar set-up's
};

/// A run over `window` with every pixel's coverage 0.
KernelRun empty_run(const PixelRect& window) {
  KernelRun run;
  run.plane.rect = window;
  run.plane.cov.assign(std::size_t(window.x1 - window.x0) * std::size_t(window.y1 - window.y0), 0);
  return run;
}

/// Copies rows [y_begin, y_end) of a group's output `buf` (row y at (y - buf_y0) *
/// kColumnGroup) into run.plane, lanes [0, lanes) only, and counts non-zero values in the
/// lanes beyond (the kernel must write 0 there).
void keep_group_rows(const std::vector<std::uint16_t>& buf, int buf_y0, int g, int lanes,
                     int y_begin, int y_end, KernelRun& run) {
  for (int y = y_begin; y < y_end; ++y) {
    for (int lane = 0; lane < kColumnGroup; ++lane) {
      const std::uint16_t v = buf[std::size_t(y - buf_y0) * kColumnGroup + lane];
      if (lane < lanes) {
        run.plane.at(g + lane, y) = v;
      } else if (v != 0) {
        ++run.nonzero_beyond_span;
      }
    }
  }
}

/// Runs make_coverage_triangle + the column set-up + `fn` over `window` ∩ the triangle's box.
/// The scalar kernel runs with the scalar set-up (setup_column_group_scalar), so the
/// reference is scalar end to end; any other kernel with the dispatched SIMD set-up, as draw.
KernelRun run_kernel(const TriangleSetup& t, const PixelRect& window, CoverageRowsFn fn,
                     RowMode mode) {
  static thread_local std::unique_ptr<CoverageColumns> cols_ptr =
      std::make_unique<CoverageColumns>();
  CoverageColumns& cols = *cols_ptr;
  KernelRun run = empty_run(window);
  const PixelRect r = covrast::detail::intersect(covrast::detail::touched_pixels(t), window);
  const CoverageTriangle tri = covrast::detail::make_coverage_triangle(t);
  run.sign = tri.sign;
  if (r.empty()) return run;
  std::vector<std::uint16_t> buf(std::size_t(r.y1 - r.y0) * kColumnGroup);
  for (int g = r.x0; g < r.x1; g += kColumnGroup) {
    const int lanes = std::min(kColumnGroup, r.x1 - g);
    // The same set-up as CoverageRasterizer::draw.
    const covrast::detail::GroupRows rows =
        fn == covrast::detail::coverage_rows_scalar
            ? covrast::detail::setup_column_group_scalar(tri, g, lanes, r.y0, r.y1, cols)
            : covrast::detail::setup_column_group(tri, g, lanes, r.y0, r.y1, cols);
    // Poison the buffer: a row of [first, end) that nothing writes shows up as a mismatch.
    std::fill(buf.begin(), buf.end(), kPoison);
    int copy_begin = r.y0, copy_end = r.y1;
    if (mode == RowMode::AllRows) {
      fn(cols, 0, r.y0, r.y1, tri.sign, buf.data(), kColumnGroup);
    } else {
      if (rows.empty()) continue;
      const int first = rows.first, end = rows.end;
      const int interior_begin = rows.interior_begin, interior_end = rows.interior_end;
      fn(cols, 0, first, interior_begin, tri.sign,
         buf.data() + std::size_t(first - r.y0) * kColumnGroup, kColumnGroup);
      for (int y = interior_begin; y < interior_end; ++y) {
        for (int lane = 0; lane < kColumnGroup; ++lane) {
          buf[std::size_t(y - r.y0) * kColumnGroup + lane] = std::uint16_t(cols.width_q[0][lane]);
        }
      }
      fn(cols, 0, interior_end, end, tri.sign,
         buf.data() + std::size_t(interior_end - r.y0) * kColumnGroup, kColumnGroup);
      // draw() hands on rows [first, end) only; the others stay 0.
      copy_begin = first;
      copy_end = end;
    }
    keep_group_rows(buf, r.y0, g, lanes, copy_begin, copy_end, run);
  }
  return run;
}

/// Runs make_coverage_triangle + `fn` over `window` ∩ the triangle's box exactly as
/// CoverageRasterizer::draw does (one call per group, output at row r.y0), keeping rows
/// [first, end) of each group; also compares each group's rows with the scalar set-up's.
KernelRun run_group(const TriangleSetup& t, const PixelRect& window, CoverGroupFn fn) {
  static thread_local std::unique_ptr<CoverageColumns> cols_ptr =
      std::make_unique<CoverageColumns>();
  KernelRun run = empty_run(window);
  const PixelRect r = covrast::detail::intersect(covrast::detail::touched_pixels(t), window);
  const CoverageTriangle tri = covrast::detail::make_coverage_triangle(t);
  run.sign = tri.sign;
  if (r.empty()) return run;
  std::vector<std::uint16_t> buf(std::size_t(r.y1 - r.y0) * kColumnGroup);
  for (int g = r.x0; g < r.x1; g += kColumnGroup) {
    const int lanes = std::min(kColumnGroup, r.x1 - g);
    // Poison the buffer: a row of [first, end) that nothing writes shows up as a mismatch.
    std::fill(buf.begin(), buf.end(), kPoison);
    const covrast::detail::GroupRows rows = fn(tri, g, lanes, r.y0, r.y1, buf.data(), kColumnGroup);
    const covrast::detail::GroupRows ref =
        covrast::detail::setup_column_group_scalar(tri, g, lanes, r.y0, r.y1, *cols_ptr);
    run.rows_mismatch += rows.first != ref.first || rows.end != ref.end ||
                         rows.interior_begin != ref.interior_begin ||
                         rows.interior_end != ref.interior_end;
    keep_group_rows(buf, r.y0, g, lanes, rows.first, rows.end, run);
  }
  return run;
}

// ---- Random triangles, snapped to 1/256 pixel ------------------------------------------

enum class Kind { Ordinary, Sliver, InPixel, OnGrid, Huge };

struct TestTriangle {
  TriangleSetup setup;
  PixelRect window;  ///< pixels to evaluate (the whole box unless the box is huge)
  Kind kind;
};

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::Ordinary:
      return "ordinary";
    case Kind::Sliver:
      return "sliver";
    case Kind::InPixel:
      return "in-pixel";
    case Kind::OnGrid:
      return "on-grid";
    case Kind::Huge:
      return "huge";
  }
  return "?";
}

class TriangleGenerator {
 public:
  explicit TriangleGenerator(std::uint32_t seed) : rng_(seed) {}

  TestTriangle next(Kind kind) {
    for (;;) {
      Fx8Point v[3];
      PixelRect window{};
      switch (kind) {
        case Kind::Ordinary: {
          static constexpr double kSizes[] = {1.5, 4.0, 12.0, 30.0};
          const double size = kSizes[pick(4)];
          const double ox = uniform(-200, 200), oy = uniform(-200, 200);
          for (auto& p : v) p = {snap(ox + uniform(0, size)), snap(oy + uniform(0, size))};
          break;
        }
        case Kind::Sliver: {
          // Long edge at 0.1..89.9 degrees off an axis, third vertex a hair off it.
          const double deg = uniform(0.1, 89.9) + 90.0 * pick(4);
          const double rad = deg * 3.14159265358979323846 / 180.0;
          const double dx = std::cos(rad), dy = std::sin(rad);
          const double length = uniform(1.0, 80.0);
          const double ox = uniform(-50, 50), oy = uniform(-50, 50);
          const double along = uniform(0, 1) * length;
          const double off =
              std::exp(uniform(std::log(1.0 / 256), std::log(0.6))) * (pick(2) ? 1.0 : -1.0);
          v[0] = {snap(ox), snap(oy)};
          v[1] = {snap(ox + length * dx), snap(oy + length * dy)};
          v[2] = {snap(ox + along * dx - off * dy), snap(oy + along * dy + off * dx)};
          break;
        }
        case Kind::InPixel: {
          const std::int32_t cx = std::int32_t(pick(200)) - 100, cy = std::int32_t(pick(200)) - 100;
          for (auto& p : v) {
            p = {cx * kSubpixelOne + std::int32_t(pick(kSubpixelOne + 1)),
                 cy * kSubpixelOne + std::int32_t(pick(kSubpixelOne + 1))};
          }
          break;
        }
        case Kind::OnGrid: {
          // Each coordinate on a pixel border with probability 0.7, so vertices fall on
          // borders and corners and edges run along borders.
          const std::int32_t ox = std::int32_t(pick(40)) - 20, oy = std::int32_t(pick(40)) - 20;
          const int span = 1 + int(pick(8));
          for (auto& p : v) {
            auto coord = [&](std::int32_t o) {
              const std::int32_t cell = o + std::int32_t(pick(std::uint32_t(span) + 1));
              return pick(10) < 7 ? cell * kSubpixelOne
                                  : cell * kSubpixelOne + std::int32_t(pick(kSubpixelOne));
            };
            p = {coord(ox), coord(oy)};
          }
          break;
        }
        case Kind::Huge: {
          for (auto& p : v) p = {snap(uniform(-16384, 16384)), snap(uniform(-16384, 16384))};
          break;
        }
      }
      TestTriangle out;
      out.kind = kind;
      if (!make_setup(v[0], v[1], v[2], out.setup)) continue;
      window = covrast::detail::touched_pixels(out.setup);
      if (kind == Kind::Huge) {
        // Only a 64 x 64 window, as a tile would see, around a vertex, a point of an edge
        // or a point inside.
        const int k = int(pick(3));
        const int i = int(pick(3)), j = (i + 1) % 3;
        const double s = uniform(0, 1), u = uniform(0, 1);
        double fx, fy;
        const TriangleSetup& t = out.setup;
        if (k == 0) {
          fx = t.x_fx8[i];
          fy = t.y_fx8[i];
        } else if (k == 1) {
          fx = t.x_fx8[i] + s * (t.x_fx8[j] - t.x_fx8[i]);
          fy = t.y_fx8[i] + s * (t.y_fx8[j] - t.y_fx8[i]);
        } else {
          const double a = std::min(s, u), b = std::max(s, u);
          fx = a * t.x_fx8[0] + (b - a) * t.x_fx8[1] + (1 - b) * t.x_fx8[2];
          fy = a * t.y_fx8[0] + (b - a) * t.y_fx8[1] + (1 - b) * t.y_fx8[2];
        }
        const int cx = int(std::floor(fx / kSubpixelOne)), cy = int(std::floor(fy / kSubpixelOne));
        window = PixelRect{cx - 32, cy - 32, cx + 32, cy + 32};
      }
      out.window = window;
      return out;
    }
  }

  std::uint32_t pick(std::uint32_t n) {
    return std::uniform_int_distribution<std::uint32_t>(0, n - 1)(rng_);
  }
  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }

 private:
  std::mt19937 rng_;
};

std::string describe(const TriangleSetup& t) {
  std::ostringstream s;
  s << "fx8 vertices (" << t.x_fx8[0] << ", " << t.y_fx8[0] << ") (" << t.x_fx8[1] << ", "
    << t.y_fx8[1] << ") (" << t.x_fx8[2] << ", " << t.y_fx8[2] << ")";
  return s.str();
}

/// Kinds in the mix for 100,000 triangles of test 1.
struct KindCount {
  Kind kind;
  int count;
};
constexpr KindCount kMix[] = {{Kind::Ordinary, 40000},
                              {Kind::Sliver, 25000},
                              {Kind::InPixel, 10000},
                              {Kind::OnGrid, 15000},
                              {Kind::Huge, 10000}};

}  // namespace

// [sanitizer-slow]: 100,000 triangles, each pixel against the exact area: over 10 minutes
// under ASan+UBSan (-O1), where the SIMD-versus-scalar kernel tests run the same code.
TEST_CASE("coverage kernel matches the exact area of triangle and pixel",
          "[coverage][sanitizer-slow]") {
  const auto start = std::chrono::steady_clock::now();
  TriangleGenerator gen(0x5eedc0feu);
  std::uint64_t pixels = 0, triangles = 0, bad_alpha = 0, draw_mismatch = 0, beyond_span = 0,
                rows_mismatch = 0;
  std::uint64_t signs[2] = {0, 0};
  double max_err_q = 0, sum_err_q = 0, sum_err_alpha = 0, sum_err_rounded = 0;
  int max_err_alpha_rounded = 0;
  std::string max_err_where, first_bad;
  for (const KindCount& kc : kMix) {
    for (int n = 0; n < kc.count; ++n) {
      const TestTriangle tt = gen.next(kc.kind);
      const TriangleSetup& t = tt.setup;
      // The fused SIMD group function as draw() drives it, and the scalar twin on every row.
      const KernelRun simd = run_group(t, tt.window, covrast::detail::cover_group_simd);
      const KernelRun all =
          run_kernel(t, tt.window, covrast::detail::coverage_rows_scalar, RowMode::AllRows);
      beyond_span += simd.nonzero_beyond_span + all.nonzero_beyond_span;
      rows_mismatch += simd.rows_mismatch;
      ++signs[simd.sign > 0 ? 1 : 0];
      ++triangles;
      const PixelRect r = covrast::detail::intersect(covrast::detail::touched_pixels(t), tt.window);
      for (int y = r.y0; y < r.y1; ++y) {
        for (int x = r.x0; x < r.x1; ++x) {
          const std::uint32_t cov = simd.plane.at(x, y);
          if (cov != all.plane.at(x, y) && ++draw_mismatch == 1 && first_bad.empty()) {
            std::ostringstream s;
            s << kind_name(tt.kind) << " " << describe(t) << " pixel (" << x << ", " << y
              << "): draw-like run " << cov << " vs kernel on all rows " << all.plane.at(x, y);
            first_bad = s.str();
          }
          const double area = exact_area(t, x, y);
          const double err_q = std::fabs(double(cov) - kCoverageOne * area);
          const int alpha = covrast::detail::coverage_to_alpha8(cov);
          const int expected = int(std::lround(255.0 * area));
          const int err_rounded = std::abs(alpha - expected);
          ++pixels;
          sum_err_q += err_q;
          sum_err_alpha += std::fabs(alpha - 255.0 * area);
          sum_err_rounded += err_rounded;
          max_err_alpha_rounded = std::max(max_err_alpha_rounded, err_rounded);
          if (err_q > max_err_q) {
            max_err_q = err_q;
            std::ostringstream s;
            s << kind_name(tt.kind) << " " << describe(t) << " pixel (" << x << ", " << y
              << "): 8.8 " << cov << ", exact " << kCoverageOne * area;
            max_err_where = s.str();
          }
          if (err_rounded > 1 && ++bad_alpha == 1) {
            std::ostringstream s;
            s << kind_name(tt.kind) << " " << describe(t) << " pixel (" << x << ", " << y
              << "): alpha " << alpha << " (8.8 " << cov << "), expected round(255 * " << area
              << ") = " << expected;
            first_bad = s.str();
          }
        }
      }
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double mean_err_q = sum_err_q / double(pixels);
  const double mean_err_alpha = sum_err_alpha / double(pixels);
  const double mean_err_rounded = sum_err_rounded / double(pixels);
  WARN("kernel vs exact area: " << triangles << " triangles, " << pixels << " pixels, " << seconds
                                << " s; max |8.8 - 65280 * area| = " << max_err_q << " at "
                                << max_err_where << "; mean |8.8 error| = " << mean_err_q
                                << "; mean |alpha8 - 255 * area| = " << mean_err_alpha
                                << "; max |alpha8 - round(255 * area)| = " << max_err_alpha_rounded
                                << ", mean " << mean_err_rounded
                                << "; triangles with sign -1 / +1: " << signs[0] << " / "
                                << signs[1]);
  INFO(first_bad);
  REQUIRE(triangles == 100000);
  CHECK(signs[0] > 10000);
  CHECK(signs[1] > 10000);
  CHECK(beyond_span == 0);
  CHECK(rows_mismatch == 0);
  CHECK(draw_mismatch == 0);
  CHECK(bad_alpha == 0);
  // Three edge terms, each rounded (1/2 unit) with float error far below a unit, plus the
  // flat-edge mid-point fallback (at most kFlatEdgeEps / 8 * 65280 < 8 units): <= 10 units.
  CHECK(max_err_q <= 10.0);
  // The 8-bit alpha is within rounding of the ideal: mean error about 1/4 level, and almost
  // never off the correctly rounded value.
  CHECK(mean_err_alpha < 0.26);
  CHECK(mean_err_rounded < 0.001);
}

TEST_CASE("coverage kernel: every SIMD target gives the scalar twin's bits", "[coverage]") {
  // Read before any forcing: SupportedTargets() reports the mock once one is set.
  const std::int64_t supported = hwy::SupportedTargets();
  const std::vector<std::int64_t> targets = covrast::test::usable_targets();
  std::string names;
  for (std::int64_t t : targets) names += std::string(hwy::TargetName(t)) + " ";
  WARN("coverage kernel targets compiled and supported here: " << names);
  REQUIRE(!targets.empty());

  // The same triangles for every target, the hard cases included.
  std::vector<TestTriangle> tris;
  TriangleGenerator gen(0xb17b17u);
  for (const KindCount& kc : kMix) {
    for (int n = 0; n < kc.count / 25; ++n) tris.push_back(gen.next(kc.kind));
  }
  REQUIRE(tris.size() == 4000);
  std::vector<KernelRun> scalar;
  for (const TestTriangle& tt : tris) {
    scalar.push_back(
        run_kernel(tt.setup, tt.window, covrast::detail::coverage_rows_scalar, RowMode::AllRows));
  }

  // The separate kernel on all rows and as draw drove it, and the fused group function
  // (the product's path; its scalar twin once, before any target is forced).
  enum class Path { KernelAllRows, KernelLikeDraw, Fused, FusedScalar };
  auto run_path = [](const TestTriangle& tt, Path path) {
    switch (path) {
      case Path::KernelAllRows:
        return run_kernel(tt.setup, tt.window, covrast::detail::coverage_rows_simd,
                          RowMode::AllRows);
      case Path::KernelLikeDraw:
        return run_kernel(tt.setup, tt.window, covrast::detail::coverage_rows_simd,
                          RowMode::LikeDraw);
      case Path::Fused:
        return run_group(tt.setup, tt.window, covrast::detail::cover_group_simd);
      case Path::FusedScalar:
        break;
    }
    return run_group(tt.setup, tt.window, covrast::detail::cover_group_scalar);
  };
  struct Mismatch {
    std::uint64_t pixels = 0, beyond = 0, rows = 0;
    std::string first;
  };
  auto compare = [&](std::initializer_list<Path> paths) {
    Mismatch m;
    for (std::size_t i = 0; i < tris.size(); ++i) {
      for (Path path : paths) {
        const KernelRun simd = run_path(tris[i], path);
        m.beyond += simd.nonzero_beyond_span;
        m.rows += simd.rows_mismatch;
        for (std::size_t p = 0; p < simd.plane.cov.size(); ++p) {
          if (simd.plane.cov[p] == scalar[i].plane.cov[p]) continue;
          if (++m.pixels == 1) {
            std::ostringstream s;
            const int w = tris[i].window.x1 - tris[i].window.x0;
            s << "path " << int(path) << ": " << kind_name(tris[i].kind) << " "
              << describe(tris[i].setup) << " pixel ("
              << tris[i].window.x0 + int(p % std::size_t(w)) << ", "
              << tris[i].window.y0 + int(p / std::size_t(w)) << "): simd " << simd.plane.cov[p]
              << ", scalar " << scalar[i].plane.cov[p];
            m.first = s.str();
          }
        }
      }
    }
    return m;
  };
  {
    const Mismatch m = compare({Path::FusedScalar});
    INFO("cover_group_scalar: " << m.first);
    CHECK(m.pixels == 0);
    CHECK(m.beyond == 0);
    CHECK(m.rows == 0);
  }
  for (std::int64_t target : targets) {
    const covrast::test::ScopedSimdTarget forced(target);
    INFO("target " << hwy::TargetName(target));
    CHECK(std::string(covrast::detail::testing::simd_target_name()) == hwy::TargetName(target));
    const Mismatch m = compare({Path::KernelAllRows, Path::KernelLikeDraw, Path::Fused});
    INFO(m.first);
    CHECK(m.pixels == 0);
    CHECK(m.beyond == 0);
    CHECK(m.rows == 0);
  }
  CHECK(hwy::SupportedTargets() == supported);
}

TEST_CASE("coverage kernel: SIMD equals scalar on raw column inputs", "[coverage]") {
  // Inputs drawn directly (not through setup_column): ends on and near row borders, exact
  // halves (ties of the rounding), long steep pieces, flat pieces around kFlatEdgeEps, at
  // every group offset `col` inside the columns arrays, both signs.
  std::mt19937 rng(0xc01u);
  auto pick = [&](std::uint32_t n) {
    return std::uniform_int_distribution<std::uint32_t>(0, n - 1)(rng);
  };
  auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  auto t_value = [&]() -> float {
    switch (pick(5)) {
      case 0:
        return float(pick(9)) * 0.25f;  // row borders and quarters
      case 1:
        return float(uniform(0, 2));
      case 2:
        return float(uniform(0, 3000));  // steep piece
      case 3:
        return float(pick(4)) + float(uniform(-1.0 / 2048, 1.0 / 2048));  // near a border
      default:
        return float(pick(256)) / 256.0f;
    }
  };
  auto cols = std::make_unique<CoverageColumns>();
  const std::vector<std::int64_t> targets = covrast::test::usable_targets();
  constexpr int kRows = 12;
  std::uint64_t compared = 0, differing = 0;
  std::string first;
  for (int round = 0; round < 3000; ++round) {
    for (int e = 0; e < 3; ++e) {
      for (int c = 0; c < covrast::detail::kMaxSpanColumns; ++c) {
        float tl = t_value(),
              tr = pick(3) == 0 ? tl + float(uniform(-1.0 / 512, 1.0 / 512)) : t_value();
        if (tl < 0) tl = 0;
        if (tr < 0) tr = 0;
        const float wq = float(255 * pick(257));
        cols->t_left[e][c] = tl;
        cols->t_right[e][c] = tr;
        cols->width_q[e][c] = wq;
        cols->slope_q[e][c] =
            std::fabs(tr - tl) >= covrast::detail::kFlatEdgeEps ? wq / (tr - tl) : 0.0f;
        cols->base_row[e][c] = int(pick(8)) - 4;
      }
    }
    const int col =
        kColumnGroup * int(pick(std::uint32_t(covrast::detail::kMaxSpanColumns / kColumnGroup)));
    const int row_begin = int(pick(8)) - 6;
    const int sign = pick(2) ? 1 : -1;
    std::vector<std::uint16_t> scalar(kRows * kColumnGroup), simd(kRows * kColumnGroup);
    covrast::detail::coverage_rows_scalar(*cols, col, row_begin, row_begin + kRows, sign,
                                          scalar.data(), kColumnGroup);
    for (std::int64_t target : targets) {
      const covrast::test::ScopedSimdTarget forced(target);
      std::fill(simd.begin(), simd.end(), kPoison);
      covrast::detail::coverage_rows_simd(*cols, col, row_begin, row_begin + kRows, sign,
                                          simd.data(), kColumnGroup);
      for (int i = 0; i < kRows * kColumnGroup; ++i) {
        ++compared;
        if (simd[std::size_t(i)] == scalar[std::size_t(i)]) continue;
        if (++differing == 1) {
          const int c = col + i % kColumnGroup;
          std::ostringstream s;
          s << hwy::TargetName(target) << ": column " << c << " row "
            << row_begin + i / kColumnGroup << " sign " << sign << ": simd " << simd[std::size_t(i)]
            << ", scalar " << scalar[std::size_t(i)]
            << "; edges (t_left, t_right, width_q, slope_q, base_row):";
          for (int e = 0; e < 3; ++e) {
            s << " (" << cols->t_left[e][c] << ", " << cols->t_right[e][c] << ", "
              << cols->width_q[e][c] << ", " << cols->slope_q[e][c] << ", " << cols->base_row[e][c]
              << ")";
          }
          first = s.str();
        }
      }
    }
  }
  INFO(first);
  CHECK(compared == 3000u * targets.size() * kRows * kColumnGroup);
  CHECK(differing == 0);
}

// ---- Triangle and column set-up: the fast paths against their references ---------------

namespace {

using covrast::detail::CoverageEdge;
using covrast::detail::GroupRows;

/// make_coverage_triangle of the same vertices handed to it already in std::sort's (x, then
/// y) order: the sorting network must give exactly this for every permutation of them.
CoverageTriangle reference_coverage_triangle(const TriangleSetup& t) {
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) {
    return t.x_fx8[i] < t.x_fx8[j] || (t.x_fx8[i] == t.x_fx8[j] && t.y_fx8[i] < t.y_fx8[j]);
  });
  TriangleSetup sorted = t;
  for (int k = 0; k < 3; ++k) {
    sorted.x_fx8[k] = t.x_fx8[order[k]];
    sorted.y_fx8[k] = t.y_fx8[order[k]];
  }
  return covrast::detail::make_coverage_triangle(sorted);
}

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

bool same_triangle(const CoverageTriangle& a, const CoverageTriangle& b) {
  for (int e = 0; e < 3; ++e) {
    const CoverageEdge &p = a.edge[e], &q = b.edge[e];
    if (!same_bits(p.x0, q.x0) || !same_bits(p.y0, q.y0) || !same_bits(p.x1, q.x1) ||
        !same_bits(p.y1, q.y1) || !same_bits(p.slope, q.slope)) {
      return false;
    }
  }
  return a.sign == b.sign && same_bits(a.x_min, b.x_min) && same_bits(a.x_max, b.x_max);
}

/// Writes a quiet-NaN pattern (never a set-up value) to the group's lanes of all arrays, so
/// a lane the set-up leaves unwritten differs from the reference.
void poison_group(CoverageColumns& c, std::uint32_t pattern) {
  for (int e = 0; e < 3; ++e) {
    for (int lane = 0; lane < kColumnGroup; ++lane) {
      c.t_left[e][lane] = std::bit_cast<float>(pattern);
      c.t_right[e][lane] = std::bit_cast<float>(pattern + 1);
      c.width_q[e][lane] = std::bit_cast<float>(pattern + 2);
      c.slope_q[e][lane] = std::bit_cast<float>(pattern + 3);
      c.base_row[e][lane] = std::int32_t(pattern + 4);
    }
  }
}

/// Compares lanes [0, kColumnGroup) of the five arrays bit for bit; on a difference,
/// describes the first one.
bool same_group(const CoverageColumns& simd, const CoverageColumns& scalar, std::string& what) {
  struct Array {
    const char* name;
    const void* simd;
    const void* scalar;
  };
  for (int e = 0; e < 3; ++e) {
    const Array arrays[] = {{"t_left", simd.t_left[e], scalar.t_left[e]},
                            {"t_right", simd.t_right[e], scalar.t_right[e]},
                            {"width_q", simd.width_q[e], scalar.width_q[e]},
                            {"slope_q", simd.slope_q[e], scalar.slope_q[e]},
                            {"base_row", simd.base_row[e], scalar.base_row[e]}};
    for (const Array& a : arrays) {
      for (int lane = 0; lane < kColumnGroup; ++lane) {
        std::uint32_t x, y;  // all five arrays hold 4-byte elements
        std::memcpy(&x, static_cast<const char*>(a.simd) + 4 * lane, 4);
        std::memcpy(&y, static_cast<const char*>(a.scalar) + 4 * lane, 4);
        if (x == y) continue;
        std::ostringstream s;
        s << a.name << "[" << e << "][" << lane << "]: simd bits 0x" << std::hex << x
          << ", scalar bits 0x" << y;
        what = s.str();
        return false;
      }
    }
  }
  return true;
}

/// One call of the group set-up: a triangle, a group of columns, a row window.
struct SetupCase {
  TriangleSetup setup;
  int col, lanes, row_min, row_max;
};

}  // namespace

TEST_CASE("coverage set-up: the sorting network orders vertices as std::sort", "[coverage]") {
  std::mt19937 rng(0x50a7u);
  auto pick = [&](std::uint32_t n) {
    return std::uniform_int_distribution<std::uint32_t>(0, n - 1)(rng);
  };
  // Coordinates from small sets (ties in x, in y, repeated vertices), anywhere in the guard
  // band, and at the extremes of 24.8 fixed point, each sign.
  auto coord = [&]() -> std::int32_t {
    switch (pick(4)) {
      case 0:
        return (std::int32_t(pick(5)) - 2) * kSubpixelOne;
      case 1:
        return std::int32_t(pick(7)) - 3;
      case 2:
        return std::int32_t(pick(2 * 16384 * kSubpixelOne + 1)) - 16384 * kSubpixelOne;
      default:
        return pick(2) ? (1 << 23) - 1 - std::int32_t(pick(3)) : -(1 << 23) + std::int32_t(pick(3));
    }
  };
  std::uint64_t compared = 0, mismatches = 0, x_ties = 0;
  std::string first;
  for (int n = 0; n < 20000; ++n) {
    std::int32_t x[3], y[3];
    for (int k = 0; k < 3; ++k) {
      x[k] = coord();
      y[k] = coord();
    }
    if (x[0] == x[1] || x[1] == x[2] || x[0] == x[2]) ++x_ties;
    int perm[3] = {0, 1, 2};
    do {
      TriangleSetup t{};
      for (int k = 0; k < 3; ++k) {
        t.x_fx8[k] = x[perm[k]];
        t.y_fx8[k] = y[perm[k]];
      }
      ++compared;
      if (same_triangle(covrast::detail::make_coverage_triangle(t), reference_coverage_triangle(t)))
        continue;
      if (++mismatches == 1) first = describe(t);
    } while (std::next_permutation(perm, perm + 3));
  }
  INFO("first mismatch: " << first);
  CHECK(compared == 120000);
  CHECK(x_ties > 1000);
  CHECK(mismatches == 0);
}

namespace {

/// Triangles for the set-up comparison: the kernel tests' mix (ordinary, slivers, in-pixel,
/// on the pixel grid, huge up to +-16384 px), right triangles with a vertical and a
/// horizontal edge (on pixel borders half of the time), and small triangles far out at up
/// to +-16384 px.
std::vector<TriangleSetup> setup_test_triangles(std::mt19937& rng) {
  auto pick = [&](std::uint32_t n) {
    return std::uniform_int_distribution<std::uint32_t>(0, n - 1)(rng);
  };
  auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  std::vector<TriangleSetup> tris;
  TriangleGenerator gen(0x5e7091u);
  for (const KindCount& kc : kMix) {
    for (int n = 0; n < kc.count / 4; ++n) tris.push_back(gen.next(kc.kind).setup);
  }
  auto far_coord = [&]() {
    const std::int32_t c = std::int32_t(pick(2 * 16384 - 64)) - 16384 + 32;
    return c * kSubpixelOne + (pick(2) ? 0 : std::int32_t(pick(kSubpixelOne)));
  };
  auto extent = [&]() {
    static constexpr double kSizes[] = {1.0 / 256, 0.5, 1.0, 3.0, 7.0, 20.0};
    const double size = kSizes[pick(6)];
    const std::int32_t d =
        pick(2) ? std::int32_t(size * kSubpixelOne) : std::max(1, snap(uniform(0, size)));
    return pick(2) ? d : -d;
  };
  while (tris.size() < 35000) {
    const Fx8Point a{far_coord(), far_coord()};
    const bool right = tris.size() < 30000;
    Fx8Point b{a.x + extent(), a.y}, c{a.x, a.y + extent()};
    if (!right) {
      b = {a.x + extent(), a.y + extent()};
      c = {a.x + extent(), a.y + extent()};
    }
    TriangleSetup t;
    if (make_setup(a, b, c, t)) tris.push_back(t);
  }

  return tris;
}

/// Column groups for the set-up comparison: the rasterizer's own (every group of the box,
/// the last one partial), random groups that overhang the box or lie outside it with 0..8
/// lanes, and row windows that are the box's rows, cut through the triangle, or miss it.
std::vector<SetupCase> setup_test_groups(const std::vector<TriangleSetup>& tris,
                                         std::mt19937& rng) {
  auto pick = [&](std::uint32_t n) {
    return std::uniform_int_distribution<std::uint32_t>(0, n - 1)(rng);
  };
  std::vector<SetupCase> cases;
  for (const TriangleSetup& t : tris) {
    const PixelRect box = covrast::detail::touched_pixels(t);
    auto rows = [&](SetupCase& sc) {
      switch (pick(3)) {
        case 0:
          sc.row_min = box.y0;
          sc.row_max = box.y1;
          break;
        case 1: {
          const int h = box.y1 - box.y0;
          sc.row_min = box.y0 - 2 + int(pick(std::uint32_t(std::min(h, 40) + 4)));
          sc.row_max = sc.row_min + int(pick(std::uint32_t(std::min(h, 40) + 3)));
          break;
        }
        default:
          sc.row_min = INT_MIN / 2;
          sc.row_max = INT_MAX / 2;
      }
    };
    if (box.x1 - box.x0 <= 8 * kColumnGroup) {
      for (int g = box.x0; g < box.x1; g += kColumnGroup) {
        SetupCase sc{t, g, std::min(kColumnGroup, box.x1 - g), 0, 0};
        rows(sc);
        cases.push_back(sc);
      }
    } else {
      for (int k = 0; k < 4; ++k) {
        const int g = box.x0 + int(pick(std::uint32_t(box.x1 - box.x0)));
        SetupCase sc{t, g, std::min(kColumnGroup, box.x1 - g), 0, 0};
        rows(sc);
        cases.push_back(sc);
      }
    }
    const int width = std::min(box.x1 - box.x0, 64);
    for (int k = 0; k < 2; ++k) {
      SetupCase sc{t, box.x0 - 10 + int(pick(std::uint32_t(width + 12))),
                   int(pick(kColumnGroup + 1)), 0, 0};
      rows(sc);
      cases.push_back(sc);
    }
  }

  return cases;
}

/// The scalar twin's rows for every case, and how many cases are partial groups, empty, with
/// an interior run, or clipped by their row window (the branches the comparison must reach).
struct ScalarSetup {
  std::vector<GroupRows> rows;
  std::uint64_t partial = 0, empty = 0, interior = 0, clipped = 0;
};
ScalarSetup run_scalar_setup(const std::vector<SetupCase>& cases) {
  auto scalar_cols = std::make_unique<CoverageColumns>();
  ScalarSetup out;
  out.rows.resize(cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const SetupCase& sc = cases[i];
    const CoverageTriangle tri = covrast::detail::make_coverage_triangle(sc.setup);
    const GroupRows g = covrast::detail::setup_column_group_scalar(
        tri, sc.col, sc.lanes, sc.row_min, sc.row_max, *scalar_cols);
    out.rows[i] = g;
    out.partial += sc.lanes < kColumnGroup;
    out.empty += g.empty();
    out.interior += g.interior_begin < g.interior_end;
    const GroupRows unclipped = covrast::detail::setup_column_group_scalar(
        tri, sc.col, sc.lanes, INT_MIN / 2, INT_MAX / 2, *scalar_cols);
    out.clipped += !g.empty() && (g.first != unclipped.first || g.end != unclipped.end);
  }
  return out;
}

/// The first difference between the SIMD and the scalar set-up over `cases` (empty: none),
/// and how many cases differ.
std::string first_setup_difference(const std::vector<SetupCase>& cases,
                                   const std::vector<GroupRows>& scalar_rows,
                                   std::uint64_t& differing) {
  auto scalar_cols = std::make_unique<CoverageColumns>();
  auto simd_cols = std::make_unique<CoverageColumns>();
  differing = 0;
  std::string first;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const SetupCase& sc = cases[i];
    const CoverageTriangle tri = covrast::detail::make_coverage_triangle(sc.setup);
    poison_group(*scalar_cols, 0x7fc00010u);
    poison_group(*simd_cols, 0x7fc00020u);
    covrast::detail::setup_column_group_scalar(tri, sc.col, sc.lanes, sc.row_min, sc.row_max,
                                               *scalar_cols);
    const GroupRows g = covrast::detail::setup_column_group(tri, sc.col, sc.lanes, sc.row_min,
                                                            sc.row_max, *simd_cols);
    const GroupRows& ref = scalar_rows[i];
    std::string what;
    if (g.first != ref.first || g.end != ref.end || g.interior_begin != ref.interior_begin ||
        g.interior_end != ref.interior_end) {
      std::ostringstream s;
      s << "rows simd (" << g.first << ", " << g.end << ", " << g.interior_begin << ", "
        << g.interior_end << "), scalar (" << ref.first << ", " << ref.end << ", "
        << ref.interior_begin << ", " << ref.interior_end << ")";
      what = s.str();
    } else if (same_group(*simd_cols, *scalar_cols, what)) {
      continue;
    }
    if (++differing == 1) {
      std::ostringstream s;
      s << describe(sc.setup) << " col " << sc.col << " lanes " << sc.lanes << " rows ["
        << sc.row_min << ", " << sc.row_max << "): " << what;
      first = s.str();
    }
  }
  return first;
}

}  // namespace

TEST_CASE("coverage set-up: every SIMD target gives the scalar twin's bits", "[coverage]") {
  REQUIRE(!covrast::test::usable_targets().empty());
  std::mt19937 rng(0x5e7091u);
  const std::vector<TriangleSetup> tris = setup_test_triangles(rng);
  const std::vector<SetupCase> cases = setup_test_groups(tris, rng);
  const ScalarSetup scalar = run_scalar_setup(cases);
  WARN("column set-up: " << tris.size() << " triangles, " << cases.size() << " groups ("
                         << scalar.partial << " partial, " << scalar.empty << " empty, "
                         << scalar.interior << " with an interior run, " << scalar.clipped
                         << " clipped) on " << covrast::test::usable_targets().size()
                         << " targets");
  CHECK(scalar.partial > 20000);
  CHECK(scalar.empty > 2000);
  CHECK(scalar.interior > 5000);
  CHECK(scalar.clipped > 5000);

  covrast::test::for_each_target([&](std::int64_t) {
    std::uint64_t differing = 0;
    const std::string first = first_setup_difference(cases, scalar.rows, differing);
    INFO(first);
    CHECK(differing == 0);
  });
}

// ---- Tessellations: coverages add up to exactly one pixel ------------------------------

namespace {

struct TessellationResult {
  std::uint64_t full_pixels = 0;    ///< pixels whose exact covered area is 1
  std::uint64_t wrong = 0;          ///< of those, pixels whose 8.8 sum is not kCoverageOne
  std::uint64_t over = 0;           ///< any pixel whose 8.8 sum exceeds kCoverageOne
  std::uint64_t rows_mismatch = 0;  ///< groups whose rows differ from the scalar set-up's
  std::string first_wrong;
};

/// Sums the 8.8 coverage of all triangles per pixel (as draw() computes it, cover_group_simd)
/// and checks pixels whose exact covered area is 1.
TessellationResult check_tessellation(const std::vector<TriangleSetup>& tris) {
  PixelRect box{INT32_MAX, INT32_MAX, INT32_MIN, INT32_MIN};
  for (const TriangleSetup& t : tris) {
    const PixelRect r = covrast::detail::touched_pixels(t);
    box = PixelRect{std::min(box.x0, r.x0), std::min(box.y0, r.y0), std::max(box.x1, r.x1),
                    std::max(box.y1, r.y1)};
  }
  const std::size_t w = std::size_t(box.x1 - box.x0), h = std::size_t(box.y1 - box.y0);
  std::vector<std::uint32_t> sum(w * h, 0);
  std::vector<double> exact(w * h, 0.0);
  std::vector<std::vector<std::pair<std::size_t, std::uint16_t>>> parts(w * h);
  TessellationResult res;
  for (std::size_t i = 0; i < tris.size(); ++i) {
    const KernelRun run = run_group(tris[i], box, covrast::detail::cover_group_simd);
    res.rows_mismatch += run.rows_mismatch;
    const PixelRect r = covrast::detail::touched_pixels(tris[i]);
    for (int y = r.y0; y < r.y1; ++y) {
      for (int x = r.x0; x < r.x1; ++x) {
        const std::size_t p = std::size_t(y - box.y0) * w + std::size_t(x - box.x0);
        const std::uint16_t c = run.plane.at(x, y);
        sum[p] += c;
        exact[p] += exact_area(tris[i], x, y);
        if (c != 0) parts[p].emplace_back(i, c);
      }
    }
  }
  for (std::size_t p = 0; p < w * h; ++p) {
    if (sum[p] > std::uint32_t(kCoverageOne)) ++res.over;
    if (std::fabs(exact[p] - 1.0) > 1e-9) continue;
    ++res.full_pixels;
    if (sum[p] == std::uint32_t(kCoverageOne)) continue;
    if (++res.wrong == 1) {
      std::ostringstream s;
      s << "pixel (" << box.x0 + int(p % w) << ", " << box.y0 + int(p / w) << "): sum " << sum[p]
        << " of";
      for (auto [i, c] : parts[p]) {
        s << " [" << describe(tris[i]) << " -> " << c << ", exact "
          << kCoverageOne * exact_area(tris[i], box.x0 + int(p % w), box.y0 + int(p / w)) << "]";
      }
      res.first_wrong = s.str();
    }
  }
  return res;
}

void add_triangle(std::vector<TriangleSetup>& tris, Fx8Point a, Fx8Point b, Fx8Point c) {
  TriangleSetup t;
  if (make_setup(a, b, c, t)) tris.push_back(t);
}

/// n x n cells of `cell` px from (x0, y0): interior vertices jittered by up to 0.2 cell in x
/// and y (below 0.25, so every cell stays convex and neither diagonal folds), border vertices
/// on the square's border, each cell cut along a random diagonal.
std::vector<TriangleSetup> jittered_grid(double x0, double y0, int n, double cell,
                                         std::mt19937& rng) {
  std::uniform_real_distribution<double> jitter(-0.2 * cell, 0.2 * cell);
  std::vector<Fx8Point> v(std::size_t(n + 1) * std::size_t(n + 1));
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      double x = x0 + i * cell, y = y0 + j * cell;
      if (i > 0 && i < n) x += jitter(rng);
      if (j > 0 && j < n) y += jitter(rng);
      v[std::size_t(j) * std::size_t(n + 1) + std::size_t(i)] = {snap(x), snap(y)};
    }
  }
  std::vector<TriangleSetup> tris;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      auto at = [&](int a, int b) {
        return v[std::size_t(b) * std::size_t(n + 1) + std::size_t(a)];
      };
      const Fx8Point p00 = at(i, j), p10 = at(i + 1, j), p01 = at(i, j + 1), p11 = at(i + 1, j + 1);
      if (rng() & 1) {
        add_triangle(tris, p00, p10, p11);
        add_triangle(tris, p00, p11, p01);
      } else {
        add_triangle(tris, p00, p10, p01);
        add_triangle(tris, p10, p11, p01);
      }
    }
  }
  return tris;
}

/// A fan of `spokes` triangles around `centre` out to a snapped circle of radius `radius_px`.
std::vector<TriangleSetup> fan(double cx, double cy, double radius_px, int spokes) {
  std::vector<TriangleSetup> tris;
  const Fx8Point c{snap(cx), snap(cy)};
  auto rim = [&](int k) {
    const double a = 2.0 * 3.14159265358979323846 * k / spokes + 0.1234;
    return Fx8Point{snap(cx + radius_px * std::cos(a)), snap(cy + radius_px * std::sin(a))};
  };
  for (int k = 0; k < spokes; ++k) add_triangle(tris, c, rim(k), rim(k + 1));
  return tris;
}

/// The front half of a rotated UV sphere projected orthographically: triangles whose
/// outward normal faces the viewer (z > 0.05 at the face centre, so none is near edge-on).
std::vector<TriangleSetup> projected_sphere(double cx, double cy, double radius_px, int stacks,
                                            int slices) {
  const double pi = 3.14159265358979323846;
  const double ax = 0.7, ay = 0.4;  // rotations about x then y [radians]
  std::vector<glm::dvec3> p;
  for (int i = 0; i <= stacks; ++i) {
    const double theta = pi * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double phi = 2 * pi * j / slices;
      glm::dvec3 q(std::sin(theta) * std::cos(phi), std::cos(theta),
                   std::sin(theta) * std::sin(phi));
      q = glm::dvec3(q.x, q.y * std::cos(ax) - q.z * std::sin(ax),
                     q.y * std::sin(ax) + q.z * std::cos(ax));
      q = glm::dvec3(q.x * std::cos(ay) + q.z * std::sin(ay), q.y,
                     -q.x * std::sin(ay) + q.z * std::cos(ay));
      p.push_back(q);
    }
  }
  auto id = [&](int i, int j) {
    return std::size_t(i) * std::size_t(slices) + std::size_t(j % slices);
  };
  std::vector<TriangleSetup> tris;
  auto face = [&](std::size_t a, std::size_t b, std::size_t c) {
    const glm::dvec3 centre = (p[a] + p[b] + p[c]) / 3.0;
    if (centre.z / glm::length(centre) < 0.05) return;
    auto s = [&](std::size_t k) {
      return Fx8Point{snap(cx + radius_px * p[k].x), snap(cy - radius_px * p[k].y)};
    };
    add_triangle(tris, s(a), s(b), s(c));
  };
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      if (i > 0) face(id(i, j), id(i + 1, j), id(i, j + 1));
      if (i + 1 < stacks) face(id(i, j + 1), id(i + 1, j), id(i + 1, j + 1));
    }
  }
  return tris;
}

}  // namespace

TEST_CASE("coverage of a tessellation adds up to exactly one pixel", "[coverage]") {
  std::mt19937 rng(20240611u);
  struct Case {
    std::string name;
    std::vector<TriangleSetup> tris;
    std::int64_t square_area2 = 0;  ///< grids: doubled area of the snapped outer square
  };
  std::vector<Case> cases;
  std::ostringstream summary;
  auto grid = [&](const char* name, double x0, double y0, int n, double cell) {
    const std::int64_t side_x = snap(x0 + n * cell) - snap(x0);
    const std::int64_t side_y = snap(y0 + n * cell) - snap(y0);
    cases.push_back({name, jittered_grid(x0, y0, n, cell, rng), 2 * side_x * side_y});
  };
  grid("grid 12 x 12 cells of 7.3 px", 3.37, 5.81, 12, 7.3);
  grid("grid 40 x 40 cells of 1.3 px", -20.6, 11.2, 40, 1.3);
  grid("grid 60 x 60 cells of 0.37 px", 0.5, 0.25, 60, 0.37);
  grid("grid 5 x 5 cells of 23 px", -7.0, -3.0, 5, 23.0);
  cases.push_back({"fan of 64 around (40.3, 40.7)", fan(40.3, 40.7, 30.0, 64)});
  cases.push_back({"fan of 720 around (40.3, 40.7)", fan(40.3, 40.7, 30.0, 720)});
  cases.push_back({"fan of 360 around the corner (40, 40)", fan(40.0, 40.0, 25.0, 360)});
  cases.push_back({"fan of 200 around (-3.5, 1000.5)", fan(-3.5, 1000.5, 12.0, 200)});
  cases.push_back({"projected UV sphere 24 x 48", projected_sphere(100.37, 90.61, 60.0, 24, 48)});
  cases.push_back({"projected UV sphere 64 x 128", projected_sphere(50.5, 60.25, 45.0, 64, 128)});
  for (const Case& c : cases) {
    if (c.square_area2 != 0) {
      // No fold: the triangles' (positive) areas add up to the square's exactly.
      std::int64_t area2 = 0;
      for (const TriangleSetup& t : c.tris) {
        area2 += doubled_area({t.x_fx8[0], t.y_fx8[0]}, {t.x_fx8[1], t.y_fx8[1]},
                              {t.x_fx8[2], t.y_fx8[2]});
      }
      INFO(c.name);
      REQUIRE(area2 == c.square_area2);
    }
    const TessellationResult res = check_tessellation(c.tris);
    INFO(c.name << ": " << c.tris.size() << " triangles, " << res.full_pixels
                << " fully covered pixels, " << res.wrong << " with a sum != 65280, " << res.over
                << " pixels over 65280; first: " << res.first_wrong);
    CHECK(res.full_pixels > 50);
    CHECK(res.wrong == 0);
    CHECK(res.over == 0);
    CHECK(res.rows_mismatch == 0);
    summary << c.name << ": " << res.full_pixels << " full pixels, " << res.wrong << " wrong; ";
  }
  WARN("tessellations: " << summary.str());
}
