// KHR_materials_variants for the glTF reader (mesh_gltf.cpp): the file's variant names, and
// per primitive the material each variant draws there. A variant is chosen when the file is
// loaded (a scene's "variant", `--variant`): the loader then reads each primitive with the
// variant's material in the place of its own, so colours, alpha and textures all follow.
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace covrast::detail {

inline constexpr std::string_view kVariantsExtension = "KHR_materials_variants";

/// The names of the file's variants (the root's KHR_materials_variants.variants, in order);
/// empty without the extension. Throws InputError naming the JSON path of a malformed entry.
std::vector<std::string> material_variant_names(const tinygltf::Model& model,
                                                const std::string& name);

/// For messages: "variants: a, b", or "the file has none".
std::string material_variants_text(const std::vector<std::string>& names);

/// Per variant, the glTF material that `primitive`'s KHR_materials_variants mappings draw
/// for it, or -1 where no mapping names the variant (the primitive's own material); empty when
/// the primitive has no mappings. `what` names the primitive in messages ("mesh 0 primitive
/// 1"). Throws InputError naming the JSON path of a malformed mapping.
std::vector<std::int32_t> primitive_variant_materials(const tinygltf::Model& model,
                                                      const tinygltf::Primitive& primitive,
                                                      std::size_t variant_count,
                                                      const std::string& name,
                                                      const std::string& what);

}  // namespace covrast::detail
