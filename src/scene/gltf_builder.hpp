// glTF reader, the mesh builder: the triangle primitives of the node trees into one MeshData.
// Its node walk and placement (transforms, instancing, skins, cameras) are in
// gltf_builder.cpp; a primitive's attributes (vertices, UV sets, tangents, colours, corners)
// in gltf_primitives.cpp. Private to the scene stage.
#pragma once

#include "scene/gltf_accessors.hpp"
#include "scene/gltf_draco.hpp"
#include "scene/gltf_pose.hpp"
#include "scene/scene_internal.hpp"

#include <tiny_gltf.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace covrast::detail {

/// Where a primitive's attributes come from: its accessors, or its decoded Draco stream.
struct PrimitiveSource {
  const tinygltf::Primitive& primitive;
  std::optional<DracoPrimitive> draco;
};

/// A primitive's UV sets and tangents as the file gives them (empty: absent).
struct TextureAttributes {
  std::vector<double> uv[kMaxTexcoordSets];
  std::vector<double> tangents;
};

/// How one node's mesh reaches the file's world space, and its morph weights.
struct Placement {
  std::vector<glm::dmat4> worlds;       ///< one copy per matrix (instances); unskinned only
  std::vector<glm::dmat4> skin_joints;  ///< skinned: the joint matrices, `worlds` unused
  std::vector<double> morph_weights;    ///< the node's weights, else the mesh's
};

/// Collects the triangle primitives of the node tree into one MeshData: positions, indices,
/// materials and normals as it goes, and the colours with what decides between vertex
/// colours and one uniform colour (LoadedMesh::has_uniform_color) at the end.
class GltfMeshBuilder {
 public:
  /// `variant`: the KHR_materials_variants variant to draw (empty: the default materials).
  GltfMeshBuilder(const tinygltf::Model& model, const std::string& name,
                  const std::filesystem::path& base_dir, std::string_view variant);

  /// Walks the node trees under `roots` depth first, in file order, composing the node
  /// transforms, and adds every mesh it meets once per node that uses it.
  void add_node_trees(const std::vector<int>& roots);

  LoadedMesh finish();

 private:
  /// Mesh `mesh_index` of node `node_index`, placed by `placement` with the node's morph
  /// weights. Primitives of the point and line modes are counted (LoadedMesh::warnings), not
  /// drawn.
  void add_mesh(int node_index, int mesh_index, Placement placement);

  /// The material the drawn variant maps `primitive` to (its own without a variant or where
  /// no mapping names it); the mappings are checked whether a variant is drawn or not.
  int variant_material(const tinygltf::Primitive& primitive, const std::string& what) const;

  /// One primitive of a triangle mode (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN); `what`
  /// names it in messages.
  void add_primitive(const tinygltf::Primitive& primitive, int mode, const std::string& what,
                     const Placement& placement);

  /// Before `copies` placed copies of a primitive are made: the file's vertices stay within
  /// 32-bit indices and its triangles within kMaxSceneTriangles (instancing multiplies both).
  void check_copies(std::size_t copies, std::size_t vertex_count, std::size_t triangle_count,
                    const std::string& what) const;

  /// Camera `camera_index` at node `node_index`, unless an earlier node placed it.
  void place_camera(int node_index, int camera_index);

  /// How node `node_index`'s mesh is placed: skinned by its skin's joints (the node's own
  /// transform then does not apply, glTF 2.0, 3.7.3.3), or once per EXT_mesh_gpu_instancing
  /// instance, or once at the node.
  Placement node_placement(int node_index) const;

  /// The primitive's JOINTS_0 / WEIGHTS_0, JOINTS_1 / WEIGHTS_1, ... sets (glTF 2.0, 3.7.3.3).
  std::vector<SkinInfluences> skin_influences(const PrimitiveSource& source,
                                              std::size_t vertex_count,
                                              const std::string& what) const;

  /// glTF 2.0, 3.7.3.3: JOINTS_n are unsigned bytes or shorts, WEIGHTS_n floats or normalized
  /// unsigned bytes or shorts. Any other type (a float or signed joint number) is an error
  /// naming the accessor, before a joint number is used as an index.
  void check_skin_component_types(const tinygltf::Primitive& primitive, const std::string& suffix,
                                  const std::string& what) const;

  /// Appends one placed copy of a primitive: its vertices moved by `world`, its colours, its
  /// triangles (turned when `world` mirrors), their material and their normals.
  void place(const PrimitiveVertices& vertices, const std::vector<std::uint32_t>& corners,
             const std::vector<glm::vec3>& colors, const std::vector<float>& alphas,
             std::uint32_t material, const glm::dmat4& world,
             const TextureAttributes& texture_attributes);

  /// Counts a primitive whose material samples a UV set the primitive does not have.
  void count_missing_texcoords(const TextureAttributes& attributes, std::uint32_t material);

  /// TEXCOORD_0 and _1 (VEC2 of float, or of normalized unsigned byte or short, or any type
  /// KHR_mesh_quantization allows: the accessor reader maps each to numbers) and TANGENT
  /// (VEC4), each empty when absent.
  TextureAttributes read_texture_attributes(const PrimitiveSource& source, const std::string& what,
                                            std::size_t vertex_count) const;

  /// Corner UVs and tangents of the indices from `first_index` on (like add_corner_normals:
  /// a set starts at the first primitive that has it, earlier corners get zeros). Tangents
  /// move with `world`'s 3x3 part as vectors, and their sign turns when it mirrors.
  void add_corner_texture_attributes(const TextureAttributes& attributes, const glm::dmat4& world,
                                     std::size_t base, std::size_t first_index);

  /// The primitive's Draco stream decoded, when it has the extension (gltf_draco.hpp).
  std::optional<DracoPrimitive> decode_draco_primitive(const tinygltf::Primitive& primitive,
                                                       const std::string& what) const;

  /// The accessor of the primitive's attribute `name`, or nullptr when it has none or names
  /// one that does not exist (reading the attribute reports that).
  const tinygltf::Accessor* attribute_accessor(const tinygltf::Primitive& primitive,
                                               const std::string& name) const;

  /// Attribute `attribute` of the primitive (its Draco values first, else its accessor), or
  /// nullopt when it has none; `components` receives the element width.
  std::optional<std::vector<double>> attribute_values(const PrimitiveSource& source,
                                                      const std::string& attribute,
                                                      const std::string& what,
                                                      int& components) const;

  /// POSITION and NORMAL (when present) as the file gives them.
  PrimitiveVertices read_vertices(const PrimitiveSource& source, const std::string& what) const;

  /// The primitive's material's baseColorFactor (RGB), or 1 without a material.
  glm::dvec3 base_color_factor(const tinygltf::Primitive& primitive, const std::string& what) const;

  /// The primitive's vertex colours: COLOR_0 x baseColorFactor, or the (clamped) factor
  /// alone. Notes what decides the mesh's colour selection (finish()). `alphas`: COLOR_0's
  /// fourth component (clamped to 0..1), or 1 (the factor's alpha is Material::base_alpha).
  std::vector<glm::vec3> vertex_colors(const PrimitiveSource& source, const std::string& what,
                                       std::size_t vertex_count, std::vector<float>& alphas);

  /// The primitive's vertex sequence: its index accessor, its Draco faces, or 0, 1, ... when
  /// it has neither.
  std::vector<std::uint32_t> vertex_sequence(const PrimitiveSource& source, const std::string& what,
                                             std::size_t vertex_count) const;

  /// The corners of the triangles that `mode` makes of `sequence`, 3 per triangle (glTF 2.0
  /// spec, 3.7.2.1): TRIANGLES takes them three by three; TRIANGLE_STRIP makes triangle i
  /// (v_i, v_{i+1+i%2}, v_{i+2-i%2}), so every other one is turned to keep the winding;
  /// TRIANGLE_FAN makes (v_{i+1}, v_{i+2}, v_0).
  ///
  ///   strip  1---3---5        fan   2---1
  ///         / \ / \ /              |  /|
  ///        0---2---4                | / |
  ///                                 |/  |
  ///                                 0---4 ... around v_0
  /// `indexed`: the sequence comes from an index accessor (for messages).
  std::vector<std::uint32_t> triangle_corners(int mode, std::vector<std::uint32_t> sequence,
                                              bool indexed, const std::string& what) const;

  /// Appends triangle corners (primitive vertex numbers) as mesh indices; the primitive's
  /// vertices start at `base`.
  void add_triangles(const std::vector<std::uint32_t>& corners, std::size_t base);

  /// Corner normals of the indices from `first_index` on, from the primitive's world normals
  /// (empty: none, face normals). The mesh has corner normals from its first primitive with
  /// NORMAL on; corners before it get none.
  void add_corner_normals(const std::vector<glm::vec3>& normals, std::size_t base,
                          std::size_t first_index);

  /// "name: 3 primitives not drawn (POINTS 1, LINES 2): covrast draws triangles only", or
  /// empty when every primitive was a triangle one.
  std::string undrawn_primitives_message() const;

  /// The nodes of the trees under `roots` in depth-first file order; sets node_world_ (the
  /// composed transforms) and reached_ for each.
  std::vector<int> walk_nodes(const std::vector<int>& roots);

  const tinygltf::Model& model_;
  const std::string& name_;
  const GltfReader reader_;
  std::shared_ptr<MeshData> mesh_;
  int variant_ = -1;                    ///< the drawn variant's index, or -1
  std::uint32_t default_material_ = 0;  ///< glTF's default material, after the file's
  bool any_normals_ = false;
  std::size_t missing_texcoords_ = 0;  ///< primitives sampling a UV set they lack
  std::vector<std::string> warnings_;  ///< spec violations in what covrast does not use
  std::vector<FileCamera> cameras_;
  std::vector<FileLight> lights_;       ///< KHR_lights_punctual, in walk order
  std::vector<glm::dmat4> node_world_;  ///< per node: its transform to the file's world space
  std::vector<bool> reached_;           ///< per node: in the walked scene
  /// Primitives of the modes POINTS, LINES, LINE_LOOP, LINE_STRIP (0..3), counted once per
  /// node that uses them.
  std::array<std::size_t, 4> undrawn_primitives_{};
  std::vector<glm::vec3> colors_;  ///< per vertex: COLOR_0 x factor, or the factor alone
  std::vector<float> alphas_;      ///< per vertex: COLOR_0's alpha, or 1
  bool any_color_alpha_ = false;   ///< some COLOR_0 has four components
  bool any_color_attribute_ = false;
  bool any_primitive_ = false;
  bool factors_differ_ = false;
  glm::vec3 first_factor_{1.0f};  ///< the first primitive's clamped baseColorFactor
};

}  // namespace covrast::detail
