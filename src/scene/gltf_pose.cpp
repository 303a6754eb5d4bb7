// Static-pose glTF posing (gltf_pose.hpp): morph targets, skins, EXT_mesh_gpu_instancing.
#include "scene/gltf_pose.hpp"

#include <covrast/scene.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace covrast::detail {
namespace {

/// values += weight * the target's `attribute` (VEC3, one per vertex), when it has one.
void add_delta(const GltfReader& reader, const std::map<std::string, int>& target,
               const char* attribute, double weight, const std::string& what,
               std::vector<double>& values) {
  const auto it = target.find(attribute);
  if (it == target.end()) return;
  int components = 0;
  const std::vector<double> delta =
      reader.read_accessor(what + " " + attribute, it->second, components);
  if (components != 3 || delta.size() != values.size()) {
    fail(reader.name, what + ": " + attribute + " must be VEC3 with one value per vertex");
  }
  for (std::size_t i = 0; i < values.size(); ++i) values[i] += weight * delta[i];
}

/// One instancing attribute's values (`width` per instance), or empty when not given.
std::vector<double> instance_attribute(const GltfReader& reader, const tinygltf::Value& attributes,
                                       const char* key, int width, const std::string& what) {
  if (!attributes.Has(key)) return {};
  const tinygltf::Value& accessor = attributes.Get(key);
  if (!accessor.IsInt()) fail(reader.name, what + ": " + key + " must be an accessor index");
  // Checked before reading: each instance becomes a copy of the mesh (a matrix of 128 bytes
  // now, and its vertices later), so the limit is far below an accessor's.
  const int index = accessor.GetNumberAsInt();
  if (index >= 0 && std::size_t(index) < reader.model.accessors.size() &&
      reader.model.accessors[std::size_t(index)].count > kMaxGltfInstances) {
    fail(reader.name, what + ": " + key + " gives " +
                          std::to_string(reader.model.accessors[std::size_t(index)].count) +
                          " instances, more than " + std::to_string(kMaxGltfInstances) +
                          " (docs/limits.md)");
  }
  int components = 0;
  std::vector<double> values = reader.read_accessor(what + " " + key, index, components);
  if (components != width) {
    fail(reader.name, what + ": " + key + (width == 3 ? " must be VEC3" : " must be VEC4"));
  }
  return values;
}

}  // namespace

glm::dmat4 rotation_matrix(double x, double y, double z, double w) {
  const double length = std::sqrt(x * x + y * y + z * z + w * w);
  if (length > 0.0) {
    x /= length;
    y /= length;
    z /= length;
    w /= length;
  }
  glm::dmat4 r(1.0);
  r[0] = glm::dvec4(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0.0);
  r[1] = glm::dvec4(2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0.0);
  r[2] = glm::dvec4(2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0.0);
  return r;
}

void add_morph_targets(const GltfReader& reader, const tinygltf::Primitive& primitive,
                       const std::vector<double>& weights, const std::string& what,
                       PrimitiveVertices& vertices) {
  if (primitive.targets.empty() || weights.empty()) return;
  if (weights.size() != primitive.targets.size()) {
    fail(reader.name, what + ": " + std::to_string(primitive.targets.size()) +
                          " morph targets but " + std::to_string(weights.size()) + " weights");
  }
  for (std::size_t t = 0; t < primitive.targets.size(); ++t) {
    if (weights[t] == 0.0) continue;
    const std::string target = what + " target " + std::to_string(t);
    add_delta(reader, primitive.targets[t], "POSITION", weights[t], target, vertices.positions);
    if (!vertices.normals.empty()) {
      add_delta(reader, primitive.targets[t], "NORMAL", weights[t], target, vertices.normals);
    }
  }
}

std::vector<glm::dmat4> joint_matrices(const GltfReader& reader, int skin_index, int node_index,
                                       const std::vector<glm::dmat4>& node_world,
                                       const std::vector<bool>& reached) {
  const std::string what =
      "node " + std::to_string(node_index) + ": skin " + std::to_string(skin_index);
  if (static_cast<std::size_t>(skin_index) >= reader.model.skins.size()) {
    fail(reader.name, what + " does not exist");
  }
  const tinygltf::Skin& skin = reader.model.skins[static_cast<std::size_t>(skin_index)];
  if (skin.joints.empty()) fail(reader.name, what + " has no joints");
  std::vector<double> inverse_binds;
  if (skin.inverseBindMatrices >= 0) {
    int components = 0;
    inverse_binds =
        reader.read_accessor(what + " inverseBindMatrices", skin.inverseBindMatrices, components);
    if (components != 16 || inverse_binds.size() / 16 < skin.joints.size()) {
      fail(reader.name, what + ": inverseBindMatrices must be one MAT4 per joint");
    }
  }
  std::vector<glm::dmat4> joints;
  for (std::size_t i = 0; i < skin.joints.size(); ++i) {
    const int joint = skin.joints[i];
    if (joint < 0 || static_cast<std::size_t>(joint) >= reached.size() ||
        !reached[static_cast<std::size_t>(joint)]) {
      fail(reader.name, what + ": joint node " + std::to_string(joint) + " is not in the scene");
    }
    glm::dmat4 inverse_bind(1.0);
    for (std::size_t k = 0; k < 16 && !inverse_binds.empty(); ++k) {
      inverse_bind[static_cast<int>(k / 4)][static_cast<int>(k % 4)] = inverse_binds[16 * i + k];
    }
    joints.push_back(node_world[static_cast<std::size_t>(joint)] * inverse_bind);
  }
  return joints;
}

std::vector<glm::dmat4> vertex_skin_matrices(const std::vector<SkinInfluences>& sets,
                                             std::size_t vertex_count,
                                             const std::vector<glm::dmat4>& joints,
                                             const std::string& name, const std::string& what) {
  std::vector<glm::dmat4> skin(vertex_count, glm::dmat4(0.0));
  for (const SkinInfluences& set : sets) {
    for (std::size_t i = 0; i < 4 * vertex_count; ++i) {
      if (set.weights[i] == 0.0) continue;
      // Checked as a double before the conversion: a Draco stream's joint numbers are not
      // bound by the accessor's component type, and a negative or non-finite number converted
      // to an index is undefined.
      const double joint = set.joints[i];
      if (!(joint >= 0.0 && joint < static_cast<double>(joints.size()))) {
        fail(name, what + ": joint " + number_text(joint) + " out of range (" +
                       std::to_string(joints.size()) + " joints)");
      }
      skin[i / 4] += set.weights[i] * joints[static_cast<std::size_t>(joint)];
    }
  }
  return skin;
}

PrimitiveVertices skinned(const PrimitiveVertices& vertices, const std::vector<glm::dmat4>& skin) {
  PrimitiveVertices posed;
  posed.positions.resize(vertices.positions.size());
  posed.normals.resize(vertices.normals.size());
  for (std::size_t v = 0; v < vertices.count(); ++v) {
    const glm::dvec4 p =
        skin[v] * glm::dvec4(vertices.positions[3 * v], vertices.positions[3 * v + 1],
                             vertices.positions[3 * v + 2], 1.0);
    for (int c = 0; c < 3; ++c) posed.positions[3 * v + static_cast<std::size_t>(c)] = p[c];
    if (vertices.normals.empty()) continue;
    const glm::dvec3 n = glm::transpose(glm::inverse(glm::dmat3(skin[v]))) *
                         glm::dvec3(vertices.normals[3 * v], vertices.normals[3 * v + 1],
                                    vertices.normals[3 * v + 2]);
    for (int c = 0; c < 3; ++c) posed.normals[3 * v + static_cast<std::size_t>(c)] = n[c];
  }
  return posed;
}

std::vector<glm::dmat4> instance_transforms(const GltfReader& reader,
                                            const tinygltf::Value& extension, int node_index) {
  const std::string what =
      "node " + std::to_string(node_index) + ": " + std::string(kInstancingExtension);
  if (!extension.IsObject() || !extension.Get("attributes").IsObject()) {
    fail(reader.name, what + ": needs an attributes object");
  }
  const tinygltf::Value& attributes = extension.Get("attributes");
  const std::vector<double> t = instance_attribute(reader, attributes, "TRANSLATION", 3, what);
  const std::vector<double> r = instance_attribute(reader, attributes, "ROTATION", 4, what);
  const std::vector<double> s = instance_attribute(reader, attributes, "SCALE", 3, what);
  const std::size_t count = std::max({t.size() / 3, r.size() / 4, s.size() / 3});
  if ((!t.empty() && t.size() / 3 != count) || (!r.empty() && r.size() / 4 != count) ||
      (!s.empty() && s.size() / 3 != count)) {
    fail(reader.name, what + ": TRANSLATION, ROTATION and SCALE counts differ");
  }
  std::vector<glm::dmat4> instances(count, glm::dmat4(1.0));
  for (std::size_t i = 0; i < count; ++i) {
    glm::dmat4 translation(1.0), rotation(1.0), scale(1.0);
    if (!t.empty()) translation[3] = glm::dvec4(t[3 * i], t[3 * i + 1], t[3 * i + 2], 1.0);
    if (!r.empty()) rotation = rotation_matrix(r[4 * i], r[4 * i + 1], r[4 * i + 2], r[4 * i + 3]);
    if (!s.empty()) {
      scale[0][0] = s[3 * i];
      scale[1][1] = s[3 * i + 1];
      scale[2][2] = s[3 * i + 2];
    }
    instances[i] = translation * rotation * scale;
  }
  return instances;
}

}  // namespace covrast::detail
