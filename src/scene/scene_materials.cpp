// Scene file loader, materials: the shading model, the glTF material extensions' keys and the
// rest of a "material" object (SceneReader, scene_reader.hpp), and the materials an instance
// draws with, the file's with the scene's keys applied.
#include "scene/scene_reader.hpp"

#include <numbers>
#include <string>
#include <vector>

namespace covrast::detail {

ShadingModel SceneReader::shading_model(const json& value, const std::string& path) const {
  if (value == "unlit") return ShadingModel::Unlit;
  if (value == "lambert") return ShadingModel::Lambert;
  if (value == "blinn-phong") return ShadingModel::BlinnPhong;
  if (value == "pbr") return ShadingModel::Pbr;
  fail(file_, path,
       "expected \"unlit\", \"lambert\", \"blinn-phong\" or \"pbr\", got " + shown(value));
}

/// The keys of the glTF material extensions (KHR_materials_ior, _specular, _clearcoat,
/// _sheen, _iridescence, _anisotropy, _transmission, _volume).
void SceneReader::apply_material_extensions(const json& object, const std::string& key,
                                            Material& m) const {
  if (const auto it = object.find("ior"); it != object.end()) {
    const double ior = number_in(*it, key + ".ior", 0.0, 1e6);
    if (ior != 0.0 && ior < 1.0) {
      fail(file_, key + ".ior", "expected 0 or a number >= 1, got " + shown(*it));
    }
    m.ior = static_cast<float>(ior);
  }
  if (const auto it = object.find("specular_factor"); it != object.end()) {
    m.specular_factor = static_cast<float>(number_in(*it, key + ".specular_factor", 0.0, 1.0));
  }
  if (const auto it = object.find("clearcoat"); it != object.end()) {
    m.clearcoat = static_cast<float>(number_in(*it, key + ".clearcoat", 0.0, 1.0));
  }
  if (const auto it = object.find("iridescence"); it != object.end()) {
    m.iridescence = static_cast<float>(number_in(*it, key + ".iridescence", 0.0, 1.0));
  }
  if (const auto it = object.find("iridescence_ior"); it != object.end()) {
    m.iridescence_ior = static_cast<float>(number_in(*it, key + ".iridescence_ior", 1.0, 10.0));
  }
  if (const auto it = object.find("iridescence_thickness_nm"); it != object.end()) {
    m.iridescence_thickness_max_nm =
        static_cast<float>(number_in(*it, key + ".iridescence_thickness_nm", 0.0, 10000.0));
  }
  if (const auto it = object.find("sheen_color"); it != object.end()) {
    m.sheen_color_factor = srgb_color(*it, key + ".sheen_color");
  }
  if (const auto it = object.find("sheen_roughness"); it != object.end()) {
    m.sheen_roughness = static_cast<float>(number_in(*it, key + ".sheen_roughness", 0.0, 1.0));
  }
  if (const auto it = object.find("clearcoat_roughness"); it != object.end()) {
    m.clearcoat_roughness =
        static_cast<float>(number_in(*it, key + ".clearcoat_roughness", 0.0, 1.0));
  }
  if (const auto it = object.find("anisotropy"); it != object.end()) {
    m.anisotropy = static_cast<float>(number_in(*it, key + ".anisotropy", 0.0, 1.0));
  }
  if (const auto it = object.find("anisotropy_rotation_deg"); it != object.end()) {
    const double degrees = number_in(*it, key + ".anisotropy_rotation_deg", -360.0, 360.0);
    m.anisotropy_rotation = static_cast<float>(degrees * (std::numbers::pi / 180.0));
  }
  if (const auto it = object.find("transmission"); it != object.end()) {
    m.transmission = static_cast<float>(number_in(*it, key + ".transmission", 0.0, 1.0));
  }
  if (const auto it = object.find("thickness"); it != object.end()) {
    m.thickness = static_cast<float>(number_in(*it, key + ".thickness", 0.0, 1e6));
  }
  if (const auto it = object.find("attenuation_color"); it != object.end()) {
    m.attenuation_color = srgb_color(*it, key + ".attenuation_color");
  }
  if (const auto it = object.find("attenuation_distance"); it != object.end()) {
    const double distance = number_in(*it, key + ".attenuation_distance", 0.0, 1e6);
    if (!(distance > 0.0)) {
      fail(file_, key + ".attenuation_distance", "expected a number > 0, got " + shown(*it));
    }
    m.attenuation_distance = static_cast<float>(distance);
  }
}

/// Applies the keys of a scene "material" object to `m` (keys not given keep its value).
void SceneReader::apply_material(const json& object, const std::string& key, Material& m) const {
  if (const auto it = object.find("model"); it != object.end()) {
    m.model = shading_model(*it, key + ".model");
  }
  if (const auto it = object.find("metallic"); it != object.end()) {
    m.metallic = static_cast<float>(number_in(*it, key + ".metallic", 0.0, 1.0));
  }
  if (const auto it = object.find("roughness"); it != object.end()) {
    m.roughness = static_cast<float>(number_in(*it, key + ".roughness", 0.0, 1.0));
  }
  if (const auto it = object.find("emissive"); it != object.end()) {
    m.emissive_linear = srgb_color(*it, key + ".emissive");
  }
  if (const auto it = object.find("shininess"); it != object.end()) {
    m.shininess = static_cast<float>(number_in(*it, key + ".shininess", 1e-3, 1e4));
  }
  if (const auto it = object.find("specular"); it != object.end()) {
    m.specular_linear = glm::vec3(static_cast<float>(number_in(*it, key + ".specular", 0.0, 1.0)));
  }
  apply_material_extensions(object, key, m);
  if (const auto it = object.find("double_sided"); it != object.end()) {
    if (!it->is_boolean()) {
      fail(file_, key + ".double_sided", "expected true or false, got " + shown(*it));
    }
    m.double_sided = it->get<bool>();
  }
  if (const auto it = object.find("alpha_mode"); it != object.end()) {
    m.alpha_mode = alpha_mode(*it, key + ".alpha_mode");
  }
  if (const auto it = object.find("alpha_cutoff"); it != object.end()) {
    m.alpha_cutoff = number_in(*it, key + ".alpha_cutoff", 0.0, 1.0);
  }
  if (const auto it = object.find("base_alpha"); it != object.end()) {
    m.base_alpha = number_in(*it, key + ".base_alpha", 0.0, 1.0);
  }
}

AlphaMode SceneReader::alpha_mode(const json& value, const std::string& path) const {
  if (value == "opaque") return AlphaMode::Opaque;
  if (value == "mask") return AlphaMode::Mask;
  if (value == "blend") return AlphaMode::Blend;
  fail(file_, path, "expected \"opaque\", \"mask\" or \"blend\", got " + shown(value));
}

/// The instance's materials: the file's, or one default (lambert for OBJ, which has none in
/// covrast yet; glTF files always list theirs), with the scene's "material" keys applied.
std::vector<Material> instance_materials(const SceneReader& reader, const json& entry,
                                         const std::string& key, const MeshData& mesh) {
  std::vector<Material> materials = mesh.materials;
  if (materials.empty()) {
    Material lambert;
    lambert.model = ShadingModel::Lambert;
    materials.push_back(lambert);
  }
  if (const auto it = entry.find("material"); it != entry.end()) {
    const json& object = reader.require_object(*it, key + ".material");
    for (Material& m : materials) reader.apply_material(object, key + ".material", m);
  }
  return materials;
}

}  // namespace covrast::detail
