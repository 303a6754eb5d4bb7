// Tests of the FXAA row kernels (src/post/fxaa_kernel.hpp): on every Highway target compiled
// and supported here, the SIMD kernels give the scalar twins' luma bits and output bytes, on
// generated images: step edges at many angles, discs and polygons touching the borders, thin
// lines and dots (also on the border rows and columns), stripes whose edges end within the
// search, flat areas, noise of every amplitude and noise near the contrast thresholds; at
// widths around the vector and chunk sizes, and with other options and presets.
#include "post/fxaa.hpp"

#include <catch2/catch.hpp>

#include "test_targets.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using covrast::FxaaOptions;
using covrast::Image;

namespace {

using Rgb = std::array<std::uint8_t, 3>;

struct NamedImage {
  std::string name;
  Image image;
};

Image blank(int width, int height, Rgb colour) {
  Image image{width, height, std::vector<std::uint8_t>(std::size_t(width) * height * 3), {}};
  for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = colour[i % 3];
  return image;
}

void put(Image& image, int x, int y, Rgb colour) {
  std::uint8_t* p = image.pixel(x, y);
  p[0] = colour[0];
  p[1] = colour[1];
  p[2] = colour[2];
}

Rgb random_colour(std::mt19937& rng) {
  std::uniform_int_distribution<int> byte(0, 255);
  return {std::uint8_t(byte(rng)), std::uint8_t(byte(rng)), std::uint8_t(byte(rng))};
}

/// The generated images; every side from 1 to a few hundred pixels.
std::vector<NamedImage> generated_images() {
  std::mt19937 rng(0xf0aa5u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<NamedImage> images;

  // Step edges between two colours at angles 0..180 degrees in 5-degree steps, through a
  // random point; odd sizes, so vectors end inside the rows.
  for (int k = 0; k < 36; ++k) {
    const double angle = k * 3.14159265358979323846 / 36.0;
    const int width = 37 + 7 * (k % 5), height = 29 + 5 * (k % 3);
    const Rgb a = random_colour(rng), b = random_colour(rng);
    Image image = blank(width, height, a);
    const double cx = width * unit(rng), cy = height * unit(rng);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const double d = (x + 0.5 - cx) * std::sin(angle) - (y + 0.5 - cy) * std::cos(angle);
        if (d > 0) put(image, x, y, b);
      }
    }
    images.push_back({"edge at " + std::to_string(5 * k) + " degrees", std::move(image)});
  }

  // Discs and triangles of random colours over a background, some cut by the borders; one
  // image wider than the filter's 256-pixel chunks.
  for (const auto& [width, height] : std::vector<std::pair<int, int>>{{97, 61}, {300, 40}}) {
    Image image = blank(width, height, random_colour(rng));
    for (int shape = 0; shape < 24; ++shape) {
      const Rgb colour = random_colour(rng);
      const double cx = width * unit(rng), cy = height * unit(rng);
      const double r = 3.0 + 20.0 * unit(rng);
      const double a0 = 6.3 * unit(rng);
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
          bool inside = dx * dx + dy * dy < r * r;
          if (shape % 2 == 1) {
            // A triangle inscribed in the circle: inside all three edges.
            inside = true;
            for (int e = 0; e < 3; ++e) {
              const double p0 = a0 + e * 2.0944, p1 = p0 + 2.0944;
              const double ex = r * (std::cos(p1) - std::cos(p0));
              const double ey = r * (std::sin(p1) - std::sin(p0));
              inside = inside && ex * (dy - r * std::sin(p0)) - ey * (dx - r * std::cos(p0)) > 0;
            }
          }
          if (inside) put(image, x, y, colour);
        }
      }
    }
    images.push_back(
        {"shapes " + std::to_string(width) + "x" + std::to_string(height), std::move(image)});
  }

  // Thin lines and dots on a flat background, also on the first and last rows and columns.
  {
    const int width = 45, height = 33;
    const Rgb bg{20, 30, 40}, fg{240, 230, 200};
    Image image = blank(width, height, bg);
    for (int x = 0; x < width; ++x) {
      put(image, x, 0, fg);
      put(image, x, 17, fg);
    }
    for (int y = 0; y < height; ++y) {
      put(image, width - 1, y, fg);
      put(image, 9, y, fg);
    }
    for (int i = 0; i < 30; ++i) put(image, 20 + i % 20, 3 + (i * 7) % 28, fg);  // dots
    put(image, 0, height - 1, fg);
    for (int x = 22; x < width; ++x) put(image, x, 5 + (x - 22) / 3, fg);  // a shallow line
    images.push_back({"lines and dots", std::move(image)});
  }

  // Stripes: edges that end within the search's reach, both ways.
  {
    const int width = 71, height = 47;
    Image image = blank(width, height, {200, 200, 200});
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        if ((x / 3 + y / 5) % 2 == 0 && x % 23 < 17) put(image, x, y, {10, 60, 30});
      }
    }
    images.push_back({"stripes", std::move(image)});
  }

  // Flat, and flat but for one pixel in a corner.
  images.push_back({"flat", blank(33, 9, {90, 120, 150})});
  {
    Image image = blank(19, 7, {90, 120, 150});
    put(image, 18, 6, {0, 0, 0});
    images.push_back({"flat, one corner pixel", std::move(image)});
  }

  // Noise: every byte random, and small noise around a grey (ranges near the thresholds).
  {
    Image image = blank(83, 41, {0, 0, 0});
    for (std::uint8_t& b : image.rgb) b = std::uint8_t(rng() & 0xff);
    images.push_back({"noise", std::move(image)});
  }
  for (const int amplitude : {10, 24, 40}) {
    Image image = blank(66, 35, {0, 0, 0});
    std::uniform_int_distribution<int> delta(-amplitude, amplitude);
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        const int grey = 40 + 3 * x + delta(rng);
        const std::uint8_t v = std::uint8_t(std::clamp(grey, 0, 255));
        put(image, x, y, {v, v, v});
      }
    }
    images.push_back({"low noise +-" + std::to_string(amplitude), std::move(image)});
  }

  // Tiny and one-row or one-column frames.
  for (const auto& [width, height] :
       std::vector<std::pair<int, int>>{{1, 1}, {2, 1}, {1, 5}, {3, 2}, {17, 1}, {1, 33}}) {
    Image image = blank(width, height, {0, 0, 0});
    for (std::uint8_t& b : image.rgb) b = std::uint8_t(rng() & 0xff);
    images.push_back(
        {"tiny " + std::to_string(width) + "x" + std::to_string(height), std::move(image)});
  }
  return images;
}

/// The option sets compared: FXAA's defaults, and thresholds, sub-pixel shares and presets
/// that exercise other branches (every cross passes, no sub-pixel weight, the longest and
/// shortest searches).
std::vector<std::pair<std::string, FxaaOptions>> option_sets() {
  std::vector<std::pair<std::string, FxaaOptions>> sets;
  sets.emplace_back("defaults", FxaaOptions{});
  FxaaOptions o;
  o.edge_threshold = 0.0f;
  o.edge_threshold_min = 0.0f;
  o.subpix = 1.0f;
  o.quality_preset = 39;
  sets.emplace_back("thresholds 0, subpix 1, preset 39", o);
  o = FxaaOptions{};
  o.subpix = 0.0f;
  o.quality_preset = 10;
  sets.emplace_back("subpix 0, preset 10", o);
  o = FxaaOptions{};
  o.edge_threshold = 0.3f;
  o.quality_preset = 29;
  sets.emplace_back("threshold 0.3, preset 29", o);
  return sets;
}

/// "" when equal, else where the first difference is.
std::string first_difference(const Image& a, const Image& b) {
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      if (std::memcmp(a.pixel(x, y), b.pixel(x, y), 3) != 0) {
        std::ostringstream s;
        s << "first difference at pixel (" << x << ", " << y << "): " << int(a.pixel(x, y)[0])
          << " " << int(a.pixel(x, y)[1]) << " " << int(a.pixel(x, y)[2]) << " vs "
          << int(b.pixel(x, y)[0]) << " " << int(b.pixel(x, y)[1]) << " " << int(b.pixel(x, y)[2]);
        return s.str();
      }
    }
  }
  return "";
}

}  // namespace

TEST_CASE("fxaa kernels: every SIMD target gives the scalar twin's luma bits", "[fxaa]") {
  std::mt19937 rng(0x1a3au);
  std::vector<std::uint8_t> rgb(3 * 300);
  for (std::uint8_t& b : rgb) b = std::uint8_t(rng() & 0xff);
  // The extremes: black and white, and the largest byte in each channel.
  const std::array<std::uint8_t, 15> extremes{0, 0, 0,   255, 255, 255, 255, 0,
                                              0, 0, 255, 0,   0,   0,   255};
  std::copy(extremes.begin(), extremes.end(), rgb.begin());
  const auto scalar = covrast::detail::fxaa_kernels_scalar();
  int targets = 0;
  covrast::test::for_each_target([&](std::int64_t) {
    const auto simd = covrast::detail::fxaa_kernels_simd();
    // Every width up to 300, so that every vector length ends every way inside a row.
    int wrong_widths = 0;
    for (int width = 1; width <= 300; ++width) {
      std::vector<float> expected(std::size_t(width) + 1, -1.0f), got = expected;
      scalar.luma_row(rgb.data(), width, expected.data());
      simd.luma_row(rgb.data(), width, got.data());
      if (std::memcmp(expected.data(), got.data(), sizeof(float) * expected.size()) != 0) {
        ++wrong_widths;
        UNSCOPED_INFO("width " << width << " differs (or wrote past the row)");
      }
    }
    CHECK(wrong_widths == 0);
    ++targets;
  });
  CHECK(targets >= 1);
}

TEST_CASE("fxaa kernels: every SIMD target gives the scalar twin's bytes", "[fxaa]") {
  const std::vector<NamedImage> images = generated_images();
  const auto options = option_sets();
  const auto scalar = covrast::detail::fxaa_kernels_scalar();
  // The scalar outputs, and a check that the comparisons are not between untouched copies.
  std::vector<std::vector<Image>> expected(options.size());
  std::size_t changed_images = 0;
  for (std::size_t o = 0; o < options.size(); ++o) {
    for (const NamedImage& n : images) {
      expected[o].push_back(covrast::detail::fxaa(n.image, options[o].second, scalar));
      changed_images += expected[o].back().rgb != n.image.rgb;
    }
  }
  CHECK(changed_images > 2 * images.size());
  int targets = 0;
  covrast::test::for_each_target([&](std::int64_t) {
    const auto simd = covrast::detail::fxaa_kernels_simd();
    for (std::size_t o = 0; o < options.size(); ++o) {
      for (std::size_t i = 0; i < images.size(); ++i) {
        const Image got = covrast::detail::fxaa(images[i].image, options[o].second, simd);
        INFO("image '" << images[i].name << "', options " << options[o].first << ": "
                       << first_difference(got, expected[o][i]));
        CHECK(got.rgb == expected[o][i].rgb);
      }
    }
    // The filter carries candidates over from row to row within a call: bands of 1 to 3
    // rows (as threads split a frame) give the same bytes.
    for (std::size_t i = 0; i < images.size(); ++i) {
      const Image& in = images[i].image;
      covrast::detail::LumaPlane luma{in.width, in.height,
                                      std::vector<float>(std::size_t(in.width) * in.height)};
      covrast::detail::fxaa_luma_rows(in, luma, 0, in.height, simd);
      Image banded = in;
      for (int y = 0, band = 1; y < in.height; y += band, band = band % 3 + 1) {
        covrast::detail::fxaa_rows(in, luma, options[0].second, banded, y,
                                   std::min(y + band, in.height), simd);
      }
      INFO("image '" << images[i].name
                     << "' in bands: " << first_difference(banded, expected[0][i]));
      CHECK(banded.rgb == expected[0][i].rgb);
    }
    ++targets;
  });
  CHECK(targets >= 1);
}
