// Tests of the image files (src/image/image_io.cpp): exact PNG round trip, 16-bit depth PNG
// and PFM layouts, and atomic writes (no temporary files left behind, the target untouched on
// failure). The 16-bit PNG is decoded with stb_image, a decoder independent of our encoder.
#include <covrast/image.hpp>
#include <covrast/tools.hpp>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <catch2/catch.hpp>

#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "test_tempdir.hpp"

namespace fs = std::filesystem;

namespace {

/// A temporary directory of this file's tests.
class TempDir : public covrast::test::TempDir {
 public:
  TempDir() : covrast::test::TempDir("covrast-test-image") {}
};

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
  REQUIRE(out.good());
}

std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

/// A deterministic image whose bytes cover all 256 values and have no simple pattern.
covrast::Image noise_image(int width, int height) {
  covrast::Image image;
  image.width = width;
  image.height = height;
  image.rgb.resize(std::size_t(width) * height * 3);
  std::uint32_t state = 12345u;
  for (auto& byte : image.rgb) {
    state = state * 1664525u + 1013904223u;  // LCG (Numerical Recipes)
    byte = std::uint8_t(state >> 24);
  }
  return image;
}

std::uint32_t float_bits(float value) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, 4);
  return bits;
}

}  // namespace

TEST_CASE("image: PNG write then read is exact", "[image]") {
  TempDir dir;
  for (const auto& [width, height] : {std::pair{1, 1}, std::pair{7, 5}, std::pair{64, 3}}) {
    const covrast::Image image = noise_image(width, height);
    const fs::path path = dir / ("img" + std::to_string(width) + ".png");
    covrast::write_png(image, path);
    const covrast::Image back = covrast::read_png(path);
    CHECK(back.width == width);
    CHECK(back.height == height);
    CHECK(back.rgb == image.rgb);
  }
  CHECK(names_in(dir.path()) == std::vector<std::string>{"img1.png", "img64.png", "img7.png"});
}

TEST_CASE("image: read_png drops alpha and expands grey", "[image]") {
  TempDir dir;
  // 2x1 grey+alpha and RGBA files written with stb directly.
  const std::uint8_t grey_alpha[] = {10, 255, 200, 0};
  REQUIRE(stbi_write_png((dir / "ga.png").c_str(), 2, 1, 2, grey_alpha, 4) != 0);
  covrast::Image image = covrast::read_png(dir / "ga.png");
  CHECK(image.width == 2);
  CHECK(image.rgb == std::vector<std::uint8_t>{10, 10, 10, 200, 200, 200});

  const std::uint8_t rgba[] = {1, 2, 3, 4, 5, 6, 7, 8};
  REQUIRE(stbi_write_png((dir / "rgba.png").c_str(), 2, 1, 4, rgba, 8) != 0);
  image = covrast::read_png(dir / "rgba.png");
  CHECK(image.rgb == std::vector<std::uint8_t>{1, 2, 3, 5, 6, 7});
}

TEST_CASE("image: read_png errors are InputErrors naming the file", "[image]") {
  TempDir dir;
  const fs::path missing = dir / "missing.png";
  CHECK_THROWS_AS(covrast::read_png(missing), covrast::InputError);
  CHECK_THROWS_WITH(covrast::read_png(missing),
                    Catch::StartsWith(missing.string() + ": cannot read PNG: "));

  write_bytes(dir / "text.png", "hello, I am not a PNG\n");
  CHECK_THROWS_WITH(covrast::read_png(dir / "text.png"),
                    (dir / "text.png").string() + ": cannot read PNG: not a PNG file");

  covrast::write_png(noise_image(16, 16), dir / "good.png");
  const std::string good = read_bytes(dir / "good.png");
  write_bytes(dir / "truncated.png", good.substr(0, 60));
  CHECK_THROWS_WITH(covrast::read_png(dir / "truncated.png"),
                    Catch::StartsWith((dir / "truncated.png").string() + ": cannot read PNG: "));
}

TEST_CASE("image: depth PNG is 16-bit greyscale, round(depth * 65535)", "[image]") {
  TempDir dir;
  covrast::DepthImage depth;
  depth.width = 3;
  depth.height = 2;
  depth.depth = {0.0f, 1.0f, 0.5f, std::numeric_limits<float>::quiet_NaN(), -0.25f, 0.25f};
  const fs::path path = dir / "depth.png";
  covrast::write_depth(depth, path);

  const std::string bytes = read_bytes(path);
  REQUIRE(bytes.size() > 33);
  CHECK(bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
  CHECK(bytes.compare(12, 4, "IHDR") == 0);
  CHECK(std::uint8_t(bytes[24]) == 16);  // bit depth
  CHECK(std::uint8_t(bytes[25]) == 0);   // colour type: greyscale

  int width = 0;
  int height = 0;
  int channels = 0;
  std::uint16_t* values = stbi_load_16(path.c_str(), &width, &height, &channels, 1);
  REQUIRE(values != nullptr);
  CHECK(width == 3);
  CHECK(height == 2);
  CHECK(channels == 1);
  // 0.5 * 65535 = 32767.5 rounds to 32768; NaN is far (65535); values are clamped to [0, 1].
  const std::vector<std::uint16_t> got(values, values + 6);
  stbi_image_free(values);
  CHECK(got == std::vector<std::uint16_t>{0, 65535, 32768, 65535, 0, 16384});
}

TEST_CASE("image: depth PFM header and byte layout", "[image]") {
  TempDir dir;
  covrast::DepthImage depth;
  depth.width = 3;
  depth.height = 2;
  depth.depth = {0.0f, 0.125f, 0.25f, 0.5f, 0.75f, 1.0f};  // top row first
  const fs::path path = dir / "depth.PFM";                 // extension is case-insensitive
  covrast::write_depth(depth, path);

  const std::string bytes = read_bytes(path);
  const std::string header = "Pf\n3 2\n-1.0\n";
  REQUIRE(bytes.size() == header.size() + 6 * 4);
  CHECK(bytes.compare(0, header.size(), header) == 0);
  // Rows bottom-to-top, each float little-endian.
  const float expected[6] = {0.5f, 0.75f, 1.0f, 0.0f, 0.125f, 0.25f};
  for (int i = 0; i < 6; ++i) {
    const std::uint32_t bits = float_bits(expected[i]);
    for (int b = 0; b < 4; ++b) {
      INFO("float " << i << " byte " << b);
      CHECK(std::uint8_t(bytes[header.size() + std::size_t(i) * 4 + b]) ==
            std::uint8_t(bits >> (8 * b)));
    }
  }
}

TEST_CASE("image: depth with another extension is refused", "[image]") {
  TempDir dir;
  covrast::DepthImage depth;
  depth.width = 1;
  depth.height = 1;
  depth.depth = {0.5f};
  CHECK_THROWS_AS(covrast::write_depth(depth, dir / "depth.exr"), covrast::InputError);
  CHECK_THROWS_AS(covrast::write_depth(depth, dir / "depth"), covrast::InputError);
  CHECK(names_in(dir.path()).empty());
}

TEST_CASE("image: atomic writes leave no temporary files and replace the target", "[image]") {
  TempDir dir;
  const fs::path path = dir / "out.png";
  write_bytes(path, "old contents");
  const covrast::Image image = noise_image(5, 4);
  covrast::write_png(image, path);
  CHECK(covrast::read_png(path).rgb == image.rgb);
  CHECK(names_in(dir.path()) == std::vector<std::string>{"out.png"});
}

TEST_CASE("image: failed writes leave no file and do not touch the target", "[image]") {
  TempDir dir;
  const covrast::Image image = noise_image(5, 4);

  SECTION("missing directory") {
    const fs::path path = dir / "no-such-dir" / "out.png";
    CHECK_THROWS_WITH(covrast::write_png(image, path),
                      path.string() + ": cannot write: No such file or directory");
    CHECK(names_in(dir.path()).empty());
  }
  SECTION("target is a directory: the rename fails, the temporary file is removed") {
    fs::create_directory(dir / "out.png");
    CHECK_THROWS_AS(covrast::write_png(image, dir / "out.png"), covrast::InputError);
    CHECK(names_in(dir.path()) == std::vector<std::string>{"out.png"});
    CHECK(fs::is_directory(dir / "out.png"));
  }
  SECTION("the disk fills up while writing") {
    // A child process with a 64-byte file size limit: write() fails with EFBIG halfway
    // through the PNG. The child reports through its exit status.
    const fs::path path = dir / "out.png";
    const std::string before = "previous image bytes";
    write_bytes(path, before);
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      ::signal(SIGXFSZ, SIG_IGN);
      const rlimit limit{64, 64};
      if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(3);
      try {
        covrast::write_png(noise_image(64, 64), path);
      } catch (const covrast::InputError& e) {
        const std::string expected = path.string() + ": cannot write: File too large";
        ::_exit(std::string(e.what()) == expected ? 0 : 4);
      } catch (...) {
        ::_exit(5);
      }
      ::_exit(6);
    }
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
    CHECK(read_bytes(path) == before);
    CHECK(names_in(dir.path()) == std::vector<std::string>{"out.png"});
  }
  SECTION("empty image") {
    CHECK_THROWS_AS(covrast::write_png(covrast::Image{}, dir / "empty.png"), covrast::InputError);
    CHECK(names_in(dir.path()).empty());
  }
}

TEST_CASE("image: read_png checks the header's size before allocating", "[image]") {
  TempDir dir;
  // A valid 1x1 PNG whose IHDR is rewritten to claim 12000x12000 (within the side limit,
  // over the pixel limit) and 20000x1 (over the side limit), with the chunk CRC fixed up.
  covrast::write_png(noise_image(1, 1), dir / "one.png");
  const std::string one = read_bytes(dir / "one.png");
  const auto forged = [&](std::uint32_t width, std::uint32_t height) {
    std::string png = one;
    for (int k = 0; k < 4; ++k) {
      png[16 + k] = char(width >> (24 - 8 * k));
      png[20 + k] = char(height >> (24 - 8 * k));
    }
    // CRC-32 of "IHDR" and its 13 bytes (PNG's polynomial), big-endian after them.
    std::uint32_t crc = 0xFFFFFFFFu;
    for (int i = 12; i < 29; ++i) {
      crc ^= std::uint8_t(png[std::size_t(i)]);
      for (int b = 0; b < 8; ++b) crc = (crc & 1u) ? 0xEDB88320u ^ (crc >> 1) : crc >> 1;
    }
    crc ^= 0xFFFFFFFFu;
    for (int k = 0; k < 4; ++k) png[29 + k] = char(crc >> (24 - 8 * k));
    return png;
  };
  write_bytes(dir / "big.png", forged(12000, 12000));
  CHECK_THROWS_WITH(covrast::read_png(dir / "big.png"),
                    Catch::Contains("12000x12000 is more than the 67108864 pixels"));
  write_bytes(dir / "wide.png", forged(20000, 1));
  CHECK_THROWS_AS(covrast::read_png(dir / "wide.png"), covrast::InputError);
  // A FIFO is refused, not opened (opening one would block).
  REQUIRE(::mkfifo((dir / "fifo.png").c_str(), 0600) == 0);
  CHECK_THROWS_WITH(covrast::read_png(dir / "fifo.png"),
                    (dir / "fifo.png").string() + ": cannot read PNG: not a regular file");
}

TEST_CASE("image: PNG text records round trip and are checked", "[image]") {
  TempDir dir;
  const covrast::Image image = noise_image(8, 4);
  covrast::write_png(image, dir / "t.png",
                     {{"covrast", R"({"mode":"coverage"})"}, {"Comment", "two\nlines"}});
  const std::vector<covrast::PngText> text = covrast::read_png_text(dir / "t.png");
  REQUIRE(text.size() == 2);
  CHECK(text[0].keyword == "covrast");
  CHECK(text[0].text == R"({"mode":"coverage"})");
  CHECK(text[1].text == "two\nlines");
  CHECK(covrast::read_png(dir / "t.png").rgb == image.rgb);  // the pixels are unaffected
  // The same PNG as encode_png gives in memory.
  CHECK(read_bytes(dir / "t.png") == [&] {
    const auto bytes = covrast::encode_png(
        image, {{"covrast", R"({"mode":"coverage"})"}, {"Comment", "two\nlines"}});
    return std::string(bytes.begin(), bytes.end());
  }());
  CHECK_THROWS(covrast::write_png(image, dir / "bad.png", {{"", "empty keyword"}}));
  CHECK_THROWS(covrast::write_png(image, dir / "bad.png", {{"k", std::string("nul\0", 4)}}));
  CHECK_FALSE(fs::exists(dir / "bad.png"));
  CHECK(covrast::read_png_text(dir / "t.png").size() == 2);
  write_bytes(dir / "text.png", "not a png");
  CHECK_THROWS_AS(covrast::read_png_text(dir / "text.png"), covrast::InputError);
}
