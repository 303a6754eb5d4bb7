// covrast public API: images and their files. The last stage of the pipeline; the only
// part of covrast that decodes or encodes image files.
#pragma once

#include <covrast/error.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace covrast {

/// 8-bit sRGB-encoded RGB image, row 0 at the top, rows packed (stride = 3 * width), with an
/// optional alpha plane.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;
  /// Empty: opaque (PNG RGB). Else one linear 8-bit alpha per pixel, the colour not
  /// premultiplied (PNG RGBA): a transparent background (Scene::background_kind).
  std::vector<std::uint8_t> alpha;
  std::uint8_t* pixel(int x, int y) { return &rgb[(std::size_t(y) * width + x) * 3]; }
  const std::uint8_t* pixel(int x, int y) const { return &rgb[(std::size_t(y) * width + x) * 3]; }
};

/// Window depth per pixel in [0, 1] (0 = near plane, 1 = far plane); background = 1.
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<float> depth;
};

/// A text record of a PNG file (a tEXt chunk): a keyword of 1..79 printable ASCII characters
/// and ASCII text (golden images record what rendered them this way).
struct PngText {
  std::string keyword;
  std::string text;
};

/// Writes a PNG atomically: a temporary file beside the target, then rename, so that a
/// failure never leaves a partial or overwritten file. Throws InputError naming the path.
/// `text` records go into tEXt chunks right after the header.
void write_png(const Image& image, const std::filesystem::path& path,
               const std::vector<PngText>& text = {});

/// The PNG file write_png writes, in memory (for embedding, e.g. in an HTML report).
std::vector<std::uint8_t> encode_png(const Image& image, const std::vector<PngText>& text = {});

/// Writes depth as 16-bit greyscale PNG (.png) or as a little-endian PFM (.pfm), atomically.
void write_depth(const DepthImage& depth, const std::filesystem::path& path);

/// The largest PNG read_png reads: each side at most kMaxPngSide, at most kMaxPngPixels in
/// all (a 8192x8192 image; 192 MiB as RGB), chunks of at most kMaxPngChunkBytes. Checked
/// from the header before anything is allocated.
inline constexpr int kMaxPngSide = 16384;
inline constexpr std::uint64_t kMaxPngPixels = std::uint64_t(1) << 26;
inline constexpr std::size_t kMaxPngChunkBytes = std::size_t(1) << 26;

/// Reads a PNG of any colour type and bit depth as 8-bit RGB (grey expanded, palette looked
/// up, 16-bit samples reduced to their high byte); an alpha channel (colour types 4 and 6) is
/// kept in Image::alpha, not composited (tRNS is dropped). Throws InputError naming
/// the file and the problem, also for files over the limits above or not regular files.
Image read_png(const std::filesystem::path& path);

/// 8-bit RGBA texels of a decoded image file (textures), row 0 at the top, 4 bytes a texel.
struct RgbaImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;
};

/// Decodes a PNG (libspng), JPEG (libturbojpeg) or WebP (libwebp) held in memory, recognised
/// by its first bytes (the PNG signature, the JPEG start-of-image marker FF D8 FF, or a RIFF
/// header of form WEBP), never by a file name. PNG: any colour type and bit depth, tRNS
/// applied as alpha, 16-bit samples reduced to their high byte. JPEG: baseline or
/// progressive, grey or YCbCr (a CMYK file is refused), alpha 255; any corrupt-data warning
/// is an error. WebP: lossy or lossless, with or without alpha; an animation is refused. The
/// limits of read_png (kMaxPngSide, kMaxPngPixels) are checked from the header before
/// anything is allocated. Throws InputError("NAME: cannot decode image: why").
RgbaImage decode_image(const std::uint8_t* bytes, std::size_t size, const std::string& name);

/// decode_image of a whole file; refuses what is not a regular file (a FIFO would block).
/// Throws InputError("NAME: cannot read image: why") when it cannot be read, with `name` as
/// given (e.g. "model.gltf: image 2 (wood.png)").
RgbaImage read_image(const std::filesystem::path& path, const std::string& name);

}  // namespace covrast
