// KHR_materials_variants (gltf_variants.hpp), as its specification in KhronosGroup/glTF,
// extensions/2.0/Khronos/KHR_materials_variants, defines it.
#include "scene/gltf_variants.hpp"

#include "scene/gltf_accessors.hpp"

#include <covrast/error.hpp>

namespace covrast::detail {

std::vector<std::string> material_variant_names(const tinygltf::Model& model,
                                                const std::string& name) {
  const auto it = model.extensions.find(std::string(kVariantsExtension));
  if (it == model.extensions.end()) return {};
  const std::string where = "extensions." + std::string(kVariantsExtension) + ".variants";
  const tinygltf::Value& root = it->second;
  if (!root.IsObject() || !root.Has("variants") || !root.Get("variants").IsArray()) {
    fail(name, where + ": expected an array of variants");
  }
  const tinygltf::Value& variants = root.Get("variants");
  std::vector<std::string> names;
  for (std::size_t i = 0; i < variants.ArrayLen(); ++i) {
    const tinygltf::Value& v = variants.Get(int(i));
    if (!v.IsObject() || !v.Has("name") || !v.Get("name").IsString()) {
      fail(name, where + "[" + std::to_string(i) + "].name: expected a string");
    }
    names.push_back(v.Get("name").Get<std::string>());
  }
  return names;
}

std::string material_variants_text(const std::vector<std::string>& names) {
  if (names.empty()) return "the file has none";
  std::string text = "variants: ";
  for (std::size_t i = 0; i < names.size(); ++i) text += (i == 0 ? "" : ", ") + printable(names[i]);
  return text;
}

std::vector<std::int32_t> primitive_variant_materials(const tinygltf::Model& model,
                                                      const tinygltf::Primitive& primitive,
                                                      std::size_t variant_count,
                                                      const std::string& name,
                                                      const std::string& what) {
  const auto it = primitive.extensions.find(std::string(kVariantsExtension));
  if (it == primitive.extensions.end()) return {};
  const std::string where = what + ": extensions." + std::string(kVariantsExtension) + ".mappings";
  const tinygltf::Value& ext = it->second;
  if (!ext.IsObject() || !ext.Has("mappings") || !ext.Get("mappings").IsArray()) {
    fail(name, where + ": expected an array of mappings");
  }
  std::vector<std::int32_t> materials(variant_count, -1);
  const tinygltf::Value& mappings = ext.Get("mappings");
  for (std::size_t m = 0; m < mappings.ArrayLen(); ++m) {
    const std::string at = where + "[" + std::to_string(m) + "]";
    const tinygltf::Value& mapping = mappings.Get(int(m));
    if (!mapping.IsObject()) fail(name, at + ": expected an object");
    const std::optional<int> material =
        mapping.Has("material")
            ? whole_number(mapping.Get("material"), 0, int(model.materials.size()) - 1)
            : std::nullopt;
    if (!material) {
      fail(name, at + ".material: expected the index of one of the file's " +
                     std::to_string(model.materials.size()) + " materials");
    }
    if (!mapping.Has("variants") || !mapping.Get("variants").IsArray()) {
      fail(name, at + ".variants: expected an array of variant indices");
    }
    const tinygltf::Value& variants = mapping.Get("variants");
    for (std::size_t k = 0; k < variants.ArrayLen(); ++k) {
      const std::optional<int> variant =
          whole_number(variants.Get(int(k)), 0, int(variant_count) - 1);
      if (!variant) {
        fail(name, at + ".variants[" + std::to_string(k) + "]: expected the index of one of the " +
                       std::to_string(variant_count) + " variants");
      }
      // The specification: a variant appears in at most one mapping of a primitive.
      if (materials[std::size_t(*variant)] >= 0) {
        fail(name, at + ".variants[" + std::to_string(k) + "]: variant " +
                       std::to_string(*variant) + " is mapped twice");
      }
      materials[std::size_t(*variant)] = *material;
    }
  }
  return materials;
}

}  // namespace covrast::detail
