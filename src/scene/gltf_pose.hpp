// Posing a glTF mesh in the file's static pose (mesh_gltf.cpp): morph targets at their
// default weights, skins by their joints' node transforms (no animation), and
// EXT_mesh_gpu_instancing's instance transforms.
#pragma once

#include "scene/gltf_accessors.hpp"

#include <glm/glm.hpp>

#include <cstddef>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace covrast::detail {

inline constexpr std::string_view kInstancingExtension = "EXT_mesh_gpu_instancing";

/// A primitive's vertex data as the file gives it, before placement.
struct PrimitiveVertices {
  std::vector<double> positions;  ///< object space, 3 per vertex
  std::vector<double> normals;    ///< object space, 3 per vertex; empty without NORMAL
  std::size_t count() const { return positions.size() / 3; }
};

/// Unit quaternion (x, y, z, w) -> rotation matrix; normalised first for robustness.
glm::dmat4 rotation_matrix(double x, double y, double z, double w);

/// Adds the morph targets' POSITION and NORMAL deltas, each times its weight (glTF 2.0,
/// 3.7.2.2): p = p_0 + sum_i w_i * d_i. Targets of weight 0 are not read.
void add_morph_targets(const GltfReader& reader, const tinygltf::Primitive& primitive,
                       const std::vector<double>& weights, const std::string& what,
                       PrimitiveVertices& vertices);

/// Skin `skin_index`'s joint matrices globalTransform(joint_i) * inverseBindMatrix_i (glTF
/// 2.0, 3.7.3), from the walked nodes' world transforms; a joint outside the walk is an error.
std::vector<glm::dmat4> joint_matrices(const GltfReader& reader, int skin_index, int node_index,
                                       const std::vector<glm::dmat4>& node_world,
                                       const std::vector<bool>& reached);

/// One JOINTS_n / WEIGHTS_n pair of a primitive: 4 joint numbers and 4 weights per vertex.
struct SkinInfluences {
  std::vector<double> joints;
  std::vector<double> weights;
};

/// Each vertex's skin matrix M = sum_i w_i * joints[j_i] over every set of influences;
/// `name` and `what` name the file and primitive of an out-of-range joint number.
std::vector<glm::dmat4> vertex_skin_matrices(const std::vector<SkinInfluences>& sets,
                                             std::size_t vertex_count,
                                             const std::vector<glm::dmat4>& joints,
                                             const std::string& name, const std::string& what);

/// The vertices posed by their skin matrices (linear blend skinning, glTF 2.0, 3.7.3.3):
/// p' = M p and n' = M^-T n.
PrimitiveVertices skinned(const PrimitiveVertices& vertices, const std::vector<glm::dmat4>& skin);

/// EXT_mesh_gpu_instancing: one T * R * S per instance from the TRANSLATION, ROTATION
/// (quaternion) and SCALE accessors, each optional, all of one count.
std::vector<glm::dmat4> instance_transforms(const GltfReader& reader,
                                            const tinygltf::Value& extension, int node_index);

}  // namespace covrast::detail
