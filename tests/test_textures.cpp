// Tests of textures (docs/textures.md): exact texel reproduction, mip levels and bilinear
// magnification in linear light, wrap modes and KHR_texture_transform against an analytic
// texel lookup, the exact UV derivatives and the level of detail on a tilted plane, the same
// bytes for every thread count and tile size, decoding PNG and JPEG (by content), and bad
// images as InputErrors naming the image and the model. Every image is generated here.
#include <covrast/error.hpp>
#include <covrast/image.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include "raster/coverage/fragment_shading.hpp"
#include "scene/scene_internal.hpp"
#include "shading/shading_inputs.hpp"
#include "texture/texture_sampling.hpp"

#include <turbojpeg.h>
#include <webp/encode.h>
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "test_gltf_files.hpp"
#include "test_meshes.hpp"
#include "test_splits.hpp"
#include "test_tempdir.hpp"

using Catch::Matchers::Contains;

namespace {

double srgb_decode(int code) {
  const double c = code / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}
double srgb_encode_255(double linear) {
  const double l = std::clamp(linear, 0.0, 1.0);
  return 255.0 * (l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055);
}

/// A smooth opaque 32x16 image (red along x, green along y, blue 100): what lossy codecs keep
/// within a few levels.
std::vector<std::uint8_t> smooth_rgba_32x16() {
  std::vector<std::uint8_t> rgba(32 * 16 * 4, 255);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 32; ++x) {
      rgba[(y * 32 + x) * 4 + 0] = std::uint8_t(x * 8);
      rgba[(y * 32 + x) * 4 + 1] = std::uint8_t(y * 16);
      rgba[(y * 32 + x) * 4 + 2] = 100;
    }
  }
  return rgba;
}

/// Deterministic texels: 8-bit RGBA, alpha 255.
std::vector<std::uint8_t> random_rgba(int width, int height, std::uint32_t seed) {
  std::vector<std::uint8_t> rgba(std::size_t(width) * height * 4);
  for (std::size_t i = 0; i < rgba.size(); ++i) {
    seed = seed * 1664525u + 1013904223u;
    rgba[i] = (i % 4 == 3) ? 255 : std::uint8_t(seed >> 24);
  }
  return rgba;
}

/// The quad [-1, 1]^2 at z = 0 seen from (0, 0, 1) with a 90 degree field of view in a
/// square image: it fills the image exactly; UV (0, 0) at the top-left corner, (1, 1) at the
/// bottom-right, scaled to [uv0, uv1].
covrast::Scene quad_scene(int size, const covrast::TextureSlot& slot, float uv0 = 0.0f,
                          float uv1 = 1.0f) {
  covrast::Scene scene;
  scene.width = size;
  scene.height = size;
  scene.camera.eye = {0.0, 0.0, 1.0};
  scene.camera.fovy_deg = 90.0;
  scene.camera.near = 0.5;
  scene.camera.far = 10.0;
  covrast::MeshArrays quad{.name = "quad",
                           .positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}},
                           .indices = {0, 1, 2, 0, 2, 3}};
  const glm::vec2 uv[4] = {{uv0, uv1}, {uv1, uv1}, {uv1, uv0}, {uv0, uv0}};
  for (const std::uint32_t i : quad.indices) quad.corner_texcoords.push_back(uv[i]);
  covrast::Material material;
  material.base_color_texture = slot;
  covrast::add_instance(scene, covrast::make_mesh(quad), {.material = material});
  return scene;
}

covrast::TextureSlot slot_of(std::shared_ptr<const covrast::Texture> texture,
                             covrast::TextureFilter mag, covrast::TextureFilter min,
                             covrast::MipFilter mip) {
  covrast::TextureSlot slot;
  slot.texture = std::move(texture);
  slot.sampler.mag = mag;
  slot.sampler.min = min;
  slot.sampler.mip = mip;
  return slot;
}

using covrast::test::render_mode;

}  // namespace

TEST_CASE("textures: a 64x64 texture on a 64x64 quad with NEAREST reproduces its bytes",
          "[textures]") {
  const auto rgba = random_rgba(64, 64, 7);
  const auto texture = covrast::make_texture("noise", 64, 64, rgba, true);
  const covrast::Scene scene =
      quad_scene(64, slot_of(texture, covrast::TextureFilter::Nearest,
                             covrast::TextureFilter::Nearest, covrast::MipFilter::None));
  for (const char* mode : {"coverage", "aliased", "msaa:4"}) {
    INFO(mode);
    const covrast::Image image = render_mode(scene, mode);
    int differing = 0;
    for (int i = 0; i < 64 * 64; ++i) {
      for (int c = 0; c < 3; ++c) differing += image.rgb[3 * i + c] != rgba[4 * i + c];
    }
    REQUIRE(differing == 0);
  }
}

TEST_CASE("textures: mip level 1 is the 2x2 mean in linear light (LINEAR_MIPMAP_LINEAR at 32x32)",
          "[textures]") {
  const auto rgba = random_rgba(64, 64, 11);
  const auto texture = covrast::make_texture("noise", 64, 64, rgba, true);
  REQUIRE(texture->levels.size() == 7);
  const covrast::Scene scene =
      quad_scene(32, slot_of(texture, covrast::TextureFilter::Linear,
                             covrast::TextureFilter::Linear, covrast::MipFilter::Linear));
  // Aliased mode looks up at each pixel's centre, which is level 1's texel centre (lod 1
  // exactly); coverage mode averages the bilinear filter over the pixel, which blurs it.
  const covrast::Image image = render_mode(scene, "aliased");
  double worst = 0.0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      for (int c = 0; c < 3; ++c) {
        double mean = 0.0;
        for (int dy = 0; dy < 2; ++dy) {
          for (int dx = 0; dx < 2; ++dx) {
            mean += srgb_decode(rgba[((2 * y + dy) * 64 + 2 * x + dx) * 4 + c]) / 4.0;
          }
        }
        worst = std::max(worst, std::abs(image.pixel(x, y)[c] - srgb_encode_255(mean)));
      }
    }
  }
  REQUIRE(worst <= 1.0);
}

TEST_CASE("textures: LINEAR magnification at 128x128 is the bilinear blend in linear light",
          "[textures]") {
  const auto rgba = random_rgba(64, 64, 13);
  const auto texture = covrast::make_texture("noise", 64, 64, rgba, true);
  const covrast::Scene scene =
      quad_scene(128, slot_of(texture, covrast::TextureFilter::Linear,
                              covrast::TextureFilter::Linear, covrast::MipFilter::Linear));
  const covrast::Image image = render_mode(scene, "coverage");
  double worst = 0.0;
  for (int y = 0; y < 128; ++y) {
    for (int x = 0; x < 128; ++x) {
      // Texel coordinates of the pixel centre: (x + 0.5) / 128 * 64 - 0.5 = x / 2 - 0.25.
      const double tx = x / 2.0 - 0.25, ty = y / 2.0 - 0.25;
      const int x0 = int(std::floor(tx)), y0 = int(std::floor(ty));
      const double fx = tx - x0, fy = ty - y0;
      for (int c = 0; c < 3; ++c) {
        const auto texel = [&](int i, int j) {
          return srgb_decode(rgba[(((j + 64) % 64) * 64 + (i + 64) % 64) * 4 + c]);
        };
        const double value = (texel(x0, y0) * (1 - fx) + texel(x0 + 1, y0) * fx) * (1 - fy) +
                             (texel(x0, y0 + 1) * (1 - fx) + texel(x0 + 1, y0 + 1) * fx) * fy;
        worst = std::max(worst, std::abs(image.pixel(x, y)[c] - srgb_encode_255(value)));
      }
    }
  }
  REQUIRE(worst <= 1.0);
}

TEST_CASE("textures: mip chain of odd sizes keeps every texel (3-texel boxes at the odd end)",
          "[textures]") {
  // 5x3: level 1 is 2x1, its texel 1 averages columns 2..4 and rows 0..2.
  std::vector<std::uint8_t> rgba(5 * 3 * 4, 255);
  for (int i = 0; i < 15; ++i) rgba[4 * i] = std::uint8_t(i * 17);
  const auto texture = covrast::make_texture("odd", 5, 3, rgba, false);
  REQUIRE(texture->levels.size() == 3);
  REQUIRE(texture->levels[1].width == 2);
  REQUIRE(texture->levels[1].height == 1);
  double expected = 0.0;
  for (int y = 0; y < 3; ++y) {
    for (int x = 2; x < 5; ++x) expected += (y * 5 + x) * 17 / 255.0 / 9.0;
  }
  // 136 / 255 exactly: the mean of 17 x (2, 3, 4, 7, 8, 9, 12, 13, 14) is 17 x 8.
  REQUIRE(texture->levels[1].at(1, 0)[0] == 136);
  REQUIRE(texture->linear(1, 1, 0).r == Approx(expected).epsilon(1e-12));
  // The last level is the whole image's mean for even sides, to the nearest code.
  const auto even = covrast::make_texture("even", 8, 4, random_rgba(8, 4, 3), false);
  double mean = 0.0;
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 8; ++x) mean += even->linear(0, x, y).g / 32.0;
  }
  REQUIRE(std::abs(even->linear(int(even->levels.size()) - 1, 0, 0).g - mean) <= 0.5 / 255.0);
  // Level 0 keeps every byte through the 8 x 8 block layout, sides not multiples of 8 too.
  const auto rows = random_rgba(13, 11, 9);
  const auto blocked = covrast::make_texture("blocked", 13, 11, rows, true);
  REQUIRE(blocked->levels[0].rgba8.size() == 2 * 2 * 64 * 4);
  int moved = 0;
  for (int y = 0; y < 11; ++y) {
    for (int x = 0; x < 13; ++x) {
      for (int c = 0; c < 4; ++c)
        moved += blocked->levels[0].at(x, y)[c] != rows[(y * 13 + x) * 4 + c];
    }
  }
  REQUIRE(moved == 0);
  REQUIRE(blocked->linear(0, 12, 10).r ==
          Approx(srgb_decode(rows[(10 * 13 + 12) * 4])).epsilon(1e-12));
  // A code-built level whose storage does not match its size is refused, not read.
  auto broken = std::make_shared<covrast::Texture>(*blocked);
  broken->levels[1].rgba8.resize(16);
  covrast::Material material;
  material.base_color_texture.texture = broken;
  covrast::Scene scene = quad_scene(8, covrast::TextureSlot{});
  REQUIRE_THROWS_WITH(covrast::add_instance(scene, scene.meshes[0].mesh, {.material = material}),
                      Contains("do not match its size"));
}

TEST_CASE("textures: each stored mip code is the nearest to the exact linear-light box mean",
          "[textures]") {
  // Reference: the chain in double from level 0's decoded codes, each level from the
  // unrounded level above (make_texture's definition); a stored code may differ from
  // 255 encode(exact mean) by at most half a code. Filtering from the rounded 8-bit level
  // above instead accumulates rounding and fails this on the deeper levels.
  for (const bool srgb : {true, false}) {
    INFO("srgb " << srgb);
    const int width = 37, height = 23;
    const auto rgba = random_rgba(width, height, 17);
    const auto texture = covrast::make_texture("odd", width, height, rgba, srgb);
    const auto decode = [&](int code, int c) {
      return srgb && c < 3 ? srgb_decode(code) : code / 255.0;
    };
    const auto encode_255 = [&](double linear, int c) {
      return srgb && c < 3 ? srgb_encode_255(linear) : 255.0 * linear;
    };
    int w = width, h = height;
    std::vector<double> above(std::size_t(w) * h * 4);
    for (std::size_t i = 0; i < above.size(); ++i) above[i] = decode(rgba[i], int(i % 4));
    double worst = 0.0;
    int checked = 0;
    for (std::size_t level = 1; level < texture->levels.size(); ++level) {
      const int nw = std::max(1, w / 2), nh = std::max(1, h / 2);
      REQUIRE(texture->levels[level].width == nw);
      REQUIRE(texture->levels[level].height == nh);
      // Per axis: texels 2i, 2i + 1, and 2i + 2 for the last texel of an odd side.
      const auto span = [](int i, int n, int m) {
        return n == 1 ? std::pair(0, 1) : std::pair(2 * i, (n % 2 == 1 && i == m - 1) ? 3 : 2);
      };
      std::vector<double> next(std::size_t(nw) * nh * 4);
      for (int j = 0; j < nh; ++j) {
        for (int i = 0; i < nw; ++i) {
          const auto [x0, nx] = span(i, w, nw);
          const auto [y0, ny] = span(j, h, nh);
          for (int c = 0; c < 4; ++c) {
            double sum = 0.0;
            for (int y = y0; y < y0 + ny; ++y) {
              for (int x = x0; x < x0 + nx; ++x) sum += above[(std::size_t(y) * w + x) * 4 + c];
            }
            const double mean = sum / (nx * ny);
            next[(std::size_t(j) * nw + i) * 4 + c] = mean;
            const int code = texture->levels[level].at(i, j)[c];
            worst = std::max(worst, std::abs(code - encode_255(mean, c)));
            ++checked;
          }
        }
      }
      above = std::move(next);
      w = nw;
      h = nh;
    }
    REQUIRE(checked > 1000);
    REQUIRE(worst <= 0.5 + 1e-9);
  }
}

TEST_CASE("textures: wrap modes and KHR_texture_transform against an analytic texel lookup",
          "[textures]") {
  // 8x8 texels, each with its own colour (i, j and the checkerboard parity).
  std::vector<std::uint8_t> rgba(8 * 8 * 4, 255);
  for (int j = 0; j < 8; ++j) {
    for (int i = 0; i < 8; ++i) {
      std::uint8_t* t = &rgba[(j * 8 + i) * 4];
      t[0] = std::uint8_t(i * 32);
      t[1] = std::uint8_t(j * 32);
      t[2] = (i + j) % 2 == 0 ? 0 : 255;
    }
  }
  const auto texture = covrast::make_texture("checker", 8, 8, rgba, true);
  using covrast::TextureWrap;
  struct Case {
    TextureWrap s, t;
    covrast::TextureTransform transform;
  };
  const Case cases[] = {
      {TextureWrap::Repeat, TextureWrap::MirroredRepeat, {}},
      {TextureWrap::ClampToEdge, TextureWrap::Repeat, {}},
      {TextureWrap::MirroredRepeat,
       TextureWrap::ClampToEdge,
       {glm::dvec2(0.25, -0.1), 0.3, glm::dvec2(1.5, 0.75)}},
  };
  for (const Case& c : cases) {
    covrast::TextureSlot slot = slot_of(texture, covrast::TextureFilter::Nearest,
                                        covrast::TextureFilter::Nearest, covrast::MipFilter::None);
    slot.sampler.wrap_s = c.s;
    slot.sampler.wrap_t = c.t;
    slot.transform = c.transform;
    const covrast::Scene scene = quad_scene(96, slot, -1.0f, 2.0f);
    // aliased: one lookup at each pixel centre (coverage mode averages NEAREST textures over
    // the pixel: "coverage mode's NEAREST texture is the exact mean over the pixel" checks that).
    const covrast::Image image = render_mode(scene, "aliased");
    int mismatches = 0, near_boundary = 0;
    for (int y = 0; y < 96; ++y) {
      for (int x = 0; x < 96; ++x) {
        const double u = -1.0 + 3.0 * (x + 0.5) / 96.0, v = -1.0 + 3.0 * (y + 0.5) / 96.0;
        // T R S: u' = cos r (su u) + sin r (sv v) + ou, v' = -sin r (su u) + cos r (sv v) + ov.
        const double su = u * c.transform.scale.x, sv = v * c.transform.scale.y;
        const double r = c.transform.rotation;
        const double tu = (std::cos(r) * su + std::sin(r) * sv + c.transform.offset.x) * 8.0;
        const double tv = (-std::sin(r) * su + std::cos(r) * sv + c.transform.offset.y) * 8.0;
        const int i = covrast::detail::wrap_texel((long long)std::floor(tu), 8, c.s);
        const int j = covrast::detail::wrap_texel((long long)std::floor(tv), 8, c.t);
        const std::uint8_t* p = image.pixel(x, y);
        if (p[0] != i * 32 || p[1] != j * 32) {
          ++mismatches;
          // Only where the exact coordinate is a hair from a texel boundary.
          const double du = std::abs(tu - std::round(tu)), dv = std::abs(tv - std::round(tv));
          if (std::min(du, dv) < 1e-4) ++near_boundary;
        }
      }
    }
    REQUIRE(mismatches == near_boundary);
    REQUIRE(mismatches < 20);
  }
  // The wrap rules themselves.
  REQUIRE(covrast::detail::wrap_texel(-1, 8, TextureWrap::Repeat) == 7);
  REQUIRE(covrast::detail::wrap_texel(-1, 8, TextureWrap::MirroredRepeat) == 0);
  REQUIRE(covrast::detail::wrap_texel(8, 8, TextureWrap::MirroredRepeat) == 7);
  REQUIRE(covrast::detail::wrap_texel(17, 8, TextureWrap::MirroredRepeat) == 1);
  REQUIRE(covrast::detail::wrap_texel(-5, 8, TextureWrap::ClampToEdge) == 0);
  REQUIRE(covrast::detail::wrap_texel(99, 8, TextureWrap::ClampToEdge) == 7);
}

TEST_CASE("textures: the analytic derivatives of the perspective-correct weights", "[textures]") {
  covrast::detail::TriangleSetup t{};
  const double xs[3] = {10.25, 200.5, 40.0}, ys[3] = {20.0, 60.75, 180.5};
  for (int k = 0; k < 3; ++k) {
    t.x_fx8[k] = std::int32_t(xs[k] * 256);
    t.y_fx8[k] = std::int32_t(ys[k] * 256);
  }
  t.inv_w[0] = 1.0f;
  t.inv_w[1] = 0.25f;
  t.inv_w[2] = 0.6f;
  // mu(x, y) exactly as shade() computes it.
  const auto mu = [&](double x, double y, double out[3]) {
    const double area = (xs[1] - xs[0]) * (ys[2] - ys[0]) - (xs[2] - xs[0]) * (ys[1] - ys[0]);
    const double l[3] = {((xs[2] - xs[1]) * (y - ys[1]) - (ys[2] - ys[1]) * (x - xs[1])) / area,
                         ((xs[0] - xs[2]) * (y - ys[2]) - (ys[0] - ys[2]) * (x - xs[2])) / area,
                         ((xs[1] - xs[0]) * (y - ys[0]) - (ys[1] - ys[0]) * (x - xs[0])) / area};
    double sum = 0.0;
    for (int k = 0; k < 3; ++k) sum += l[k] * t.inv_w[k];
    for (int k = 0; k < 3; ++k) out[k] = l[k] * t.inv_w[k] / sum;
  };
  for (const auto& point : {glm::dvec2(60.0, 70.0), glm::dvec2(100.3, 80.7), glm::dvec2(45, 150)}) {
    double m[3], px[3], nx[3], py[3], ny[3];
    mu(point.x, point.y, m);
    const double h = 1e-3;
    mu(point.x + h, point.y, px);
    mu(point.x - h, point.y, nx);
    mu(point.x, point.y + h, py);
    mu(point.x, point.y - h, ny);
    const covrast::detail::WeightDerivatives d =
        covrast::detail::weight_derivatives(t, m[0], m[1], m[2]);
    for (int k = 0; k < 3; ++k) {
      REQUIRE(d.dx[k] == Approx((px[k] - nx[k]) / (2 * h)).margin(1e-9));
      REQUIRE(d.dy[k] == Approx((py[k] - ny[k]) / (2 * h)).margin(1e-9));
    }
  }
}

namespace {

/// A tilted floor y = -1, x in [-4, 4], z in [-40, 2], seen from (0, 0.5, 3) looking down
/// the corridor; u = (x + 4) / 8 x 2, v = (2 - z) / 42 x 16.
covrast::Scene floor_scene(const covrast::TextureSlot& slot, int width, int height) {
  covrast::Scene scene;
  scene.width = width;
  scene.height = height;
  scene.camera.eye = {0.0, 0.5, 3.0};
  scene.camera.target = {0.0, -1.0, -6.0};
  scene.camera.fovy_deg = 60.0;
  scene.camera.near = 0.1;
  scene.camera.far = 100.0;
  covrast::MeshArrays floor{.name = "floor",
                            .positions = {{-4, -1, 2}, {4, -1, 2}, {4, -1, -40}, {-4, -1, -40}},
                            .indices = {0, 1, 2, 0, 2, 3}};
  const glm::vec2 uv[4] = {{0, 0}, {2, 0}, {2, 16}, {0, 16}};
  for (const std::uint32_t i : floor.indices) floor.corner_texcoords.push_back(uv[i]);
  covrast::Material material;
  material.base_color_texture = slot;
  covrast::add_instance(scene, covrast::make_mesh(floor), {.material = material});
  return scene;
}

}  // namespace

TEST_CASE("textures: the level of detail on a tilted plane follows the derivative formula",
          "[textures]") {
  // 256x256 with nine levels, each one solid colour of its own (red = 20 x level + 10).
  auto texture = std::make_shared<covrast::Texture>();
  texture->srgb = true;
  for (int level = 0, side = 256; side >= 1; ++level, side /= 2) {
    std::vector<std::uint8_t> rows;
    for (int t = 0; t < side * side; ++t) {
      rows.insert(rows.end(), {std::uint8_t(20 * level + 10), 0, 0, 255});
    }
    texture->levels.push_back(covrast::TextureLevel::from_rows(side, side, rows));
  }
  covrast::TextureSlot slot;
  slot.texture = texture;
  slot.sampler.min = covrast::TextureFilter::Nearest;
  slot.sampler.mag = covrast::TextureFilter::Nearest;
  slot.sampler.mip = covrast::MipFilter::Nearest;
  const int width = 160, height = 120;
  const covrast::Scene scene = floor_scene(slot, width, height);
  const covrast::Image image = render_mode(scene, "coverage");
  // The exact mapping by ray casting: pixel (px, py) -> ray -> floor point -> (u, v).
  const glm::dvec3 eye = scene.camera.eye;
  const glm::dvec3 forward = glm::normalize(scene.camera.target - eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, scene.camera.up));
  const glm::dvec3 up = glm::cross(right, forward);
  const double half = std::tan(glm::radians(scene.camera.fovy_deg) / 2.0);
  const auto uv_at = [&](double px, double py) {
    const double nx = 2.0 * px / width - 1.0, ny = 1.0 - 2.0 * py / height;
    const glm::dvec3 dir = forward + right * (nx * half * width / height) + up * (ny * half);
    const double s = (-1.0 - eye.y) / dir.y;
    const glm::dvec3 p = eye + dir * s;
    return glm::dvec2((p.x + 4.0) / 8.0 * 2.0, (2.0 - p.z) / 42.0 * 16.0);
  };
  int checked = 0, mismatches = 0;
  std::string report;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double cx = x + 0.5, cy = y + 0.5;
      // Only pixels wholly on the floor (edge pixels blend with the background).
      bool inside = true;
      for (const auto& corner :
           {uv_at(x, y), uv_at(x + 1, y), uv_at(x, y + 1), uv_at(x + 1, y + 1)}) {
        inside =
            inside && corner.x > 0.01 && corner.x < 1.99 && corner.y > 0.01 && corner.y < 15.99;
      }
      // Pixels on the quad's diagonal (v = 8 u) are shaded by both triangles, each at its own
      // clamped point: left out.
      int side = 0;
      for (const auto& corner :
           {uv_at(x, y), uv_at(x + 1, y), uv_at(x, y + 1), uv_at(x + 1, y + 1)}) {
        side |= corner.y > 8.0 * corner.x ? 1 : 2;
      }
      if (!inside || side == 3) continue;
      const double h = 1e-3;
      const glm::dvec2 ddx = (uv_at(cx + h, cy) - uv_at(cx - h, cy)) / (2 * h);
      const glm::dvec2 ddy = (uv_at(cx, cy + h) - uv_at(cx, cy - h)) / (2 * h);
      const double lod = std::log2(std::max(glm::length(ddx * 256.0), glm::length(ddy * 256.0)));
      const int level = lod <= 0.5 ? 0 : std::min(8, int(std::ceil(lod + 0.5)) - 1);
      // Skip pixels within 0.02 of a level switch (snapping moves the mapping slightly).
      if (lod > 0.5 && std::abs((lod + 0.5) - std::round(lod + 0.5)) < 0.02) continue;
      ++checked;
      if (image.pixel(x, y)[0] != 20 * level + 10) {
        ++mismatches;
        if (mismatches <= 8) {
          report += "pixel " + std::to_string(x) + "," + std::to_string(y) + " lod " +
                    std::to_string(lod) + " level " + std::to_string(level) + " got " +
                    std::to_string(image.pixel(x, y)[0]) + "; ";
        }
      }
    }
  }
  INFO(report);
  REQUIRE(checked > 5000);
  REQUIRE(mismatches == 0);
}

TEST_CASE("textures: the same bytes for every thread count and tile size", "[textures]") {
  const auto texture = covrast::make_texture("noise", 64, 32, random_rgba(64, 32, 5), true);
  const covrast::Scene scene =
      floor_scene(slot_of(texture, covrast::TextureFilter::Linear, covrast::TextureFilter::Linear,
                          covrast::MipFilter::Linear),
                  160, 120);
  for (const char* mode : {"coverage", "aliased", "ssaa:2", "msaa:4"}) {
    covrast::test::expect_same_bytes_for_every_split(
        scene, mode, covrast::test::every_split({2, 4}, {8, 32, 256}));
  }
}

namespace {

std::string jpeg_bytes(const std::vector<std::uint8_t>& rgba, int width, int height) {
  tjhandle handle = tjInitCompress();
  unsigned char* out = nullptr;
  unsigned long size = 0;
  REQUIRE(tjCompress2(handle, rgba.data(), width, 0, height, TJPF_RGBA, &out, &size, TJSAMP_444,
                      100, TJFLAG_ACCURATEDCT) == 0);
  std::string bytes(reinterpret_cast<const char*>(out), size);
  tjFree(out);
  tjDestroy(handle);
  return bytes;
}

/// A valid progressive JPEG of one 8x8 grey block (all coefficients 0, mid grey), written
/// byte by byte, with successive approximation from bit `top` (<= 13, libjpeg's most) down
/// to 0 for DC and for each AC coefficient on its own: (top + 1) * 64 scans. Each scan's
/// data is one Huffman code (DC difference 0 or end of band, both the 1-bit code '0') or one
/// refinement bit '0', padded with 1s: the byte 0x7F.
std::string progressive_jpeg(int top) {
  const auto segment = [](std::string& out, std::uint8_t marker, const std::string& body) {
    out += '\xFF';
    out += char(marker);
    out += char((body.size() + 2) >> 8);
    out += char((body.size() + 2) & 255);
    out += body;
  };
  std::string out = "\xFF\xD8";
  segment(out, 0xDB, std::string(1, '\0') + std::string(64, '\1'));            // DQT 0: all 1
  segment(out, 0xC2, std::string("\x08\x00\x08\x00\x08\x01\x01\x11\x00", 9));  // SOF2 8x8
  std::string huffman(17, '\0');
  huffman[1] = 1;  // one code of length 1, for symbol 0
  huffman += '\0';
  segment(out, 0xC4, std::string(1, '\x00') + huffman.substr(1));  // DC table 0
  segment(out, 0xC4, std::string(1, '\x10') + huffman.substr(1));  // AC table 0
  const auto scan = [&](int first, int last, int high, int low) {
    std::string body("\x01\x01\x00", 3);
    body += char(first);
    body += char(last);
    body += char((high << 4) | low);
    segment(out, 0xDA, body);
    out += '\x7F';
  };
  for (int coefficient = 0; coefficient < 64; ++coefficient) {
    scan(coefficient, coefficient, 0, top);
    for (int bit = top; bit > 0; --bit) scan(coefficient, coefficient, bit, bit - 1);
  }
  out += "\xFF\xD9";
  return out;
}

std::string png_bytes(int width, int height, std::uint8_t value) {
  covrast::Image image;
  image.width = width;
  image.height = height;
  image.rgb.assign(std::size_t(width) * height * 3, value);
  const std::vector<std::uint8_t> bytes = covrast::encode_png(image);
  return std::string(bytes.begin(), bytes.end());
}

std::uint32_t crc32(const std::string& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (const char c : bytes) {
    crc ^= std::uint8_t(c);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

/// An indexed-colour PNG (bit depth 8, one row of `indices`) with `palette` (RGB triples) and
/// tRNS `alphas` when not empty; the image data as a stored (uncompressed) zlib stream.
std::string indexed_png(const std::string& indices, const std::string& palette,
                        const std::string& alphas) {
  const auto be32 = [](std::string& out, std::uint32_t v) {
    for (int i = 3; i >= 0; --i) out += char((v >> (8 * i)) & 255u);
  };
  const auto chunk = [&](std::string& out, const std::string& type, const std::string& data) {
    be32(out, std::uint32_t(data.size()));
    out += type + data;
    be32(out, crc32(type + data));
  };
  std::string ihdr;
  be32(ihdr, std::uint32_t(indices.size()));
  be32(ihdr, 1);
  ihdr += std::string("\x08\x03\x00\x00\x00", 5);
  const std::string row = std::string(1, '\0') + indices;  // filter type 0
  std::string zlib = "\x78\x01\x01";                       // one final stored block
  zlib += char(row.size() & 255u);
  zlib += char(row.size() >> 8);
  zlib += char(~row.size() & 255u);
  zlib += char((~row.size() >> 8) & 255u);
  zlib += row;
  std::uint32_t a = 1, b = 0;  // Adler-32
  for (const char c : row) {
    a = (a + std::uint8_t(c)) % 65521u;
    b = (b + a) % 65521u;
  }
  be32(zlib, (b << 16) | a);
  std::string out = "\x89PNG\r\n\x1a\n";
  chunk(out, "IHDR", ihdr);
  chunk(out, "PLTE", palette);
  if (!alphas.empty()) chunk(out, "tRNS", alphas);
  chunk(out, "IDAT", zlib);
  chunk(out, "IEND", "");
  return out;
}

/// A glTF quad whose baseColorTexture is image 0 at `uri`.
std::string textured_gltf(const std::string& uri, const nlohmann::json& extra = {}) {
  covrast::test::GltfBuilder b;
  const int pos = b.add_floats({0, 0, 0, 1, 0, 0, 1, 1, 0}, "VEC3");
  const int uv = b.add_floats({0, 0, 1, 0, 1, 1}, "VEC2");
  b.single_mesh({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"material", 0}}});
  b.gltf["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  b.gltf["textures"] = {{{"source", 0}}};
  b.gltf["images"] = {{{"uri", uri}}};
  if (!extra.is_null()) b.gltf.update(extra);
  return b.gltf_text();
}

void write_file(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

}  // namespace

TEST_CASE("textures: a progressive JPEG of more than 500 scans is refused (issue 28)",
          "[textures]") {
  // 7 * 64 = 448 scans decode; 8 * 64 = 512 are past libjpeg-turbo's limit of 500 (a valid
  // file of 2,080 scans of a larger image took 15 s and 991 MB before TJFLAG_LIMITSCANS).
  const std::string fine = progressive_jpeg(6);
  const covrast::RgbaImage image =
      covrast::decode_image(reinterpret_cast<const std::uint8_t*>(fine.data()), fine.size(), "j");
  REQUIRE(image.width == 8);
  REQUIRE(image.height == 8);
  CHECK(int(image.rgba[0]) == Approx(128).margin(1));
  const std::string many = progressive_jpeg(7);
  REQUIRE_THROWS_WITH(
      covrast::decode_image(reinterpret_cast<const std::uint8_t*>(many.data()), many.size(),
                            "many.jpg"),
      "many.jpg: cannot decode image: Progressive JPEG image has more than 500 scans");
}

TEST_CASE("textures: PNG and JPEG decoded by content, from files, data URIs and buffer views",
          "[textures]") {
  // JPEG at quality 100, 4:4:4: a smooth image survives within a few levels.
  const std::vector<std::uint8_t> rgba = smooth_rgba_32x16();
  const std::string jpeg = jpeg_bytes(rgba, 32, 16);
  const covrast::RgbaImage decoded =
      covrast::decode_image(reinterpret_cast<const std::uint8_t*>(jpeg.data()), jpeg.size(), "j");
  REQUIRE(decoded.width == 32);
  REQUIRE(decoded.height == 16);
  int worst = 0;
  for (std::size_t i = 0; i < rgba.size(); ++i)
    worst = std::max(worst, std::abs(decoded.rgba[i] - rgba[i]));
  REQUIRE(worst <= 3);

  covrast::test::TempDir dir("covrast-textures");
  // A JPEG named .png loads: the content decides.
  write_file(dir / "photo.png", jpeg);
  write_file(dir / "a.gltf", textured_gltf("photo.png"));
  const auto mesh = covrast::load_mesh(dir / "a.gltf");
  REQUIRE(mesh->materials[0].base_color_texture.texture->levels[0].width == 32);
  REQUIRE(mesh->corner_texcoords[0].size() == 3);
  // The same image as a data: URI, and from a buffer view (.glb).
  write_file(dir / "b.gltf",
             textured_gltf("data:image/jpeg;base64," + covrast::test::base64(jpeg)));
  REQUIRE(covrast::load_mesh(dir / "b.gltf")
              ->materials[0]
              .base_color_texture.texture->levels[0]
              .height == 16);
  covrast::test::GltfBuilder b;
  const int pos = b.add_floats({0, 0, 0, 1, 0, 0, 1, 1, 0}, "VEC3");
  const int view = b.add_view(png_bytes(4, 2, 128));
  b.single_mesh({{{"attributes", {{"POSITION", pos}}}, {"material", 0}}});
  b.gltf["materials"] = {{{"emissiveTexture", {{"index", 0}}}}};
  b.gltf["textures"] = {{{"source", 0}, {"sampler", 0}}};
  b.gltf["samplers"] = {
      {{"magFilter", 9728}, {"minFilter", 9986}, {"wrapS", 33071}, {"wrapT", 33648}}};
  b.gltf["images"] = {{{"bufferView", view}, {"mimeType", "image/png"}}};
  write_file(dir / "c.glb", b.glb());
  const auto c = covrast::load_mesh(dir / "c.glb");
  const covrast::TextureSlot& e = c->materials[0].emissive_texture;
  REQUIRE(e.texture->levels[0].width == 4);
  REQUIRE(e.texture->linear(0, 0, 0).r == Approx(srgb_decode(128)).epsilon(1e-12));
  REQUIRE(e.sampler.mag == covrast::TextureFilter::Nearest);
  REQUIRE(e.sampler.min == covrast::TextureFilter::Nearest);
  REQUIRE(e.sampler.mip == covrast::MipFilter::Linear);
  REQUIRE(e.sampler.wrap_s == covrast::TextureWrap::ClampToEdge);
  REQUIRE(e.sampler.wrap_t == covrast::TextureWrap::MirroredRepeat);
}

TEST_CASE("textures: KHR_texture_transform and texCoord are read per slot", "[textures]") {
  covrast::test::TempDir dir("covrast-textures");
  write_file(dir / "t.png", png_bytes(2, 2, 200));
  nlohmann::json extra;
  extra["materials"] = {{{"pbrMetallicRoughness",
                          {{"baseColorTexture",
                            {{"index", 0},
                             {"texCoord", 0},
                             {"extensions",
                              {{"KHR_texture_transform",
                                {{"offset", {0.5, -0.25}},
                                 {"rotation", 1.5},
                                 {"scale", {2, 3}},
                                 {"texCoord", 1}}}}}}},
                           {"metallicRoughnessTexture", {{"index", 0}, {"texCoord", 1}}}}},
                         {"occlusionTexture", {{"index", 0}, {"strength", 0.5}}},
                         {"normalTexture", {{"index", 0}, {"scale", 0.75}}}}};
  write_file(dir / "t.gltf", textured_gltf("t.png", extra));
  const auto mesh = covrast::load_mesh(dir / "t.gltf");
  const covrast::Material& m = mesh->materials[0];
  REQUIRE(m.base_color_texture.texcoord == 1);
  REQUIRE(m.base_color_texture.transform.offset == glm::dvec2(0.5, -0.25));
  REQUIRE(m.base_color_texture.transform.rotation == 1.5);
  REQUIRE(m.base_color_texture.transform.scale == glm::dvec2(2, 3));
  REQUIRE(m.metallic_roughness_texture.texcoord == 1);
  REQUIRE(m.occlusion_texture.scale == 0.5f);
  REQUIRE(m.normal_texture.scale == 0.75f);
  // One image, two colour spaces: sRGB for base colour, linear for the others.
  REQUIRE(m.base_color_texture.texture != m.metallic_roughness_texture.texture);
  REQUIRE(m.metallic_roughness_texture.texture == m.occlusion_texture.texture);
  REQUIRE(m.metallic_roughness_texture.texture->linear(0, 0, 0).r == Approx(200 / 255.0));
}

TEST_CASE("textures: KHR_texture_transform fields of a wrong type or range (issue 28)",
          "[textures]") {
  covrast::test::TempDir dir("covrast-textures");
  write_file(dir / "t.png", png_bytes(2, 2, 200));
  const auto load = [&](const nlohmann::json& transform) {
    nlohmann::json extra;
    extra["materials"] = {
        {{"pbrMetallicRoughness",
          {{"baseColorTexture",
            {{"index", 0}, {"extensions", {{"KHR_texture_transform", transform}}}}}}}}};
    write_file(dir / "t.gltf", textured_gltf("t.png", extra));
    return covrast::load_mesh(dir / "t.gltf");
  };
  const std::string where = "t.gltf: material 0 baseColorTexture: ";
  // texCoord 1e30 was converted to int first (undefined; "texCoord -2147483648").
  REQUIRE_THROWS_WITH(load({{"texCoord", 1e30}}),
                      Contains(where + "texCoord 1e+30 (covrast reads TEXCOORD_0 and TEXCOORD_1)"));
  REQUIRE_THROWS_WITH(load({{"texCoord", -1e30}}), Contains(where + "texCoord -1e+30 ("));
  REQUIRE_THROWS_WITH(load({{"texCoord", 0.5}}), Contains(where + "texCoord 0.5 ("));
  REQUIRE_THROWS_WITH(load({{"texCoord", "1"}}),
                      Contains(where + "KHR_texture_transform.texCoord: expected an integer >= 0"));
  // Wrong types were ignored silently; the transform is used, so each is an error.
  REQUIRE_THROWS_WITH(load({{"offset", "0.5"}}),
                      Contains(where + "KHR_texture_transform.offset: expected an array of 2 "
                                       "numbers"));
  REQUIRE_THROWS_WITH(load({{"scale", {1, 2, 3}}}),
                      Contains(where + "KHR_texture_transform.scale: expected an array of 2"));
  REQUIRE_THROWS_WITH(load({{"rotation", {1}}}),
                      Contains(where + "KHR_texture_transform.rotation: expected a number"));
  REQUIRE(load({{"texCoord", 1.0}, {"rotation", 0.25}})->materials[0].base_color_texture.texcoord ==
          1);
}

TEST_CASE("textures: bad images are InputErrors naming the image and the model", "[textures]") {
  covrast::test::TempDir dir("covrast-textures");
  const auto load = [&](const std::string& uri) {
    write_file(dir / "m.gltf", textured_gltf(uri));
    return covrast::load_mesh(dir / "m.gltf");
  };
  // A missing file is not an error but a warning, and the slot stays empty (docs/limits.md,
  // "Missing files"); a file that is there but broken is an error.
  write_file(dir / "m.gltf", textured_gltf("missing.png"));
  const covrast::Scene missing = covrast::load_mesh_scene(dir / "m.gltf", 16, 16);
  CHECK(missing.meshes[0].mesh->materials[0].base_color_texture.texture == nullptr);
  INFO(missing.warnings.size() << " warnings, first: " << missing.warnings.front()
                               << "; last: " << missing.warnings.back());
  REQUIRE(missing.warnings.size() == 1);
  CHECK_THAT(missing.warnings[0],
             Contains("m.gltf: image 0 (missing.png): no such file: its texture slots are drawn "
                      "without it"));
  const std::string png = png_bytes(16, 16, 40);
  write_file(dir / "cut.png", png.substr(0, png.size() / 2));
  REQUIRE_THROWS_WITH(load("cut.png"), Contains("m.gltf: image 0 (cut.png)"));
  // A forged header: 100000 x 100000 with a valid CRC, refused before allocating.
  std::string huge = png_bytes(1, 1, 0);
  for (int k = 0; k < 2; ++k) {
    huge[16 + 4 * k] = 0;
    huge[17 + 4 * k] = 1;
    huge[18 + 4 * k] = char(0x86);
    huge[19 + 4 * k] = char(0xA0);
  }
  const std::uint32_t crc = crc32(huge.substr(12, 17));
  for (int k = 0; k < 4; ++k) huge[29 + k] = char(crc >> (24 - 8 * k));
  write_file(dir / "huge.png", huge);
  REQUIRE_THROWS_WITH(load("huge.png"), Contains("m.gltf: image 0 (huge.png)"));
  const std::string jpeg = jpeg_bytes(random_rgba(16, 16, 1), 16, 16);
  write_file(dir / "cut.jpg", jpeg.substr(0, jpeg.size() - 40));
  REQUIRE_THROWS_WITH(load("cut.jpg"), Contains("m.gltf: image 0 (cut.jpg)"));
  write_file(dir / "text.png", "not an image at all");
  REQUIRE_THROWS_WITH(load("text.png"),
                      Contains("image 0 (text.png)") && Contains("neither PNG, JPEG nor WebP"));
  REQUIRE_THROWS_WITH(load("data:image/png;base64," + covrast::test::base64("garbage!")),
                      Contains("m.gltf: image 0"));
  // Issue 28: a wrong CRC on the last IDAT chunk decoded without a word.
  std::string bad_crc = png_bytes(4, 4, 40);
  const std::size_t iend = bad_crc.size() - 12;
  bad_crc[iend - 1] = char(bad_crc[iend - 1] ^ 1);
  write_file(dir / "crc.png", bad_crc);
  REQUIRE_THROWS_WITH(load("crc.png"),
                      Contains("m.gltf: image 0 (crc.png): cannot decode image: invalid "
                               "chunk checksum"));
}

TEST_CASE("textures: an indexed PNG's index past its palette is an error (issue 28)",
          "[textures]") {
  // Two entries (red, green), alpha 128 for the first; indices 0, 1, then 5: libspng looked
  // index 5 up without a word.
  const std::string palette("\xFF\x00\x00\x00\xFF\x00", 6);
  const std::string good = indexed_png(std::string("\x00\x01", 2), palette, "\x80");
  const covrast::RgbaImage image = covrast::decode_image(
      reinterpret_cast<const std::uint8_t*>(good.data()), good.size(), "p.png");
  REQUIRE(image.width == 2);
  CHECK(std::vector<int>(image.rgba.begin(), image.rgba.end()) ==
        std::vector<int>{255, 0, 0, 128, 0, 255, 0, 255});
  const std::string bad = indexed_png(std::string("\x00\x01\x05", 3), palette, "");
  REQUIRE_THROWS_WITH(
      covrast::decode_image(reinterpret_cast<const std::uint8_t*>(bad.data()), bad.size(), "p.png"),
      "p.png: cannot decode image: palette index 5 at (2, 0) is past the "
      "palette's 2 entries");
}

TEST_CASE("textures: image URIs with a NUL, data: URIs of other media types (issue 28)",
          "[textures]") {
  covrast::test::TempDir dir("covrast-textures");
  const auto load = [&](const std::string& uri) {
    write_file(dir / "m.gltf", textured_gltf(uri));
    return covrast::load_mesh(dir / "m.gltf");
  };
  write_file(dir / "t.png", png_bytes(2, 2, 40));
  REQUIRE(load("t.png")->materials[0].base_color_texture.texture->levels[0].width == 2);
  // "%00" decodes to a NUL: the part before it ("t.png") was opened, exit 0.
  REQUIRE_THROWS_WITH(load("t.png%00.jpg"),
                      Contains("m.gltf: image 0 (t.png%00.jpg): the path contains a NUL byte"));
  // tinygltf takes a data: URI of a media type it does not know for a file name.
  const std::string png = covrast::test::base64(png_bytes(2, 2, 40));
  REQUIRE_THROWS_WITH(
      load("data:text/html;base64," + png),
      Contains("m.gltf: image 0: data: URI of media type 'text/html' (expected image/png, "
               "image/jpeg or application/octet-stream)"));
  REQUIRE_THROWS_WITH(
      load("data:image/gif;base64," + png),
      Contains("m.gltf: image 0: data: URI of media type 'image/gif' (expected image/png, "
               "image/jpeg or application/octet-stream)"));
  // Accepted, and decoded by their content.
  for (const char* type : {"image/png", "image/jpeg", "application/octet-stream"}) {
    INFO(type);
    const auto mesh = load("data:" + std::string(type) + ";base64," + png);
    REQUIRE(mesh->materials[0].base_color_texture.texture->levels[0].width == 2);
  }
}

TEST_CASE("textures: image entries naming one file are decoded once (issue 28)", "[textures]") {
  // Eight image entries naming one PNG were eight decoded copies (with a 2^26-pixel PNG of
  // 196 KB: 3.45 GB from a 3.6 KB glTF). The same file, or buffer view, is decoded once.
  covrast::test::TempDir dir("covrast-textures");
  write_file(dir / "t.png", png_bytes(4, 4, 90));
  covrast::test::GltfBuilder b;
  const int pos = b.add_floats({0, 0, 0, 1, 0, 0, 1, 1, 0}, "VEC3");
  const int uv = b.add_floats({0, 0, 1, 0, 1, 1}, "VEC2");
  const int view = b.add_view(png_bytes(4, 4, 90));
  nlohmann::json primitives = nlohmann::json::array();
  for (int i = 0; i < 8; ++i) {
    primitives.push_back(
        {{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"material", i}});
    b.gltf["materials"].push_back(
        {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", i}}}}}});
    b.gltf["textures"].push_back({{"source", i}});
    if (i < 4) {
      b.gltf["images"].push_back({{"uri", i % 2 == 0 ? "t.png" : "./t.png"}});
    } else {
      b.gltf["images"].push_back({{"bufferView", view}, {"mimeType", "image/png"}});
    }
  }
  b.single_mesh(primitives);
  write_file(dir / "m.gltf", b.gltf_text());
  const auto mesh = covrast::load_mesh(dir / "m.gltf");
  REQUIRE(mesh->materials.size() >= 8);
  for (int i = 1; i < 8; ++i) {
    INFO(i);
    CHECK(mesh->materials[std::size_t(i)].base_color_texture.texture ==
          mesh->materials[i < 4 ? 0 : 4].base_color_texture.texture);
  }
  CHECK(mesh->materials[0].base_color_texture.texture !=
        mesh->materials[4].base_color_texture.texture);
}

TEST_CASE("textures: an image file over 1 GiB is refused from its size, unread (issue 28)",
          "[textures]") {
  // A sparse file of 1 GiB + 1 byte: it was read in full before its size was checked.
  covrast::test::TempDir dir("covrast-textures");
  const std::filesystem::path big = dir / "big.png";
  write_file(big, "");
  std::filesystem::resize_file(big, (std::uintmax_t(1) << 30) + 1);
  const auto start = std::chrono::steady_clock::now();
  REQUIRE_THROWS_WITH(covrast::read_image(big, "big.png"),
                      "big.png: cannot read image: file of 1073741825 bytes is larger than the "
                      "1 GiB limit");
  write_file(dir / "m.gltf", textured_gltf("big.png"));
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir / "m.gltf"),
                      Contains("m.gltf: image 0 (big.png): cannot read image: file of "
                               "1073741825 bytes is larger than the 1 GiB limit"));
  write_file(dir / "m.mtl", "newmtl a\nmap_Kd big.png\n");
  write_file(dir / "m.obj",
             "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl a\nf 1/1 2/1 3/1\n");
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir / "m.obj"),
                      Contains("m.obj: map_Kd big.png: cannot read image: file of 1073741825 "
                               "bytes is larger than the 1 GiB limit"));
  CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < 2.0);
}

TEST_CASE("textures: OBJ vt lines become corner UVs, v flipped to glTF's orientation",
          "[textures]") {
  covrast::test::TempDir dir("covrast-textures");
  write_file(dir / "q.obj",
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0.25 0.75\n"
             "f 1 2 3\nf 1/1 3/3 4/4\nf 1//1 2/-3 3\n");
  const auto mesh = covrast::load_mesh(dir / "q.obj");
  const std::vector<glm::vec2>& uv = mesh->corner_texcoords[0];
  REQUIRE(uv.size() == 9);
  REQUIRE(uv[0] == glm::vec2(0, 0));  // a face before the first with UVs: none
  REQUIRE(uv[3] == glm::vec2(0, 1));
  REQUIRE(uv[4] == glm::vec2(1, 0));
  REQUIRE(uv[5] == glm::vec2(0.25f, 0.25f));
  REQUIRE(uv[7] == glm::vec2(1, 1));  // -3 = the second vt line
  write_file(dir / "bad.obj", "v 0 0 0\nvt 0 nan\n");
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir / "bad.obj"), Contains("bad.obj:2"));
}

namespace {

/// A lit (Lambert) quad filling the image, with one texture slot set on its material by
/// `set_slot`; the light rig is `lights`. Returns the centre pixel's red byte.
template <class SetSlot>
int lit_quad_red(const std::vector<covrast::Light>& lights, SetSlot set_slot) {
  covrast::Scene scene = quad_scene(16, covrast::TextureSlot{});
  covrast::Material material;
  material.model = covrast::ShadingModel::Lambert;
  set_slot(material);
  scene.meshes[0].materials.assign(1, material);
  for (const covrast::Light& light : lights) covrast::add_light(scene, light);
  return render_mode(scene, "coverage").pixel(8, 8)[0];
}

covrast::TextureSlot solid_slot(std::uint8_t r, std::uint8_t g, std::uint8_t b, bool srgb) {
  std::vector<std::uint8_t> rgba(16, 255);
  for (std::size_t i = 0; i < 16; i += 4) {
    rgba[i] = r;
    rgba[i + 1] = g;
    rgba[i + 2] = b;
  }
  covrast::TextureSlot slot;
  slot.texture = covrast::make_texture("solid", 2, 2, rgba, srgb);
  return slot;
}

}  // namespace

TEST_CASE("textures: occlusion, emissive and normal textures in a lit scene", "[textures]") {
  covrast::Light ambient;
  ambient.type = covrast::LightType::Ambient;
  ambient.intensity = 0.5;
  const auto encoded = [](double linear) { return int(std::lround(srgb_encode_255(linear))); };
  // Occlusion multiplies the ambient term: 1 + strength (R - 1) with R = 0.2.
  REQUIRE(lit_quad_red({ambient}, [](covrast::Material&) {}) == encoded(0.5));
  REQUIRE(lit_quad_red({ambient}, [](covrast::Material& m) {
            m.occlusion_texture = solid_slot(51, 0, 0, false);
          }) == encoded(0.5 * 0.2));
  REQUIRE(lit_quad_red({ambient}, [](covrast::Material& m) {
            m.occlusion_texture = solid_slot(51, 0, 0, false);
            m.occlusion_texture.scale = 0.5f;
          }) == encoded(0.5 * 0.6));
  // Emission: factor x texture (sRGB 128), added.
  REQUIRE(lit_quad_red({ambient}, [](covrast::Material& m) {
            m.emissive_linear = glm::vec3(0.5f);
            m.emissive_texture = solid_slot(128, 128, 128, true);
          }) == encoded(0.5 + 0.5 * srgb_decode(128)));
  // A light grazing along +x does not light the flat quad; a normal map that turns the normal
  // to the tangent (+x, from the UVs: u grows along +x) faces it: n_ts = (1, 0, 0) from texel
  // (255, 128, 128) is (1, 0.004, 0.004) before normalising.
  covrast::Light grazing;
  grazing.direction = {-1.0, 0.0, 0.0};
  REQUIRE(lit_quad_red({grazing}, [](covrast::Material&) {}) == 0);
  const glm::dvec3 n = glm::normalize(glm::dvec3(1.0, 1.0 / 255.0, 1.0 / 255.0));
  REQUIRE(lit_quad_red({grazing}, [](covrast::Material& m) {
            m.normal_texture = solid_slot(255, 128, 128, false);
          }) == encoded(n.x));
}

TEST_CASE("textures: TEXCOORD as normalized integers, a missing UV set is a warning",
          "[textures]") {
  covrast::test::TempDir dir("covrast-textures");
  write_file(dir / "t.png", png_bytes(2, 2, 90));
  covrast::test::GltfBuilder b;
  const int pos = b.add_floats({0, 0, 0, 1, 0, 0, 1, 1, 0}, "VEC3");
  // TEXCOORD_0: normalized unsigned short (v / 65535); TEXCOORD_1: normalized unsigned byte.
  std::string u16, u8;
  for (const std::uint16_t v : {0, 65535, 32768, 0, 65535, 65535}) covrast::test::put_u16(u16, v);
  for (const std::uint8_t v : {0, 255, 51, 102, 255, 0}) covrast::test::put_u8(u8, v);
  const int view16 = b.add_view(u16), view8 = b.add_view(u8);
  b.gltf["accessors"].push_back({{"bufferView", view16},
                                 {"componentType", 5123},
                                 {"count", 3},
                                 {"type", "VEC2"},
                                 {"normalized", true}});
  b.gltf["accessors"].push_back({{"bufferView", view8},
                                 {"componentType", 5121},
                                 {"count", 3},
                                 {"type", "VEC2"},
                                 {"normalized", true}});
  const int uv0 = int(b.gltf["accessors"].size()) - 2, uv1 = uv0 + 1;
  b.single_mesh({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv0}, {"TEXCOORD_1", uv1}}},
                  {"material", 0}},
                 {{"attributes", {{"POSITION", pos}}}, {"material", 0}}});
  b.gltf["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  b.gltf["textures"] = {{{"source", 0}}};
  b.gltf["images"] = {{{"uri", "t.png"}}};
  write_file(dir / "n.gltf", b.gltf_text());
  const auto mesh = covrast::load_mesh(dir / "n.gltf");
  REQUIRE(mesh->corner_texcoords[0].size() == 6);
  REQUIRE(mesh->corner_texcoords[0][1] == glm::vec2(32768 / 65535.0f, 0.0f));
  REQUIRE(mesh->corner_texcoords[1][1] == glm::vec2(0.2f, 0.4f));
  REQUIRE(mesh->corner_texcoords[0][4] == glm::vec2(0.0f));  // the second primitive has none
  write_file(dir / "s.json", R"({"width": 8, "height": 8, "camera": {"eye": [0, 0, 3],
    "target": [0, 0, 0], "up": [0, 1, 0], "fovy_deg": 40, "near": 0.1, "far": 10},
    "meshes": [{"gltf": "n.gltf"}]})");
  const covrast::Scene scene = covrast::load_scene(dir / "s.json");
  REQUIRE(scene.warnings.size() == 1);
  REQUIRE_THAT(scene.warnings[0], Contains("1 primitives lack the TEXCOORD_n"));
}

TEST_CASE("textures: load_texture_file, the hook for OBJ map_Kd", "[textures]") {
  covrast::test::TempDir dir("covrast-textures");
  write_file(dir / "k.png", png_bytes(3, 2, 64));
  std::uint64_t texels = 0;
  const auto texture =
      covrast::detail::load_texture_file(dir / "k.png", "m.obj: map_Kd k.png", true, texels);
  REQUIRE(texture->levels[0].width == 3);
  REQUIRE(texture->linear(0, 0, 0).g == Approx(srgb_decode(64)).epsilon(1e-12));
  REQUIRE(texels == 6);
  REQUIRE_THROWS_WITH(
      covrast::detail::load_texture_file(dir / "no.png", "m.obj: map_Kd no.png", true, texels),
      Contains("m.obj: map_Kd no.png: cannot read image"));
  // The file's decoded images together stay within kMaxTextureTexels (issue 28).
  texels = covrast::detail::kMaxTextureTexels - 5;
  REQUIRE_THROWS_WITH(
      covrast::detail::load_texture_file(dir / "k.png", "m.obj: map_Kd k.png", true, texels),
      "m.obj: map_Kd k.png: its 3x2 texels take the file's decoded images past 134217728 "
      "texels (docs/limits.md)");
}

TEST_CASE("textures: the base colour texture's alpha multiplies into BLEND and MASK",
          "[textures][transparency]") {
  // Random texels with random alpha on the image-filling quad, NEAREST: each pixel sees one
  // texel, so BLEND gives c = t a + bg (1 - a) with a = base_alpha x texel alpha / 255, and
  // MASK keeps the texel where a >= cutoff, in linear light.
  std::vector<std::uint8_t> rgba = random_rgba(32, 32, 11);
  std::uint32_t seed = 5;
  for (std::size_t i = 3; i < rgba.size(); i += 4) {
    seed = seed * 1664525u + 1013904223u;
    rgba[i] = std::uint8_t(seed >> 24);
  }
  rgba[3] = 128;  // exactly at the MASK cutoff 128 / 255 below
  rgba[7] = 127;  // just below it
  const auto texture = covrast::make_texture("alpha", 32, 32, rgba, true);
  covrast::Scene scene =
      quad_scene(32, slot_of(texture, covrast::TextureFilter::Nearest,
                             covrast::TextureFilter::Nearest, covrast::MipFilter::None));
  scene.background_linear = {0.2f, 0.5f, 0.05f};
  const double bg[3] = {0.2, 0.5, 0.05};
  covrast::Material& material = scene.meshes[0].materials[0];
  for (const bool blend : {true, false}) {
    material.alpha_mode = blend ? covrast::AlphaMode::Blend : covrast::AlphaMode::Mask;
    material.base_alpha = blend ? 0.5 : 1.0;
    material.alpha_cutoff = 128.0 / 255.0;
    for (const char* mode : {"coverage", "reference", "msaa:4", "aliased"}) {
      INFO((blend ? "BLEND " : "MASK ") << mode);
      const covrast::Image image = render_mode(scene, mode);
      double worst = 0.0;
      for (int i = 0; i < 32 * 32; ++i) {
        const double a = material.base_alpha * rgba[4 * i + 3] / 255.0;
        for (int c = 0; c < 3; ++c) {
          const double texel = srgb_decode(rgba[4 * i + c]);
          const double linear =
              blend ? texel * a + bg[c] * (1.0 - a) : (rgba[4 * i + 3] >= 128 ? texel : bg[c]);
          worst = std::max(worst, std::abs(image.rgb[3 * i + c] - srgb_encode_255(linear)));
        }
      }
      REQUIRE(worst <= 1.0);
    }
  }
}

TEST_CASE("textures: coverage mode cuts a MASK texture's edges within the pixel",
          "[textures][transparency]") {
  // Random alpha noise, NEAREST, 61 texels on 48 pixels: most pixels hold texels on both
  // sides of the cutoff, and the texel edges fall between any grid's samples. One verdict
  // per fragment (coverage-blend, msaa) keeps or drops whole pixels; coverage mode keeps the
  // share of each fragment that passes at its kMaskGrid x kMaskGrid points (mask_share).
  const int size = 48, texels = 61;
  std::vector<std::uint8_t> rgba = random_rgba(texels, texels, 23);
  std::uint32_t seed = 9;
  for (std::size_t i = 3; i < rgba.size(); i += 4) {
    seed = seed * 1664525u + 1013904223u;
    rgba[i] = std::uint8_t(seed >> 24);
  }
  covrast::Scene scene =
      quad_scene(size, slot_of(covrast::make_texture("alpha", texels, texels, rgba, true),
                               covrast::TextureFilter::Nearest, covrast::TextureFilter::Nearest,
                               covrast::MipFilter::None));
  scene.background_linear = {0.2f, 0.5f, 0.05f};
  covrast::Material& material = scene.meshes[0].materials[0];
  material.alpha_mode = covrast::AlphaMode::Mask;
  material.alpha_cutoff = 0.5;
  const covrast::Image reference = render_mode(scene, "reference");
  // RMSE in linear light against the reference.
  const auto rmse = [&](const covrast::Image& image) {
    double sum = 0.0;
    for (std::size_t i = 0; i < image.rgb.size(); ++i) {
      const double d = srgb_decode(image.rgb[i]) - srgb_decode(reference.rgb[i]);
      sum += d * d;
    }
    return std::sqrt(sum / double(image.rgb.size()));
  };
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode("coverage");
  const covrast::RenderResult coverage = covrast::render(scene, options);
  const double rmse_coverage = rmse(coverage.color);
  const double rmse_ssaa = rmse(render_mode(scene, "ssaa:16"));
  const double rmse_ssaa8 = rmse(render_mode(scene, "ssaa:8"));
  const double rmse_one_verdict = rmse(render_mode(scene, "coverage-blend"));
  INFO("RMSE against the reference: coverage " << rmse_coverage << ", ssaa:16 " << rmse_ssaa
                                               << ", ssaa:8 " << rmse_ssaa8 << ", coverage-blend "
                                               << rmse_one_verdict);
  // Measured: coverage 0.0140, ssaa:8 0.0146, ssaa:16 0.0077, coverage-blend 0.147. Every
  // pixel straddles the cutoff here, the worst case: the share is as good as ssaa:8's 64
  // samples (kMaskGrid 8), not yet as ssaa:16's 256 (docs/transparency.md).
  static_assert(covrast::detail::kMaskGrid == 8, "the bound below is ssaa:8's");
  CHECK(coverage.stats.resolve_paths.transparent > std::uint64_t(size * size / 2));
  CHECK(rmse_coverage < 1.1 * rmse_ssaa8);
  CHECK(rmse_one_verdict > 5.0 * rmse_coverage);
}

namespace {

std::string webp_lossless(const std::vector<std::uint8_t>& rgba, int width, int height) {
  std::uint8_t* out = nullptr;
  const std::size_t size = WebPEncodeLosslessRGBA(rgba.data(), width, height, width * 4, &out);
  REQUIRE(size > 0);
  std::string bytes(reinterpret_cast<const char*>(out), size);
  WebPFree(out);
  return bytes;
}

covrast::RgbaImage decode_bytes(const std::string& bytes, const std::string& name = "w") {
  return covrast::decode_image(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(),
                               name);
}

}  // namespace

TEST_CASE("textures: WebP decoded by content: lossless exactly, lossy closely, bounded",
          "[textures][webp]") {
  // Lossless with alpha: every byte back.
  std::vector<std::uint8_t> rgba = random_rgba(7, 5, 11);
  for (std::size_t i = 3; i < rgba.size(); i += 4) rgba[i] = std::uint8_t(i * 37);
  const std::string lossless = webp_lossless(rgba, 7, 5);
  const covrast::RgbaImage back = decode_bytes(lossless);
  REQUIRE(back.width == 7);
  REQUIRE(back.height == 5);
  CHECK(back.rgba == rgba);
  // Lossy at quality 100 on a smooth opaque image: within a few levels.
  const std::vector<std::uint8_t> smooth = smooth_rgba_32x16();
  std::uint8_t* out = nullptr;
  const std::size_t size = WebPEncodeRGBA(smooth.data(), 32, 16, 32 * 4, 100.0f, &out);
  REQUIRE(size > 0);
  const std::string lossy(reinterpret_cast<const char*>(out), size);
  WebPFree(out);
  const covrast::RgbaImage lossy_back = decode_bytes(lossy);
  REQUIRE(lossy_back.rgba.size() == smooth.size());
  int worst = 0;
  for (std::size_t i = 0; i < smooth.size(); ++i)
    worst = std::max(worst, std::abs(lossy_back.rgba[i] - smooth[i]));
  CHECK(worst <= 8);
  // Truncated data is an error, not a partial image.
  CHECK_THROWS_WITH(decode_bytes(lossless.substr(0, lossless.size() - 4), "model: image 1"),
                    Contains("model: image 1: cannot decode image:"));
  // A header claiming 16384x16384 (the VP8L size fields, 14 bits each, all ones) is refused
  // from the header, before the 1 GiB of pixels is allocated.
  std::string huge = lossless;
  REQUIRE(huge.substr(12, 4) == "VP8L");
  std::uint32_t fields = 0;
  for (int k = 0; k < 4; ++k) fields |= std::uint32_t(std::uint8_t(huge[21 + k])) << (8 * k);
  fields |= (1u << 28) - 1u;
  for (int k = 0; k < 4; ++k) huge[21 + k] = char((fields >> (8 * k)) & 255u);
  CHECK_THROWS_WITH(decode_bytes(huge), Contains("16384"));
}

TEST_CASE("textures: EXT_texture_webp draws its source, the core source is the fallback",
          "[textures][webp][gltf]") {
  const std::vector<std::uint8_t> texels = random_rgba(3, 3, 5);
  const auto build = [&](const nlohmann::json& texture, bool required) {
    covrast::test::GltfBuilder b;
    const int pos = b.add_floats({0, 0, 0, 1, 0, 0, 1, 1, 0}, "VEC3");
    const int png = b.add_view(png_bytes(2, 2, 10));
    const int webp = b.add_view(webp_lossless(texels, 3, 3));
    b.single_mesh({{{"attributes", {{"POSITION", pos}}}, {"material", 0}}});
    b.gltf["materials"] = {{{"emissiveTexture", {{"index", 0}}}}};
    b.gltf["textures"] = nlohmann::json::array({texture});
    b.gltf["images"] = {{{"bufferView", png}, {"mimeType", "image/png"}},
                        {{"bufferView", webp}, {"mimeType", "image/webp"}}};
    b.gltf["extensionsUsed"] = {"EXT_texture_webp"};
    if (required) b.gltf["extensionsRequired"] = {"EXT_texture_webp"};
    return b.glb();
  };
  covrast::test::TempDir dir("covrast-webp");
  const auto emissive = [&](const std::string& glb) {
    write_file(dir / "w.glb", glb);
    const covrast::Scene scene = covrast::load_mesh_scene(dir / "w.glb", 16, 16);
    for (const std::string& warning : scene.warnings) {
      CHECK(warning.find("EXT_texture_webp") == std::string::npos);  // honoured, no warning
    }
    return scene.meshes.at(0).mesh->materials.at(0).emissive_texture.texture;
  };
  // With a PNG fallback as the core source: the WebP image is drawn.
  const auto with_fallback = emissive(
      build({{"source", 0}, {"extensions", {{"EXT_texture_webp", {{"source", 1}}}}}}, false));
  REQUIRE(with_fallback->levels[0].width == 3);
  CHECK(with_fallback->linear(0, 2, 1).g == Approx(srgb_decode(texels[(1 * 3 + 2) * 4 + 1])));
  // Required, with no core source at all.
  const auto required =
      emissive(build({{"extensions", {{"EXT_texture_webp", {{"source", 1}}}}}}, true));
  CHECK(required->levels[0].height == 3);
  // A source that is not an image index is an error naming the field.
  for (const nlohmann::json& bad :
       {nlohmann::json(2), nlohmann::json(-1), nlohmann::json("1"), nlohmann::json(0.5)}) {
    write_file(dir / "bad.glb",
               build({{"extensions", {{"EXT_texture_webp", {{"source", bad}}}}}}, true));
    CHECK_THROWS_WITH(covrast::load_mesh_scene(dir / "bad.glb", 16, 16),
                      Contains("EXT_texture_webp.source: expected the index of one of the "
                               "file's 2 images"));
  }
}

namespace {

/// The exact box average of a NEAREST level-0 texture of `texels`^2 on quad_scene(size) (UV
/// 0..1): pixel [p, p + 1) covers texels [p t, (p + 1) t), t = texels / size, in each axis.
double exact_pixel_mean(const std::vector<std::uint8_t>& rgba, int texels, int size, int px, int py,
                        int c) {
  const double t = double(texels) / size;
  const auto overlap = [&](int pixel, int texel) {
    return std::max(0.0,
                    std::min((pixel + 1) * t, texel + 1.0) - std::max(pixel * t, double(texel)));
  };
  double mean = 0.0;
  for (int ty = int(py * t); ty < texels && ty < (py + 1) * t; ++ty) {
    for (int tx = int(px * t); tx < texels && tx < (px + 1) * t; ++tx) {
      mean += overlap(px, tx) * overlap(py, ty) * srgb_decode(rgba[(ty * texels + tx) * 4 + c]);
    }
  }
  return mean / (t * t);
}

/// The exact box average of a LINEAR level-0 texture of `texels`^2 (REPEAT) on
/// quad_scene(size): the bilinear filter is the sum of texels times tents,
/// T_ij tent(s - i) tent(t - j) with s = u texels - 1/2, so over the pixel's box (separable)
/// its mean is sum_ij T_ij X_i Y_j with X_i the mean of tent(s - i) over the pixel's s range.
double exact_bilinear_pixel_mean(const std::vector<std::uint8_t>& rgba, int texels, int size,
                                 int px, int py, int c) {
  const double t = double(texels) / size;
  // The integral of the tent max(0, 1 - |x|) from -infinity to x.
  const auto tent_integral = [](double x) {
    if (x <= -1.0) return 0.0;
    if (x <= 0.0) return (1.0 + x) * (1.0 + x) / 2.0;
    if (x <= 1.0) return 1.0 - (1.0 - x) * (1.0 - x) / 2.0;
    return 1.0;
  };
  const auto weight = [&](int pixel, int texel) {
    const double lo = pixel * t - 0.5, hi = (pixel + 1) * t - 0.5;
    return (tent_integral(hi - texel) - tent_integral(lo - texel)) / t;
  };
  double mean = 0.0;
  for (int ty = int(std::floor(py * t - 0.5)); ty <= int(std::ceil((py + 1) * t - 0.5)); ++ty) {
    for (int tx = int(std::floor(px * t - 0.5)); tx <= int(std::ceil((px + 1) * t - 0.5)); ++tx) {
      const int i = (tx + texels) % texels, j = (ty + texels) % texels;
      mean += weight(px, tx) * weight(py, ty) * srgb_decode(rgba[(j * texels + i) * 4 + c]);
    }
  }
  return mean;
}

/// quad_scene(size) textured with `rgba` (texels x texels, sRGB), NEAREST on level 0 only.
covrast::Scene nearest_quad_scene(int size, int texels, const std::vector<std::uint8_t>& rgba) {
  return quad_scene(size, slot_of(covrast::make_texture("noise", texels, texels, rgba, true),
                                  covrast::TextureFilter::Nearest, covrast::TextureFilter::Nearest,
                                  covrast::MipFilter::None));
}

/// The largest |image - expected(px, py, c)| in 8-bit codes over the size x size pixels where
/// keep(px, py).
template <class Expected, class Keep>
int largest_difference(const covrast::Image& image, int size, const Expected& expected,
                       const Keep& keep) {
  int largest = 0;
  for (int py = 0; py < size; ++py) {
    for (int px = 0; px < size; ++px) {
      if (!keep(px, py)) continue;
      for (int c = 0; c < 3; ++c) {
        const int code = image.rgb[(std::size_t(py) * size + px) * 3 + c];
        largest = std::max(largest, std::abs(code - expected(px, py, c)));
      }
    }
  }
  return largest;
}

}  // namespace

TEST_CASE("textures: coverage mode's texture is the exact mean over the pixel", "[textures]") {
  // 64x64 random texels, level 0 only, on a quad of 48x48 pixels: each pixel spans 4/3
  // texels. NEAREST: one lookup per pixel (aliased, msaa) picks one texel where the pixel's
  // mean blends up to four. LINEAR: the bilinear filter bends at texel centres 3/4 of a pixel
  // apart, so its value at the pixel centre is not the pixel's mean. Coverage mode
  // integrates the filter over each triangle's part of the pixel
  // (raster/coverage/fragment_shading.hpp, texture/texture_sampling.hpp area_average): the exact
  // mean, on the quad's diagonal too.
  const int size = 48, texels = 64;
  for (const covrast::TextureFilter filter :
       {covrast::TextureFilter::Nearest, covrast::TextureFilter::Linear}) {
    const bool nearest = filter == covrast::TextureFilter::Nearest;
    INFO((nearest ? "NEAREST" : "LINEAR"));
    const auto rgba = random_rgba(texels, texels, nearest ? 11 : 17);
    const covrast::Scene scene =
        quad_scene(size, slot_of(covrast::make_texture("noise", texels, texels, rgba, true), filter,
                                 filter, covrast::MipFilter::None));
    const auto exact = [&](int px, int py, int c) {
      const double mean = nearest ? exact_pixel_mean(rgba, texels, size, px, py, c)
                                  : exact_bilinear_pixel_mean(rgba, texels, size, px, py, c);
      return int(std::lround(srgb_encode_255(mean)));
    };
    const auto every_pixel = [](int, int) { return true; };
    const int largest_coverage =
        largest_difference(render_mode(scene, "coverage"), size, exact, every_pixel);
    const int largest_aliased =
        largest_difference(render_mode(scene, "aliased"), size, exact, every_pixel);
    INFO("largest difference from the exact mean: coverage " << largest_coverage << ", aliased "
                                                             << largest_aliased);
    CHECK(largest_coverage <= 1);
    CHECK(largest_aliased > 40);  // the scene does test something
  }
}

namespace {

/// A 15x15 quad_scene textured with two NEAREST texels, white left, black right: their edge
/// runs down the middle of pixel column 7; plus `red`, drawn red.
constexpr int kHalvesSize = 15;
covrast::Scene halves_scene_with(const covrast::MeshArrays& red) {
  const std::vector<std::uint8_t> white_black = {255, 255, 255, 255, 0, 0, 0, 255};
  covrast::Scene scene =
      quad_scene(kHalvesSize, slot_of(covrast::make_texture("halves", 2, 1, white_black, true),
                                      covrast::TextureFilter::Nearest,
                                      covrast::TextureFilter::Nearest, covrast::MipFilter::None));
  covrast::add_instance(scene, covrast::make_mesh(red), {.color_srgb = glm::vec3(1, 0, 0)});
  return scene;
}

/// The largest channel difference in column 7 (rows `skip_from`..`skip_to` left out) from
/// (1, 1/2, 1/2) in linear light: the quad's white half beside the red half.
int column_7_difference(const covrast::Image& image, int skip_from, int skip_to) {
  const int half = int(std::lround(srgb_encode_255(0.5)));
  const int expected[3] = {255, half, half};
  int largest = 0;
  for (int py = 0; py < kHalvesSize; ++py) {
    if (py >= skip_from && py <= skip_to) continue;
    for (int c = 0; c < 3; ++c) {
      const int code = image.rgb[(std::size_t(py) * kHalvesSize + 7) * 3 + c];
      largest = std::max(largest, std::abs(code - expected[c]));
    }
  }
  return largest;
}

covrast::RenderResult render_coverage_with_stats(const covrast::Scene& scene) {
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode("coverage");
  return covrast::render(scene, options);
}

}  // namespace

TEST_CASE("textures: a partly hidden textured fragment shows the texture of its shown side",
          "[textures]") {
  // The white|black quad (halves_scene_with) and a red triangle nearer the eye that hides its
  // right half, its edge on the same line. In column 7 the reference sees the quad's white
  // half and the red half: (1, 1/2, 1/2) in linear light. The quad's mean over the whole
  // pixel is grey: weighed by its shown share it would give (3/4, 1/4, 1/4), 51 codes off in
  // green. The masked resolve moves the partly hidden fragment's colour towards its shown
  // side (raster/coverage/fragment_shading.hpp, shade_fragment_visible).
  const covrast::RenderResult result = render_coverage_with_stats(
      halves_scene_with({.name = "cover",
                         .positions = {{0, -2, 0.25f}, {2, 0, 0.25f}, {0, 2, 0.25f}},
                         .indices = {0, 1, 2}}));
  CHECK(result.stats.resolve_paths.masked >= std::uint64_t(kHalvesSize));  // column 7 at least
  const int largest = column_7_difference(result.color, -1, -1);
  INFO("largest difference in column 7 from (1, 1/2, 1/2): " << largest);
  CHECK(largest <= 2);
  // Left of it the quad's white, right of it the red triangle, exactly.
  CHECK(result.color.rgb[(7 * kHalvesSize + 6) * 3 + 1] == 255);
  CHECK(result.color.rgb[(7 * kHalvesSize + 8) * 3 + 1] == 0);
}

TEST_CASE("textures: where a plane crosses a textured surface in a pixel, each shows its side",
          "[textures]") {
  // The white|black quad and a red plane z = x / 4 that crosses it along the line of column
  // 7's middle: in front of it on the right, behind it on the left. Column 7 resolves by the
  // list's clipped path (one triangle whose plane crosses the opaque one in the pixel); the
  // reference sees white on the left half and red on the right: (1, 1/2, 1/2).
  const covrast::RenderResult result = render_coverage_with_stats(halves_scene_with(
      {.name = "plane",
       .positions =
           {{-1.5f, -3, -0.375f}, {1.5f, -3, 0.375f}, {1.5f, 3, 0.375f}, {-1.5f, 3, -0.375f}},
       .indices = {0, 1, 2, 0, 2, 3}}));
  // Column 7 but rows 6-8, where the plane's own diagonal crosses it.
  CHECK(result.stats.resolve_paths.clipped >= std::uint64_t(kHalvesSize - 3));
  const int largest = column_7_difference(result.color, 6, 8);
  INFO("largest difference in column 7 from (1, 1/2, 1/2): " << largest);
  CHECK(largest <= 2);
  CHECK(result.color.rgb[(2 * kHalvesSize + 6) * 3 + 1] == 255);  // the quad's white
  CHECK(result.color.rgb[(2 * kHalvesSize + 8) * 3 + 1] == 0);    // the red plane
}

TEST_CASE("textures: a NEAREST footprint over too many texels falls back to ssaa:4's points",
          "[textures]") {
  // 512x512 texels on 48x48 pixels, level 0 only: a pixel spans about 11 x 11 texels, more
  // than the exact mean visits, so coverage mode averages the lookups at ssaa:4's 16 sample
  // points in the triangle: ssaa:4's image off the quad's diagonal (on it, each triangle's
  // part is weighed by its exact area, not by its count of samples).
  const int size = 48, texels = 512;
  const auto rgba = random_rgba(texels, texels, 5);
  const covrast::Scene scene = nearest_quad_scene(size, texels, rgba);
  const covrast::Image ssaa = render_mode(scene, "ssaa:4");
  const auto ssaa_code = [&](int px, int py, int c) {
    return int(ssaa.rgb[(std::size_t(py) * size + px) * 3 + c]);
  };
  const auto off_diagonal = [&](int px, int py) { return std::abs(px + py - (size - 1)) > 1; };
  CHECK(largest_difference(render_mode(scene, "coverage"), size, ssaa_code, off_diagonal) <= 1);
  CHECK(largest_difference(render_mode(scene, "aliased"), size, ssaa_code, off_diagonal) > 50);
}

TEST_CASE("textures: area_average weighs NEAREST texels by their overlap areas", "[textures]") {
  // 4x4 texels, texel (i, j) grey (16 i + 64 j) / 255 in a linear texture.
  std::vector<std::uint8_t> rgba(4 * 4 * 4, 255);
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      for (int c = 0; c < 3; ++c) rgba[(j * 4 + i) * 4 + c] = std::uint8_t(16 * i + 64 * j);
    }
  }
  const auto texture = covrast::make_texture("ramp", 4, 4, rgba, false);
  covrast::TextureSampler sampler;
  sampler.mag = sampler.min = covrast::TextureFilter::Nearest;
  sampler.mip = covrast::MipFilter::None;
  const auto polygon = [](std::initializer_list<glm::dvec2> points) {
    covrast::detail::ConvexPolygon p;
    for (const glm::dvec2& q : points) p.add(q.x / 4.0, q.y / 4.0);  // texel units -> UV
    return p;
  };
  const auto grey = [&](const covrast::detail::ConvexPolygon& p) {
    const auto mean = covrast::detail::area_average(*texture, sampler, p, -1.0);
    REQUIRE(mean.has_value());
    return mean->r * 255.0;
  };
  // Inside texel (1, 2): its value.
  CHECK(grey(polygon({{1.2, 2.2}, {1.8, 2.2}, {1.8, 2.9}})) == Approx(16 + 128).margin(1e-9));
  // The square [0.5, 1.5] x [0, 1]: half of texel (0, 0), half of (1, 0).
  CHECK(grey(polygon({{0.5, 0.0}, {1.5, 0.0}, {1.5, 1.0}, {0.5, 1.0}})) ==
        Approx(8.0).margin(1e-9));
  // The triangle (0, 0), (2, 0), (0, 2): area 2, of which texel (0, 0) holds 1, (1, 0) and
  // (0, 1) a half each: (0 + 16 / 2 + 64 / 2) / 2 = 20.
  CHECK(grey(polygon({{0.0, 0.0}, {2.0, 0.0}, {0.0, 2.0}})) == Approx(20.0).margin(1e-9));
  // Across the REPEAT seam: [-0.5, 0.5] x [0, 1] is half texel (3, 0), half (0, 0).
  CHECK(grey(polygon({{-0.5, 0.0}, {0.5, 0.0}, {0.5, 1.0}, {-0.5, 1.0}})) ==
        Approx(24.0).margin(1e-9));
  // A footprint over more than 64 texel cells: declined.
  sampler.wrap_s = sampler.wrap_t = covrast::TextureWrap::Repeat;
  CHECK_FALSE(
      covrast::detail::area_average(*texture, sampler,
                                    polygon({{0.0, 0.0}, {9.0, 0.0}, {9.0, 9.0}, {0.0, 9.0}}), -1.0)
          .has_value());
  // No area: declined.
  CHECK_FALSE(covrast::detail::area_average(*texture, sampler,
                                            polygon({{0.0, 0.0}, {1.0, 1.0}, {2.0, 2.0}}), -1.0)
                  .has_value());
}

TEST_CASE("textures: area_average integrates the LINEAR filter exactly", "[textures]") {
  covrast::TextureSampler sampler;
  sampler.mag = sampler.min = covrast::TextureFilter::Linear;
  sampler.mip = covrast::MipFilter::None;
  // Polygons given in s, t = texel coordinates - 1/2 (texel centres at integers).
  const auto polygon = [](std::initializer_list<glm::dvec2> points) {
    covrast::detail::ConvexPolygon p;
    for (const glm::dvec2& q : points) p.add((q.x + 0.5) / 4.0, (q.y + 0.5) / 4.0);
    return p;
  };
  const auto mean_of = [&](const std::shared_ptr<const covrast::Texture>& texture,
                           const covrast::detail::ConvexPolygon& p) {
    const auto mean = covrast::detail::area_average(*texture, sampler, p, -1.0);
    REQUIRE(mean.has_value());
    return mean->r;
  };
  SECTION("a linear ramp: the filter is linear between the centres, its mean the centroid's") {
    // Texel (i, j) grey (16 i + 64 j) / 255 in a linear texture; f = (16 s + 64 t) / 255 on
    // [0, 3]^2.
    std::vector<std::uint8_t> rgba(4 * 4 * 4, 255);
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 4; ++i) {
        for (int c = 0; c < 3; ++c) rgba[(j * 4 + i) * 4 + c] = std::uint8_t(16 * i + 64 * j);
      }
    }
    const auto ramp = covrast::make_texture("ramp", 4, 4, rgba, false);
    // A triangle over six cells, centroid (1.5, 1.2): 16 x 1.5 + 64 x 1.2 = 100.8.
    CHECK(mean_of(ramp, polygon({{0.2, 0.3}, {2.9, 0.6}, {1.4, 2.7}})) * 255.0 ==
          Approx(100.8).margin(1e-9));
    // A square inside one cell, centred on (0.5, 2.5): 8 + 160 = 168.
    CHECK(mean_of(ramp, polygon({{0.25, 2.25}, {0.75, 2.25}, {0.75, 2.75}, {0.25, 2.75}})) *
              255.0 ==
          Approx(168.0).margin(1e-9));
  }
  SECTION("one white texel: its tent tent(s - 1) tent(t - 1) integrated") {
    std::vector<std::uint8_t> rgba(4 * 4 * 4, 0);
    for (int c = 0; c < 4; ++c) rgba[(1 * 4 + 1) * 4 + c] = 255;
    const auto spot = covrast::make_texture("spot", 4, 4, rgba, false);
    // [0, 2]^2 holds the whole tent (integral 1) in area 4.
    CHECK(mean_of(spot, polygon({{0, 0}, {2, 0}, {2, 2}, {0, 2}})) == Approx(0.25).margin(1e-12));
    // [1, 2]^2: (1/2)(1/2) in area 1.
    CHECK(mean_of(spot, polygon({{1, 1}, {2, 1}, {2, 2}, {1, 2}})) == Approx(0.25).margin(1e-12));
    // The triangle (1, 1), (2, 1), (1, 2): the integral of (1 - a)(1 - b) over a + b <= 1 is
    // 1/3 - 1/8 = 5/24, in area 1/2.
    CHECK(mean_of(spot, polygon({{1, 1}, {2, 1}, {1, 2}})) == Approx(5.0 / 12.0).margin(1e-12));
    // The same triangle clockwise: the orientation cancels.
    CHECK(mean_of(spot, polygon({{1, 1}, {1, 2}, {2, 1}})) == Approx(5.0 / 12.0).margin(1e-12));
    // Across the REPEAT seam: [-1, 0] x [0, 1] sees texel (3, .) and (0, .), not the spot.
    CHECK(mean_of(spot, polygon({{-1, 0}, {0, 0}, {0, 1}, {-1, 1}})) == Approx(0.0).margin(1e-12));
    // Shifted by the period, the spot's square [1, 2]^2 again.
    CHECK(mean_of(spot, polygon({{5, 5}, {6, 5}, {6, 6}, {5, 6}})) == Approx(0.25).margin(1e-12));
  }
}
