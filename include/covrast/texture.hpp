// covrast public API: textures as materials use them (docs/textures.md). A Texture is an image
// decoded once at scene load into linear-light RGBA with its whole mip chain; a TextureSlot
// is a material's use of one: the texture, how it is sampled (wrap and filters), which UV set
// and the KHR_texture_transform. The raster modes only read them.
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

/// One mip level: linear-light RGBA (alpha as stored, never sRGB-decoded), row 0 is the
/// image's first (top) row, which glTF's v = 0 addresses.
struct TextureLevel {
  int width = 0;
  int height = 0;
  std::vector<glm::vec4> texels;  ///< width x height, row by row
  const glm::vec4& at(int x, int y) const { return texels[std::size_t(y) * width + x]; }
};

/// A decoded texture: levels[0] is the image, level k + 1 the 2x2 box filter of level k
/// (make_texture), down to 1x1.
struct Texture {
  std::string name;  ///< for messages: "model.gltf: image 2 (helmet.png)"
  std::vector<TextureLevel> levels;
};

/// A texture from 8-bit RGBA texels (row 0 at the top, 4 bytes per texel): RGB decoded from
/// sRGB when `srgb` (baseColor, emissive, OBJ map_Kd), kept linear otherwise (metallic-
/// roughness, normal, occlusion); alpha always linear. Builds the mip chain in linear light:
/// each level's side is max(1, floor(side / 2)); texel (i, j) is the mean of the source texels
/// 2i, 2i + 1 (and 2i + 2 for the last texel of an odd side) in x times the same in y, so that
/// every source texel contributes and a level's mean equals its source's.
std::shared_ptr<const Texture> make_texture(std::string name, int width, int height,
                                            const std::vector<std::uint8_t>& rgba8, bool srgb);

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
