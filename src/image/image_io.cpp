// Image files: the last stage of the pipeline and the only code in covrast that includes stb.
//
// Every writer first encodes the whole file in memory, then writes it atomically: the bytes
// go into "<name>.tmp-<pid>-<random>" beside the target (same directory, so the same file
// system), which is flushed, fsync'ed, closed and finally renamed over the target. A failure
// at any step removes the temporary file, so the target is either the complete new file or
// exactly what it was before (possibly absent).
//
// Depth formats:
//  - .png: 16-bit greyscale PNG (colour type 0, bit depth 16, big-endian samples as PNG
//    requires), value = round(clamp(depth, 0, 1) * 65535); NaN is written as 65535 (far).
//    stb_image_write only writes 8-bit PNGs, so the PNG container is assembled here and only
//    the zlib stream comes from stb (stbi_zlib_compress, exported by libstb).
//  - .pfm: "Pf" greyscale Portable Float Map, scale -1.0 (little-endian float32), rows stored
//    bottom-to-top as the PFM format specifies.
#include <covrast/image.hpp>

#include <stb_image.h>
#include <stb_image_write.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

// Defined (with STBIWDEF, i.e. extern "C") in the implementation part of stb_image_write.h,
// which Debian compiles into libstb, but not declared in the header part. Returns a zlib
// stream allocated with malloc.
extern "C" unsigned char* stbi_zlib_compress(unsigned char* data, int data_len, int* out_len,
                                             int quality);

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

void append_be32(Bytes& out, std::uint32_t value) {
  out.push_back(std::uint8_t(value >> 24));
  out.push_back(std::uint8_t(value >> 16));
  out.push_back(std::uint8_t(value >> 8));
  out.push_back(std::uint8_t(value));
}

/// CRC-32 (ISO 3309, polynomial 0xEDB88320 reflected), as PNG chunks require.
std::uint32_t crc32(const std::uint8_t* data, std::size_t size) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t n = 0; n < 256; ++n) {
      std::uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) c = table[(c ^ data[i]) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

void append_chunk(Bytes& out, const char type[4], const std::uint8_t* data, std::size_t size) {
  append_be32(out, static_cast<std::uint32_t>(size));
  const std::size_t type_at = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data, data + size);
  append_be32(out, crc32(out.data() + type_at, size + 4));
}

/// 16-bit greyscale PNG. Every scanline uses filter 1 (Sub, predictor = the sample two bytes
/// to the left), which compresses smooth depth far better than no filter.
Bytes encode_png_grey16(const DepthImage& depth, const std::filesystem::path& path) {
  const std::size_t row_bytes = std::size_t(depth.width) * 2;
  const std::size_t raw_size = (row_bytes + 1) * std::size_t(depth.height);
  if (raw_size > std::size_t(0x7FFFFFFF)) throw_cannot_write(path, "depth image too large");
  Bytes raw(raw_size);
  Bytes row(row_bytes);
  for (int y = 0; y < depth.height; ++y) {
    for (int x = 0; x < depth.width; ++x) {
      const float d = depth.depth[std::size_t(y) * depth.width + x];
      const double clamped = std::isnan(d) ? 1.0 : std::clamp(double(d), 0.0, 1.0);
      const auto v = static_cast<std::uint16_t>(std::lround(clamped * 65535.0));
      row[std::size_t(x) * 2] = std::uint8_t(v >> 8);
      row[std::size_t(x) * 2 + 1] = std::uint8_t(v & 0xFFu);
    }
    std::uint8_t* out = &raw[std::size_t(y) * (row_bytes + 1)];
    out[0] = 1;  // filter type Sub
    for (std::size_t i = 0; i < row_bytes; ++i) {
      out[1 + i] = std::uint8_t(row[i] - (i >= 2 ? row[i - 2] : 0));
    }
  }
  int zlib_size = 0;
  unsigned char* zlib = stbi_zlib_compress(raw.data(), int(raw.size()), &zlib_size, 8);
  if (zlib == nullptr) throw std::runtime_error(path.string() + ": zlib compression failed");

  static constexpr std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  Bytes png(std::begin(kSignature), std::end(kSignature));
  Bytes ihdr;
  append_be32(ihdr, std::uint32_t(depth.width));
  append_be32(ihdr, std::uint32_t(depth.height));
  ihdr.insert(ihdr.end(), {16, 0, 0, 0, 0});  // bit depth, grey, deflate, filter 0, no interlace
  append_chunk(png, "IHDR", ihdr.data(), ihdr.size());
  append_chunk(png, "IDAT", zlib, std::size_t(zlib_size));
  std::free(zlib);
  append_chunk(png, "IEND", nullptr, 0);
  return png;
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

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

namespace {

/// Bytes of the PNG signature and the IHDR chunk (4 length + 4 type + 13 data + 4 CRC): the
/// text chunks go right after them.
constexpr std::size_t kPngHeaderBytes = 8 + 25;

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
  Bytes png;
  const auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<Bytes*>(context);
    const auto* bytes = static_cast<const std::uint8_t*>(data);
    out->insert(out->end(), bytes, bytes + size);
  };
  if (stbi_write_png_to_func(append, &png, image.width, image.height, 3, image.rgb.data(),
                             image.width * 3) == 0) {
    throw std::runtime_error("PNG encoding failed");
  }
  Bytes chunks;
  for (const PngText& record : text) {
    check_png_text(record);
    Bytes data(record.keyword.begin(), record.keyword.end());
    data.push_back(0);
    data.insert(data.end(), record.text.begin(), record.text.end());
    append_chunk(chunks, "tEXt", data.data(), data.size());
  }
  png.insert(png.begin() + kPngHeaderBytes, chunks.begin(), chunks.end());
  return png;
}

std::uint32_t read_be32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}

}  // namespace

std::vector<std::uint8_t> encode_png(const Image& image, const std::vector<PngText>& text) {
  check_image_shape(image.width, image.height, image.rgb.size(), 3, "PNG");
  return encode_png_rgb8(image, text);
}

void write_png(const Image& image, const std::filesystem::path& path,
               const std::vector<PngText>& text) {
  check_image_shape(image.width, image.height, image.rgb.size(), 3, path);
  write_atomically(path, encode_png_rgb8(image, text));
}

std::vector<PngText> read_png_text(const std::filesystem::path& path) {
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
  const std::string ext = lower_extension(path);
  if (ext != ".png" && ext != ".pfm") {
    throw InputError(path.string() + ": unsupported depth format '" + ext +
                     "' (use .png for 16-bit greyscale or .pfm for float)");
  }
  check_image_shape(depth.width, depth.height, depth.depth.size(), 1, path);
  write_atomically(path, ext == ".png" ? encode_png_grey16(depth, path) : encode_pfm(depth));
}

Image read_png(const std::filesystem::path& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw InputError(path.string() + ": cannot read PNG: " + errno_message(errno));
  }
  // stb_image sniffs many formats; only PNG is accepted here.
  static constexpr std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::uint8_t head[8] = {};
  const std::size_t got = std::fread(head, 1, sizeof head, file);
  if (got != sizeof head || std::memcmp(head, kSignature, sizeof head) != 0) {
    std::fclose(file);
    throw InputError(path.string() + ": cannot read PNG: not a PNG file");
  }
  std::rewind(file);
  int width = 0;
  int height = 0;
  int channels_in_file = 0;
  stbi_uc* pixels = stbi_load_from_file(file, &width, &height, &channels_in_file, 3);
  std::fclose(file);
  if (pixels == nullptr) {
    const char* reason = stbi_failure_reason();
    throw InputError(path.string() + ": cannot read PNG: " + (reason ? reason : "unknown error"));
  }
  Image image;
  image.width = width;
  image.height = height;
  image.rgb.assign(pixels, pixels + std::size_t(width) * std::size_t(height) * 3);
  stbi_image_free(pixels);
  return image;
}

}  // namespace covrast
