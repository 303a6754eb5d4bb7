// The glTF reader's materials (gltf_materials.hpp): the core factors, the textures
// (GltfTextures) and the extensions of the pbr material.
#include "scene/gltf_materials.hpp"

#include "scene/gltf_accessors.hpp"
#include "scene/gltf_textures.hpp"

#include <tiny_gltf.h>

#include <algorithm>
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

/// A number of an extension object ("emissiveStrength" of KHR_materials_emissive_strength),
/// or `fallback`.
double extension_number(const tinygltf::ExtensionMap& extensions, const char* extension,
                        const char* key, double fallback) {
  const auto it = extensions.find(extension);
  if (it == extensions.end() || !it->second.IsObject() || !it->second.Has(key)) return fallback;
  const tinygltf::Value& value = it->second.Get(key);
  return value.IsNumber() ? value.GetNumberAsDouble() : fallback;
}

/// A glTF material's factors as covrast shades them (glTF 2.0, 3.9 and 5.19; the textures
/// come from GltfTextures::apply): pbrMetallicRoughness' metallic and roughness factors,
/// emissiveFactor x KHR_materials_emissive_strength, doubleSided; KHR_materials_unlit selects
/// ShadingModel::Unlit. The base colour factor goes into the colour selection, as unlit.
Material convert_material(const tinygltf::Material& source) {
  Material m;
  m.model =
      source.extensions.count("KHR_materials_unlit") != 0 ? ShadingModel::Unlit : ShadingModel::Pbr;
  m.metallic = clamp_unit(source.pbrMetallicRoughness.metallicFactor);
  m.roughness = clamp_unit(source.pbrMetallicRoughness.roughnessFactor);
  const double strength = extension_number(source.extensions, "KHR_materials_emissive_strength",
                                           "emissiveStrength", 1.0);
  const double scale = std::isfinite(strength) && strength > 0.0 ? strength : 0.0;
  if (source.emissiveFactor.size() == 3) {
    for (int c = 0; c < 3; ++c) {
      m.emissive_linear[c] =
          static_cast<float>(clamp_unit(source.emissiveFactor[std::size_t(c)]) * scale);
    }
  }
  m.double_sided = source.doubleSided;
  // alphaMode, alphaCutoff and baseColorFactor's alpha (3.9.4); GltfMeshBuilder refuses other
  // modes (tinygltf's default is "OPAQUE").
  m.alpha_mode = source.alphaMode == "MASK"    ? AlphaMode::Mask
                 : source.alphaMode == "BLEND" ? AlphaMode::Blend
                                               : AlphaMode::Opaque;
  // In double, as the file gives them (a cutoff of 0.3 stays 0.3); NaN becomes 0.
  const auto unit = [](double v) { return v >= 0.0 ? std::min(v, 1.0) : 0.0; };
  m.alpha_cutoff = unit(source.alphaCutoff);
  const std::vector<double>& factor = source.pbrMetallicRoughness.baseColorFactor;
  if (factor.size() == 4) m.base_alpha = unit(factor[3]);
  return m;
}

/// KHR_materials_iridescence: iridescenceFactor (0..1) and its texture (R), iridescenceIor
/// (>= 1), iridescenceThicknessMinimum and Maximum (nm, >= 0) and the thickness texture (G).
void read_iridescence(const ExtensionObject& e, const std::string& name, GltfTextures& textures,
                      Material& m) {
  m.iridescence = static_cast<float>(number_in(e, "iridescenceFactor", 0.0, 0.0, 1.0, name));
  m.iridescence_ior = static_cast<float>(number_in(e, "iridescenceIor", 1.3, 1.0, 1e6, name));
  m.iridescence_thickness_min_nm =
      static_cast<float>(number_in(e, "iridescenceThicknessMinimum", 100.0, 0.0, 1e6, name));
  m.iridescence_thickness_max_nm =
      static_cast<float>(number_in(e, "iridescenceThicknessMaximum", 400.0, 0.0, 1e6, name));
  m.iridescence_texture = texture(e, "iridescenceTexture", false, textures);
  m.iridescence_thickness_texture = texture(e, "iridescenceThicknessTexture", false, textures);
}

/// KHR_materials_anisotropy: anisotropyStrength (0..1) and anisotropyRotation (radians, any
/// finite number), anisotropyTexture (RG direction, B strength; linear).
void read_anisotropy(const ExtensionObject& e, const std::string& name, GltfTextures& textures,
                     Material& m) {
  m.anisotropy = static_cast<float>(number_in(e, "anisotropyStrength", 0.0, 0.0, 1.0, name));
  m.anisotropy_rotation =
      static_cast<float>(number_in(e, "anisotropyRotation", 0.0, -1e6, 1e6, name));
  m.anisotropy_texture = texture(e, "anisotropyTexture", false, textures);
}

/// KHR_materials_transmission: transmissionFactor (0..1) and transmissionTexture (R, linear).
void read_transmission(const ExtensionObject& e, const std::string& name, GltfTextures& textures,
                       Material& m) {
  m.transmission = static_cast<float>(number_in(e, "transmissionFactor", 0.0, 0.0, 1.0, name));
  m.transmission_texture = texture(e, "transmissionTexture", false, textures);
}

/// KHR_materials_volume: thicknessFactor (>= 0, the mesh's units) and thicknessTexture (G),
/// attenuationDistance (> 0; absent: infinite) and attenuationColor (three numbers in 0..1).
void read_volume(const ExtensionObject& e, const std::string& name, GltfTextures& textures,
                 Material& m) {
  m.thickness = static_cast<float>(number_in(e, "thicknessFactor", 0.0, 0.0, 1e30, name));
  m.thickness_texture = texture(e, "thicknessTexture", false, textures);
  if (e.value->Has("attenuationDistance")) {
    const double distance = number_in(e, "attenuationDistance", 0.0, 0.0, 1e30, name);
    if (!(distance > 0.0)) fail(name, e.path + ".attenuationDistance: expected a number > 0");
    m.attenuation_distance = static_cast<float>(distance);
  }
  read_unit_color(e, "attenuationColor", name, m.attenuation_color);
}

/// KHR_materials_dispersion: dispersion (>= 0), kept: without refraction it spreads nothing.
void read_dispersion(const ExtensionObject& e, const std::string& name, Material& m) {
  m.dispersion = static_cast<float>(number_in(e, "dispersion", 0.0, 0.0, 1e30, name));
}

}  // namespace

std::vector<Material> read_materials(const tinygltf::Model& model, GltfTextures& textures,
                                     std::vector<std::string>& warnings) {
  const std::string& name = textures.file_name();
  std::vector<Material> materials;
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    const std::string& mode = model.materials[i].alphaMode;
    if (mode != "OPAQUE" && mode != "MASK" && mode != "BLEND") {
      fail(name, "material " + std::to_string(i) + ": alphaMode \"" + mode +
                     "\" is not OPAQUE, MASK or BLEND");
    }
    // glTF 2.0, 5.19: alphaCutoff >= 0. Used in MASK mode: an error; else ignored: a
    // warning (issue 28: -1 was taken as 0).
    if (const double cutoff = model.materials[i].alphaCutoff; !(cutoff >= 0.0)) {
      const std::string message = "material " + std::to_string(i) + ": alphaCutoff " +
                                  number_text(cutoff) + " must be >= 0";
      if (mode == "MASK") fail(name, message);
      warnings.push_back(name + ": " + message + " (ignored: alphaMode is " + mode + ")");
    }
    materials.push_back(convert_material(model.materials[i]));
    textures.apply(model.materials[i], int(i), materials.back());
    read_material_extensions(model.materials[i], int(i), textures, materials.back());
  }
  materials.push_back(convert_material(tinygltf::Material{}));
  return materials;
}

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
  if (const ExtensionObject e = find_extension(source, index, kIridescenceExtension, name);
      e.value) {
    read_iridescence(e, name, textures, m);
  }
  if (const ExtensionObject e = find_extension(source, index, kAnisotropyExtension, name);
      e.value) {
    read_anisotropy(e, name, textures, m);
  }
  if (const ExtensionObject e = find_extension(source, index, kTransmissionExtension, name);
      e.value) {
    read_transmission(e, name, textures, m);
  }
  if (const ExtensionObject e = find_extension(source, index, kVolumeExtension, name); e.value) {
    read_volume(e, name, textures, m);
  }
  if (const ExtensionObject e = find_extension(source, index, kDispersionExtension, name);
      e.value) {
    read_dispersion(e, name, m);
  }
}

}  // namespace covrast::detail
