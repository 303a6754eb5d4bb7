// What covrast does with each glTF extension (docs/scene-format.md, "glTF extensions"): the
// one table behind the loader's warnings and `covrast info`.
#include <covrast/scene.hpp>

#include <array>
#include <string_view>

namespace covrast {
namespace {

struct KnownExtension {
  std::string_view name;
  GltfExtensionSupport support;
  std::string_view effect;
};

constexpr std::string_view kCoreMaterial =
    "drawn with the core metallic-roughness material, without the extension's layer";
constexpr std::string_view kFallbackImage =
    "each texture uses its core image, the fallback the extension asks files to give";

constexpr std::array<KnownExtension, 28> kKnown{{
    {"EXT_mesh_gpu_instancing", GltfExtensionSupport::Honoured, "instances drawn"},
    {"KHR_draco_mesh_compression", GltfExtensionSupport::Honoured, "decoded (libdraco)"},
    {"KHR_lights_punctual", GltfExtensionSupport::Honoured,
     "lights used with \"lights\": \"gltf\""},
    {"KHR_materials_emissive_strength", GltfExtensionSupport::Honoured, "emission scaled"},
    {"KHR_materials_unlit", GltfExtensionSupport::Honoured, "unlit materials"},
    {"KHR_mesh_quantization", GltfExtensionSupport::Honoured, "quantized attributes read"},
    {"KHR_texture_transform", GltfExtensionSupport::Honoured, "texture transforms applied"},
    {"EXT_texture_webp", GltfExtensionSupport::Honoured, "WebP images decoded (libwebp)"},
    {"KHR_materials_variants", GltfExtensionSupport::Honoured,
     "the default materials, or the variant --variant or a scene's \"variant\" names"},
    {"EXT_meshopt_compression", GltfExtensionSupport::Honoured,
     "compressed buffer views decoded (libmeshoptimizer)"},
    {"KHR_materials_anisotropy", GltfExtensionSupport::Honoured,
     "the specular lobe stretched along its direction, with its texture"},
    {"KHR_materials_clearcoat", GltfExtensionSupport::Honoured,
     "the clear coat layered over the material, with its textures and normal map"},
    {"KHR_materials_diffuse_transmission", GltfExtensionSupport::Ignored, kCoreMaterial},
    {"KHR_materials_dispersion", GltfExtensionSupport::Honoured,
     "read; without refraction (thin-walled transmission) there is no spread to draw"},
    {"KHR_materials_ior", GltfExtensionSupport::Honoured,
     "the dielectric's F0 from its index of refraction"},
    {"KHR_materials_iridescence", GltfExtensionSupport::Honoured,
     "the thin film's interference colours in the Fresnel term, with its textures"},
    {"KHR_materials_pbrSpecularGlossiness", GltfExtensionSupport::Ignored,
     "drawn with the core metallic-roughness material the file gives beside it"},
    {"KHR_materials_sheen", GltfExtensionSupport::Honoured,
     "the sheen layered over the material, with its textures"},
    {"KHR_materials_specular", GltfExtensionSupport::Honoured,
     "the dielectric's specular strength and F0 colour, with their textures"},
    {"KHR_materials_transmission", GltfExtensionSupport::Honoured,
     "thin-walled: what is behind shows through, tinted, without refraction or blur"},
    {"KHR_materials_volume", GltfExtensionSupport::Honoured,
     "attenuation over the thickness of what passes; no refraction"},
    {"KHR_animation_pointer", GltfExtensionSupport::Ignored,
     "its channels are not animated (--time poses the core channels)"},
    {"KHR_xmp_json_ld", GltfExtensionSupport::Ignored, "metadata: nothing to draw"},
    {"KHR_xmp", GltfExtensionSupport::Ignored, "metadata: nothing to draw"},
    {"KHR_texture_basisu", GltfExtensionSupport::Unreadable, kFallbackImage},
    {"EXT_texture_avif", GltfExtensionSupport::Unreadable, kFallbackImage},
    {"KHR_meshopt_compression", GltfExtensionSupport::Unreadable,
     "the uncompressed fallback buffers are read; without them the file does not load"},
    {"EXT_lights_image_based", GltfExtensionSupport::Ignored,
     "its environment is not used (give one with --environment)"},
}};

}  // namespace

GltfExtensionStatus gltf_extension_support(const std::string& name) {
  for (const KnownExtension& known : kKnown) {
    if (known.name == name) return {known.support, std::string(known.effect)};
  }
  return {GltfExtensionSupport::Ignored, "unknown to covrast: drawn without it"};
}

}  // namespace covrast
