// Tests of the sample-based modes: ssaa:N, ssaa-grid:N, ssaa-cmj:N, msaa:K and reference
// (src/raster/sample_raster.cpp, ssaa.cpp, msaa.cpp, reference.cpp, sample_kernel.cpp).
//
// Most tests drive the tile rasterizers directly with screen triangles built here from
// 24.8 fixed-point vertices, so the geometry is known exactly and the resolved linear
// colours can be read before 8-bit encoding; the scene tests go through covrast::render.
#include "color/srgb8.hpp"
#include "core/testing_hooks.hpp"
#include "core/triangle_setup.hpp"
#include "raster/rasterizers.hpp"
#include "raster/reference/reference.hpp"
#include "raster/samples/sample_kernel.hpp"
#include "raster/samples/sample_pattern.hpp"
#include "raster/samples/sample_raster.hpp"
#include "test_meshes.hpp"
#include "test_splits.hpp"

#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <hwy/targets.h>

#include <catch2/catch.hpp>

#include "test_hooks.hpp"

#include "test_targets.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using covrast::ColorSource;
using covrast::Image;
using covrast::MeshData;
using covrast::MeshInstance;
using covrast::RenderOptions;
using covrast::Scene;
using covrast::detail::FrameTarget;
using covrast::detail::kSubpixelOne;
using covrast::detail::PixelRect;
using covrast::detail::ReferenceRasterizer;
using covrast::detail::SamplePattern;
using covrast::detail::SampleRasterizer;
using covrast::detail::ShadingRate;
using covrast::detail::TriangleSetup;
using covrast::test::add_instance;
using covrast::test::render_mode;
using covrast::test::uv_sphere;

// ---------------------------------------------------------------------------------------
// Screen triangles

/// Vertices in 24.8 fixed point, positive doubled area (the setup's orientation).
struct Tri {
  std::int64_t x[3];
  std::int64_t y[3];
};

std::int64_t doubled_area(const Tri& t) {
  return (t.x[1] - t.x[0]) * (t.y[2] - t.y[0]) - (t.x[2] - t.x[0]) * (t.y[1] - t.y[0]);
}

/// Swaps two vertices when needed so that the doubled area is positive; false if zero.
bool orient(Tri& t) {
  const std::int64_t a = doubled_area(t);
  if (a == 0) return false;
  if (a < 0) {
    std::swap(t.x[1], t.x[2]);
    std::swap(t.y[1], t.y[2]);
  }
  return true;
}

/// The setup of `t` with per-vertex depths `z` (window depth, a plane) and colours.
TriangleSetup make_setup(const Tri& t, const std::array<double, 3>& z,
                         const std::array<glm::vec3, 3>& color, std::uint32_t primitive) {
  TriangleSetup s{};
  for (int i = 0; i < 3; ++i) {
    s.x_fx8[i] = std::int32_t(t.x[i]);
    s.y_fx8[i] = std::int32_t(t.y[i]);
    s.inv_w[i] = 1.0f;
    s.color[i] = color[std::size_t(i)];
  }
  // z = z0 + a (x - x0) + b (y - y0) through the three vertices [pixels].
  const double x1 = double(t.x[1] - t.x[0]) / kSubpixelOne,
               y1 = double(t.y[1] - t.y[0]) / kSubpixelOne;
  const double x2 = double(t.x[2] - t.x[0]) / kSubpixelOne,
               y2 = double(t.y[2] - t.y[0]) / kSubpixelOne;
  const double det = x1 * y2 - x2 * y1;
  const double z1 = z[1] - z[0], z2 = z[2] - z[0];
  s.z0 = z[0];
  s.dzdx = (z1 * y2 - z2 * y1) / det;
  s.dzdy = (x1 * z2 - x2 * z1) / det;
  s.primitive = primitive;
  s.surface = 0;
  s.front_facing = true;
  s.flat_color = color[0] == color[1] && color[1] == color[2];
  return s;
}

TriangleSetup flat_setup(const Tri& t, double z, glm::vec3 color, std::uint32_t primitive = 0) {
  return make_setup(t, {z, z, z}, {color, color, color}, primitive);
}

/// A random triangle around a random point of [lo, hi)^2 [pixels], of random size
/// (0.35 .. 11 pixels), vertices on the 1/256 grid.
Tri random_triangle(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> centre(lo, hi), unit(-1.0, 1.0), log_size(-1.5, 3.5);
  for (;;) {
    const double cx = centre(rng), cy = centre(rng), size = std::exp2(log_size(rng));
    Tri t;
    for (int i = 0; i < 3; ++i) {
      t.x[i] = std::llround((cx + size * unit(rng)) * kSubpixelOne);
      t.y[i] = std::llround((cy + size * unit(rng)) * kSubpixelOne);
    }
    if (orient(t)) return t;
  }
}

/// A right triangle with horizontal and vertical legs (lengths 0.5 .. 8 pixels).
Tri axis_triangle(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> corner(lo, hi), leg(0.5, 8.0);
  std::bernoulli_distribution flip(0.5);
  const std::int64_t x = std::llround(corner(rng) * kSubpixelOne);
  const std::int64_t y = std::llround(corner(rng) * kSubpixelOne);
  const std::int64_t w = std::llround(leg(rng) * kSubpixelOne) * (flip(rng) ? -1 : 1);
  const std::int64_t h = std::llround(leg(rng) * kSubpixelOne) * (flip(rng) ? -1 : 1);
  Tri t{{x, x + w, x}, {y, y, y + h}};
  orient(t);
  return t;
}

/// Edge function of edge i -> i+1 at (px, py) [fx8^2], as in raster/edge_function.hpp.
std::int64_t edge_value(const Tri& t, int i, std::int64_t px, std::int64_t py) {
  const int j = (i + 1) % 3;
  return (t.x[j] - t.x[i]) * (py - t.y[i]) - (t.y[j] - t.y[i]) * (px - t.x[i]);
}

/// Point-in-triangle with the top-left rule, written independently of the library: on an
/// edge, the point belongs to the triangle when the edge is a top edge (dy == 0, dx > 0)
/// or a left edge (dy < 0).
bool covers(const Tri& t, std::int64_t px, std::int64_t py) {
  for (int i = 0; i < 3; ++i) {
    const std::int64_t e = edge_value(t, i, px, py);
    if (e < 0) return false;
    if (e == 0) {
      const int j = (i + 1) % 3;
      const std::int64_t dx = t.x[j] - t.x[i], dy = t.y[j] - t.y[i];
      if (!(dy < 0 || (dy == 0 && dx > 0))) return false;
    }
  }
  return true;
}

/// Whether (px, py) lies on the triangle's boundary (closed triangle, some edge value 0).
bool on_boundary(const Tri& t, std::int64_t px, std::int64_t py) {
  bool zero = false;
  for (int i = 0; i < 3; ++i) {
    const std::int64_t e = edge_value(t, i, px, py);
    if (e < 0) return false;
    zero |= e == 0;
  }
  return zero;
}

/// Exact area of the triangle inside pixel (px, py): Sutherland-Hodgman clipping of the
/// triangle against the four sides of the pixel square, then the shoelace formula.
double clip_area(const Tri& t, int px, int py) {
  std::vector<glm::dvec2> poly;
  for (int i = 0; i < 3; ++i) {
    poly.emplace_back(double(t.x[i]) / kSubpixelOne, double(t.y[i]) / kSubpixelOne);
  }
  // Keep the part with sign * (coordinate axis of p - bound) >= 0.
  auto clip = [&](int axis, double bound, double sign) {
    std::vector<glm::dvec2> out;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const glm::dvec2 a = poly[i], b = poly[(i + 1) % poly.size()];
      const double da = sign * (a[axis] - bound), db = sign * (b[axis] - bound);
      if (da >= 0) out.push_back(a);
      if ((da >= 0) != (db >= 0)) out.push_back(a + (b - a) * (da / (da - db)));
    }
    poly = out;
  };
  clip(0, px, 1.0);
  clip(0, px + 1.0, -1.0);
  clip(1, py, 1.0);
  clip(1, py + 1.0, -1.0);
  double area = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec2 a = poly[i], b = poly[(i + 1) % poly.size()];
    area += a.x * b.y - b.x * a.y;
  }
  return std::abs(area) / 2;
}

/// How many of the triangle's edge lines pass through the open pixel square (the corner
/// values have both signs), and whether one that does is horizontal or vertical.
struct PixelEdges {
  int crossing = 0;
  bool axis_aligned = false;
};
PixelEdges pixel_edges(const Tri& t, int px, int py) {
  PixelEdges pe;
  for (int i = 0; i < 3; ++i) {
    std::int64_t lo = INT64_MAX, hi = INT64_MIN;
    for (int c = 0; c < 4; ++c) {
      const std::int64_t v = edge_value(t, i, std::int64_t(px + (c & 1)) * kSubpixelOne,
                                        std::int64_t(py + (c >> 1)) * kSubpixelOne);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (lo < 0 && hi > 0) {
      ++pe.crossing;
      const int j = (i + 1) % 3;
      pe.axis_aligned = t.x[j] == t.x[i] || t.y[j] == t.y[i];
    }
  }
  return pe;
}

// ---------------------------------------------------------------------------------------
// Driving a tile rasterizer

/// Draws `tris` in order into the tile `rect` and returns the resolved linear colours,
/// row-major over the rect.
template <typename Raster>
std::vector<glm::dvec3> render_tile(Raster& raster, int tile_px, const PixelRect& rect,
                                    const std::vector<TriangleSetup>& tris, glm::vec3 background) {
  const FrameTarget target{nullptr, nullptr, background};
  raster.begin_tile(rect, target);
  for (const TriangleSetup& t : tris) raster.draw(t);
  raster.resolve_tile(target);
  std::vector<glm::dvec3> out;
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; ++x) {
      out.push_back(glm::dvec3(raster.linear()[std::size_t(y - rect.y0) * std::size_t(tile_px) +
                                               std::size_t(x - rect.x0)]));
    }
  }
  return out;
}

/// The same through end_tile: 8-bit sRGB, as the renderer writes it.
Image encode_tile(covrast::detail::TileRasterizer& raster, const PixelRect& rect,
                  const std::vector<TriangleSetup>& tris, glm::vec3 background) {
  Image image;
  image.width = rect.x1;
  image.height = rect.y1;
  image.rgb.assign(std::size_t(rect.x1) * rect.y1 * 3, 0);
  const FrameTarget target{&image, nullptr, background};
  raster.begin_tile(rect, target);
  for (const TriangleSetup& t : tris) raster.draw(t);
  raster.end_tile(target);
  return image;
}

/// The ssaa-grid:N (grid) or ssaa-cmj:N (!grid) rasterizer.
std::unique_ptr<SampleRasterizer> ssaa_raster(int tile_px, int n, bool grid) {
  return std::make_unique<SampleRasterizer>(
      tile_px, grid ? covrast::detail::ssaa_grid_pattern(n) : covrast::detail::ssaa_cmj_pattern(n),
      ShadingRate::PerSample, covrast::detail::sample_kernels_simd());
}

}  // namespace

// ---------------------------------------------------------------------------------------

TEST_CASE(
    "ssaa-cmj patterns are n-rooks on the 1/256 grid, ssaa and ssaa-grid are the ordered grid",
    "[ssaa]") {
  for (int n = 1; n <= 16; ++n) {
    // ssaa:N uses the ordered grid (docs/supersampling.md says why).
    const SamplePattern grid = covrast::detail::ssaa_grid_pattern(n);
    REQUIRE(covrast::detail::ssaa_pattern(n).x == grid.x);
    REQUIRE(covrast::detail::ssaa_pattern(n).y == grid.y);
    const SamplePattern p = covrast::detail::ssaa_cmj_pattern(n);
    REQUIRE(p.size() == n * n);
    std::vector<int> per_column(std::size_t(n * n), 0), per_row(std::size_t(n * n), 0);
    std::vector<int> per_cell(std::size_t(n * n), 0);
    for (int s = 0; s < n * n; ++s) {
      const int x = p.x[std::size_t(s)], y = p.y[std::size_t(s)];
      REQUIRE(x >= 0);
      REQUIRE(x < 256);
      REQUIRE(y >= 0);
      REQUIRE(y < 256);
      // Fine cell k spans [floor(k 256 / n^2), floor((k + 1) 256 / n^2)).
      int kx = 0, ky = 0;
      while ((kx + 1) * 256 / (n * n) <= x) ++kx;
      while ((ky + 1) * 256 / (n * n) <= y) ++ky;
      ++per_column[std::size_t(kx)];
      ++per_row[std::size_t(ky)];
      ++per_cell[std::size_t((ky / n) * n + kx / n)];
    }
    INFO("n = " << n);
    for (int k = 0; k < n * n; ++k) {
      REQUIRE(per_column[std::size_t(k)] == 1);
      REQUIRE(per_row[std::size_t(k)] == 1);
      REQUIRE(per_cell[std::size_t(k)] == 1);
    }
  }
  // The ordered grid: N distinct x values only, each (i + 0.5) / N rounded to 1/256.
  const SamplePattern g = covrast::detail::ssaa_grid_pattern(4);
  REQUIRE(g.x == std::vector<std::int32_t>{32, 96, 160, 224, 32, 96, 160, 224, 32, 96, 160, 224, 32,
                                           96, 160, 224});
  REQUIRE(g.y[5] == 96);
  const SamplePattern g3 = covrast::detail::ssaa_grid_pattern(3);
  REQUIRE(g3.x[0] == 43);  // 42.67
  REQUIRE(g3.x[1] == 128);
  REQUIRE(g3.x[2] == 213);  // 213.33
}

// Error bounds (docs/supersampling.md), for ssaa-cmj:N (n-rooks) and the ordered grid of
// ssaa-grid:N and ssaa:N. Both patterns put exactly one sample in each of the
// N x N cells of side 1/N (for N = 1, 2, 4, 8, 16 the cells are exact on the 1/256 grid).
// The estimate of the area of K = triangle ∩ pixel is (1/N^2) * #samples inside, so
//   error = sum over cells c of [ I(sample_c inside) / N^2 - area(K ∩ c) ],
// and a cell contributes nothing unless the triangle's boundary passes through its open
// interior, or its sample lies exactly on the boundary (a tie, decided by the top-left
// rule). Each contributing cell adds at most 1/N^2. K is convex: its boundary splits into
// four monotone chains, a monotone chain meets at most (rows + columns - 1) open cells,
// and the four chains span at most 4 (N + 1) rows and columns together, so at most 4N
// cells are crossed:
//   |error| <= (4N + t) / N^2,        t = samples exactly on the boundary.
// When a single straight edge crosses the pixel (half-plane case) a line meets at most
// 2N - 1 open cells:  |error| <= (2N - 1 + t) / N^2.
// For a horizontal (or vertical) edge alone, the n-rooks pattern has exactly one sample
// in each of the N^2 rows of height 1/N^2, so the count is within one of h N^2:
// |error| <= 1 / N^2 (ties included); the ordered grid has N rows of N samples at
// (i + 0.5) / N, so |error| <= 1 / (2N), reached as h sweeps: only N + 1 levels.
TEST_CASE("ssaa coverage error against the exact area stays within its bound and falls with N",
          "[ssaa]") {
  constexpr int kTile = 16;
  const int ns[] = {1, 2, 4, 8, 16};
  struct Config {
    int n;
    bool grid;
    std::unique_ptr<SampleRasterizer> raster;
    SamplePattern pattern;
    double max_error = 0, sum_error = 0, max_axis_error = 0;
    long partial_pixels = 0, violations = 0;
    std::string first_violation;
  };
  std::vector<Config> configs;
  for (bool grid : {false, true}) {
    for (int n : ns) {
      Config c;
      c.n = n;
      c.grid = grid;
      c.raster = ssaa_raster(kTile, n, grid);
      c.pattern =
          grid ? covrast::detail::ssaa_grid_pattern(n) : covrast::detail::ssaa_cmj_pattern(n);
      configs.push_back(std::move(c));
    }
  }
  std::mt19937_64 rng(20240611);
  const PixelRect rect{0, 0, kTile, kTile};
  constexpr int kRandom = 2000, kAxis = 600;
  for (int k = 0; k < kRandom + kAxis; ++k) {
    const Tri tri =
        k < kRandom ? random_triangle(rng, 1.0, kTile - 1.0) : axis_triangle(rng, 1.0, kTile - 1.0);
    const std::vector<TriangleSetup> setups{flat_setup(tri, 0.5, glm::vec3(1.0f))};
    // Exact areas and edge crossings of the pixels the triangle's bounding box touches.
    std::vector<double> exact(kTile * kTile, 0.0);
    std::vector<PixelEdges> crossing(kTile * kTile);
    const PixelRect box =
        covrast::detail::intersect(covrast::detail::touched_pixels(setups[0]), rect);
    for (int y = box.y0; y < box.y1; ++y) {
      for (int x = box.x0; x < box.x1; ++x) {
        exact[std::size_t(y * kTile + x)] = clip_area(tri, x, y);
        crossing[std::size_t(y * kTile + x)] = pixel_edges(tri, x, y);
      }
    }
    for (Config& c : configs) {
      const std::vector<glm::dvec3> lin =
          render_tile(*c.raster, kTile, rect, setups, glm::vec3(0.0f));
      const double n2 = double(c.n) * c.n;
      for (int y = 0; y < kTile; ++y) {
        for (int x = 0; x < kTile; ++x) {
          const std::size_t i = std::size_t(y * kTile + x);
          // White on black: the resolved red channel is (samples inside) / N^2.
          const double estimate = lin[i].r, area = exact[i];
          const double error = std::abs(estimate - area);
          if (area > 0 && area < 1) {
            c.max_error = std::max(c.max_error, error);
            c.sum_error += error;
            ++c.partial_pixels;
          }
          const PixelEdges& pe = crossing[i];
          double bound = (4 * c.n) / n2;
          if (pe.crossing == 1) bound = (2 * c.n - 1) / n2;
          if (pe.crossing == 1 && pe.axis_aligned) {
            bound = c.grid ? 1.0 / (2 * c.n) : 1.0 / n2;
            c.max_axis_error = std::max(c.max_axis_error, error);
          }
          if (error <= bound + 1e-9) continue;
          // Only then count the ties (they can only loosen the first two bounds).
          int ties = 0;
          if (!(pe.crossing == 1 && pe.axis_aligned)) {
            for (int s = 0; s < c.pattern.size(); ++s) {
              ties += on_boundary(tri, std::int64_t(x) * kSubpixelOne + c.pattern.x[std::size_t(s)],
                                  std::int64_t(y) * kSubpixelOne + c.pattern.y[std::size_t(s)]);
            }
          }
          if (error <= bound + ties / n2 + 1e-9) continue;
          if (c.violations++ == 0) {
            c.first_violation = "triangle " + std::to_string(k) + " pixel (" + std::to_string(x) +
                                ", " + std::to_string(y) + "): estimate " +
                                std::to_string(estimate) + " exact " + std::to_string(area);
          }
        }
      }
    }
  }
  for (std::size_t i = 0; i < configs.size(); ++i) {
    const Config& c = configs[i];
    INFO((c.grid ? "ssaa-grid:" : "ssaa-cmj:")
         << c.n << " max error " << c.max_error << " mean " << c.sum_error / c.partial_pixels
         << " axis-aligned max " << c.max_axis_error << "; " << c.first_violation);
    REQUIRE(c.violations == 0);
    REQUIRE(c.partial_pixels > 10000);
    if (c.n > 1) {
      // Both the worst and the mean error fall with every doubling of N.
      const Config& prev = configs[i - 1];
      REQUIRE(c.max_error < prev.max_error);
      REQUIRE(c.sum_error / c.partial_pixels < prev.sum_error / prev.partial_pixels);
    }
  }
  // On axis-aligned edges n-rooks resolves N^2 levels, the ordered grid N + 1: its error
  // reaches almost 1 / (2N) while n-rooks stays below 1 / N^2. Measured (max / mean error
  // over partly covered pixels):
  //   N:          1            2            4            8             16
  //   ssaa-cmj  0.98/0.20    0.65/0.078   0.20/0.032   0.058/0.0089  0.024/0.0033
  //   ssaa-grid 0.98/0.19    0.44/0.074   0.21/0.029   0.11/0.011    0.052/0.0047
  // and from N = 8 on n-rooks is ahead on both counts.
  for (std::size_t i = 1; i < std::size(ns); ++i) {
    const Config& rooks = configs[i];
    const Config& grid = configs[i + std::size(ns)];
    INFO("N = " << rooks.n);
    REQUIRE(rooks.max_axis_error <= 1.0 / (rooks.n * rooks.n) + 1e-9);
    REQUIRE(grid.max_axis_error > 0.8 / (2 * grid.n));
    if (rooks.n >= 8) {
      REQUIRE(rooks.max_error < grid.max_error);
      REQUIRE(rooks.sum_error / rooks.partial_pixels < grid.sum_error / grid.partial_pixels);
    }
  }
}

namespace {

/// Area of the half-plane c x + s y <= d inside the pixel [0, 1]^2, in closed form; c and s
/// must both be nonzero. Reflecting x -> 1 - x where c < 0 (and y -> 1 - y where s < 0)
/// turns it into a x + b y <= e with a = |c|, b = |s|, e = d - min(c, 0) - min(s, 0). The
/// triangle {x, y >= 0 : a x + b y <= u} has the area F(u) = max(u, 0)^2 / (2ab), and
/// inclusion-exclusion over the square's corners gives F(e) - F(e - a) - F(e - b) +
/// F(e - a - b).
double half_plane_area(double c, double s, double d) {
  const double a = std::abs(c), b = std::abs(s);
  const double e = d - std::min(c, 0.0) - std::min(s, 0.0);
  auto f = [](double u) { return u > 0 ? u * u : 0.0; };
  return (f(e) - f(e - a) - f(e - b) + f(e - a - b)) / (2 * a * b);
}

/// The same area by clipping the square's polygon to the half-plane (shoelace formula):
/// an independent check of the closed form.
double half_plane_area_clipped(double c, double s, double d) {
  const glm::dvec2 square[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  std::vector<glm::dvec2> poly;
  for (int i = 0; i < 4; ++i) {
    const glm::dvec2 p = square[i], q = square[(i + 1) % 4];
    const double dp = d - (c * p.x + s * p.y), dq = d - (c * q.x + s * q.y);
    if (dp >= 0) poly.push_back(p);
    if ((dp >= 0) != (dq >= 0)) poly.push_back(p + (q - p) * (dp / (dp - dq)));
  }
  double area = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec2 p = poly[i], q = poly[(i + 1) % poly.size()];
    area += p.x * q.y - q.x * p.y;
  }
  return std::abs(area) / 2;
}

/// A straight edge through the pixel: the half-plane c x + s y <= d and its exact area.
struct HalfPlane {
  double c, s, d, area;
};

/// The fixed edge set: 720 normal directions (k + 0.5) * 0.5 deg over the whole circle
/// (every edge direction with either side inside; none exactly axis-aligned), each with 64
/// offsets d evenly spread across the range in which the line crosses the open pixel.
std::vector<HalfPlane> edge_set() {
  constexpr int kAngles = 720, kOffsets = 64;
  const double pi = std::acos(-1.0);
  std::vector<HalfPlane> edges;
  for (int k = 0; k < kAngles; ++k) {
    const double theta = (k + 0.5) * 2 * pi / kAngles;
    const double c = std::cos(theta), s = std::sin(theta);
    const double lo = std::min(c, 0.0) + std::min(s, 0.0), hi = std::max(c, 0.0) + std::max(s, 0.0);
    for (int o = 0; o < kOffsets; ++o) {
      const double d = lo + (hi - lo) * (o + 0.5) / kOffsets;
      edges.push_back({c, s, d, half_plane_area(c, s, d)});
    }
  }
  return edges;
}

/// RMSE over `edges` of the pattern's coverage estimate (samples inside / samples) against
/// the exact area. Sample (x, y) is at (x / unit, y / unit) from the pixel's corner.
double edge_rmse(const SamplePattern& p, const std::vector<HalfPlane>& edges) {
  std::vector<double> x, y;
  for (int i = 0; i < p.size(); ++i) {
    x.push_back(double(p.x[std::size_t(i)]) / p.unit);
    y.push_back(double(p.y[std::size_t(i)]) / p.unit);
  }
  double sum = 0;
  for (const HalfPlane& e : edges) {
    int inside = 0;
    for (std::size_t i = 0; i < x.size(); ++i) inside += e.c * x[i] + e.s * y[i] <= e.d;
    const double error = double(inside) / p.size() - e.area;
    sum += error * error;
  }
  return std::sqrt(sum / double(edges.size()));
}

}  // namespace

// The default pattern must be at least as good a baseline as the ordered grid on straight
// edges: for every N, the RMSE of its coverage of a half-plane through the pixel, over all
// edge angles and positions, is no larger than that of ssaa-grid:N (no slack), and no
// larger than that of the n-rooks ssaa-cmj:N. Measured (print with -s; docs/supersampling.md):
//   N:         1      2      4      8       16
//   ssaa-grid  0.249  0.0889 0.0317 0.0113  0.00408
//   ssaa-cmj   0.280  0.102  0.0415 0.0119  0.00480
TEST_CASE("ssaa:N has a straight-edge coverage RMSE no larger than ssaa-grid:N for N = 1..16",
          "[ssaa]") {
  const std::vector<HalfPlane> edges = edge_set();
  REQUIRE(edges.size() == 720 * 64);
  double worst_formula = 0;
  for (const HalfPlane& e : edges) {
    worst_formula =
        std::max(worst_formula, std::abs(e.area - half_plane_area_clipped(e.c, e.s, e.d)));
  }
  REQUIRE(worst_formula < 1e-12);
  double previous_grid = 1;
  for (int n = 1; n <= 16; ++n) {
    const double rmse = edge_rmse(covrast::detail::ssaa_pattern(n), edges);
    const double grid = edge_rmse(covrast::detail::ssaa_grid_pattern(n), edges);
    const double cmj = edge_rmse(covrast::detail::ssaa_cmj_pattern(n), edges);
    INFO("N = " << n << ": ssaa " << rmse << ", ssaa-grid " << grid << ", ssaa-cmj " << cmj);
    CHECK(rmse <= grid);
    CHECK(rmse <= cmj);
    // The measure is not degenerate: it falls with every N.
    CHECK(grid < previous_grid);
    previous_grid = grid;
  }
}

TEST_CASE("reference mode matches the exact area to within its sampling error", "[ssaa]") {
  // 64 x 64 correlated multi-jittered samples: by the bound above |error| <= (256 + t) /
  // 4096 in the worst case; measured over these triangles the worst pixel is off by far
  // less (see the last REQUIRE).
  constexpr int kTile = 8;
  ReferenceRasterizer raster(kTile);
  std::mt19937_64 rng(77);
  const PixelRect rect{0, 0, kTile, kTile};
  double max_error = 0, sum_error = 0;
  long partial = 0;
  for (int k = 0; k < 200; ++k) {
    const Tri tri =
        k % 4 == 3 ? axis_triangle(rng, 1.0, kTile - 1.0) : random_triangle(rng, 1.0, kTile - 1.0);
    const std::vector<TriangleSetup> setups{flat_setup(tri, 0.5, glm::vec3(1.0f))};
    const std::vector<glm::dvec3> lin = render_tile(raster, kTile, rect, setups, glm::vec3(0.0f));
    for (int y = 0; y < kTile; ++y) {
      for (int x = 0; x < kTile; ++x) {
        const double area = clip_area(tri, x, y);
        const double error = std::abs(lin[std::size_t(y * kTile + x)].r - area);
        REQUIRE(error <= 256.0 / 4096 + 1e-12);
        if (area > 0 && area < 1) {
          max_error = std::max(max_error, error);
          sum_error += error;
          ++partial;
        }
      }
    }
  }
  INFO("reference: worst error " << max_error << " (" << max_error * 4096 << " / 4096), mean "
                                 << sum_error / partial << " (" << sum_error / partial * 4096
                                 << " / 4096)");
  REQUIRE(partial > 1000);
  // Measured: worst 9.7 / 4096 (2.4e-3), mean 1.5 / 4096 (3.7e-4) of a pixel. Jittered
  // strata that an edge crosses (~64 to 128 of them) each add an independent error of
  // up to 1/4096, which is what these sizes reflect.
  REQUIRE(max_error < 12.0 / 4096);
  REQUIRE(sum_error / partial < 2.0 / 4096);
}

TEST_CASE("a tessellation covers every sample exactly once in every sample-based mode", "[ssaa]") {
  // Jittered grid of vertices on the 1/256 grid over [-2, 18]^2 pixels, each cell split
  // along a random diagonal. Rendering each triangle alone (white on black) gives
  // (samples inside) / S per pixel; summed over the triangles this is exactly 1 in every
  // pixel of the tile iff the top-left rule gives each sample to exactly one triangle.
  constexpr int kTile = 16, kCells = 7;
  std::mt19937_64 rng(99);
  std::uniform_int_distribution<int> jitter(-90, 90);
  std::array<std::array<std::int64_t, kCells + 1>, kCells + 1> vx{}, vy{};
  for (int j = 0; j <= kCells; ++j) {
    for (int i = 0; i <= kCells; ++i) {
      const bool inner_x = i > 0 && i<kCells, inner_y = j> 0 && j < kCells;
      vx[std::size_t(j)][std::size_t(i)] =
          (-2 * 256) + i * (20 * 256) / kCells + (inner_x ? jitter(rng) : 0);
      vy[std::size_t(j)][std::size_t(i)] =
          (-2 * 256) + j * (20 * 256) / kCells + (inner_y ? jitter(rng) : 0);
    }
  }
  std::vector<Tri> tris;
  auto vertex = [&](int i, int j, Tri& t, int k) {
    t.x[k] = vx[std::size_t(j)][std::size_t(i)];
    t.y[k] = vy[std::size_t(j)][std::size_t(i)];
  };
  for (int j = 0; j < kCells; ++j) {
    for (int i = 0; i < kCells; ++i) {
      Tri a, b;
      if (rng() & 1) {
        vertex(i, j, a, 0), vertex(i + 1, j, a, 1), vertex(i + 1, j + 1, a, 2);
        vertex(i, j, b, 0), vertex(i + 1, j + 1, b, 1), vertex(i, j + 1, b, 2);
      } else {
        vertex(i, j, a, 0), vertex(i + 1, j, a, 1), vertex(i, j + 1, a, 2);
        vertex(i + 1, j, b, 0), vertex(i + 1, j + 1, b, 1), vertex(i, j + 1, b, 2);
      }
      REQUIRE(orient(a));
      REQUIRE(orient(b));
      tris.push_back(a);
      tris.push_back(b);
    }
  }
  const PixelRect rect{0, 0, kTile, kTile};
  auto check = [&](auto& raster, int tile_px, const PixelRect& r) {
    std::vector<double> sum(std::size_t((r.x1 - r.x0) * (r.y1 - r.y0)), 0.0);
    for (const Tri& t : tris) {
      const std::vector<TriangleSetup> one{flat_setup(t, 0.5, glm::vec3(1.0f))};
      const std::vector<glm::dvec3> lin = render_tile(raster, tile_px, r, one, glm::vec3(0.0f));
      for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += lin[i].r;
    }
    for (double s : sum) REQUIRE(std::abs(s - 1.0) < 1e-6);  // integer counts / S
  };
  SECTION("ssaa-cmj:16 (a sample on every 1/256 column and row)") {
    check(*ssaa_raster(kTile, 16, false), kTile, rect);
  }
  SECTION("ssaa-grid:4") { check(*ssaa_raster(kTile, 4, true), kTile, rect); }
  SECTION("ssaa-grid:16") { check(*ssaa_raster(kTile, 16, true), kTile, rect); }
  for (int k : {4, 16}) {
    DYNAMIC_SECTION("msaa:" << k) {
      SampleRasterizer raster(kTile, covrast::detail::msaa_pattern(k), ShadingRate::PerPixel,
                              covrast::detail::sample_kernels_simd());
      check(raster, kTile, rect);
    }
  }
  SECTION("reference") {
    ReferenceRasterizer raster(8);
    check(raster, 8, PixelRect{4, 4, 12, 12});
  }
}

namespace {

/// Camera looking down -z from (0, 0, 10).
Scene base_scene(int width, int height, glm::vec3 background) {
  Scene s;
  s.width = width;
  s.height = height;
  s.background_linear = background;
  s.camera.eye = glm::dvec3(0, 0, 10);
  s.camera.target = glm::dvec3(0, 0, 0);
  s.camera.up = glm::dvec3(0, 1, 0);
  s.camera.fovy_deg = 45;
  s.camera.near = 1.0;
  s.camera.far = 100.0;
  return s;
}

}  // namespace

TEST_CASE("seam scene: a closed sphere in the background colour renders exactly flat", "[ssaa]") {
  const glm::vec3 background(0.2f, 0.4f, 0.6f);
  Scene s = base_scene(64, 64, background);
  s.camera.eye = glm::dvec3(0.7, 2.6, 1.6);  // the north pole fan and the phi = 0 seam in view
  s.camera.fovy_deg = 50;
  s.camera.near = 0.5;
  add_instance(s, uv_sphere(16, 32), background);
  // The sphere is really there: in white it covers a good part of the image.
  Scene white = s;
  white.meshes[0].color_linear = glm::vec3(1.0f);
  const Image lit = render_mode(white, "ssaa:4", 1);
  int covered = 0;
  for (std::size_t i = 0; i < lit.rgb.size(); i += 3) covered += lit.rgb[i] == 255;
  REQUIRE(covered > 64 * 64 / 4);
  for (const char* mode : {"ssaa:4", "ssaa-grid:4", "ssaa-cmj:4", "msaa:4", "reference"}) {
    INFO(mode);
    Scene scene = s;
    if (std::string(mode) == "reference") scene.width = scene.height = 40;
    const Image img = render_mode(scene, mode, 2);
    const std::uint8_t* first = img.pixel(0, 0);
    int off = 0;
    for (int y = 0; y < img.height; ++y) {
      for (int x = 0; x < img.width; ++x) {
        const std::uint8_t* p = img.pixel(x, y);
        off += p[0] != first[0] || p[1] != first[1] || p[2] != first[2];
      }
    }
    REQUIRE(off == 0);
  }
}

// Exactness of msaa:K: the resolved value of a white flat triangle is (inside samples) / K,
// counted here from the Direct3D 11 standard positions typed in independently and the
// top-left rule; and with flat colours MSAA must equal per-sample shading at the same
// positions bit for bit. Shading once per pixel is the only difference between the two,
// and a flat colour shades the same everywhere, so coverage, per-sample depth and resolve
// must agree exactly; with vertex colours the two must differ (the test can fail).
TEST_CASE("msaa:K counts the D3D standard samples and equals per-sample shading on flat colours",
          "[ssaa]") {
  const std::vector<std::vector<std::array<int, 2>>> d3d = {
      {{4, 4}, {-4, -4}},
      {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}},
      {{1, -3}, {-1, 3}, {5, 1}, {-3, -5}, {-5, 5}, {-7, -1}, {3, 7}, {7, -7}},
      {{1, 1},
       {-1, -3},
       {-3, 2},
       {4, -1},
       {-5, -2},
       {2, 5},
       {5, 3},
       {3, -5},
       {-2, 6},
       {0, -7},
       {-4, -6},
       {-6, 4},
       {-8, 0},
       {7, -4},
       {6, 7},
       {-7, -8}}};
  constexpr int kTile = 16;
  const PixelRect rect{0, 0, kTile, kTile};
  std::mt19937_64 rng(4242);
  for (const auto& table : d3d) {
    const int k = int(table.size());
    INFO("msaa:" << k);
    auto msaa = covrast::detail::make_msaa_rasterizer(kTile, k);
    auto& raster = dynamic_cast<SampleRasterizer&>(*msaa);
    for (int n = 0; n < 150; ++n) {
      const Tri tri = random_triangle(rng, 1.0, kTile - 1.0);
      const std::vector<glm::dvec3> lin = render_tile(
          raster, kTile, rect, {flat_setup(tri, 0.5, glm::vec3(1.0f))}, glm::vec3(0.0f));
      for (int y = 0; y < kTile; ++y) {
        for (int x = 0; x < kTile; ++x) {
          int count = 0;
          for (const auto& o : table) {
            count += covers(tri, std::int64_t(x) * 256 + 128 + 16 * o[0],
                            std::int64_t(y) * 256 + 128 + 16 * o[1]);
          }
          REQUIRE(lin[std::size_t(y * kTile + x)].r == double(count) / k);
        }
      }
    }
    // Overlapping triangles at different depths (planes not parallel), random colours.
    std::uniform_real_distribution<double> depth(0.1, 0.9);
    std::uniform_real_distribution<float> channel(0.0f, 1.0f);
    std::vector<TriangleSetup> flat, smooth;
    for (std::uint32_t n = 0; n < 80; ++n) {
      const Tri tri = random_triangle(rng, 0.0, kTile);
      const std::array<double, 3> z{depth(rng), depth(rng), depth(rng)};
      std::array<glm::vec3, 3> c;
      for (auto& v : c) v = glm::vec3(channel(rng), channel(rng), channel(rng));
      flat.push_back(make_setup(tri, z, {c[0], c[0], c[0]}, n));
      smooth.push_back(make_setup(tri, z, c, n));
    }
    SampleRasterizer per_sample(kTile, covrast::detail::msaa_pattern(k), ShadingRate::PerSample,
                                covrast::detail::sample_kernels_simd());
    const glm::vec3 background(0.1f, 0.2f, 0.3f);
    REQUIRE(render_tile(raster, kTile, rect, flat, background) ==
            render_tile(per_sample, kTile, rect, flat, background));
    REQUIRE(render_tile(raster, kTile, rect, smooth, background) !=
            render_tile(per_sample, kTile, rect, smooth, background));
  }
}

TEST_CASE("msaa:4 has no dark edge where a far triangle drawn second meets a near one", "[ssaa]") {
  // The square [-4, 36]^2 split along its diagonal: A (red, near) drawn first, B (green,
  // far, tilted differently) second. With one depth per pixel, B would lose the pixels
  // along the diagonal to A's depth and leave background there; with per-sample depth
  // every pixel of the tile is k/4 red + (4 - k)/4 green, never any black.
  constexpr int kTile = 32;
  const std::int64_t lo = -4 * 256, hi = 36 * 256;
  Tri a{{lo, hi, hi}, {lo, lo, hi}};
  Tri b{{lo, hi, lo}, {lo, hi, hi}};
  REQUIRE(orient(a));
  REQUIRE(orient(b));
  const glm::vec3 red(1, 0, 0), green(0, 1, 0);
  const std::vector<TriangleSetup> tris{make_setup(a, {0.2, 0.3, 0.25}, {red, red, red}, 0),
                                        make_setup(b, {0.7, 0.6, 0.8}, {green, green, green}, 1)};
  auto msaa = covrast::detail::make_msaa_rasterizer(kTile, 4);
  const PixelRect rect{0, 0, kTile, kTile};
  const std::vector<glm::dvec3> lin =
      render_tile(dynamic_cast<SampleRasterizer&>(*msaa), kTile, rect, tris, glm::vec3(0.0f));
  int mixed = 0;
  for (const glm::dvec3& c : lin) {
    REQUIRE(c.r + c.g == 1.0);
    REQUIRE(c.b == 0.0);
    REQUIRE(c.r * 4 == std::floor(c.r * 4));
    mixed += c.r > 0 && c.r < 1;
  }
  REQUIRE(mixed >= kTile);  // the diagonal's pixels really are shared
  // The encoded image: every pixel is one of the five blends, none darker than both.
  const Image img = encode_tile(*msaa, rect, tris, glm::vec3(0.0f));
  for (int y = 0; y < kTile; ++y) {
    for (int x = 0; x < kTile; ++x) {
      const std::uint8_t* p = img.pixel(x, y);
      bool blend = false;
      for (int k = 0; k <= 4; ++k) {
        blend |= p[0] == covrast::detail::encode_srgb8(k / 4.0f) &&
                 p[1] == covrast::detail::encode_srgb8(1.0f - k / 4.0f) && p[2] == 0;
      }
      REQUIRE(blend);
    }
  }
}

namespace {

/// Random overlapping triangles with vertex colours, a flat-coloured instance of the same
/// mesh further back, and one huge floor triangle whose screen edges (clipped to the guard
/// band) are far too long for the int32 lanes, so the int64 path runs too.
Scene determinism_scene(int width, int height) {
  Scene s = base_scene(width, height, glm::vec3(0.05f, 0.1f, 0.15f));
  std::mt19937_64 rng(31337);
  std::uniform_real_distribution<float> pos(-3.5f, 3.5f), z(-2.0f, 2.0f), channel(0.0f, 1.0f);
  auto soup = std::make_shared<MeshData>();
  soup->source = "soup";
  for (std::uint32_t i = 0; i < 3 * 150; ++i) {
    if (i % 3 == 0) {
      const float cx = pos(rng), cy = pos(rng), cz = z(rng);
      for (int k = 0; k < 3; ++k) {
        soup->positions.push_back(glm::vec3(cx + 0.4f * pos(rng) / 3.5f * (1 + (i % 7)),
                                            cy + 0.4f * pos(rng) / 3.5f * (1 + (i % 5)),
                                            cz + 0.5f * z(rng)));
        soup->colors_linear.push_back(glm::vec3(channel(rng), channel(rng), channel(rng)));
      }
    }
    soup->indices.push_back(i);
  }
  add_instance(s, soup, glm::vec3(1.0f), ColorSource::Vertex);
  add_instance(s, soup, glm::vec3(0.9f, 0.5f, 0.2f));
  s.meshes.back().model = glm::dmat4(1.0);
  s.meshes.back().model[3] = glm::dvec4(0.3, -0.2, -1.5, 1.0);
  auto floor = std::make_shared<MeshData>();
  floor->source = "floor";
  floor->positions = {glm::vec3(-20000, -1.5f, -60), glm::vec3(20000, -1.5f, -60),
                      glm::vec3(0, -1.5f, 8)};
  floor->indices = {0, 1, 2};
  add_instance(s, floor, glm::vec3(0.3f, 0.6f, 0.3f));
  return s;
}

}  // namespace

TEST_CASE(
    "sample-based modes give identical bytes for every thread count, tile size and SIMD target",
    "[ssaa][threads]") {
  const Scene scene = determinism_scene(97, 61);
  const Scene small = determinism_scene(41, 27);
  const std::int64_t targets =
      covrast::detail::testing::compiled_simd_targets() & hwy::SupportedTargets();
  int forced = 0;
  for (const char* mode : {"ssaa:1", "ssaa:2", "ssaa:3", "ssaa:4", "ssaa:16", "ssaa-grid:5",
                           "ssaa-cmj:1", "ssaa-cmj:2", "ssaa-cmj:3", "ssaa-cmj:4", "ssaa-cmj:16",
                           "msaa:2", "msaa:4", "msaa:8", "msaa:16", "reference"}) {
    INFO(mode);
    const bool reference = std::string(mode) == "reference";
    const Scene& s = reference ? small : scene;
    // Tiles 8 and 24 start off the 16-pixel group grid of ssaa:1.
    const Image base =
        covrast::test::expect_same_bytes_for_every_split(
            s, mode, {{2, 16}, {2, 64}, {2, 128}, {1, 16}, {1, 128}, {2, 8}, {2, 24}})
            .color;
    if (reference) continue;  // no SIMD kernels in the reference mode
    for (std::int64_t bits = targets; bits != 0; bits &= bits - 1) {
      const std::int64_t target = bits & -bits;
      INFO("target " << hwy::TargetName(target));
      const Image img = [&] {
        const covrast::test::ScopedSimdTarget forced(target);
        return render_mode(s, mode, 2, 64);
      }();
      REQUIRE(img.rgb == base.rgb);
      ++forced;
    }
  }
  std::string names;
  for (std::int64_t bits = targets; bits != 0; bits &= bits - 1) {
    names += std::string(" ") + hwy::TargetName(bits & -bits);
  }
  WARN("sample kernels checked on targets:" << names);
  REQUIRE(forced >= 10);
  // Forcing really switches the kernels: one distinct function per target.
  std::vector<covrast::detail::SampleGroupFn> kernels;
  for (std::int64_t bits = targets; bits != 0; bits &= bits - 1) {
    const covrast::test::ScopedSimdTarget forced(bits & -bits);
    kernels.push_back(covrast::detail::sample_kernels_simd().sample);
  }
  std::sort(kernels.begin(), kernels.end(), std::less<covrast::detail::SampleGroupFn>());
  REQUIRE(std::unique(kernels.begin(), kernels.end()) - kernels.begin() ==
          std::ptrdiff_t(kernels.size()));
  // The picture is not trivial: most of it is covered, in many colours.
  const Image img = render_mode(scene, "ssaa:4", 1);
  std::vector<std::uint32_t> colors;
  for (std::size_t i = 0; i < img.rgb.size(); i += 3) {
    colors.push_back(std::uint32_t(img.rgb[i]) << 16 | std::uint32_t(img.rgb[i + 1]) << 8 |
                     img.rgb[i + 2]);
  }
  std::sort(colors.begin(), colors.end());
  REQUIRE(std::unique(colors.begin(), colors.end()) - colors.begin() > 1000);
}

TEST_CASE("the sample kernels on every SIMD target give their scalar twins' samples", "[ssaa]") {
  // Flat and vertex-coloured triangles at random depths, some with edges beyond the int32
  // bound (the int64 path), in tiles whose rect starts off the group grid.
  std::mt19937_64 rng(2718);
  std::uniform_real_distribution<double> depth(0.05, 0.95);
  std::uniform_real_distribution<float> channel(0.0f, 1.0f);
  std::vector<TriangleSetup> tris;
  for (std::uint32_t n = 0; n < 120; ++n) {
    Tri tri = random_triangle(rng, 8.0, 8.0 + 24);
    if (n % 17 == 0) {
      // A long sliver reaching far outside: |dx| + |dy| > 2^22 fx8.
      tri.x[1] += 40000 * 256;
      tri.y[1] -= 3000 * 256;
      orient(tri);
    }
    std::array<glm::vec3, 3> c;
    for (auto& v : c) v = glm::vec3(channel(rng), channel(rng), channel(rng));
    if (n % 3 == 0) c[1] = c[2] = c[0];
    tris.push_back(make_setup(tri, {depth(rng), depth(rng), depth(rng)}, c, n));
  }
  const PixelRect rect{8, 8, 8 + 24, 8 + 24};
  const glm::vec3 background(0.25f, 0.5f, 0.75f);
  std::vector<SamplePattern> patterns;
  for (int n : {1, 2, 3, 5, 16}) patterns.push_back(covrast::detail::ssaa_cmj_pattern(n));
  for (int n : {3, 16}) patterns.push_back(covrast::detail::ssaa_pattern(n));
  for (int k : {2, 4, 8, 16}) patterns.push_back(covrast::detail::msaa_pattern(k));
  int wide_triangles = 0;
  for (const TriangleSetup& t : tris) {
    bool wide = false;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      const std::int64_t dx = std::int64_t(t.x_fx8[j]) - t.x_fx8[i];
      const std::int64_t dy = std::int64_t(t.y_fx8[j]) - t.y_fx8[i];
      wide |= std::abs(dx) + std::abs(dy) > (std::int64_t(1) << 22);
    }
    wide_triangles += wide;
  }
  REQUIRE(wide_triangles >= 5);
  covrast::test::for_each_target([&](std::int64_t) {
    for (const SamplePattern& p : patterns) {
      for (ShadingRate rate : {ShadingRate::PerSample, ShadingRate::PerPixel}) {
        INFO("samples " << p.size() << ", per "
                        << (rate == ShadingRate::PerSample ? "sample" : "pixel"));
        // A small band budget so that the tile is also split into bands.
        SampleRasterizer simd(32, p, rate, covrast::detail::sample_kernels_simd(), 64 << 10);
        SampleRasterizer scalar(32, p, rate, covrast::detail::sample_kernels_scalar());
        REQUIRE(render_tile(simd, 32, rect, tris, background) ==
                render_tile(scalar, 32, rect, tris, background));
      }
    }
  });
}

TEST_CASE("banded replay is reported as raster time, not resolve time", "[ssaa]") {
  // A tile too large for one band records its triangles and rasterises them band by band
  // inside end_tile (resolve_tile here); the renderer subtracts deferred_raster_ms() from
  // the time it books as resolve, so that --stats attributes the work correctly.
  std::mt19937_64 rng(99);
  std::vector<TriangleSetup> tris;
  for (std::uint32_t n = 0; n < 200; ++n) {
    tris.push_back(make_setup(random_triangle(rng, 0.0, 32.0), {0.3, 0.5, 0.7},
                              {glm::vec3(1.0f), glm::vec3(1.0f), glm::vec3(1.0f)}, n));
  }
  const PixelRect rect{0, 0, 32, 32};
  const SamplePattern pattern = covrast::detail::ssaa_cmj_pattern(16);
  SampleRasterizer banded(32, pattern, ShadingRate::PerPixel,
                          covrast::detail::sample_kernels_scalar(), 64 << 10);
  SampleRasterizer whole(32, pattern, ShadingRate::PerPixel,
                         covrast::detail::sample_kernels_scalar(), 64 << 20);
  REQUIRE(banded.deferred_raster_ms() == 0.0);
  const auto a = render_tile(banded, 32, rect, tris, glm::vec3(0.0f));
  const double after_one = banded.deferred_raster_ms();
  CHECK(after_one > 0.0);
  // Summed over tiles.
  render_tile(banded, 32, rect, tris, glm::vec3(0.0f));
  CHECK(banded.deferred_raster_ms() > after_one);
  // The same tile in one band rasterises as it draws: nothing deferred, same image.
  CHECK(render_tile(whole, 32, rect, tris, glm::vec3(0.0f)) == a);
  CHECK(whole.deferred_raster_ms() == 0.0);
}
