// The glTF reader's materials (mesh_gltf.cpp): the core material's factors and textures, and
// the material extensions that change the pbr material (docs/shading.md, "Material
// extensions"), read as their specifications in
// KhronosGroup/glTF, extensions/2.0/Khronos/, define them: KHR_materials_ior, _specular,
// _clearcoat, _sheen and _iridescence.
#pragma once

#include <covrast/scene.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace tinygltf {
class Model;
struct Material;
}  // namespace tinygltf

namespace covrast::detail {

class GltfTextures;

inline constexpr std::string_view kIorExtension = "KHR_materials_ior";
inline constexpr std::string_view kSpecularExtension = "KHR_materials_specular";
inline constexpr std::string_view kClearcoatExtension = "KHR_materials_clearcoat";
inline constexpr std::string_view kSheenExtension = "KHR_materials_sheen";
inline constexpr std::string_view kIridescenceExtension = "KHR_materials_iridescence";
inline constexpr std::string_view kAnisotropyExtension = "KHR_materials_anisotropy";
inline constexpr std::string_view kTransmissionExtension = "KHR_materials_transmission";
inline constexpr std::string_view kVolumeExtension = "KHR_materials_volume";
inline constexpr std::string_view kDispersionExtension = "KHR_materials_dispersion";

/// The file's materials as covrast shades them, in file order, then glTF's default material
/// (for primitives without one): each material's factors (glTF 2.0, 3.9 and 5.19), textures
/// (`textures`) and extensions. An alphaMode other than OPAQUE, MASK and BLEND, or a negative
/// alphaCutoff in MASK mode, is an InputError; a negative alphaCutoff otherwise a line of
/// `warnings`.
std::vector<Material> read_materials(const tinygltf::Model& model, GltfTextures& textures,
                                     std::vector<std::string>& warnings);

/// Sets `m`'s extension fields and texture slots from material `index`'s extensions. Every
/// value is checked for type and range as the extensions' schemas give them; a wrong one is
/// an InputError naming its JSON path (materials[i].extensions.NAME.key).
void read_material_extensions(const tinygltf::Material& source, int index, GltfTextures& textures,
                              Material& m);

}  // namespace covrast::detail
