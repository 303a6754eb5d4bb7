// KHR_lights_punctual (KhronosGroup/glTF, extensions/2.0/Khronos/KHR_lights_punctual): a light
// is defined once at the top level ("extensions": {"KHR_lights_punctual": {"lights": [...]}},
// which tinygltf reads into Model::lights) and placed by every node that names it; it sits at
// the node's origin and shines down the node's -z. Colours are linear, intensity in lux
// (directional) or candela (point, spot), range 0 (absent) = infinite, cone angles in radians.
#include "scene/gltf_lights.hpp"

#include <tiny_gltf.h>

#include <cmath>
#include <numbers>

namespace covrast::detail {
namespace {

[[noreturn]] void fail(const std::string& what, const std::string& message) {
  throw InputError(what + ": " + message);
}

/// The file's light `source` as a covrast Light, position and direction not yet set.
Light convert_light(const tinygltf::Light& source, const std::string& what) {
  Light light;
  if (source.type == "directional") {
    light.type = LightType::Directional;
  } else if (source.type == "point") {
    light.type = LightType::Point;
  } else if (source.type == "spot") {
    light.type = LightType::Spot;
  } else {
    fail(what, "type must be \"directional\", \"point\" or \"spot\"");
  }
  if (!source.color.empty()) {
    if (source.color.size() != 3) fail(what, "color must have 3 components");
    for (int c = 0; c < 3; ++c) {
      const double x = source.color[std::size_t(c)];
      if (!(x >= 0.0 && std::isfinite(x))) fail(what, "color must be finite and >= 0");
      light.color_linear[c] = static_cast<float>(x);
    }
  }
  if (!(source.intensity >= 0.0 && std::isfinite(source.intensity))) {
    fail(what, "intensity must be finite and >= 0");
  }
  light.intensity = source.intensity;
  if (!(source.range >= 0.0 && std::isfinite(source.range))) fail(what, "range must be > 0");
  light.range = light.type == LightType::Directional ? 0.0 : source.range;
  if (light.type == LightType::Spot) {
    const double inner = source.spot.innerConeAngle, outer = source.spot.outerConeAngle;
    if (!(inner >= 0.0 && inner < outer && outer <= std::numbers::pi / 2.0)) {
      fail(what, "cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2");
    }
    light.inner_cone_deg = inner * (180.0 / std::numbers::pi);
    light.outer_cone_deg = outer * (180.0 / std::numbers::pi);
  }
  return light;
}

}  // namespace

std::optional<FileLight> node_light(const tinygltf::Model& model, int node_index,
                                    const glm::dmat4& world, const std::string& name) {
  const tinygltf::Node& node = model.nodes[static_cast<std::size_t>(node_index)];
  const auto it = node.extensions.find(std::string(kLightsExtension));
  if (it == node.extensions.end()) return std::nullopt;
  const std::string node_what = name + ": node " + std::to_string(node_index);
  if (!it->second.IsObject() || !it->second.Has("light") || !it->second.Get("light").IsInt()) {
    fail(node_what, std::string(kLightsExtension) + " needs a light index");
  }
  const int index = it->second.Get("light").GetNumberAsInt();
  if (index < 0 || static_cast<std::size_t>(index) >= model.lights.size()) {
    fail(node_what, "light " + std::to_string(index) + " does not exist (" +
                        std::to_string(model.lights.size()) + " lights)");
  }
  FileLight placed;
  placed.light = convert_light(model.lights[static_cast<std::size_t>(index)],
                               node_what + ": light " + std::to_string(index));
  placed.world = world;
  placed.index = index;
  placed.node = node_index;
  return placed;
}

}  // namespace covrast::detail
