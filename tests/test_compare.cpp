// Tests of the image comparison (include/covrast/compare.hpp) on small synthetic images
// whose metrics are known exactly or computed independently here from the sRGB formula.
#include <covrast/compare.hpp>
#include <covrast/error.hpp>
#include <covrast/image.hpp>
#include <covrast/tools.hpp>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <string>
#include <utility>

#include "test_tempdir.hpp"

namespace {

using covrast::CompareResult;
using covrast::Image;

Image make_image(int width_px, int height_px, std::array<std::uint8_t, 3> colour) {
  Image image;
  image.width = width_px;
  image.height = height_px;
  image.rgb.resize(std::size_t(width_px) * std::size_t(height_px) * 3);
  for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = colour[i % 3];
  return image;
}

// IEC 61966-2-1 decoding, written out independently of the implementation's table.
double srgb_to_linear(int code) {
  const double c = code / 255.0;
  if (c <= 0.04045) return c / 12.92;
  return std::pow((c + 0.055) / 1.055, 2.4);
}

std::array<std::uint8_t, 3> heat_at(const Image& heatmap, int x, int y) {
  const std::uint8_t* p = heatmap.pixel(x, y);
  return {p[0], p[1], p[2]};
}

}  // namespace

TEST_CASE("identical images compare as equal", "[compare]") {
  const Image a = make_image(5, 4, {12, 200, 77});
  const CompareResult r = covrast::compare_images(a, a);
  CHECK(r.width == 5);
  CHECK(r.height == 4);
  CHECK(r.rmse_linear == 0.0);
  CHECK(std::isinf(r.psnr_db));
  CHECK(r.psnr_db > 0);
  CHECK(r.max_diff_srgb8 == 0);
  CHECK(r.pixels_over_1 == 0);
  CHECK(r.pixels_over_8 == 0);
  CHECK(r.share_over_1 == 0.0);
  CHECK(r.share_over_8 == 0.0);
}

TEST_CASE("a single pixel off by 1, 2 or 9 units is counted exactly", "[compare]") {
  struct Case {
    int delta;  // signed change of one channel of one pixel
    std::size_t over_1;
    std::size_t over_8;
  };
  // Thresholds are "more than 1" (>= 2) and "more than 8" (>= 9); negative deltas check |a-b|.
  const Case cases[] = {{1, 0, 0},  {2, 1, 0},  {8, 1, 0},  {9, 1, 1},
                        {-1, 0, 0}, {-2, 1, 0}, {-9, 1, 1}, {0, 0, 0}};
  for (const Case& c : cases) {
    for (int channel = 0; channel < 3; ++channel) {
      INFO("delta " << c.delta << " channel " << channel);
      const Image a = make_image(4, 3, {128, 128, 128});
      Image b = a;
      b.pixel(2, 1)[channel] = std::uint8_t(128 + c.delta);
      const CompareResult r = covrast::compare_images(a, b);
      CHECK(r.max_diff_srgb8 == std::abs(c.delta));
      CHECK(r.pixels_over_1 == c.over_1);
      CHECK(r.pixels_over_8 == c.over_8);
      CHECK(r.share_over_1 == double(c.over_1) / 12.0);
      CHECK(r.share_over_8 == double(c.over_8) / 12.0);
      // One channel of 36 differs: rmse = |lin(128 + delta) - lin(128)| / 6.
      const double expected_rmse =
          std::abs(srgb_to_linear(128 + c.delta) - srgb_to_linear(128)) / 6.0;
      CHECK(r.rmse_linear == Approx(expected_rmse).epsilon(1e-12));
      CHECK((c.delta == 0) == std::isinf(r.psnr_db));
    }
  }
}

TEST_CASE("rmse over all channels matches the sRGB formula", "[compare]") {
  // Two pixel patterns in a checkerboard; every channel differs, including the linear
  // segment of the transfer function (codes <= 10) and both extremes (0 and 255).
  const std::array<std::array<std::uint8_t, 3>, 2> a_colours = {{{10, 100, 200}, {0, 64, 250}}};
  const std::array<std::array<std::uint8_t, 3>, 2> b_colours = {{{3, 130, 255}, {7, 60, 190}}};
  const int width_px = 6;
  const int height_px = 5;
  Image a = make_image(width_px, height_px, {0, 0, 0});
  Image b = a;
  double sum_squared = 0;
  int max_diff = 0;
  for (int y = 0; y < height_px; ++y) {
    for (int x = 0; x < width_px; ++x) {
      const std::size_t pattern = std::size_t((x + y) % 2);
      for (int ch = 0; ch < 3; ++ch) {
        const int ca = a_colours[pattern][std::size_t(ch)];
        const int cb = b_colours[pattern][std::size_t(ch)];
        a.pixel(x, y)[ch] = std::uint8_t(ca);
        b.pixel(x, y)[ch] = std::uint8_t(cb);
        const double diff = srgb_to_linear(ca) - srgb_to_linear(cb);
        sum_squared += diff * diff;
        max_diff = std::max(max_diff, std::abs(ca - cb));
      }
    }
  }
  const double expected_rmse = std::sqrt(sum_squared / (width_px * height_px * 3));
  const CompareResult r = covrast::compare_images(a, b);
  CHECK(max_diff == 60);
  CHECK(r.max_diff_srgb8 == 60);
  CHECK(r.rmse_linear == Approx(expected_rmse).epsilon(1e-12));
  CHECK(r.psnr_db == Approx(20.0 * std::log10(1.0 / expected_rmse)).epsilon(1e-12));
  // Pattern 0 differs by at most 55, pattern 1 by at most 60: every pixel is over 8.
  CHECK(r.pixels_over_1 == 30);
  CHECK(r.pixels_over_8 == 30);
  CHECK(r.share_over_1 == 1.0);
  CHECK(r.share_over_8 == 1.0);
  // The comparison is symmetric.
  const CompareResult swapped = covrast::compare_images(b, a);
  CHECK(swapped.rmse_linear == r.rmse_linear);
  CHECK(swapped.max_diff_srgb8 == r.max_diff_srgb8);
}

TEST_CASE("black against white has rmse 1 and psnr 0", "[compare]") {
  const Image black = make_image(3, 2, {0, 0, 0});
  const Image white = make_image(3, 2, {255, 255, 255});
  const CompareResult r = covrast::compare_images(black, white);
  // lin(0) = 0 and lin(255) = ((1 + 0.055) / 1.055)^2.4 = 1 exactly in double.
  CHECK(r.rmse_linear == 1.0);
  CHECK(r.psnr_db == 0.0);
  CHECK(r.max_diff_srgb8 == 255);
  CHECK(r.pixels_over_8 == 6);
  CHECK(r.share_over_8 == 1.0);
}

TEST_CASE("comparing images of different sizes throws InputError", "[compare]") {
  const Image a = make_image(4, 3, {0, 0, 0});
  const Image b = make_image(3, 4, {0, 0, 0});
  CHECK_THROWS_MATCHES(covrast::compare_images(a, b), covrast::InputError,
                       Catch::Matchers::Message("image sizes differ: 4x3 vs 3x4"));
  CHECK_THROWS_AS(covrast::difference_heatmap(a, b), covrast::InputError);
  // A buffer that does not match the declared size is rejected instead of read past its end.
  Image short_buffer = a;
  short_buffer.rgb.pop_back();
  CHECK_THROWS_AS(covrast::compare_images(a, short_buffer), covrast::InputError);
}

TEST_CASE("difference heatmap follows the black-blue-green-yellow-red ramp", "[compare]") {
  SECTION("equal images give an all-black map of the same size") {
    const Image a = make_image(7, 3, {90, 10, 250});
    const Image heatmap = covrast::difference_heatmap(a, a);
    CHECK(heatmap.width == 7);
    CHECK(heatmap.height == 3);
    REQUIRE(heatmap.rgb.size() == a.rgb.size());
    for (std::uint8_t value : heatmap.rgb) CHECK(value == 0);
  }
  SECTION("the ramp stops and saturation") {
    // Pixel x of row 0 differs by d = expected[x].first in its green channel only.
    const std::pair<int, std::array<std::uint8_t, 3>> expected[] = {
        {0, {0, 0, 0}},    {4, {0, 0, 128}},    {8, {0, 0, 255}},    {12, {0, 128, 128}},
        {16, {0, 255, 0}}, {20, {128, 255, 0}}, {24, {255, 255, 0}}, {28, {255, 128, 0}},
        {32, {255, 0, 0}}, {33, {255, 0, 0}},   {200, {255, 0, 0}},  {1, {0, 0, 32}}};
    const int width_px = int(std::size(expected));
    const Image a = make_image(width_px, 2, {0, 0, 0});
    Image b = a;
    for (int x = 0; x < width_px; ++x) b.pixel(x, 0)[1] = std::uint8_t(expected[x].first);
    const Image heatmap = covrast::difference_heatmap(a, b);
    for (int x = 0; x < width_px; ++x) {
      INFO("d = " << expected[x].first);
      CHECK(heat_at(heatmap, x, 0) == expected[x].second);
      CHECK(heat_at(heatmap, x, 1) == std::array<std::uint8_t, 3>{0, 0, 0});
    }
  }
  SECTION("d is the largest channel difference, in either direction") {
    const Image a = make_image(1, 1, {100, 100, 100});
    Image b = a;
    b.rgb = {99, 140, 98};  // channel diffs 1, 40, 2 -> d = 40 >= 32
    CHECK(heat_at(covrast::difference_heatmap(a, b), 0, 0) ==
          std::array<std::uint8_t, 3>{255, 0, 0});
    CHECK(heat_at(covrast::difference_heatmap(b, a), 0, 0) ==
          std::array<std::uint8_t, 3>{255, 0, 0});
  }
}

TEST_CASE("to_json is one line that parses back to the result", "[compare]") {
  SECTION("identical images: psnr_db is null") {
    const Image a = make_image(4, 2, {1, 2, 3});
    const std::string text = covrast::to_json(covrast::compare_images(a, a));
    CHECK(text.find('\n') == std::string::npos);
    const nlohmann::json json = nlohmann::json::parse(text);
    CHECK(json.size() == 9);
    CHECK(json.at("width") == 4);
    CHECK(json.at("height") == 2);
    CHECK(json.at("rmse_linear").get<double>() == 0.0);
    CHECK(json.at("psnr_db").is_null());
    CHECK(json.at("max_diff_srgb8") == 0);
    CHECK(json.at("share_over_1").get<double>() == 0.0);
    CHECK(json.at("share_over_8").get<double>() == 0.0);
    CHECK(json.at("pixels_over_1") == 0);
    CHECK(json.at("pixels_over_8") == 0);
  }
  SECTION("different images: every number round-trips exactly") {
    const Image a = make_image(4, 2, {1, 2, 3});
    Image b = a;
    b.pixel(0, 0)[0] = 50;  // d = 49
    b.pixel(3, 1)[2] = 8;   // d = 5
    const CompareResult r = covrast::compare_images(a, b);
    const std::string text = covrast::to_json(r);
    CHECK(text.find('\n') == std::string::npos);
    const nlohmann::json json = nlohmann::json::parse(text);
    CHECK(json.size() == 9);
    CHECK(json.at("width") == 4);
    CHECK(json.at("height") == 2);
    CHECK(json.at("rmse_linear").get<double>() == r.rmse_linear);
    REQUIRE(json.at("psnr_db").is_number());
    CHECK(json.at("psnr_db").get<double>() == r.psnr_db);
    CHECK(json.at("max_diff_srgb8") == 49);
    CHECK(json.at("pixels_over_1") == 2);
    CHECK(json.at("pixels_over_8") == 1);
    CHECK(json.at("share_over_1").get<double>() == 0.25);
    CHECK(json.at("share_over_8").get<double>() == 0.125);
  }
}

TEST_CASE("compare: alpha is a fourth channel when either image has it, and PNGs keep it",
          "[compare]") {
  Image a = make_image(4, 2, {10, 20, 30});
  Image b = a;
  a.alpha.assign(8, 255);
  b.alpha.assign(8, 255);
  b.alpha[5] = 200;  // colours equal, one alpha 55 lower
  const CompareResult r = covrast::compare_images(a, b);
  CHECK(r.max_diff_srgb8 == 55);
  CHECK(r.pixels_over_8 == 1);
  // Four channels of eight pixels, one off by 55/255 in linear units.
  CHECK(r.rmse_linear == Approx(std::sqrt((55.0 / 255.0) * (55.0 / 255.0) / 32.0)));
  // An image without alpha compares as opaque.
  Image opaque = make_image(4, 2, {10, 20, 30});
  CHECK(covrast::compare_images(opaque, a).max_diff_srgb8 == 0);
  CHECK(covrast::compare_images(opaque, b).max_diff_srgb8 == 55);
  // RGB images compare over three channels, as before.
  CHECK(covrast::compare_images(opaque, opaque).rmse_linear == 0.0);
  // A PNG written with alpha reads back with it (RGBA), one without it without.
  const covrast::test::TempDir dir("covrast-compare");
  const std::filesystem::path with = dir / "alpha.png";
  const std::filesystem::path without = dir / "opaque.png";
  covrast::write_png(b, with);
  covrast::write_png(opaque, without);
  const Image back = covrast::read_png(with);
  CHECK(back.rgb == b.rgb);
  CHECK(back.alpha == b.alpha);
  CHECK(covrast::read_png(without).alpha.empty());
}
