// The glTF material extensions that change the pbr material (docs/shading.md, "Material
// extensions"), read for the glTF reader (mesh_gltf.cpp) as their specifications in
// KhronosGroup/glTF, extensions/2.0/Khronos/, define them: KHR_materials_ior, _specular,
// _clearcoat and _sheen.
#pragma once

#include <covrast/scene.hpp>

#include <string_view>

namespace tinygltf {
struct Material;
}

namespace covrast::detail {

class GltfTextures;

inline constexpr std::string_view kIorExtension = "KHR_materials_ior";
inline constexpr std::string_view kSpecularExtension = "KHR_materials_specular";
inline constexpr std::string_view kClearcoatExtension = "KHR_materials_clearcoat";
inline constexpr std::string_view kSheenExtension = "KHR_materials_sheen";

/// Sets `m`'s extension fields and texture slots from material `index`'s extensions. Every
/// value is checked for type and range as the extensions' schemas give them; a wrong one is
/// an InputError naming its JSON path (materials[i].extensions.NAME.key).
void read_material_extensions(const tinygltf::Material& source, int index, GltfTextures& textures,
                              Material& m);

}  // namespace covrast::detail
