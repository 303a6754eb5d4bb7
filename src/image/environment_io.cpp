// Environment maps from files (docs/environments.md): Radiance .hdr (RGBE, decoded here: no
// Debian library reads it), OpenEXR through libopenexr, and 8-bit PNG/JPEG through the texture
// decoder, as linear radiance in the orientation of include/covrast/environment.hpp. Every
// input is bounded like the others: the file through read_whole_file, the size from the header
// before any texel is allocated.
#include <covrast/environment.hpp>
#include <covrast/error.hpp>
#include <covrast/image.hpp>

#include "color/srgb.hpp"
#include "core/file_read.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#if COVRAST_HAS_OPENEXR
#include <OpenEXR/ImfArray.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfRgbaFile.h>
#endif

namespace covrast {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& why) {
  throw InputError(name + ": cannot decode environment: " + why);
}

/// Refuses a map over the limits before anything is allocated for it.
void check_size(const std::string& name, std::int64_t width, std::int64_t height) {
  if (width < 1 || height < 1) fail(name, "empty image");
  if (width > kMaxEnvironmentSide || height > kMaxEnvironmentSide) {
    fail(name, std::to_string(width) + "x" + std::to_string(height) + " is over the limit of " +
                   std::to_string(kMaxEnvironmentSide) + " texels a side");
  }
  if (std::uint64_t(width) * std::uint64_t(height) > kMaxEnvironmentTexels) {
    fail(name, std::to_string(width) + "x" + std::to_string(height) + " is over the limit of " +
                   std::to_string(kMaxEnvironmentTexels) + " texels");
  }
}

// ---- Radiance RGBE (Greg Ward, "Real Pixels", Graphics Gems II, 1991; the Radiance file
// format, radsite.lbl.gov). Header lines up to an empty line, the first "#?RADIANCE" or
// "#?RGBE"; then the resolution line "-Y H +X W" (rows top to bottom, columns left to right:
// the only orientation accepted); then H scanlines, each flat (4 bytes a texel), in the old
// run-length form (a texel 1 1 1 n repeats the previous one n << shift times) or in the new
// one (2 2 hi lo with hi lo = W, then each of the four components as runs: a count c > 128
// repeats the next byte c - 128 times, c <= 128 is c literal bytes).

/// Reads one header line (without '\n') from bytes[at..]; false at the end of the data.
bool next_line(const std::uint8_t* bytes, std::size_t size, std::size_t& at, std::string& line) {
  line.clear();
  while (at < size) {
    const char c = char(bytes[at++]);
    if (c == '\n') return true;
    line.push_back(c);
    if (line.size() > 4096) return false;  // not a header any more
  }
  return false;
}

/// One RGBE texel: (c + 0.5) x 2^(e - 136) for e > 0 (Radiance's colr_color), 0 for e = 0.
glm::vec3 rgbe_radiance(const std::uint8_t rgbe[4]) {
  if (rgbe[3] == 0) return glm::vec3(0.0f);
  const double f = std::ldexp(1.0, int(rgbe[3]) - 136);
  return glm::vec3(float((rgbe[0] + 0.5) * f), float((rgbe[1] + 0.5) * f),
                   float((rgbe[2] + 0.5) * f));
}

/// Decodes one scanline of `width` texels at bytes[at..] into `rgbe` (4 bytes a texel).
void read_rgbe_scanline(const std::string& name, const std::uint8_t* bytes, std::size_t size,
                        std::size_t& at, int width, int row, std::vector<std::uint8_t>& rgbe) {
  const auto truncated = [&] { fail(name, "truncated at row " + std::to_string(row)); };
  const bool new_rle = width >= 8 && width < 32768 && at + 4 <= size && bytes[at] == 2 &&
                       bytes[at + 1] == 2 && (bytes[at + 2] & 0x80) == 0;
  if (new_rle) {
    if (((int(bytes[at + 2]) << 8) | int(bytes[at + 3])) != width) {
      fail(name, "row " + std::to_string(row) + " has a run-length scanline of another width");
    }
    at += 4;
    for (int c = 0; c < 4; ++c) {
      int x = 0;
      while (x < width) {
        if (at >= size) truncated();
        int count = bytes[at++];
        if (count > 128) {
          count -= 128;
          if (at >= size) truncated();
          if (x + count > width) fail(name, "a run past the end of row " + std::to_string(row));
          const std::uint8_t value = bytes[at++];
          for (int k = 0; k < count; ++k) rgbe[std::size_t(x++) * 4 + std::size_t(c)] = value;
        } else {
          if (count == 0) fail(name, "a run of length 0 in row " + std::to_string(row));
          if (x + count > width) fail(name, "a run past the end of row " + std::to_string(row));
          if (at + std::size_t(count) > size) truncated();
          for (int k = 0; k < count; ++k) rgbe[std::size_t(x++) * 4 + std::size_t(c)] = bytes[at++];
        }
      }
    }
    return;
  }
  // Flat texels, with the old run-length repeats.
  int x = 0, shift = 0;
  while (x < width) {
    if (at + 4 > size) truncated();
    const std::uint8_t* t = bytes + at;
    at += 4;
    if (t[0] == 1 && t[1] == 1 && t[2] == 1) {
      if (x == 0) fail(name, "a repeat with no texel before it in row " + std::to_string(row));
      if (shift > 24) fail(name, "a repeat count too large in row " + std::to_string(row));
      const std::int64_t count = std::int64_t(t[3]) << shift;
      if (x + count > width) fail(name, "a repeat past the end of row " + std::to_string(row));
      for (std::int64_t k = 0; k < count; ++k, ++x) {
        std::memcpy(&rgbe[std::size_t(x) * 4], &rgbe[std::size_t(x - 1) * 4], 4);
      }
      shift += 8;
    } else {
      std::memcpy(&rgbe[std::size_t(x) * 4], t, 4);
      ++x;
      shift = 0;
    }
  }
}

EnvironmentMap decode_hdr(const std::uint8_t* bytes, std::size_t size, const std::string& name) {
  std::size_t at = 0;
  std::string line;
  if (!next_line(bytes, size, at, line) || (line != "#?RADIANCE" && line != "#?RGBE")) {
    fail(name, "not a Radiance file (its first line is not #?RADIANCE or #?RGBE)");
  }
  while (true) {
    if (!next_line(bytes, size, at, line)) fail(name, "the header does not end");
    if (line.empty()) break;
    if (line.rfind("FORMAT=", 0) == 0 && line != "FORMAT=32-bit_rle_rgbe") {
      fail(name, "format " + line.substr(7) + " (only 32-bit_rle_rgbe is read)");
    }
  }
  if (!next_line(bytes, size, at, line)) fail(name, "no resolution line");
  long long height = 0, width = 0;
  char tail = 0;
  if (std::sscanf(line.c_str(), "-Y %lld +X %lld%c", &height, &width, &tail) != 2) {
    fail(name, "resolution line '" + line.substr(0, 40) +
                   "' (only -Y H +X W, rows from the top, is read)");
  }
  check_size(name, width, height);
  EnvironmentMap map;
  map.width = int(width);
  map.height = int(height);
  // Row by row: the texels grow with the rows that decode, so a short file claiming a large
  // map fails before the map is allocated (run-length rows are at least 8 bytes).
  std::vector<std::uint8_t> rgbe(std::size_t(width) * 4);
  for (int y = 0; y < map.height; ++y) {
    read_rgbe_scanline(name, bytes, size, at, map.width, y, rgbe);
    for (int x = 0; x < map.width; ++x) {
      map.radiance_linear.push_back(rgbe_radiance(&rgbe[std::size_t(x) * 4]));
    }
  }
  return map;
}

// ---- OpenEXR, from memory through an Imf::IStream.
#if COVRAST_HAS_OPENEXR
class MemoryStream : public Imf::IStream {
 public:
  MemoryStream(const std::uint8_t* bytes, std::size_t size, const std::string& name)
      : Imf::IStream(name.c_str()), bytes_(bytes), size_(size) {}
  bool read(char c[], int n) override {
    if (n < 0 || std::uint64_t(n) > size_ - at_) throw std::runtime_error("unexpected end of file");
    std::memcpy(c, bytes_ + at_, std::size_t(n));
    at_ += std::size_t(n);
    return at_ < size_;
  }
  std::uint64_t tellg() override { return at_; }
  void seekg(std::uint64_t pos) override {
    if (pos > size_) throw std::runtime_error("seek past the end of file");
    at_ = std::size_t(pos);
  }
  void clear() override {}

 private:
  const std::uint8_t* bytes_;
  std::size_t size_;
  std::size_t at_ = 0;
};

EnvironmentMap decode_exr(const std::uint8_t* bytes, std::size_t size, const std::string& name) {
  try {
    MemoryStream stream(bytes, size, name);
    Imf::RgbaInputFile file(stream);
    const Imath::Box2i window = file.dataWindow();
    const std::int64_t width = std::int64_t(window.max.x) - window.min.x + 1;
    const std::int64_t height = std::int64_t(window.max.y) - window.min.y + 1;
    check_size(name, width, height);
    Imf::Array2D<Imf::Rgba> texels(height, width);
    // The frame buffer is addressed by data-window coordinates.
    file.setFrameBuffer(&texels[0][0] - window.min.x - window.min.y * width, 1, std::size_t(width));
    file.readPixels(window.min.y, window.max.y);
    EnvironmentMap map;
    map.width = int(width);
    map.height = int(height);
    map.radiance_linear.reserve(std::size_t(width) * std::size_t(height));
    for (std::int64_t y = 0; y < height; ++y) {
      for (std::int64_t x = 0; x < width; ++x) {
        const Imf::Rgba& t = texels[y][x];
        map.radiance_linear.push_back(glm::vec3(float(t.r), float(t.g), float(t.b)));
      }
    }
    return map;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    fail(name, std::string("OpenEXR: ") + e.what());
  }
}
#endif

/// 8-bit PNG or JPEG as sRGB: each code through the exact sRGB decode (color/srgb.hpp).
EnvironmentMap decode_ldr(const std::uint8_t* bytes, std::size_t size, const std::string& name) {
  const RgbaImage image = decode_image(bytes, size, name);
  check_size(name, image.width, image.height);
  const std::array<double, 256>& decoded = detail::srgb8_decode_table();
  float linear[256];
  for (int c = 0; c < 256; ++c) linear[c] = float(decoded[std::size_t(c)]);
  EnvironmentMap map;
  map.width = image.width;
  map.height = image.height;
  map.radiance_linear.reserve(std::size_t(image.width) * std::size_t(image.height));
  for (std::size_t i = 0; i < std::size_t(image.width) * std::size_t(image.height); ++i) {
    map.radiance_linear.push_back(glm::vec3(
        linear[image.rgba[4 * i]], linear[image.rgba[4 * i + 1]], linear[image.rgba[4 * i + 2]]));
  }
  return map;
}

}  // namespace

EnvironmentMap decode_environment(const std::uint8_t* bytes, std::size_t size,
                                  const std::string& name, std::vector<std::string>* warnings) {
  EnvironmentMap map;
  if (size >= 2 && bytes[0] == '#' && bytes[1] == '?') {
    map = decode_hdr(bytes, size, name);
  } else if (size >= 4 && bytes[0] == 0x76 && bytes[1] == 0x2f && bytes[2] == 0x31 &&
             bytes[3] == 0x01) {
#if COVRAST_HAS_OPENEXR
    map = decode_exr(bytes, size, name);
#else
    fail(name, "an OpenEXR file, and this covrast was built without OpenEXR (libopenexr-dev)");
#endif
  } else if ((size >= 8 && bytes[0] == 0x89 && bytes[1] == 'P') ||
             (size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8)) {
    map = decode_ldr(bytes, size, name);
  } else {
    fail(name,
         size == 0 ? "empty" : "not Radiance .hdr, OpenEXR, PNG or JPEG (by its first bytes)");
  }
  // Radiance must be finite and >= 0 for the lighting's sums; what is not becomes 0.
  std::size_t replaced = 0;
  for (glm::vec3& texel : map.radiance_linear) {
    for (int c = 0; c < 3; ++c) {
      if (!(texel[c] >= 0.0f) || !std::isfinite(texel[c])) {
        texel[c] = 0.0f;
        ++replaced;
      }
    }
  }
  if (replaced != 0 && warnings != nullptr) {
    warnings->push_back(name + ": " + std::to_string(replaced) +
                        " texel values negative, NaN or infinite, read as 0");
  }
  return map;
}

EnvironmentMap load_environment(const std::filesystem::path& path,
                                std::vector<std::string>* warnings) {
  std::vector<unsigned char> bytes;
  if (std::string error; !detail::read_whole_file(path, bytes, error, kMaxEnvironmentFileBytes)) {
    throw InputError(path.string() + ": cannot read environment: " + error);
  }
  return decode_environment(bytes.data(), bytes.size(), path.string(), warnings);
}

}  // namespace covrast
