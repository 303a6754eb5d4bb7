// glTF reader, the mesh builder's node walk (gltf_builder.hpp): node transforms composed
// depth first, meshes placed once per node that uses them (instances, skins, morph weights),
// the file's cameras, materials and variants, and what the builder hands back at the end.
#include "scene/gltf_builder.hpp"
#include "scene/gltf_lights.hpp"
#include "scene/gltf_materials.hpp"
#include "scene/gltf_textures.hpp"
#include "scene/gltf_variants.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <map>
#include <optional>
#include <string_view>
#include <vector>

namespace covrast::detail {
namespace {

/// Node-local transform: the matrix when given (column-major, like GLM), else T * R * S.
glm::dmat4 local_transform(const tinygltf::Node& node, const std::string& name, int node_index) {
  const std::string what = "node " + std::to_string(node_index);
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16) fail(name, what + ": matrix needs 16 numbers");
    glm::dmat4 m(1.0);
    for (int col = 0; col < 4; ++col) {
      for (int row = 0; row < 4; ++row)
        m[col][row] = node.matrix[static_cast<std::size_t>(col * 4 + row)];
    }
    return m;
  }
  if ((!node.translation.empty() && node.translation.size() != 3) ||
      (!node.rotation.empty() && node.rotation.size() != 4) ||
      (!node.scale.empty() && node.scale.size() != 3)) {
    fail(name, what + ": translation/scale need 3 numbers, rotation 4");
  }
  glm::dmat4 t(1.0);
  if (!node.translation.empty()) {
    t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
  }
  glm::dmat4 r(1.0);
  if (!node.rotation.empty()) {
    r = rotation_matrix(node.rotation[0], node.rotation[1], node.rotation[2], node.rotation[3]);
  }
  glm::dmat4 s(1.0);
  if (!node.scale.empty()) {
    s[0][0] = node.scale[0];
    s[1][1] = node.scale[1];
    s[2][2] = node.scale[2];
  }
  return t * r * s;
}

/// A glTF camera's projection (glTF 2.0, 3.10.2); aspectRatio is not kept: the image's
/// width and height decide it.
FileCamera file_camera(const tinygltf::Camera& camera) {
  FileCamera out;
  out.orthographic = camera.type == "orthographic";
  if (out.orthographic) {
    out.ymag = camera.orthographic.ymag;
    out.znear = camera.orthographic.znear;
    out.zfar = camera.orthographic.zfar;
  } else {
    out.yfov_rad = camera.perspective.yfov;
    out.znear = camera.perspective.znear;
    out.zfar = camera.perspective.zfar;
  }
  return out;
}

/// Normals of one primitive in the node's world space: n_world = normalize(M^-T n) for the
/// upper 3x3 M of the node's matrix (normals are covectors).
std::vector<glm::vec3> world_normals(const std::vector<double>& values, const glm::dmat4& world) {
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(glm::dmat3(world)));
  std::vector<glm::vec3> normals(values.size() / 3, glm::vec3(0.0f));
  for (std::size_t v = 0; v < normals.size(); ++v) {
    const glm::dvec3 n =
        normal_matrix * glm::dvec3(values[3 * v], values[3 * v + 1], values[3 * v + 2]);
    const double length = glm::length(n);
    if (length > 0.0 && std::isfinite(length)) normals[v] = glm::vec3(n / length);
  }
  return normals;
}

}  // namespace

/// `variant`: the KHR_materials_variants variant to draw (empty: the default materials).
GltfMeshBuilder::GltfMeshBuilder(const tinygltf::Model& model, const std::string& name,
                                 const std::filesystem::path& base_dir, std::string_view variant)
    : model_(model), name_(name), reader_{model, name}, mesh_(std::make_shared<MeshData>()) {
  mesh_->source = name;
  // The file's materials with their textures (each image decoded once), then glTF's default
  // material for primitives without one.
  GltfTextures textures(model, reader_, base_dir, warnings_);
  mesh_->materials = read_materials(model, textures, warnings_);
  default_material_ = static_cast<std::uint32_t>(model.materials.size());
  mesh_->material_variants = material_variant_names(model, name);
  if (!variant.empty()) {
    const auto& names = mesh_->material_variants;
    const auto it = std::find(names.begin(), names.end(), variant);
    if (it == names.end()) {
      fail(name, "no material variant '" + std::string(variant) + "' (" +
                     material_variants_text(names) + ")");
    }
    variant_ = int(it - names.begin());
  }
  for (const tinygltf::Camera& camera : model.cameras) cameras_.push_back(file_camera(camera));
}

/// Walks the node trees under `roots` depth first, in file order, composing the node
/// transforms, and adds every mesh it meets once per node that uses it.
void GltfMeshBuilder::add_node_trees(const std::vector<int>& roots) {
  for (const int node_index : walk_nodes(roots)) {
    const tinygltf::Node& node = model_.nodes[static_cast<std::size_t>(node_index)];
    if (node.mesh >= 0) add_mesh(node_index, node.mesh, node_placement(node_index));
    if (node.camera >= 0) place_camera(node_index, node.camera);
    const glm::dmat4& world = node_world_[static_cast<std::size_t>(node_index)];
    if (auto light = node_light(model_, node_index, world, name_)) lights_.push_back(*light);
  }
}

LoadedMesh GltfMeshBuilder::finish() {
  LoadedMesh loaded;
  loaded.cameras = std::move(cameras_);
  loaded.lights = std::move(lights_);
  if (const std::string undrawn = undrawn_primitives_message(); !undrawn.empty()) {
    loaded.warnings.push_back(undrawn);
  }
  loaded.warnings.insert(loaded.warnings.end(), warnings_.begin(), warnings_.end());
  if (missing_texcoords_ > 0) {
    loaded.warnings.push_back(name_ + ": " + std::to_string(missing_texcoords_) +
                              " primitives lack the TEXCOORD_n their material's textures use; "
                              "UV (0, 0) used there");
  }
  if (any_color_alpha_) mesh_->color_alphas = std::move(alphas_);
  if (any_color_attribute_ || factors_differ_) {
    // Per-vertex colours: COLOR_0 where present, each primitive's own factor elsewhere.
    mesh_->colors_linear = std::move(colors_);
  } else if (any_primitive_) {
    loaded.has_uniform_color = true;
    loaded.uniform_color_linear = first_factor_;
  }
  loaded.dropped_nonfinite_triangles = drop_nonfinite_triangles(*mesh_);
  analyze_mesh_topology(*mesh_);  // once per file: instances share the result
  loaded.data = std::move(mesh_);
  return loaded;
}

/// Mesh `mesh_index` of node `node_index`, placed by `placement` with the node's morph
/// weights. Primitives of the point and line modes are counted (LoadedMesh::warnings), not
/// drawn.
void GltfMeshBuilder::add_mesh(int node_index, int mesh_index, Placement placement) {
  if (static_cast<std::size_t>(mesh_index) >= model_.meshes.size()) {
    fail(name_, "node " + std::to_string(node_index) + ": mesh " + std::to_string(mesh_index) +
                    " does not exist");
  }
  const tinygltf::Mesh& gltf_mesh = model_.meshes[static_cast<std::size_t>(mesh_index)];
  // glTF 2.0, 3.7.2.2: the node's weights override the mesh's default weights.
  const std::vector<double>& node_weights =
      model_.nodes[static_cast<std::size_t>(node_index)].weights;
  placement.morph_weights = node_weights.empty() ? gltf_mesh.weights : node_weights;
  for (std::size_t p = 0; p < gltf_mesh.primitives.size(); ++p) {
    const tinygltf::Primitive& primitive = gltf_mesh.primitives[p];
    const std::string what =
        "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(p);
    const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
    if (mode > TINYGLTF_MODE_TRIANGLE_FAN) {
      fail(name_, what + ": unknown mode " + std::to_string(mode) + " (glTF has 0..6)");
    }
    if (mode < TINYGLTF_MODE_TRIANGLES) {
      ++undrawn_primitives_[static_cast<std::size_t>(mode)];
      continue;
    }
    if (const int material = variant_material(primitive, what); material != primitive.material) {
      // KHR_materials_variants: the variant's material in the place of the primitive's
      // own, for everything that reads it (colours, alpha, textures).
      tinygltf::Primitive chosen = primitive;
      chosen.material = material;
      add_primitive(chosen, mode, what, placement);
      continue;
    }
    add_primitive(primitive, mode, what, placement);
  }
}

/// The material the drawn variant maps `primitive` to (its own without a variant or where
/// no mapping names it); the mappings are checked whether a variant is drawn or not.
int GltfMeshBuilder::variant_material(const tinygltf::Primitive& primitive,
                                      const std::string& what) const {
  const std::vector<std::int32_t> mapped =
      primitive_variant_materials(model_, primitive, mesh_->material_variants.size(), name_, what);
  if (variant_ < 0 || mapped.empty() || mapped[std::size_t(variant_)] < 0) {
    return primitive.material;
  }
  return mapped[std::size_t(variant_)];
}

/// One primitive of a triangle mode (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN); `what`
/// names it in messages.
void GltfMeshBuilder::add_primitive(const tinygltf::Primitive& primitive, int mode,
                                    const std::string& what, const Placement& placement) {
  const PrimitiveSource source{primitive, decode_draco_primitive(primitive, what)};
  if (source.draco) mode = TINYGLTF_MODE_TRIANGLES;  // the decoded faces are a triangle list
  PrimitiveVertices vertices = read_vertices(source, what);
  add_morph_targets(reader_, primitive, placement.morph_weights, what, vertices);
  const std::size_t vertex_count = vertices.count();
  if (vertex_count > kMaxVertices - mesh_->positions.size()) fail(name_, "too many vertices");
  const std::vector<std::uint32_t> corners = triangle_corners(
      mode, vertex_sequence(source, what, vertex_count), primitive.indices >= 0, what);
  std::vector<float> alphas;
  const std::vector<glm::vec3> colors = vertex_colors(source, what, vertex_count, alphas);
  const TextureAttributes texture_attributes = read_texture_attributes(source, what, vertex_count);
  check_copies(placement.skin_joints.empty() ? placement.worlds.size() : 1, vertex_count,
               corners.size() / 3, what);
  const std::uint32_t material =
      primitive.material >= 0 ? static_cast<std::uint32_t>(primitive.material) : default_material_;
  count_missing_texcoords(texture_attributes, material);
  if (placement.skin_joints.empty()) {
    for (const glm::dmat4& world : placement.worlds) {
      place(vertices, corners, colors, alphas, material, world, texture_attributes);
    }
  } else {
    const std::vector<glm::dmat4> skin =
        vertex_skin_matrices(skin_influences(source, vertices.count(), what), vertices.count(),
                             placement.skin_joints, name_, what);
    place(skinned(vertices, skin), corners, colors, alphas, material, glm::dmat4(1.0),
          texture_attributes);
  }
}

/// Before `copies` placed copies of a primitive are made: the file's vertices stay within
/// 32-bit indices and its triangles within kMaxSceneTriangles (instancing multiplies both).
void GltfMeshBuilder::check_copies(std::size_t copies, std::size_t vertex_count,
                                   std::size_t triangle_count, const std::string& what) const {
  const std::uint64_t vertices = std::uint64_t(copies) * vertex_count;
  const std::uint64_t triangles = std::uint64_t(copies) * triangle_count;
  if (vertices > kMaxVertices - mesh_->positions.size()) {
    fail(name_, what + ": more than " + std::to_string(kMaxVertices) + " vertices in all");
  }
  if (triangles > kMaxSceneTriangles - mesh_->triangle_count()) {
    fail(name_, what + ": " + std::to_string(copies) + " copies make more than " +
                    std::to_string(kMaxSceneTriangles) + " triangles (docs/limits.md)");
  }
}

/// Camera `camera_index` at node `node_index`, unless an earlier node placed it.
void GltfMeshBuilder::place_camera(int node_index, int camera_index) {
  if (static_cast<std::size_t>(camera_index) >= cameras_.size()) {
    fail(name_, "node " + std::to_string(node_index) + ": camera " + std::to_string(camera_index) +
                    " does not exist");
  }
  FileCamera& camera = cameras_[static_cast<std::size_t>(camera_index)];
  if (camera.placed) return;
  camera.placed = true;
  camera.world = node_world_[static_cast<std::size_t>(node_index)];
}

/// How node `node_index`'s mesh is placed: skinned by its skin's joints (the node's own
/// transform then does not apply, glTF 2.0, 3.7.3.3), or once per EXT_mesh_gpu_instancing
/// instance, or once at the node.
Placement GltfMeshBuilder::node_placement(int node_index) const {
  const tinygltf::Node& node = model_.nodes[static_cast<std::size_t>(node_index)];
  Placement placement;
  if (node.skin >= 0) {
    placement.skin_joints = joint_matrices(reader_, node.skin, node_index, node_world_, reached_);
    return placement;
  }
  const glm::dmat4& world = node_world_[static_cast<std::size_t>(node_index)];
  const auto instancing = node.extensions.find(std::string(kInstancingExtension));
  if (instancing == node.extensions.end()) {
    placement.worlds.push_back(world);
    return placement;
  }
  for (const glm::dmat4& instance : instance_transforms(reader_, instancing->second, node_index)) {
    placement.worlds.push_back(world * instance);
  }
  return placement;
}

/// The primitive's JOINTS_0 / WEIGHTS_0, JOINTS_1 / WEIGHTS_1, ... sets (glTF 2.0, 3.7.3.3).
std::vector<SkinInfluences> GltfMeshBuilder::skin_influences(const PrimitiveSource& source,
                                                             std::size_t vertex_count,
                                                             const std::string& what) const {
  std::vector<SkinInfluences> sets;
  for (int set = 0;; ++set) {
    // Appended piecewise: "_" + std::to_string(set) trips a g++ 12 -Wrestrict false positive.
    std::string suffix = "_";
    suffix += std::to_string(set);
    int joint_components = 0, weight_components = 0;
    auto joints = attribute_values(source, "JOINTS" + suffix, what, joint_components);
    auto weights = attribute_values(source, "WEIGHTS" + suffix, what, weight_components);
    if (!joints && !weights) return sets;
    if (!joints || !weights || joint_components != 4 || weight_components != 4 ||
        joints->size() != 4 * vertex_count || weights->size() != 4 * vertex_count) {
      fail(name_, what + ": JOINTS" + suffix + " and WEIGHTS" + suffix +
                      " must both be VEC4 with one value per vertex");
    }
    check_skin_component_types(source.primitive, suffix, what);
    sets.push_back({std::move(*joints), std::move(*weights)});
  }
}

/// glTF 2.0, 3.7.3.3: JOINTS_n are unsigned bytes or shorts, WEIGHTS_n floats or normalized
/// unsigned bytes or shorts. Any other type (a float or signed joint number) is an error
/// naming the accessor, before a joint number is used as an index.
void GltfMeshBuilder::check_skin_component_types(const tinygltf::Primitive& primitive,
                                                 const std::string& suffix,
                                                 const std::string& what) const {
  const tinygltf::Accessor* joints = attribute_accessor(primitive, "JOINTS" + suffix);
  const tinygltf::Accessor* weights = attribute_accessor(primitive, "WEIGHTS" + suffix);
  const auto unsigned_integer = [](int type) {
    return type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
           type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  };
  if (joints != nullptr && (!unsigned_integer(joints->componentType) || joints->normalized)) {
    fail(name_, what + ": JOINTS" + suffix + " (accessor " +
                    std::to_string(primitive.attributes.at("JOINTS" + suffix)) +
                    ") has component type " + std::to_string(joints->componentType) +
                    (joints->normalized ? " normalized" : "") +
                    ": joints must be UNSIGNED_BYTE (5121) or UNSIGNED_SHORT (5123)");
  }
  if (weights != nullptr && !(weights->componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                              (unsigned_integer(weights->componentType) && weights->normalized))) {
    fail(name_, what + ": WEIGHTS" + suffix + " (accessor " +
                    std::to_string(primitive.attributes.at("WEIGHTS" + suffix)) +
                    ") has component type " + std::to_string(weights->componentType) +
                    (weights->normalized ? " normalized" : "") +
                    ": weights must be FLOAT (5126) or normalized UNSIGNED_BYTE (5121) or "
                    "UNSIGNED_SHORT (5123)");
  }
}

/// Appends one placed copy of a primitive: its vertices moved by `world`, its colours, its
/// triangles (turned when `world` mirrors), their material and their normals.
void GltfMeshBuilder::place(const PrimitiveVertices& vertices,
                            const std::vector<std::uint32_t>& corners,
                            const std::vector<glm::vec3>& colors, const std::vector<float>& alphas,
                            std::uint32_t material, const glm::dmat4& world,
                            const TextureAttributes& texture_attributes) {
  const std::size_t base = mesh_->positions.size();
  const std::vector<double>& positions = vertices.positions;
  for (std::size_t v = 0; v < vertices.count(); ++v) {
    const glm::dvec4 p_world =
        world * glm::dvec4(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2], 1.0);
    mesh_->positions.emplace_back(static_cast<float>(p_world.x), static_cast<float>(p_world.y),
                                  static_cast<float>(p_world.z));
  }
  colors_.insert(colors_.end(), colors.begin(), colors.end());
  alphas_.insert(alphas_.end(), alphas.begin(), alphas.end());
  const std::size_t first_index = mesh_->indices.size();
  add_triangles(corners, base);
  // glTF 2.0, 3.7.2.1: a node with a negative determinant turns its faces' winding
  // clockwise; swapping two corners keeps counter-clockwise = front after baking.
  if (glm::determinant(glm::dmat3(world)) < 0.0) {
    for (std::size_t i = first_index; i < mesh_->indices.size(); i += 3) {
      std::swap(mesh_->indices[i + 1], mesh_->indices[i + 2]);
    }
  }
  mesh_->triangle_materials.resize(mesh_->indices.size() / 3, material);
  add_corner_normals(
      vertices.normals.empty() ? std::vector<glm::vec3>{} : world_normals(vertices.normals, world),
      base, first_index);
  add_corner_texture_attributes(texture_attributes, world, base, first_index);
}

/// "name: 3 primitives not drawn (POINTS 1, LINES 2): covrast draws triangles only", or
/// empty when every primitive was a triangle one.
std::string GltfMeshBuilder::undrawn_primitives_message() const {
  static const char* const kModeNames[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
  std::size_t total = 0;
  std::string counts;
  for (std::size_t mode = 0; mode < undrawn_primitives_.size(); ++mode) {
    if (undrawn_primitives_[mode] == 0) continue;
    total += undrawn_primitives_[mode];
    counts += (counts.empty() ? "" : ", ") + std::string(kModeNames[mode]) + " " +
              std::to_string(undrawn_primitives_[mode]);
  }
  if (total == 0) return {};
  return name_ + ": " + std::to_string(total) + " primitives not drawn (" + counts +
         "): covrast draws triangles only";
}

/// The nodes of the trees under `roots` in depth-first file order; sets node_world_ (the
/// composed transforms) and reached_ for each.
std::vector<int> GltfMeshBuilder::walk_nodes(const std::vector<int>& roots) {
  struct Pending {
    int node;
    glm::dmat4 parent;
  };
  const std::size_t node_count = model_.nodes.size();
  node_world_.assign(node_count, glm::dmat4(1.0));
  reached_.assign(node_count, false);
  std::vector<Pending> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) {
    stack.push_back({*it, glm::dmat4(1.0)});
  }
  std::vector<int> order;
  while (!stack.empty()) {
    const Pending current = stack.back();
    stack.pop_back();
    if (current.node < 0 || static_cast<std::size_t>(current.node) >= node_count) {
      fail(name_, "node " + std::to_string(current.node) + " does not exist");
    }
    const auto node_index = static_cast<std::size_t>(current.node);
    if (reached_[node_index]) {
      fail(name_, "node " + std::to_string(current.node) +
                      " is reached twice (the node hierarchy must be a tree)");
    }
    reached_[node_index] = true;
    const tinygltf::Node& node = model_.nodes[node_index];
    node_world_[node_index] = current.parent * local_transform(node, name_, current.node);
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) {
      stack.push_back({*it, node_world_[node_index]});
    }
    order.push_back(current.node);
  }
  return order;
}

}  // namespace covrast::detail
