// covrast public API: textures as materials use them (docs/textures.md). A Texture is an image
// decoded once at scene load, kept as 8-bit RGBA with its whole mip chain (filtered in linear
// light); a TextureSlot is a material's use of one: the texture, how it is sampled (wrap and
// filters), which UV set and the KHR_texture_transform. The raster modes only read them.
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace covrast {

/// glTF sampler wrap modes (glTF 2.0, 5.26: 10497 REPEAT, 33648 MIRRORED_REPEAT, 33071
/// CLAMP_TO_EDGE).
enum class TextureWrap : std::uint8_t { Repeat, MirroredRepeat, ClampToEdge };
/// Texel filter within one level: the nearest texel, or bilinear over the four nearest.
enum class TextureFilter : std::uint8_t { Nearest, Linear };
/// Between levels when minifying: level 0 only (glTF NEAREST / LINEAR minification), the
/// nearest level (*_MIPMAP_NEAREST), or linear between the two nearest (*_MIPMAP_LINEAR).
enum class MipFilter : std::uint8_t { None, Nearest, Linear };

/// How a texture is sampled. The defaults (a glTF texture without a sampler, whose filters
/// the specification leaves to the implementation): REPEAT, LINEAR magnification,
/// LINEAR_MIPMAP_LINEAR minification (trilinear).
struct TextureSampler {
  TextureWrap wrap_s = TextureWrap::Repeat;
  TextureWrap wrap_t = TextureWrap::Repeat;
  TextureFilter mag = TextureFilter::Linear;
  TextureFilter min = TextureFilter::Linear;
  MipFilter mip = MipFilter::Linear;
};

/// One mip level: 8-bit RGBA, 4 bytes a texel; texel row 0 is the image's first (top) row,
/// which glTF's v = 0 addresses. RGB are sRGB codes in an sRGB texture (Texture::srgb), code /
/// 255 otherwise; alpha is always code / 255 (Texture::linear decodes a texel).
/// Layout: blocks of 8 x 8 texels (256 bytes), each stored row by row, the blocks row by row;
/// the sides are padded to multiples of 8 (padding texels are zero and never read). A bilinear
/// footprint then mostly lies in one block, and a screen tile's texels in few memory pages.
struct TextureLevel {
  static constexpr int kBlockSide = 8;
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba8;  ///< bytes(width, height) bytes, in 8 x 8 blocks

  static int blocks(int side) { return (side + kBlockSide - 1) / kBlockSide; }
  /// The storage of a width x height level: whole blocks of 8 x 8 texels x 4 bytes.
  static std::size_t bytes(int width, int height) {
    return std::size_t(blocks(width)) * std::size_t(blocks(height)) * kBlockSide * kBlockSide * 4;
  }
  /// Byte offset of texel (x, y): block (x / 8, y / 8), then row y % 8 and column x % 8.
  std::size_t offset(int x, int y) const {
    const std::size_t block =
        std::size_t(y / kBlockSide) * std::size_t(blocks(width)) + std::size_t(x / kBlockSide);
    return (block * (kBlockSide * kBlockSide) + std::size_t(y % kBlockSide) * kBlockSide +
            std::size_t(x % kBlockSide)) *
           4;
  }
  const std::uint8_t* at(int x, int y) const { return &rgba8[offset(x, y)]; }
  std::uint8_t* at(int x, int y) { return &rgba8[offset(x, y)]; }
  /// A level from texels stored row by row (4 bytes a texel, width x height of them).
  static TextureLevel from_rows(int width, int height, const std::vector<std::uint8_t>& rows);
};

/// A decoded texture: levels[0] is the image, level k + 1 the 2x2 box filter of level k in
/// linear light (make_texture), down to 1x1.
struct Texture {
  std::string name;   ///< for messages: "model.gltf: image 2 (helmet.png)"
  bool srgb = false;  ///< RGB codes are sRGB-encoded (baseColor, emissive, OBJ map_Kd)
  std::vector<TextureLevel> levels;
  /// Texel (x, y) of `level` in linear light: RGB through the IEC 61966-2-1 decoding when
  /// `srgb`, code / 255 otherwise; alpha code / 255.
  glm::dvec4 linear(int level, int x, int y) const;
};

/// A texture from 8-bit RGBA texels (row by row, row 0 at the top, 4 bytes per texel), which
/// become level 0 as they are (rearranged into blocks): RGB sRGB-encoded when `srgb` (baseColor,
/// emissive, OBJ map_Kd), linear otherwise (metallic-roughness, normal, occlusion); alpha always
/// linear. Builds the mip chain in linear light: each level's side is max(1, floor(side / 2));
/// texel (i, j) is the mean of the source texels 2i, 2i + 1 (and 2i + 2 for the last texel of an
/// odd side) in x times the same in y, so that every source texel contributes and a level's mean
/// equals its source's. Means are taken in double precision from the unrounded level above (level
/// 0: the decoded codes) and stored as the nearest 8-bit code in the texture's encoding.
std::shared_ptr<const Texture> make_texture(std::string name, int width, int height,
                                            std::vector<std::uint8_t> rgba8, bool srgb);

/// KHR_texture_transform: uv' = T(offset) R(rotation) S(scale) uv, rotation counter-clockwise
/// in radians as the extension defines it (u' = cos r u + sin r v, v' = -sin r u + cos r v).
struct TextureTransform {
  glm::dvec2 offset{0.0};
  double rotation = 0.0;
  glm::dvec2 scale{1.0};
};

/// A material's use of a texture. An empty slot (no texture) changes nothing.
struct TextureSlot {
  std::shared_ptr<const Texture> texture;
  TextureSampler sampler;
  int texcoord = 0;  ///< which UV set (glTF TEXCOORD_n): 0 or 1
  /// normalTexture: scale of the tangent-space x and y; occlusionTexture: strength.
  float scale = 1.0f;
  TextureTransform transform;
  explicit operator bool() const { return texture != nullptr; }
};

/// Most UV sets a mesh carries (TEXCOORD_0 and TEXCOORD_1).
inline constexpr int kMaxTexcoordSets = 2;

}  // namespace covrast
