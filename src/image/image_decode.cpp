// Texture images from memory (docs/textures.md): PNG through libspng, JPEG through
// libturbojpeg, WebP through libwebp, chosen by content, each as RGBA8. Every decoder reads
// and checks the header against covrast's limits (docs/limits.md) before any pixel memory is
// allocated; the file form (read_image) reads a bounded regular file first.
#include "image/spng_context.hpp"

#include "core/file_read.hpp"

#include <covrast/image.hpp>

#include <spng.h>
#include <turbojpeg.h>
#include <webp/decode.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace covrast {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr std::uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};

/// The size limits of a decoded image (docs/limits.md), from a header's dimensions; empty when they
/// pass.
std::string over_limits(std::uint64_t width, std::uint64_t height) {
  if (width == 0 || height == 0) return "image is empty";
  if (width > std::uint64_t(kMaxPngSide) || height > std::uint64_t(kMaxPngSide) ||
      width * height > kMaxPngPixels) {
    return std::to_string(width) + "x" + std::to_string(height) + " is more than the " +
           std::to_string(kMaxPngPixels) + " pixels (sides up to " + std::to_string(kMaxPngSide) +
           ") covrast reads";
  }
  return {};
}

/// An indexed PNG: libspng looks up an index past the palette without a word (issue 28), so
/// the indices are decoded as they are stored, each checked, then looked up here in the
/// palette, with tRNS as alpha.
void decode_indexed_png(spng_ctx* ctx, const spng_ihdr& ihdr, RgbaImage& image,
                        const std::function<void(const std::string&)>& fail) {
  spng_plte plte{};
  if (const int error = spng_get_plte(ctx, &plte); error != 0) fail(spng_strerror(error));
  spng_trns trns{};
  const bool has_trns = spng_get_trns(ctx, &trns) == 0;
  std::size_t raw_size = 0;
  if (const int error = spng_decoded_image_size(ctx, SPNG_FMT_PNG, &raw_size); error != 0) {
    fail(spng_strerror(error));
  }
  Bytes raw(raw_size);
  if (const int error = spng_decode_image(ctx, raw.data(), raw_size, SPNG_FMT_PNG, 0); error != 0) {
    fail(spng_strerror(error));
  }
  const std::size_t width = ihdr.width, height = ihdr.height, bits = ihdr.bit_depth;
  const std::size_t row_bytes = raw_size / height;
  image.rgba.resize(width * height * 4);
  for (std::size_t y = 0; y < height; ++y) {
    for (std::size_t x = 0; x < width; ++x) {
      const std::size_t bit = x * bits;
      const unsigned byte = raw[y * row_bytes + bit / 8];
      const unsigned index = (byte >> (8 - bits - bit % 8)) & ((1u << bits) - 1u);
      if (index >= plte.n_entries) {
        fail("palette index " + std::to_string(index) + " at (" + std::to_string(x) + ", " +
             std::to_string(y) + ") is past the palette's " + std::to_string(plte.n_entries) +
             " entries");
      }
      std::uint8_t* out = &image.rgba[(y * width + x) * 4];
      out[0] = plte.entries[index].red;
      out[1] = plte.entries[index].green;
      out[2] = plte.entries[index].blue;
      out[3] = has_trns && index < trns.n_type3_entries ? trns.type3_alpha[index] : 255;
    }
  }
}

/// PNG from memory through libspng, as RGBA8 with tRNS applied.
RgbaImage decode_png_rgba(const std::uint8_t* bytes, std::size_t size,
                          const std::function<void(const std::string&)>& fail) {
  const SpngContext png(0);
  spng_ctx* ctx = png.get();
  spng_set_image_limits(ctx, std::uint32_t(kMaxPngSide), std::uint32_t(kMaxPngSide));
  spng_set_chunk_limits(ctx, kMaxPngChunkBytes, kMaxPngChunkBytes);
  spng_set_png_buffer(ctx, bytes, size);
  spng_ihdr ihdr{};
  if (const int error = spng_get_ihdr(ctx, &ihdr); error != 0) fail(spng_strerror(error));
  if (const std::string why = over_limits(ihdr.width, ihdr.height); !why.empty()) fail(why);
  std::size_t out_size = 0;
  if (const int error = spng_decoded_image_size(ctx, SPNG_FMT_RGBA8, &out_size); error != 0) {
    fail(spng_strerror(error));
  }
  RgbaImage image;
  image.width = int(ihdr.width);
  image.height = int(ihdr.height);
  if (ihdr.color_type == SPNG_COLOR_TYPE_INDEXED) {
    decode_indexed_png(ctx, ihdr, image, fail);
  } else {
    image.rgba.resize(out_size);
    if (const int error =
            spng_decode_image(ctx, image.rgba.data(), out_size, SPNG_FMT_RGBA8, SPNG_DECODE_TRNS);
        error != 0) {
      fail(spng_strerror(error));
    }
  }
  // libspng checks the last IDAT chunk's CRC only when it reads on: a PNG whose image data
  // fails its checksum decoded without a word (issue 28). The chunks after the image are
  // read here (bounded by the chunk limits), so that it and a missing IEND are errors.
  if (const int error = spng_decode_chunks(ctx); error != 0) fail(spng_strerror(error));
  return image;
}

/// Owns a libturbojpeg decompressor.
class TurboJpeg {
 public:
  TurboJpeg() : handle_(tjInitDecompress()) {
    if (handle_ == nullptr) throw std::bad_alloc();
  }
  ~TurboJpeg() { tjDestroy(handle_); }
  TurboJpeg(const TurboJpeg&) = delete;
  TurboJpeg& operator=(const TurboJpeg&) = delete;
  tjhandle get() const { return handle_; }

 private:
  tjhandle handle_;
};

/// JPEG from memory through libturbojpeg, as RGBA8 (alpha 255). TJFLAG_STOPONWARNING makes a
/// corrupt or truncated stream an error instead of a partly grey image; TJFLAG_LIMITSCANS
/// refuses a progressive JPEG of more than 500 scans (libjpeg-turbo's limit: a valid file of
/// 2,080 scans took 15 s and 991 MB to decode, issue 28).
RgbaImage decode_jpeg_rgba(const std::uint8_t* bytes, std::size_t size,
                           const std::function<void(const std::string&)>& fail) {
  if (size > std::size_t(0xFFFFFFFFu)) fail("file too large");
  const TurboJpeg jpeg;
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(jpeg.get(), bytes, static_cast<unsigned long>(size), &width, &height,
                          &subsampling, &colorspace) != 0) {
    fail(tjGetErrorStr2(jpeg.get()));
  }
  if (width <= 0 || height <= 0) fail("image is empty");
  if (const std::string why = over_limits(std::uint64_t(width), std::uint64_t(height));
      !why.empty()) {
    fail(why);
  }
  if (colorspace == TJCS_CMYK || colorspace == TJCS_YCCK) fail("CMYK JPEG is not supported");
  RgbaImage image;
  image.width = width;
  image.height = height;
  image.rgba.resize(std::size_t(width) * std::size_t(height) * 4);
  if (tjDecompress2(jpeg.get(), bytes, static_cast<unsigned long>(size), image.rgba.data(), width,
                    0, height, TJPF_RGBA,
                    TJFLAG_ACCURATEDCT | TJFLAG_STOPONWARNING | TJFLAG_LIMITSCANS) != 0) {
    fail(tjGetErrorStr2(jpeg.get()));
  }
  return image;
}

/// Whether the bytes are a WebP file: a RIFF container of form type WEBP.
bool is_webp(const std::uint8_t* bytes, std::size_t size) {
  return size >= 12 && std::memcmp(bytes, "RIFF", 4) == 0 && std::memcmp(bytes + 8, "WEBP", 4) == 0;
}

/// WebP from memory through libwebp (lossy, lossless, with or without alpha; EXT_texture_webp)
/// as RGBA8. The size comes from the header (WebPGetFeatures) and is checked against the
/// limits before the pixels are allocated; an animation is refused (a texture has one image).
RgbaImage decode_webp_rgba(const std::uint8_t* bytes, std::size_t size,
                           const std::function<void(const std::string&)>& fail) {
  WebPBitstreamFeatures features;
  if (const VP8StatusCode status = WebPGetFeatures(bytes, size, &features);
      status != VP8_STATUS_OK) {
    fail("not a valid WebP header (libwebp status " + std::to_string(int(status)) + ")");
  }
  if (features.has_animation) fail("animated WebP is not supported");
  if (features.width <= 0 || features.height <= 0) fail("image is empty");
  if (const std::string why =
          over_limits(std::uint64_t(features.width), std::uint64_t(features.height));
      !why.empty()) {
    fail(why);
  }
  RgbaImage image;
  image.width = features.width;
  image.height = features.height;
  image.rgba.resize(std::size_t(image.width) * std::size_t(image.height) * 4);
  if (WebPDecodeRGBAInto(bytes, size, image.rgba.data(), image.rgba.size(), image.width * 4) ==
      nullptr) {
    fail("corrupt or truncated WebP data");
  }
  return image;
}

}  // namespace

RgbaImage decode_image(const std::uint8_t* bytes, std::size_t size, const std::string& name) {
  const std::function<void(const std::string&)> fail = [&](const std::string& why) {
    throw InputError(name + ": cannot decode image: " + why);
  };
  if (size >= sizeof kPngSignature &&
      std::memcmp(bytes, kPngSignature, sizeof kPngSignature) == 0) {
    return decode_png_rgba(bytes, size, fail);
  }
  if (size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF) {
    return decode_jpeg_rgba(bytes, size, fail);
  }
  if (is_webp(bytes, size)) return decode_webp_rgba(bytes, size, fail);
  fail(size == 0 ? "empty" : "neither PNG, JPEG nor WebP (by its first bytes)");
  return {};
}

RgbaImage read_image(const std::filesystem::path& path, const std::string& name) {
  const auto fail = [&](const std::string& why) {
    throw InputError(name + ": cannot read image: " + why);
  };
  // Bounded: an image over the limits is refused from its header anyway, and no PNG or JPEG
  // of at most kMaxPngPixels needs more than this many bytes. The reader refuses what is not
  // a regular file and, before a byte is read, a file over the limit (issue 28: a file near
  // 1 GiB was read in full, into a growing buffer, before its size was checked).
  constexpr std::uint64_t kMaxImageFileBytes = std::uint64_t(1) << 30;
  Bytes bytes;
  if (std::string error; !detail::read_whole_file(path, bytes, error, kMaxImageFileBytes)) {
    fail(error);
  }
  return decode_image(bytes.data(), bytes.size(), name);
}

}  // namespace covrast
