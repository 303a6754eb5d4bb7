// The glTF material extensions of the pbr material (gltf_materials.hpp).
#include "scene/gltf_materials.hpp"

#include "scene/gltf_accessors.hpp"
#include "scene/gltf_textures.hpp"

#include <tiny_gltf.h>

#include <cmath>
#include <string>

namespace covrast::detail {
namespace {

/// One extension object of a material, with its JSON path for messages.
struct ExtensionObject {
  const tinygltf::Value* value = nullptr;  ///< null: the material does not use it
  std::string path;
};

ExtensionObject find_extension(const tinygltf::Material& source, int index,
                               std::string_view extension, const std::string& name) {
  ExtensionObject out;
  out.path = "materials[" + std::to_string(index) + "].extensions." + std::string(extension);
  const auto it = source.extensions.find(std::string(extension));
  if (it == source.extensions.end()) return out;
  if (!it->second.IsObject()) fail(name, out.path + ": expected an object");
  out.value = &it->second;
  return out;
}

/// The number `key` of an extension object in [lo, hi], or `fallback` when absent.
double number_in(const ExtensionObject& e, const char* key, double fallback, double lo, double hi,
                 const std::string& name) {
  if (!e.value->Has(key)) return fallback;
  const tinygltf::Value& v = e.value->Get(key);
  const double x = v.IsNumber() ? v.GetNumberAsDouble() : std::nan("");
  if (!(x >= lo && x <= hi)) {
    fail(name,
         e.path + "." + key + ": expected a number in " + number_text(lo) + ".." + number_text(hi));
  }
  return x;
}

/// The texture `key` of an extension object (a textureInfo), or an empty slot when absent.
TextureSlot texture(const ExtensionObject& e, const char* key, bool srgb, GltfTextures& textures) {
  if (!e.value->Has(key)) return {};
  return textures.info_slot(e.value->Get(key), srgb, e.path + "." + key);
}

/// KHR_materials_ior: {"ior": 0 or >= 1, default 1.5}.
void read_ior(const ExtensionObject& e, const std::string& name, Material& m) {
  if (!e.value->Has("ior")) return;
  const tinygltf::Value& v = e.value->Get("ior");
  const double ior = v.IsNumber() ? v.GetNumberAsDouble() : std::nan("");
  if (!(ior == 0.0 || (ior >= 1.0 && std::isfinite(ior)))) {
    fail(name, e.path + ".ior: expected 0 or a number >= 1");
  }
  m.ior = static_cast<float>(ior);
}

/// KHR_materials_specular: specularFactor (0..1), specularTexture (A), specularColorFactor
/// (three numbers >= 0, linear), specularColorTexture (RGB, sRGB).
void read_specular(const ExtensionObject& e, const std::string& name, GltfTextures& textures,
                   Material& m) {
  m.specular_factor = static_cast<float>(number_in(e, "specularFactor", 1.0, 0.0, 1.0, name));
  if (e.value->Has("specularColorFactor")) {
    const tinygltf::Value& a = e.value->Get("specularColorFactor");
    bool ok = a.IsArray() && a.ArrayLen() == 3;
    for (int c = 0; ok && c < 3; ++c) {
      const tinygltf::Value& v = a.Get(c);
      ok = v.IsNumber() && v.GetNumberAsDouble() >= 0.0 && std::isfinite(v.GetNumberAsDouble());
      if (ok) m.specular_color_factor[c] = static_cast<float>(v.GetNumberAsDouble());
    }
    if (!ok) fail(name, e.path + ".specularColorFactor: expected an array of 3 numbers >= 0");
  }
  m.specular_texture = texture(e, "specularTexture", false, textures);
  m.specular_color_texture = texture(e, "specularColorTexture", true, textures);
}

/// KHR_materials_clearcoat: clearcoatFactor and clearcoatRoughnessFactor (0..1, default 0),
/// their textures (R and G, linear) and clearcoatNormalTexture (a normalTextureInfo).
void read_clearcoat(const ExtensionObject& e, const std::string& name, GltfTextures& textures,
                    Material& m) {
  m.clearcoat = static_cast<float>(number_in(e, "clearcoatFactor", 0.0, 0.0, 1.0, name));
  m.clearcoat_roughness =
      static_cast<float>(number_in(e, "clearcoatRoughnessFactor", 0.0, 0.0, 1.0, name));
  m.clearcoat_texture = texture(e, "clearcoatTexture", false, textures);
  m.clearcoat_roughness_texture = texture(e, "clearcoatRoughnessTexture", false, textures);
  m.clearcoat_normal_texture = texture(e, "clearcoatNormalTexture", false, textures);
}

/// Three numbers in [0, 1] (sheenColorFactor) into `out`, which keeps its value when absent.
void read_unit_color(const ExtensionObject& e, const char* key, const std::string& name,
                     glm::vec3& out) {
  if (!e.value->Has(key)) return;
  const tinygltf::Value& a = e.value->Get(key);
  bool ok = a.IsArray() && a.ArrayLen() == 3;
  for (int c = 0; ok && c < 3; ++c) {
    const tinygltf::Value& v = a.Get(c);
    const double x = v.IsNumber() ? v.GetNumberAsDouble() : std::nan("");
    ok = x >= 0.0 && x <= 1.0;
    if (ok) out[c] = static_cast<float>(x);
  }
  if (!ok) fail(name, e.path + "." + key + ": expected an array of 3 numbers in 0..1");
}

/// KHR_materials_sheen: sheenColorFactor (three numbers in 0..1, linear, default black: no
/// sheen), sheenColorTexture (RGB, sRGB), sheenRoughnessFactor (0..1) and its texture (A).
void read_sheen(const ExtensionObject& e, const std::string& name, GltfTextures& textures,
                Material& m) {
  read_unit_color(e, "sheenColorFactor", name, m.sheen_color_factor);
  m.sheen_roughness = static_cast<float>(number_in(e, "sheenRoughnessFactor", 0.0, 0.0, 1.0, name));
  m.sheen_color_texture = texture(e, "sheenColorTexture", true, textures);
  m.sheen_roughness_texture = texture(e, "sheenRoughnessTexture", false, textures);
}

}  // namespace

void read_material_extensions(const tinygltf::Material& source, int index, GltfTextures& textures,
                              Material& m) {
  const std::string& name = textures.file_name();
  if (const ExtensionObject e = find_extension(source, index, kIorExtension, name); e.value) {
    read_ior(e, name, m);
  }
  if (const ExtensionObject e = find_extension(source, index, kSpecularExtension, name); e.value) {
    read_specular(e, name, textures, m);
  }
  if (const ExtensionObject e = find_extension(source, index, kClearcoatExtension, name); e.value) {
    read_clearcoat(e, name, textures, m);
  }
  if (const ExtensionObject e = find_extension(source, index, kSheenExtension, name); e.value) {
    read_sheen(e, name, textures, m);
  }
}

}  // namespace covrast::detail
