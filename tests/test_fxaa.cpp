// FXAA post-process (src/post/fxaa.cpp, docs/fxaa.md): synthetic aliased images with a known
// answer, and the fxaa mode through the Renderer.
//
// The expected blend weights follow from the algorithm's formulas, not from runs:
//   - sub-pixel weight: c = |lowpass - M| / range, lowpass = (2 (N + S + W + E) + corners) / 12,
//     weight = (c^2 (3 - 2c))^2 * subpix. Beside a straight step edge between lumas a and b,
//     lowpass - M = (b - a) / 3 and range = |b - a|, so c = 1/3; on a 1-pixel line c = 2/3.
//   - edge-search weight: 0.5 - nearer end / span length. Along an edge that runs across the
//     whole image both searches run through all their steps, so both ends are equally far
//     and the weight is 0: only the sub-pixel weight remains.
//   - a pixel blends with one 4-neighbour, by at most max(0.5, subpix).
#include "post/fxaa.hpp"
#include "test_meshes.hpp"
#include "test_splits.hpp"

#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

using namespace covrast;

namespace {

using Rgb = std::array<std::uint8_t, 3>;

/// smoothstep(c) squared times subpix: FXAA's sub-pixel weight for a contrast share c.
double subpix_weight(double c, double subpix) {
  const double s = c * c * (3.0 - 2.0 * c);
  return s * s * subpix;
}

Image filled(int width, int height, Rgb colour) {
  Image image{width, height, std::vector<std::uint8_t>(std::size_t(width) * height * 3), {}};
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) std::copy(colour.begin(), colour.end(), image.pixel(x, y));
  }
  return image;
}

void put(Image& image, int x, int y, Rgb colour) {
  std::copy(colour.begin(), colour.end(), image.pixel(x, y));
}

Rgb at(const Image& image, int x, int y) {
  const std::uint8_t* p = image.pixel(x, y);
  return {p[0], p[1], p[2]};
}

double to_linear(std::uint8_t code) {
  const double e = code / 255.0;
  return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
}

/// The weight w with out = (1 - w) a + w b in linear light, from the channel where a and b
/// differ most; NaN when the output is not between them on that channel.
double blend_weight(const Rgb& a, const Rgb& b, const Rgb& out) {
  int c = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(a[k] - b[k]) > std::abs(a[c] - b[c])) c = k;
  }
  const double la = to_linear(a[c]), lb = to_linear(b[c]), lo = to_linear(out[c]);
  const double w = (lo - la) / (lb - la);
  return w >= -1e-9 && w <= 1.0 + 1e-9 ? w : std::nan("");
}

/// The weight's uncertainty from the 8-bit output: half a code step of the sRGB curve, as a
/// share of the linear distance between the two colours on that channel.
double weight_tolerance(const Rgb& a, const Rgb& b) {
  int c = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(a[k] - b[k]) > std::abs(a[c] - b[c])) c = k;
  }
  double step = 0;
  for (int code = 1; code < 256; ++code) {
    step = std::max(step, to_linear(std::uint8_t(code)) - to_linear(std::uint8_t(code - 1)));
  }
  return 0.5 * step / std::fabs(to_linear(b[c]) - to_linear(a[c]));
}

constexpr Rgb kDark{40, 52, 30};
constexpr Rgb kLight{230, 210, 190};
constexpr int kSide = 48;

}  // namespace

TEST_CASE("fxaa: a vertical and a horizontal step edge get the sub-pixel weight", "[fxaa]") {
  const FxaaOptions options;
  const double expected = subpix_weight(1.0 / 3.0, options.subpix);  // (7/27)^2 * 3/4 = 0.0504
  const double tolerance = weight_tolerance(kDark, kLight);
  for (const bool vertical : {true, false}) {
    // Dark before column (row) 20, light from it on: the edge lies between 19 and 20.
    Image in = filled(kSide, kSide, kDark);
    for (int y = 0; y < kSide; ++y) {
      for (int x = 0; x < kSide; ++x) {
        if ((vertical ? x : y) >= 20) put(in, x, y, kLight);
      }
    }
    const Image out = detail::fxaa(in, options);
    int wrong = 0;
    for (int y = 0; y < kSide; ++y) {
      for (int x = 0; x < kSide; ++x) {
        const int across = vertical ? x : y;
        const Rgb own = at(in, x, y);
        if (across != 19 && across != 20) {
          wrong += at(out, x, y) != own;  // a flat cross: skipped
          continue;
        }
        // Blended with the pixel across the edge, along the image axis normal to it.
        const Rgb other = across == 19 ? kLight : kDark;
        const double w = blend_weight(own, other, at(out, x, y));
        INFO((vertical ? "vertical" : "horizontal")
             << " edge, pixel (" << x << ", " << y << "): weight " << w);
        CHECK(std::fabs(w - expected) <= tolerance);
      }
    }
    CHECK(wrong == 0);
  }
}

TEST_CASE("fxaa: contrast below the thresholds is left alone", "[fxaa]") {
  // Luma step 0.0666 < edge_threshold_min 0.0833 (and < 0.166 * max luma).
  const Rgb a{100, 100, 100}, b{117, 117, 117};
  Image in = filled(kSide, kSide, a);
  for (int y = 0; y < kSide; ++y) {
    for (int x = 24; x < kSide; ++x) put(in, x, y, b);
  }
  CHECK(detail::fxaa(in, FxaaOptions{}).rgb == in.rgb);
  // The same step passes a lower threshold.
  FxaaOptions low;
  low.edge_threshold = 0.05f;
  low.edge_threshold_min = 0.05f;
  CHECK(detail::fxaa(in, low).rgb != in.rgb);
}

TEST_CASE("fxaa: a single-pixel line is blurred by the sub-pixel weight", "[fxaa]") {
  const FxaaOptions options;
  // On the line: c = |(2 (a + a + b + b) + 4 a) / 12 - b| / |b - a| = 2/3, towards the row
  // above (the tie between above and below goes to "before"). Beside it: c = 1/3, towards
  // the line.
  const double on_line = subpix_weight(2.0 / 3.0, options.subpix);  // (20/27)^2 * 3/4 = 0.4115
  const double beside = subpix_weight(1.0 / 3.0, options.subpix);
  const double tolerance = weight_tolerance(kDark, kLight);
  for (const bool vertical : {false, true}) {
    Image in = filled(kSide, kSide, kDark);
    for (int i = 0; i < kSide; ++i) put(in, vertical ? 17 : i, vertical ? i : 17, kLight);
    const Image out = detail::fxaa(in, options);
    int wrong = 0;
    for (int y = 0; y < kSide; ++y) {
      for (int x = 0; x < kSide; ++x) {
        const int across = vertical ? x : y;
        const Rgb own = at(in, x, y), got = at(out, x, y);
        if (across < 16 || across > 18) {
          wrong += got != own;
          continue;
        }
        const double w = blend_weight(own, across == 17 ? kDark : kLight, got);
        INFO((vertical ? "vertical" : "horizontal")
             << " line, pixel (" << x << ", " << y << "): weight " << w);
        CHECK(std::fabs(w - (across == 17 ? on_line : beside)) <= tolerance);
      }
    }
    CHECK(wrong == 0);
    // The direction: the line pixel takes the colour of the pixel before it, which is the
    // background; blending with its own line would leave it unchanged.
    CHECK(at(out, vertical ? 17 : 5, vertical ? 5 : 17) != kLight);
  }
}

TEST_CASE("fxaa: a 30-degree edge is blended across it, towards its exact coverage", "[fxaa]") {
  // An aliased half-plane: pixel centres below y = y0 + tan(30 deg) (x - x0) are light.
  const FxaaOptions options;
  const double slope = std::tan(3.14159265358979323846 / 6.0);
  const double y0 = 10.3, x0 = 0.0;
  const auto edge_y = [&](double x) { return y0 + slope * (x - x0); };
  Image in = filled(kSide, kSide, kDark);
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      if (y + 0.5 > edge_y(x + 0.5)) put(in, x, y, kLight);
    }
  }
  const Image out = detail::fxaa(in, options);
  // Exact share of pixel (x, y) below the line: 64 x 64 sub-samples are enough to rank the
  // two images (their errors differ by far more than 1/64).
  const auto coverage = [&](int x, int y) {
    int below = 0;
    for (int j = 0; j < 64; ++j) {
      for (int i = 0; i < 64; ++i) below += y + (j + 0.5) / 64 > edge_y(x + (i + 0.5) / 64);
    }
    return below / 4096.0;
  };
  detail::LumaPlane luma{kSide, kSide, std::vector<float>(kSide * kSide)};
  detail::fxaa_luma_rows(in, luma, 0, kSide);
  const auto steps = detail::fxaa_search_steps(options.quality_preset);
  const double max_weight = std::max(0.5, double(options.subpix));
  const double tolerance = weight_tolerance(kDark, kLight);
  double error_aliased = 0, error_fxaa = 0;
  int blended = 0, not_across = 0, over_bound = 0, output_mismatch = 0, far_changed = 0;
  for (int y = 1; y + 1 < kSide; ++y) {
    for (int x = 1; x + 1 < kSide; ++x) {
      const Rgb own = at(in, x, y), got = at(out, x, y);
      const bool cross_flat = at(in, x - 1, y) == own && at(in, x + 1, y) == own &&
                              at(in, x, y - 1) == own && at(in, x, y + 1) == own;
      if (cross_flat) {
        far_changed += got != own;
        continue;
      }
      // A slope under 45 degrees: the second differences across rows dominate, so the edge
      // is horizontal and the pixel blends with the pixel above or below, on the other side.
      const detail::FxaaBlend b = detail::fxaa_pixel_blend(luma, x, y, options, steps);
      double w = 0;
      if (b.weight > 0) {
        ++blended;
        not_across += b.dx != 0 || b.dy == 0 || at(in, x, y + b.dy) == own;
        over_bound += b.weight > max_weight;
        w = blend_weight(own, own == kLight ? kDark : kLight, got);
        output_mismatch += !(std::fabs(w - b.weight) <= tolerance);
      }
      const double light_share = own == kLight ? 1.0 - w : w;
      error_aliased += std::fabs((own == kLight ? 1.0 : 0.0) - coverage(x, y));
      error_fxaa += std::fabs(light_share - coverage(x, y));
    }
  }
  INFO("blended " << blended << ", summed |error| aliased " << error_aliased << ", fxaa "
                  << error_fxaa);
  CHECK(blended > kSide);  // both sides of the edge, in every column
  CHECK(not_across == 0);
  CHECK(over_bound == 0);
  CHECK(output_mismatch == 0);
  CHECK(far_changed == 0);
  CHECK(error_fxaa < error_aliased);
}

TEST_CASE("fxaa: the search presets are FXAA 3.11's", "[fxaa]") {
  const auto sum = [](int preset) {
    float s = 0;
    for (float step : detail::fxaa_search_steps(preset)) s += step;
    return s;
  };
  CHECK(detail::fxaa_search_steps(12).size() == 5);
  CHECK(sum(12) == 20.5f);  // 1 + 1.5 + 2 + 4 + 12
  CHECK(sum(39) == 26.5f);  // 5 x 1 + 1.5 + 4 x 2 + 4 + 8
  for (int preset : {10, 11, 12, 13, 14, 15, 20, 25, 29, 39}) CHECK(valid_fxaa_preset(preset));
  for (int preset : {0, 9, 16, 19, 30, 38, 40}) CHECK_FALSE(valid_fxaa_preset(preset));
}

// ---------------------------------------------------------------------------------------
// The fxaa mode through the Renderer
// ---------------------------------------------------------------------------------------

namespace {

using covrast::test::pixel_scene;
using covrast::test::render_mode;

void add_mesh(Scene& scene, std::vector<glm::vec3> positions, std::vector<std::uint32_t> indices,
              ColorSource source) {
  auto mesh = std::make_shared<MeshData>();
  mesh->source = "test_fxaa";
  mesh->positions = std::move(positions);
  mesh->indices = std::move(indices);
  MeshInstance instance;
  instance.mesh = std::move(mesh);
  instance.color_source = source;
  instance.color_linear = glm::vec3(1.0f);
  scene.meshes.push_back(std::move(instance));
}

/// Random overlapping triangles at random depths, one colour each (the per-triangle debug
/// colours).
Scene random_triangles_scene() {
  Scene scene = pixel_scene(300, 200);
  std::mt19937 rng(1616);
  std::uniform_real_distribution<float> x(-160.0f, 160.0f), y(-110.0f, 110.0f), z(-50.0f, 0.0f);
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  for (std::uint32_t t = 0; t < 60; ++t) {
    const float depth = z(rng);
    for (int k = 0; k < 3; ++k) positions.emplace_back(x(rng), y(rng), depth);
    for (std::uint32_t k = 0; k < 3; ++k) indices.push_back(3 * t + k);
  }
  add_mesh(scene, std::move(positions), std::move(indices), ColorSource::PerTriangle);
  return scene;
}

}  // namespace

TEST_CASE("fxaa mode: the aliased frame through FXAA, the same bytes for every split",
          "[fxaa][pipeline][threads]") {
  const Scene scene = random_triangles_scene();
  const Image aliased = render_mode(scene, "aliased", 1, 64);
  const Image expected = detail::fxaa(aliased, FxaaOptions{});
  REQUIRE(expected.rgb != aliased.rgb);  // the scene has edges for FXAA to change
  // Every split's bytes are the base's (1 thread, 64-pixel tiles), and the base's are FXAA's.
  const RenderResult base = covrast::test::expect_same_bytes_for_every_split(
      scene, "fxaa", covrast::test::every_split({1, 2, 3, 4}, {8, 16, 24, 64, 256}),
      [](const RenderResult& r, const RenderResult&, covrast::test::Split) {
        CHECK(r.stats.post_ms >= 0.0);
      });
  CHECK(base.color.rgb == expected.rgb);
}

TEST_CASE("fxaa mode: parsing, names and option checks", "[fxaa][pipeline]") {
  CHECK(parse_render_mode("fxaa").kind == ModeKind::Fxaa);
  CHECK(to_string(parse_render_mode("fxaa")) == "fxaa");
  CHECK_THROWS_AS(parse_render_mode("fxaa:12"), InputError);
  const Scene scene = pixel_scene(16, 16);
  RenderOptions options;
  options.mode = parse_render_mode("fxaa");
  options.fxaa.quality_preset = 16;
  CHECK_THROWS_AS(Renderer(scene, options), InputError);
  options.fxaa.quality_preset = 39;
  options.fxaa.subpix = 1.5f;
  CHECK_THROWS_AS(Renderer(scene, options), InputError);
  options.fxaa.subpix = 0.0f;
  CHECK_NOTHROW(Renderer(scene, options));
}

TEST_CASE("fxaa mode: a tessellated surface stays flat inside", "[fxaa][pipeline]") {
  // A fan of thin triangles and a jittered grid in one colour, consistent winding: the
  // aliased frame covers every pixel centre once (no seams), so inside the outline every
  // 3x3 block is flat and FXAA must leave it exactly the surface colour.
  Scene scene = pixel_scene(160, 120);
  std::vector<glm::vec3> positions{{0.0f, 0.0f, 0.0f}};
  std::vector<std::uint32_t> indices;
  const int spokes = 97;
  for (int k = 0; k <= spokes; ++k) {
    const double a = 2.0 * 3.14159265358979323846 * k / spokes;
    positions.emplace_back(float(55.0 * std::cos(a)), float(55.0 * std::sin(a)), 0.0f);
  }
  for (std::uint32_t k = 1; k <= std::uint32_t(spokes); ++k) {
    indices.insert(indices.end(), {0u, k, k + 1});
  }
  add_mesh(scene, std::move(positions), std::move(indices), ColorSource::Uniform);
  scene.meshes.back().color_linear = glm::vec3(0.8f, 0.5f, 0.2f);
  const Image aliased = render_mode(scene, "aliased", 2, 16);
  const Image fxaa = render_mode(scene, "fxaa", 2, 16);
  // Pixels whose centre lies 2 or more pixels inside the circle of the fan's inner radius
  // (55 cos(pi / 97)): their 3x3 blocks are all inside the surface.
  const Rgb surface = at(aliased, 80, 60);
  const double inner = 55.0 * std::cos(3.14159265358979323846 / spokes) - 2.0;
  int inside = 0, off_surface = 0;
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      if (std::hypot(x + 0.5 - 80.0, 60.0 - (y + 0.5)) > inner) continue;
      ++inside;
      off_surface += at(aliased, x, y) != surface;
      off_surface += at(fxaa, x, y) != surface;
    }
  }
  CHECK(inside > 7000);
  CHECK(off_surface == 0);
  CHECK(fxaa.rgb != aliased.rgb);  // the outline is blended
}

TEST_CASE("fxaa mode: the seam scene stays one flat colour", "[fxaa][pipeline]") {
  // scenes/sphere_closed.json built here: a closed UV sphere (pole fans, the phi = 0 seam)
  // drawn in the background colour. The aliased frame is one colour, every cross is flat, and
  // FXAA must not invent an edge: every pixel keeps the background's bytes.
  Scene scene;
  scene.width = 256;
  scene.height = 256;
  scene.background_linear = glm::vec3(0.3f, 0.55f, 0.25f);
  scene.camera.eye = glm::dvec3(0.6, 1.6, 2.4);
  scene.camera.target = glm::dvec3(0.0);
  scene.camera.up = glm::dvec3(0.0, 1.0, 0.0);
  scene.camera.fovy_deg = 45.0;
  scene.camera.near = 0.5;
  scene.camera.far = 10.0;
  covrast::test::add_instance(scene, covrast::test::uv_sphere(24, 48), scene.background_linear);
  for (const int tile : {16, 64}) {
    const Image image = render_mode(scene, "fxaa", 2, tile);
    const Rgb background = at(image, 0, 0);
    int off = 0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) off += at(image, x, y) != background;
    }
    INFO("tile " << tile);
    CHECK(off == 0);
  }
  // The check can fail: the same sphere in another colour is blended at its outline.
  scene.meshes[0].color_linear = glm::vec3(0.9f);
  const Image lit = render_mode(scene, "fxaa", 2, 64);
  CHECK(lit.rgb != render_mode(scene, "aliased", 2, 64).rgb);
}
