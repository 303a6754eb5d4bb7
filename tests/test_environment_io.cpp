// Environment map files (src/image/environment_io.cpp, docs/environments.md): Radiance .hdr
// written by the test (flat and run-length), OpenEXR written with libopenexr, PNG; exact texel
// values, orientation, and one-line errors for broken files.
#include <covrast/environment.hpp>
#include <covrast/error.hpp>
#include <covrast/image.hpp>

#include "color/srgb.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#if COVRAST_HAS_OPENEXR
#include <OpenEXR/ImfArray.h>
#include <OpenEXR/ImfRgbaFile.h>
#endif

#include "test_tempdir.hpp"

using Catch::Matchers::Contains;
using covrast::EnvironmentMap;
using covrast::InputError;
using covrast::load_environment;
using covrast::test::TempDir;

namespace {

using Rgbe = std::array<std::uint8_t, 4>;

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string hdr_header(int width, int height) {
  return "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n-Y " + std::to_string(height) +
         " +X " + std::to_string(width) + "\n";
}

/// A flat .hdr: 4 bytes a texel, rows from the top.
std::string flat_hdr(int width, int height, const std::vector<Rgbe>& texels) {
  std::string out = hdr_header(width, height);
  for (const Rgbe& t : texels) out.append(reinterpret_cast<const char*>(t.data()), 4);
  return out;
}

/// A run-length .hdr (new form): each component of a row as runs of equal bytes (count > 128)
/// where two or more repeat, literal runs otherwise.
std::string rle_hdr(int width, int height, const std::vector<Rgbe>& texels) {
  std::string out = hdr_header(width, height);
  for (int y = 0; y < height; ++y) {
    out += char(2);
    out += char(2);
    out += char(width >> 8);
    out += char(width & 0xFF);
    for (int c = 0; c < 4; ++c) {
      int x = 0;
      while (x < width) {
        const std::uint8_t v = texels[std::size_t(y * width + x)][std::size_t(c)];
        int run = 1;
        while (x + run < width && run < 127 &&
               texels[std::size_t(y * width + x + run)][std::size_t(c)] == v) {
          ++run;
        }
        if (run >= 2) {
          out += char(128 + run);
          out += char(v);
          x += run;
        } else {
          out += char(1);
          out += char(v);
          x += 1;
        }
      }
    }
  }
  return out;
}

/// (c + 0.5) 2^(e - 136), the decode the files must give.
float rgbe_value(std::uint8_t c, std::uint8_t e) {
  return e == 0 ? 0.0f : float((c + 0.5) * std::ldexp(1.0, int(e) - 136));
}

std::vector<Rgbe> test_texels(int width, int height) {
  std::vector<Rgbe> texels;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      // Long runs (a constant exponent, a slow ramp) and literal stretches.
      texels.push_back({std::uint8_t(x * 7 + y), std::uint8_t(x / 4 * 16), std::uint8_t(200),
                        std::uint8_t(x % 5 == 0 ? 0 : 128 + y % 3)});
    }
  }
  return texels;
}

void check_texels(const EnvironmentMap& map, int width, int height,
                  const std::vector<Rgbe>& texels) {
  REQUIRE(map.width == width);
  REQUIRE(map.height == height);
  for (int i = 0; i < width * height; ++i) {
    const Rgbe& t = texels[std::size_t(i)];
    INFO("texel " << i);
    CHECK(map.radiance_linear[std::size_t(i)].r == rgbe_value(t[0], t[3]));
    CHECK(map.radiance_linear[std::size_t(i)].g == rgbe_value(t[1], t[3]));
    CHECK(map.radiance_linear[std::size_t(i)].b == rgbe_value(t[2], t[3]));
  }
}

}  // namespace

TEST_CASE("environment files: Radiance .hdr, flat and run-length, decode exactly",
          "[environment][io]") {
  TempDir dir;
  const int w = 40, h = 6;
  const std::vector<Rgbe> texels = test_texels(w, h);
  write_bytes(dir / "flat.hdr", flat_hdr(w, h, texels));
  write_bytes(dir / "rle.hdr", rle_hdr(w, h, texels));
  check_texels(load_environment(dir / "flat.hdr"), w, h, texels);
  check_texels(load_environment(dir / "rle.hdr"), w, h, texels);
  // The known value of one texel: (128.5, 64.5, 32.5) / 128 for exponent 129.
  write_bytes(dir / "one.hdr", flat_hdr(1, 1, {Rgbe{128, 64, 32, 129}}));
  const EnvironmentMap one = load_environment(dir / "one.hdr");
  CHECK(one.radiance_linear[0] == glm::vec3(1.00390625f, 0.50390625f, 0.25390625f));
  // The old run-length form: 1 1 1 n repeats the previous texel n times.
  std::string old = hdr_header(5, 1);
  old += std::string("\x10\x20\x30\x80", 4) + std::string("\x01\x01\x01\x04", 4);
  write_bytes(dir / "old.hdr", old);
  const EnvironmentMap repeated = load_environment(dir / "old.hdr");
  for (const glm::vec3& t : repeated.radiance_linear) CHECK(t == repeated.radiance_linear[0]);
}

TEST_CASE("environment files: broken .hdr files are one-line errors naming the file",
          "[environment][io]") {
  TempDir dir;
  const int w = 16, h = 4;
  const std::string good = rle_hdr(w, h, test_texels(w, h));
  const auto error_of = [&](const std::string& name, const std::string& bytes) {
    write_bytes(dir / name, bytes);
    try {
      load_environment(dir / name);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK_THAT(error_of("cut.hdr", good.substr(0, good.size() - 9)),
             Contains("cut.hdr: cannot decode environment: truncated at row 3"));
  CHECK_THAT(error_of("magic.hdr", "#?NOPE\n\n-Y 1 +X 1\n1234"),
             Contains("magic.hdr: cannot decode environment: not a Radiance file"));
  CHECK_THAT(error_of("huge.hdr", hdr_header(100000, 2)), Contains("over the limit of 16384"));
  CHECK_THAT(error_of("many.hdr", hdr_header(16384, 16384)),
             Contains("over the limit of 33554432 texels"));
  CHECK_THAT(error_of("flip.hdr", "#?RADIANCE\n\n+Y 1 -X 1\n1234"), Contains("only -Y H +X W"));
  CHECK_THAT(error_of("xyze.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n1234"),
             Contains("format 32-bit_rle_xyze"));
  std::string long_run = hdr_header(8, 1) + std::string("\x02\x02\x00\x08", 4) + "\xff\x01";
  CHECK_THAT(error_of("run.hdr", long_run), Contains("a run past the end of row 0"));
  CHECK_THAT(error_of("text.hdr", "hello"), Contains("not Radiance .hdr, OpenEXR, PNG or JPEG"));
  CHECK_THAT(error_of("empty.hdr", ""), Contains("empty"));
  std::filesystem::create_directory(dir / "folder.hdr");
  try {
    load_environment(dir / "folder.hdr");
    FAIL("a directory loaded");
  } catch (const InputError& e) {
    CHECK_THAT(std::string(e.what()),
               Contains("folder.hdr: cannot read environment: Is a directory"));
  }
}

TEST_CASE("environment files: a PNG is sRGB, decoded exactly to linear", "[environment][io]") {
  TempDir dir;
  covrast::Image image;
  image.width = 4;
  image.height = 2;
  for (int i = 0; i < 24; ++i) image.rgb.push_back(std::uint8_t(i * 11));
  covrast::write_png(image, dir / "env.png");
  const EnvironmentMap map = load_environment(dir / "env.png");
  REQUIRE(map.width == 4);
  REQUIRE(map.height == 2);
  for (int i = 0; i < 8; ++i) {
    for (int c = 0; c < 3; ++c) {
      CHECK(map.radiance_linear[std::size_t(i)][c] ==
            float(covrast::detail::srgb_decode((i * 3 + c) * 11 / 255.0)));
    }
  }
}

#if COVRAST_HAS_OPENEXR
TEST_CASE("environment files: OpenEXR, lossless exactly and DWAB closely, NaN read as 0",
          "[environment][io]") {
  TempDir dir;
  const int w = 64, h = 32;
  Imf::Array2D<Imf::Rgba> texels(h, w);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // Values exact in half precision: multiples of 1/64 up to 64.
      texels[y][x] =
          Imf::Rgba(half(float(x) / 8.0f), half(float(y) / 4.0f), half(0.5f), half(1.0f));
    }
  }
  for (const auto& [name, compression] :
       {std::pair{"zip.exr", Imf::ZIP_COMPRESSION}, std::pair{"dwab.exr", Imf::DWAB_COMPRESSION}}) {
    INFO(name);
    {
      Imf::RgbaOutputFile out((dir / name).string().c_str(), w, h, Imf::WRITE_RGBA, 1,
                              Imath::V2f(0, 0), 1, Imf::INCREASING_Y, compression);
      out.setFrameBuffer(&texels[0][0], 1, w);
      out.writePixels(h);
    }
    const EnvironmentMap map = load_environment(dir / name);
    REQUIRE(map.width == w);
    REQUIRE(map.height == h);
    double worst = 0.0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const glm::vec3 t = map.radiance_linear[std::size_t(y * w + x)];
        const glm::vec3 want(float(x) / 8.0f, float(y) / 4.0f, 0.5f);
        for (int c = 0; c < 3; ++c) {
          worst = std::max(worst, std::abs(double(t[c]) - want[c]) / std::max(1.0f, want[c]));
        }
      }
    }
    if (compression == Imf::ZIP_COMPRESSION) {
      CHECK(worst == 0.0);
    } else {
      CHECK(worst < 0.02);  // DWAB is lossy
    }
  }
  // A NaN, an infinity and a negative value: each read as 0, one warning.
  texels[1][2] = Imf::Rgba(half(std::numeric_limits<float>::quiet_NaN()),
                           half(std::numeric_limits<float>::infinity()), half(-1.0f), half(1.0f));
  {
    Imf::RgbaOutputFile out((dir / "bad.exr").string().c_str(), w, h, Imf::WRITE_RGBA);
    out.setFrameBuffer(&texels[0][0], 1, w);
    out.writePixels(h);
  }
  std::vector<std::string> warnings;
  const EnvironmentMap map = load_environment(dir / "bad.exr", &warnings);
  CHECK(map.radiance_linear[std::size_t(1 * w + 2)] == glm::vec3(0.0f));
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Contains("bad.exr: 3 texel values negative, NaN or infinite, read as 0"));
  // A cut file: an error naming it.
  std::ifstream in(dir / "bad.exr", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  write_bytes(dir / "cut.exr", bytes.substr(0, bytes.size() / 2));
  CHECK_THROWS_WITH(load_environment(dir / "cut.exr"),
                    Contains("cut.exr: cannot decode environment: OpenEXR"));
}
#endif

TEST_CASE("environment files: the bright texel of a file lights from its direction",
          "[environment][io]") {
  // Texel (x, y) of a W x H map looks towards environment_direction((x + 0.5) / W,
  // (y + 0.5) / H); the map's centre towards +X and its top towards +Y.
  TempDir dir;
  const int w = 32, h = 16, bx = 24, by = 5;
  std::vector<Rgbe> texels(std::size_t(w * h), Rgbe{0, 0, 0, 0});
  texels[std::size_t(by * w + bx)] = Rgbe{200, 200, 200, 140};
  write_bytes(dir / "bright.hdr", rle_hdr(w, h, texels));
  const EnvironmentMap map = load_environment(dir / "bright.hdr");
  int found = -1;
  for (int i = 0; i < w * h; ++i) {
    if (map.radiance_linear[std::size_t(i)].r > 0.0f) found = i;
  }
  REQUIRE(found == by * w + bx);
  const glm::dvec3 d = covrast::environment_direction((bx + 0.5) / w, (by + 0.5) / h);
  const glm::dvec2 uv = covrast::environment_uv(d);
  CHECK(uv.x == Approx((bx + 0.5) / w));
  CHECK(uv.y == Approx((by + 0.5) / h));
  const glm::dvec3 centre = covrast::environment_direction(0.5, 0.5);
  CHECK(centre.x == Approx(1.0));
  CHECK(std::abs(centre.y) < 1e-12);
  CHECK(covrast::environment_direction(0.25, 0.5).z == Approx(-1.0));
  CHECK(covrast::environment_direction(0.3, 0.0).y == Approx(1.0));
}
