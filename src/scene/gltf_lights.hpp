// glTF KHR_lights_punctual (mesh_gltf.cpp): the lights on the nodes of the walked scene, in
// the file's world space; the scene loader places them with the mesh entry's model matrix.
#pragma once

#include "scene/scene_internal.hpp"

#include <glm/glm.hpp>

#include <optional>
#include <string>
#include <string_view>

namespace tinygltf {
class Model;
}

namespace covrast::detail {

inline constexpr std::string_view kLightsExtension = "KHR_lights_punctual";

/// The light node `node_index` carries ("extensions": {"KHR_lights_punctual": {"light": i}}),
/// placed at the node's world transform `world`; none if the node has no light. Throws
/// InputError (naming `name`, the node and the light) for a light index out of range, an
/// unknown type, a colour or intensity that is negative or not finite, or cone angles outside
/// 0 <= inner < outer <= pi/2.
std::optional<FileLight> node_light(const tinygltf::Model& model, int node_index,
                                    const glm::dmat4& world, const std::string& name);

}  // namespace covrast::detail
