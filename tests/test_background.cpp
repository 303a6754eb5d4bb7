// Transparent and skybox backgrounds (post/background.hpp): the alpha of a transparent
// background against the exact area a triangle covers in each pixel, the colour left not
// premultiplied, every mode, and the skybox against the environment seen through each pixel.
#include <covrast/environment.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include "color/srgb8.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "test_meshes.hpp"
#include "test_splits.hpp"

using covrast::BackgroundKind;
using covrast::Image;
using covrast::Scene;

namespace {

using Polygon = std::vector<glm::dvec2>;

/// The part of `poly` left of the directed line a -> b (Sutherland-Hodgman, one plane).
Polygon clip_left_of(const Polygon& poly, const glm::dvec2& a, const glm::dvec2& b) {
  Polygon out;
  auto side = [&](const glm::dvec2& p) {
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
  };
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec2& p = poly[i];
    const glm::dvec2& q = poly[(i + 1) % poly.size()];
    const double sp = side(p), sq = side(q);
    if (sp >= 0.0) out.push_back(p);
    if ((sp >= 0.0) != (sq >= 0.0)) out.push_back(p + (q - p) * (sp / (sp - sq)));
  }
  return out;
}

double polygon_area(const Polygon& poly) {
  double twice = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec2& p = poly[i];
    const glm::dvec2& q = poly[(i + 1) % poly.size()];
    twice += p.x * q.y - q.x * p.y;
  }
  return std::abs(0.5 * twice);
}

/// The exact share of pixel (x, y) inside the triangle with pixel-space corners t (any winding).
double covered_share(const std::array<glm::dvec2, 3>& t, int x, int y) {
  Polygon poly{{x, y}, {x + 1.0, y}, {x + 1.0, y + 1.0}, {x, y + 1.0}};
  const double orient =
      (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[1].y - t[0].y) * (t[2].x - t[0].x);
  for (int k = 0; k < 3 && !poly.empty(); ++k) {
    const glm::dvec2& a = t[std::size_t(k)];
    const glm::dvec2& b = t[std::size_t((k + 1) % 3)];
    poly = orient > 0.0 ? clip_left_of(poly, a, b) : clip_left_of(poly, b, a);
  }
  return poly.size() < 3 ? 0.0 : polygon_area(poly);
}

/// Pixel-space corners (x right, y down) as world points of pixel_scene's plane z = 0.
constexpr int kWidth = 48, kHeight = 32;
const std::array<glm::dvec2, 3> kTriangle{{{3.25, 2.5}, {44.75, 9.0}, {12.5, 29.75}}};
const glm::vec3 kColorSrgb(0.8f, 0.4f, 0.2f);

Scene triangle_scene(BackgroundKind background) {
  Scene scene = covrast::test::pixel_scene(kWidth, kHeight);
  std::vector<glm::vec3> positions;
  for (const glm::dvec2& p : kTriangle) {
    positions.push_back(glm::vec3(float(p.x - kWidth / 2.0), float(kHeight / 2.0 - p.y), 0.0f));
  }
  covrast::add_instance(scene, covrast::make_mesh({.positions = positions, .indices = {0, 2, 1}}),
                        {.color_srgb = kColorSrgb});
  scene.background_kind = background;
  scene.background_linear = glm::vec3(0.3f, 0.6f, 0.9f);  // ignored unless Color
  covrast::check_scene(scene);
  return scene;
}

using covrast::test::render_mode;

}  // namespace

TEST_CASE("background: a transparent background's alpha is the exact covered share within 1/255",
          "[background][analytic]") {
  const Scene scene = triangle_scene(BackgroundKind::Transparent);
  const Image image = render_mode(scene, "coverage");
  REQUIRE(image.alpha.size() == std::size_t(kWidth) * kHeight);
  const std::uint8_t flat[3] = {std::uint8_t(std::lround(kColorSrgb.r * 255.0f)),
                                std::uint8_t(std::lround(kColorSrgb.g * 255.0f)),
                                std::uint8_t(std::lround(kColorSrgb.b * 255.0f))};
  int worst_alpha = 0, worst_colour = 0, partial = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const double share = covered_share(kTriangle, x, y);
      const int alpha = image.alpha[std::size_t(y) * kWidth + std::size_t(x)];
      worst_alpha = std::max(worst_alpha, std::abs(alpha - int(std::lround(share * 255.0))));
      if (share == 0.0) CHECK(alpha == 0);
      if (share == 1.0) CHECK(alpha == 255);
      if (share > 0.0 && share < 1.0) ++partial;
      // The colour, not premultiplied, is the triangle's wherever enough of it shows to carry
      // 8 bits (below that, dividing by a small alpha magnifies the encoder's rounding).
      if (share >= 0.25) {
        for (int c = 0; c < 3; ++c) {
          worst_colour = std::max(worst_colour, std::abs(int(image.pixel(x, y)[c]) - int(flat[c])));
        }
      }
    }
  }
  INFO("worst alpha " << worst_alpha << ", worst colour " << worst_colour);
  CHECK(partial > 60);
  CHECK(worst_alpha <= 1);
  CHECK(worst_colour <= 2);
}

TEST_CASE(
    "background: a transparent background in every mode, the same bytes for every thread "
    "count and tile",
    "[background][threads]") {
  const Scene scene = triangle_scene(BackgroundKind::Transparent);
  for (const std::string mode :
       {"coverage", "coverage-blend", "aliased", "ssaa:4", "msaa:4", "reference", "fxaa"}) {
    INFO(mode);
    // The colour and alpha bytes of 2 and 3 threads with 16- and 24-pixel tiles are checked
    // against this render, which the checks below read.
    const Image first = covrast::test::expect_same_bytes_for_every_split(
                            scene, mode, covrast::test::every_split({2, 3}, {16, 24}))
                            .color;
    REQUIRE(first.alpha.size() == std::size_t(kWidth) * kHeight);
    // Away from the edges: alpha 0 outside, 255 inside, in every mode.
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const double share = covered_share(kTriangle, x, y);
        bool near_edge = false;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const double s = covered_share(kTriangle, x + dx, y + dy);
            near_edge = near_edge || (s > 0.0 && s < 1.0);
          }
        }
        if (near_edge) continue;
        CHECK(int(first.alpha[std::size_t(y) * kWidth + std::size_t(x)]) ==
              (share > 0.5 ? 255 : 0));
      }
    }
  }
}

TEST_CASE("background: without a background kind the output keeps its colour and has no alpha",
          "[background]") {
  const Scene scene = triangle_scene(BackgroundKind::Color);
  const Image image = render_mode(scene, "coverage");
  CHECK(image.alpha.empty());
  const std::uint8_t* corner = image.pixel(kWidth - 1, kHeight - 1);
  CHECK(int(corner[0]) == int(covrast::detail::encode_srgb8(0.3f)));
  CHECK(int(corner[1]) == int(covrast::detail::encode_srgb8(0.6f)));
  CHECK(int(corner[2]) == int(covrast::detail::encode_srgb8(0.9f)));
}

TEST_CASE("background: a skybox shows the environment through each pixel's centre",
          "[background][analytic]") {
  // An environment whose radiance is a smooth function of direction, L(d) = 0.3 + 0.2 d,
  // sampled at its texel centres; a skybox pixel shows the map's bilinear value along the ray
  // through the pixel's centre, which for so smooth a map is L itself to well within 1/255.
  auto map = std::make_shared<covrast::EnvironmentMap>();
  map->width = 256;
  map->height = 128;
  for (int y = 0; y < map->height; ++y) {
    for (int x = 0; x < map->width; ++x) {
      const glm::dvec3 d =
          covrast::environment_direction((x + 0.5) / map->width, (y + 0.5) / map->height);
      map->radiance_linear.push_back(glm::vec3(0.3 + 0.2 * d));
    }
  }
  Scene scene = triangle_scene(BackgroundKind::Color);
  scene.environment = covrast::EnvironmentLight{map, 0.0, 1.0};
  scene.background_kind = BackgroundKind::Skybox;
  scene.camera.fovy_deg = 60.0;  // rays spread: each pixel a different direction
  const Image image = render_mode(scene, "coverage");
  CHECK(image.alpha.empty());
  // Where the same view over a transparent background has alpha 0, only the sky shows.
  scene.background_kind = BackgroundKind::Transparent;
  const Image mask = render_mode(scene, "coverage");
  const covrast::Camera& cam = scene.camera;
  const glm::dvec3 forward = glm::normalize(cam.target - cam.eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, cam.up));
  const glm::dvec3 up = glm::cross(right, forward);
  const double half_h = std::tan(30.0 * std::numbers::pi / 180.0);
  const double half_w = half_h * kWidth / kHeight;
  int checked = 0, worst = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if (mask.alpha[std::size_t(y) * kWidth + std::size_t(x)] != 0) continue;
      const glm::dvec3 d =
          glm::normalize(forward + right * ((2.0 * (x + 0.5) / kWidth - 1.0) * half_w) +
                         up * ((1.0 - 2.0 * (y + 0.5) / kHeight) * half_h));
      const glm::dvec3 want = 0.3 + 0.2 * d;
      for (int c = 0; c < 3; ++c) {
        worst = std::max(worst, std::abs(int(image.pixel(x, y)[c]) -
                                         int(covrast::detail::encode_srgb8(float(want[c])))));
      }
      ++checked;
    }
  }
  INFO("worst " << worst);
  CHECK(checked > 300);
  CHECK(worst <= 1);
}

TEST_CASE("background: a skybox in every mode, the same bytes for every thread count and tile",
          "[background][threads]") {
  // A uniform environment: wherever only the sky shows, every mode shows its colour.
  auto map = std::make_shared<covrast::EnvironmentMap>();
  map->width = 8;
  map->height = 4;
  map->radiance_linear.assign(32, glm::vec3(0.1f, 0.4f, 0.7f));
  Scene scene = triangle_scene(BackgroundKind::Color);
  scene.environment = covrast::EnvironmentLight{map, 0.0, 1.0};
  scene.background_kind = BackgroundKind::Skybox;
  const std::uint8_t sky[3] = {covrast::detail::encode_srgb8(0.1f),
                               covrast::detail::encode_srgb8(0.4f),
                               covrast::detail::encode_srgb8(0.7f)};
  for (const std::string mode :
       {"coverage", "coverage-blend", "aliased", "ssaa:4", "msaa:4", "reference", "fxaa"}) {
    INFO(mode);
    // 2 and 3 threads with 24-pixel tiles are checked against this render.
    const Image first = covrast::test::expect_same_bytes_for_every_split(
                            scene, mode, covrast::test::every_split({2, 3}, {24}))
                            .color;
    CHECK(first.alpha.empty());
    int sky_pixels = 0;
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        bool near = false;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx)
            near = near || covered_share(kTriangle, x + dx, y + dy) > 0.0;
        }
        if (near) continue;
        ++sky_pixels;
        for (int c = 0; c < 3; ++c) CHECK(int(first.pixel(x, y)[c]) == int(sky[c]));
      }
    }
    CHECK(sky_pixels > 300);
  }
}

TEST_CASE("background: a skybox needs an environment", "[background]") {
  Scene scene = triangle_scene(BackgroundKind::Color);
  scene.background_kind = BackgroundKind::Skybox;
  CHECK_THROWS_AS(covrast::check_scene(scene), covrast::InputError);
}
