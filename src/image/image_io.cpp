// Image files: the last stage of the pipeline; with image_decode.cpp (textures from memory:
// PNG, JPEG, WebP) the only code in covrast that encodes or decodes them. PNG goes through
// libspng (with zlib), a decoder built for untrusted input, whose header is read and checked
// against covrast's limits before any pixel memory is allocated.
//
// Every writer first encodes the whole file in memory, then writes it atomically: the bytes
// go into "<name>.tmp-<pid>-<random>" beside the target (same directory, so the same file
// system), which is flushed, fsync'ed, closed and finally renamed over the target. A failure
// at any step removes the temporary file, so the target is either the complete new file or
// exactly what it was before (possibly absent).
//
// PNG encoding: every row with filter None and zlib level 6. Measured on 1920x1080 frames of
// scenes/default.json, scenes/lit.json and the per-triangle sphere grid, that was both the
// fastest and the smallest of the filter choices (libspng's adaptive choice of all five
// filters took 2-5x as long for files 1-4% larger or smaller), and 4-6x faster than
// stb_image_write's encoder (whose own deflate took 130-320 ms per frame); bench_ci measures
// it (ci/encode_png).
//
// Depth formats:
//  - .png: 16-bit greyscale PNG (colour type 0, bit depth 16, big-endian samples as PNG
//    requires), value = round(clamp(depth, 0, 1) * 65535); NaN is written as 65535 (far).
//    Rows use filter Sub, which compresses smooth depth far better than None.
//  - .pfm: "Pf" greyscale Portable Float Map, scale -1.0 (little-endian float32), rows stored
//    bottom-to-top as the PFM format specifies.
#include "image/spng_context.hpp"

#include "core/file_read.hpp"

#include <covrast/image.hpp>
#include <covrast/tools.hpp>

#include <spng.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace covrast {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::string errno_message(int error_number) {
  return std::error_code(error_number, std::generic_category()).message();
}

[[noreturn]] void throw_cannot_write(const std::filesystem::path& path, const std::string& why) {
  throw InputError(path.string() + ": cannot write: " + why);
}

/// Owns a temporary file descriptor and path; removes the file unless released.
class TempFile {
 public:
  TempFile(int fd, std::filesystem::path path) : fd_(fd), path_(std::move(path)) {}
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!released_) ::unlink(path_.c_str());
  }
  int fd() const { return fd_; }
  const std::filesystem::path& path() const { return path_; }
  /// Closes the descriptor; returns 0 or the errno of close().
  int close() {
    const int result = ::close(fd_);
    fd_ = -1;
    return result == 0 ? 0 : errno;
  }
  void release() { released_ = true; }

 private:
  int fd_;
  std::filesystem::path path_;
  bool released_ = false;
};

TempFile create_temp_beside(const std::filesystem::path& target) {
  std::random_device entropy;
  std::uniform_int_distribution<std::uint32_t> digits(0, 0xFFFFFFu);
  constexpr int kAttempts = 16;
  int last_error = EEXIST;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    char suffix[48];
    std::snprintf(suffix, sizeof suffix, ".tmp-%ld-%06x", static_cast<long>(::getpid()),
                  static_cast<unsigned>(digits(entropy)));
    std::filesystem::path temp = target;
    temp += suffix;
    // O_EXCL: never reuse (or follow a symlink at) an existing name.
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) return TempFile(fd, temp);
    last_error = errno;
    if (last_error != EEXIST) break;
  }
  throw_cannot_write(target, errno_message(last_error));
}

void write_atomically(const std::filesystem::path& path, const Bytes& bytes) {
  if (path.empty()) throw InputError("cannot write: empty output path");
  TempFile temp = create_temp_beside(path);
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(temp.fd(), bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw_cannot_write(path, errno_message(errno));
    }
    written += static_cast<std::size_t>(n);
  }
  // fsync before rename: otherwise a crash could leave the new name pointing at an empty file.
  if (::fsync(temp.fd()) != 0) throw_cannot_write(path, errno_message(errno));
  if (const int error = temp.close(); error != 0) throw_cannot_write(path, errno_message(error));
  std::error_code ec;
  std::filesystem::rename(temp.path(), path, ec);
  if (ec) throw_cannot_write(path, ec.message());
  temp.release();
}

void check_image_shape(int width, int height, std::size_t values, std::size_t channels,
                       const std::filesystem::path& path) {
  if (width <= 0 || height <= 0) throw_cannot_write(path, "image is empty");
  if (values != std::size_t(width) * std::size_t(height) * channels) {
    throw std::invalid_argument(path.string() + ": image buffer size does not match " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
}

/// zlib's level for every PNG covrast writes (see the top of the file).
constexpr int kPngZlibLevel = 6;

/// A PNG of `pixels`, rows already in PNG sample layout (8-bit RGB, or 16-bit grey in the
/// host's byte order), with `text` as tEXt chunks before the image data.
Bytes encode_png_file(const std::uint8_t* pixels, std::size_t bytes, int width, int height,
                      std::uint8_t color_type, std::uint8_t bit_depth, int filter_choice,
                      const std::vector<PngText>& text) {
  const SpngContext png(SPNG_CTX_ENCODER);
  spng_ctx* ctx = png.get();
  spng_set_option(ctx, SPNG_ENCODE_TO_BUFFER, 1);
  spng_set_option(ctx, SPNG_FILTER_CHOICE, filter_choice);
  spng_set_option(ctx, SPNG_IMG_COMPRESSION_LEVEL, kPngZlibLevel);
  spng_ihdr ihdr{};
  ihdr.width = std::uint32_t(width);
  ihdr.height = std::uint32_t(height);
  ihdr.bit_depth = bit_depth;
  ihdr.color_type = color_type;
  int error = spng_set_ihdr(ctx, &ihdr);
  std::vector<spng_text> records(text.size());
  for (std::size_t i = 0; i < text.size() && error == 0; ++i) {
    std::memcpy(records[i].keyword, text[i].keyword.c_str(), text[i].keyword.size() + 1);
    records[i].type = SPNG_TEXT;
    records[i].length = text[i].text.size();
    records[i].text = const_cast<char*>(text[i].text.c_str());  // libspng copies it
  }
  if (error == 0 && !records.empty()) {
    error = spng_set_text(ctx, records.data(), std::uint32_t(records.size()));
  }
  if (error == 0) {
    error = spng_encode_image(ctx, pixels, bytes, SPNG_FMT_PNG, SPNG_ENCODE_FINALIZE);
  }
  std::size_t size = 0;
  void* buffer = error == 0 ? spng_get_png_buffer(ctx, &size, &error) : nullptr;
  if (error != 0 || buffer == nullptr) {
    std::free(buffer);
    throw std::runtime_error(std::string("PNG encoding failed: ") + spng_strerror(error));
  }
  const auto* begin = static_cast<const std::uint8_t*>(buffer);
  Bytes out(begin, begin + size);
  std::free(buffer);
  return out;
}

/// 16-bit greyscale PNG, rows filtered with Sub (see the top of the file).
Bytes encode_png_grey16(const DepthImage& depth, const std::filesystem::path& path) {
  const std::size_t samples = std::size_t(depth.width) * std::size_t(depth.height);
  if (samples > std::size_t(0x3FFFFFFF)) throw_cannot_write(path, "depth image too large");
  // Host-endian samples: libspng's SPNG_FMT_PNG takes 16-bit samples in the host's order and
  // writes them big-endian, as PNG stores them.
  std::vector<std::uint16_t> raw(samples);
  for (std::size_t i = 0; i < samples; ++i) {
    const float d = depth.depth[i];
    const double clamped = std::isnan(d) ? 1.0 : std::clamp(double(d), 0.0, 1.0);
    raw[i] = static_cast<std::uint16_t>(std::lround(clamped * 65535.0));
  }
  return encode_png_file(reinterpret_cast<const std::uint8_t*>(raw.data()), samples * 2,
                         depth.width, depth.height, SPNG_COLOR_TYPE_GRAYSCALE, 16,
                         SPNG_FILTER_CHOICE_SUB, {});
}

Bytes encode_pfm(const DepthImage& depth) {
  const std::string header =
      "Pf\n" + std::to_string(depth.width) + " " + std::to_string(depth.height) + "\n-1.0\n";
  Bytes out(header.begin(), header.end());
  out.reserve(out.size() + depth.depth.size() * 4);
  for (int y = depth.height - 1; y >= 0; --y) {  // PFM stores the bottom row first
    for (int x = 0; x < depth.width; ++x) {
      std::uint32_t bits = 0;
      std::memcpy(&bits, &depth.depth[std::size_t(y) * depth.width + x], 4);
      for (int byte = 0; byte < 4; ++byte) out.push_back(std::uint8_t(bits >> (8 * byte)));
    }
  }
  return out;
}

}  // namespace

namespace {

void check_png_text(const PngText& record) {
  const auto printable = [](unsigned char c) { return c >= 0x20 && c < 0x7f; };
  if (record.keyword.empty() || record.keyword.size() > 79 ||
      !std::all_of(record.keyword.begin(), record.keyword.end(), printable) ||
      record.keyword.front() == ' ' || record.keyword.back() == ' ') {
    throw std::invalid_argument("PNG text keyword '" + record.keyword +
                                "' is not 1..79 printable ASCII characters");
  }
  if (!std::all_of(record.text.begin(), record.text.end(),
                   [&](unsigned char c) { return printable(c) || c == '\n'; })) {
    throw std::invalid_argument("PNG text of '" + record.keyword + "' is not printable ASCII");
  }
}

Bytes encode_png_rgb8(const Image& image, const std::vector<PngText>& text) {
  for (const PngText& record : text) check_png_text(record);
  if (image.alpha.empty()) {
    return encode_png_file(image.rgb.data(), image.rgb.size(), image.width, image.height,
                           SPNG_COLOR_TYPE_TRUECOLOR, 8, SPNG_FILTER_CHOICE_NONE, text);
  }
  std::vector<std::uint8_t> rgba(image.alpha.size() * 4);
  for (std::size_t i = 0; i < image.alpha.size(); ++i) {
    std::copy_n(&image.rgb[3 * i], 3, &rgba[4 * i]);
    rgba[4 * i + 3] = image.alpha[i];
  }
  return encode_png_file(rgba.data(), rgba.size(), image.width, image.height,
                         SPNG_COLOR_TYPE_TRUECOLOR_ALPHA, 8, SPNG_FILTER_CHOICE_NONE, text);
}

/// The RGB plane holds 3 values per pixel, the alpha plane none or 1.
void check_image_planes(const Image& image, const std::string& what) {
  check_image_shape(image.width, image.height, image.rgb.size(), 3, what);
  if (!image.alpha.empty())
    check_image_shape(image.width, image.height, image.alpha.size(), 1, what);
}

std::uint32_t read_be32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}

}  // namespace

std::vector<std::uint8_t> encode_png(const Image& image, const std::vector<PngText>& text) {
  check_image_planes(image, "PNG");
  return encode_png_rgb8(image, text);
}

void write_png(const Image& image, const std::filesystem::path& path,
               const std::vector<PngText>& text) {
  check_image_planes(image, path.string());
  write_atomically(path, encode_png_rgb8(image, text));
}

std::vector<PngText> read_png_text(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (const std::string kind = detail::unreadable_kind(status); !ec && !kind.empty()) {
    throw InputError(path.string() + ": cannot read PNG: " + kind);
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw InputError(path.string() + ": cannot read PNG: " + errno_message(errno));
  }
  // Walk the chunks up to the first IDAT (text chunks that matter come before the pixels;
  // reading no further keeps this cheap for large images).
  std::vector<PngText> text;
  std::uint8_t head[8] = {};
  static constexpr std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  bool ok = std::fread(head, 1, 8, file) == 8 && std::memcmp(head, kSignature, 8) == 0;
  constexpr std::uint32_t kMaxTextChunk = 1u << 20;
  while (ok) {
    if (std::fread(head, 1, 8, file) != 8) break;
    const std::uint32_t length = read_be32(head);
    const std::string type(reinterpret_cast<const char*>(head + 4), 4);
    if (type == "IDAT" || type == "IEND") break;
    if (type != "tEXt" || length > kMaxTextChunk) {
      ok = std::fseek(file, long(length) + 4, SEEK_CUR) == 0;
      continue;
    }
    std::string data(length, '\0');
    ok = std::fread(data.data(), 1, length, file) == length && std::fseek(file, 4, SEEK_CUR) == 0;
    const std::size_t nul = data.find('\0');
    if (ok && nul != std::string::npos) text.push_back({data.substr(0, nul), data.substr(nul + 1)});
  }
  std::fclose(file);
  if (!ok) throw InputError(path.string() + ": cannot read PNG text: not a PNG file or truncated");
  return text;
}

void write_depth(const DepthImage& depth, const std::filesystem::path& path) {
  const std::string ext = detail::lower_extension(path);
  if (ext != ".png" && ext != ".pfm") {
    throw InputError(path.string() + ": unsupported depth format '" + ext +
                     "' (use .png for 16-bit greyscale or .pfm for float)");
  }
  check_image_shape(depth.width, depth.height, depth.depth.size(), 1, path);
  write_atomically(path, ext == ".png" ? encode_png_grey16(depth, path) : encode_pfm(depth));
}

Image read_png(const std::filesystem::path& path) {
  const auto fail = [&](const std::string& why) -> Image {
    throw InputError(path.string() + ": cannot read PNG: " + why);
  };
  // libspng's words for a file cut short and for its side limit, made plain.
  const auto reason = [](int error) -> std::string {
    if (error == SPNG_IO_EOF || error == SPNG_EOF) {
      return "truncated: the file ends before the image does";
    }
    if (error == SPNG_EUSER_WIDTH || error == SPNG_EUSER_HEIGHT) {
      return "a side over the " + std::to_string(kMaxPngSide) + " pixels covrast reads";
    }
    return spng_strerror(error);
  };
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  // A FIFO or device would block or never end.
  if (const std::string kind = detail::unreadable_kind(status); !ec && !kind.empty()) {
    return fail(kind);
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return fail(errno_message(errno));
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> closer(file, std::fclose);
  static constexpr std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::uint8_t head[8] = {};
  if (std::fread(head, 1, sizeof head, file) != sizeof head ||
      std::memcmp(head, kSignature, sizeof head) != 0) {
    return fail("not a PNG file");
  }
  std::rewind(file);
  const SpngContext png(0);
  spng_ctx* ctx = png.get();
  // Limits checked before anything is allocated: a forged header cannot ask for gigabytes.
  spng_set_image_limits(ctx, std::uint32_t(kMaxPngSide), std::uint32_t(kMaxPngSide));
  spng_set_chunk_limits(ctx, kMaxPngChunkBytes, kMaxPngChunkBytes);
  spng_set_png_file(ctx, file);
  spng_ihdr ihdr{};
  if (const int error = spng_get_ihdr(ctx, &ihdr); error != 0) return fail(reason(error));
  if (std::uint64_t(ihdr.width) * ihdr.height > kMaxPngPixels) {
    return fail(std::to_string(ihdr.width) + "x" + std::to_string(ihdr.height) +
                " is more than the " + std::to_string(kMaxPngPixels) + " pixels covrast reads");
  }
  // Any colour type and bit depth to 8-bit RGB: grey expanded, palette looked up, 16-bit
  // samples reduced to their high byte. An alpha channel (colour types 4 and 6, as covrast
  // writes a transparent background) is kept in Image::alpha, not composited; tRNS is dropped.
  const bool has_alpha = ihdr.color_type == SPNG_COLOR_TYPE_GRAYSCALE_ALPHA ||
                         ihdr.color_type == SPNG_COLOR_TYPE_TRUECOLOR_ALPHA;
  const int format = has_alpha ? SPNG_FMT_RGBA8 : SPNG_FMT_RGB8;
  std::size_t size = 0;
  if (const int error = spng_decoded_image_size(ctx, format, &size); error != 0) {
    return fail(reason(error));
  }
  Image image;
  image.width = int(ihdr.width);
  image.height = int(ihdr.height);
  std::vector<std::uint8_t> decoded(size);
  if (const int error = spng_decode_image(ctx, decoded.data(), size, format, 0); error != 0) {
    return fail(reason(error));
  }
  if (has_alpha) {
    const std::size_t pixels = size / 4;
    image.rgb.resize(pixels * 3);
    image.alpha.resize(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
      std::copy_n(&decoded[4 * i], 3, &image.rgb[3 * i]);
      image.alpha[i] = decoded[4 * i + 3];
    }
  } else {
    image.rgb = std::move(decoded);
  }
  // The last IDAT chunk's CRC is checked only when libspng reads on (decode_png_rgba).
  if (const int error = spng_decode_chunks(ctx); error != 0) return fail(reason(error));
  return image;
}

}  // namespace covrast
