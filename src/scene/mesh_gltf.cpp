// glTF 2.0 reader (.gltf with embedded or external buffers, .glb) on top of tinygltf. Collects
// every triangle primitive (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN) of every mesh reachable
// from the default scene (scene 0 when none is marked, every root node when the file has no
// scene at all), posed in the file's static pose: morph targets at their default weights,
// skins by their joints' node transforms, EXT_mesh_gpu_instancing instances; bakes the node
// transforms (matrix, or T * R * S) into the positions, and COLOR_0 x baseColorFactor into
// colors_linear. Points and lines are counted in a warning; Draco streams are decoded by
// gltf_draco.cpp; the file's cameras are kept for the scene (FileCamera).
// glTF colours are linear already (glTF 2.0 spec, 3.7.2.1 and 5.19.3). Every buffer access goes
// through gltf_accessors.hpp, bounds-checked, so a broken file is an InputError, never a crash.
#include "scene/gltf_accessors.hpp"
#include "scene/gltf_animation.hpp"
#include "scene/gltf_draco.hpp"
#include "scene/gltf_input.hpp"
#include "scene/gltf_lights.hpp"
#include "scene/gltf_materials.hpp"
#include "scene/gltf_meshopt.hpp"
#include "scene/gltf_pose.hpp"
#include "scene/gltf_rewrite.hpp"
#include "scene/gltf_textures.hpp"
#include "scene/gltf_variants.hpp"
#include "scene/scene_internal.hpp"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <tiny_gltf.h>

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

/// Draco's static archive (CMakeLists.txt) holds its own copies of tinygltf and stb, in one
/// object file. GNU ld takes an archive member to define a symbol that only shared libraries
/// refer to, even when another shared library defines it: libtinygltf's calls into stb would
/// pull Draco's copy, and with it a second tinygltf whose structures differ from the one
/// covrast is compiled against (a crash on the first glTF file with an image). These
/// references from covrast's own code bind stb's functions to libstb before the archive is
/// searched; the ctest link_has_no_second_tinygltf checks the executable.
[[maybe_unused]] __attribute__((used)) const void* const kStbFunctionsTinygltfCalls[] = {
    reinterpret_cast<const void*>(&stbi_image_free),
    reinterpret_cast<const void*>(&stbi_is_16_bit_from_memory),
    reinterpret_cast<const void*>(&stbi_load_16_from_memory),
    reinterpret_cast<const void*>(&stbi_load_from_memory),
    reinterpret_cast<const void*>(&stbi_write_bmp_to_func),
    reinterpret_cast<const void*>(&stbi_write_jpg_to_func),
    reinterpret_cast<const void*>(&stbi_write_png_to_func),
};

/// tinygltf's messages can span several lines and quote raw bytes; ours are one printable
/// line. A JSON syntax error ("... parse error at line L, column C: detail") becomes
/// "name:L:C: detail", like the scene file's own syntax errors.
std::string loader_error_message(const std::string& name, std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) {
    text.pop_back();
  }
  if (text.empty()) return name + ": cannot parse glTF";
  std::string position;
  const std::string marker = "parse error at line ";
  if (const std::size_t at = text.find(marker); at != std::string::npos) {
    const std::size_t comma = text.find(", column ", at);
    const std::size_t colon = comma == std::string::npos ? comma : text.find(": ", comma);
    if (colon != std::string::npos) {
      const std::size_t line_begin = at + marker.size();
      const std::size_t column_begin = comma + 9;
      position = ":" + text.substr(line_begin, comma - line_begin) + ":" +
                 text.substr(column_begin, colon - column_begin);
      text = text.substr(colon + 2);
    }
  }
  std::string out = name + position + ": ";
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "; ";
    } else if (c != '\r') {
      out += (byte < 0x20 || byte >= 0x7f) ? '?' : c;
    }
  }
  return out;
}

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

/// The file as tinygltf reads it (images kept as bytes, keep_image_bytes; decoded later by
/// covrast's decoder, never by stb_image); its message on failure.
tinygltf::Model read_model(std::string_view bytes, const std::string& name,
                           const std::filesystem::path& base_dir, std::string& warn) {
  check_gltf_input(bytes, name, base_dir, warn);
  const std::optional<std::string> rewritten = rewritten_for_tinygltf(bytes);
  if (rewritten) bytes = *rewritten;
  if (bytes.size() > UINT_MAX) fail(name, "file too large");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&keep_image_bytes, nullptr);
  loader.SetFsCallbacks(gltf_fs_callbacks());
  tinygltf::Model model;
  std::string err;
  const bool ok =
      is_glb(bytes)
          ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                        reinterpret_cast<const unsigned char*>(bytes.data()),
                                        static_cast<unsigned>(bytes.size()), base_dir.string())
          : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                       static_cast<unsigned>(bytes.size()), base_dir.string());
  if (!ok) throw InputError(loader_error_message(name, err));
  return model;
}

/// The glTF extensions covrast implements: a file may require these (extensionsRequired).
/// KHR_mesh_quantization only widens the accessor types of the attributes, which the accessor
/// reader takes in every type anyway.
constexpr std::array<std::string_view, 15> kImplementedExtensions = {
    kDracoExtension,
    "EXT_mesh_gpu_instancing",
    "KHR_materials_emissive_strength",
    "KHR_materials_unlit",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    kLightsExtension,
    "EXT_texture_webp",
    kMeshoptExtension,
    kVariantsExtension,
    kIorExtension,
    kSpecularExtension,
    kClearcoatExtension,
    kSheenExtension,
    kIridescenceExtension};

/// glTF 2.0, 3.12: a file that requires an extension the loader does not implement must not
/// load, since drawing it without would be wrong.
void check_required_extensions(const tinygltf::Model& model, const std::string& name) {
  for (const std::string& extension : model.extensionsRequired) {
    if (std::find(kImplementedExtensions.begin(), kImplementedExtensions.end(), extension) ==
        kImplementedExtensions.end()) {
      fail(name, "requires the glTF extension " + printable(extension) +
                     ", which covrast does not implement");
    }
  }
}

/// tinygltf notes an image file it cannot open twice ("File not found : URI", "Failed to load
/// external 'uri' for image[N] ..."); where covrast has reported that image itself ("image N
/// (URI): no such file", gltf_textures.cpp), its notes say nothing more and are dropped. Notes
/// on images no material uses stay: they are the only word on them.
void drop_notes_on_missing_images(const std::string& name, std::vector<std::string>& warnings) {
  const std::string file_note = name + ": File not found : ";
  const std::string load_note = name + ": Failed to load external 'uri' for image[";
  const std::vector<std::string> all = warnings;  // looked up while `warnings` shrinks
  auto reported = [&](const std::string& fragment) {
    return std::any_of(all.begin(), all.end(), [&](const std::string& w) {
      return w.find(fragment) != std::string::npos &&
             w.find("): no such file") != std::string::npos;
    });
  };
  std::erase_if(warnings, [&](const std::string& w) {
    if (w.rfind(file_note, 0) == 0) return reported("(" + w.substr(file_note.size()) + ")");
    if (w.rfind(load_note, 0) == 0) {
      const std::size_t end = w.find(']', load_note.size());
      return end != std::string::npos &&
             reported(": image " + w.substr(load_note.size(), end - load_note.size()) + " (");
    }
    return false;
  });
}

/// Records the file's extensionsUsed, and a warning for each one covrast does not honour
/// (a material extension only matters, and warns, in a lit scene): nothing is left out
/// without a word.
void add_extension_warnings(const tinygltf::Model& model, const std::string& name,
                            LoadedMesh& loaded) {
  for (const std::string& extension : model.extensionsUsed) {
    loaded.extensions_used.push_back(extension);
    const GltfExtensionStatus status = gltf_extension_support(extension);
    if (status.support == GltfExtensionSupport::Honoured) continue;
    const bool material = extension.rfind("KHR_materials_", 0) == 0;
    (material ? loaded.lit_warnings : loaded.warnings)
        .push_back(name + ": uses the glTF extension " + printable(extension) + ", which covrast " +
                   (status.support == GltfExtensionSupport::Ignored ? "ignores" : "cannot read") +
                   ": " + status.effect);
  }
}

/// Where the node walk starts: the chosen scene's nodes, or every node that is nobody's child
/// when the file has no scene.
std::vector<int> root_nodes(const tinygltf::Model& model, const std::string& name) {
  std::vector<int> roots;
  if (!model.scenes.empty()) {
    const int scene_index = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (static_cast<std::size_t>(scene_index) >= model.scenes.size()) {
      fail(name, "scene " + std::to_string(scene_index) + " does not exist");
    }
    return model.scenes[static_cast<std::size_t>(scene_index)].nodes;
  }
  const std::size_t node_count = model.nodes.size();
  std::vector<bool> is_child(node_count, false);
  for (const tinygltf::Node& node : model.nodes) {
    for (const int child : node.children) {
      if (child >= 0 && static_cast<std::size_t>(child) < node_count) {
        is_child[static_cast<std::size_t>(child)] = true;
      }
    }
  }
  for (std::size_t i = 0; i < node_count; ++i) {
    if (!is_child[i]) roots.push_back(static_cast<int>(i));
  }
  return roots;
}

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
  void add_node_trees(const std::vector<int>& roots) {
    for (const int node_index : walk_nodes(roots)) {
      const tinygltf::Node& node = model_.nodes[static_cast<std::size_t>(node_index)];
      if (node.mesh >= 0) add_mesh(node_index, node.mesh, node_placement(node_index));
      if (node.camera >= 0) place_camera(node_index, node.camera);
      const glm::dmat4& world = node_world_[static_cast<std::size_t>(node_index)];
      if (auto light = node_light(model_, node_index, world, name_)) lights_.push_back(*light);
    }
  }

  LoadedMesh finish() {
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

 private:
  /// Mesh `mesh_index` of node `node_index`, placed by `placement` with the node's morph
  /// weights. Primitives of the point and line modes are counted (LoadedMesh::warnings), not
  /// drawn.
  void add_mesh(int node_index, int mesh_index, Placement placement) {
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
  int variant_material(const tinygltf::Primitive& primitive, const std::string& what) const {
    const std::vector<std::int32_t> mapped = primitive_variant_materials(
        model_, primitive, mesh_->material_variants.size(), name_, what);
    if (variant_ < 0 || mapped.empty() || mapped[std::size_t(variant_)] < 0) {
      return primitive.material;
    }
    return mapped[std::size_t(variant_)];
  }

  /// One primitive of a triangle mode (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN); `what`
  /// names it in messages.
  void add_primitive(const tinygltf::Primitive& primitive, int mode, const std::string& what,
                     const Placement& placement) {
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
    const TextureAttributes texture_attributes =
        read_texture_attributes(source, what, vertex_count);
    check_copies(placement.skin_joints.empty() ? placement.worlds.size() : 1, vertex_count,
                 corners.size() / 3, what);
    const std::uint32_t material = primitive.material >= 0
                                       ? static_cast<std::uint32_t>(primitive.material)
                                       : default_material_;
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
  void check_copies(std::size_t copies, std::size_t vertex_count, std::size_t triangle_count,
                    const std::string& what) const {
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
  void place_camera(int node_index, int camera_index) {
    if (static_cast<std::size_t>(camera_index) >= cameras_.size()) {
      fail(name_, "node " + std::to_string(node_index) + ": camera " +
                      std::to_string(camera_index) + " does not exist");
    }
    FileCamera& camera = cameras_[static_cast<std::size_t>(camera_index)];
    if (camera.placed) return;
    camera.placed = true;
    camera.world = node_world_[static_cast<std::size_t>(node_index)];
  }

  /// How node `node_index`'s mesh is placed: skinned by its skin's joints (the node's own
  /// transform then does not apply, glTF 2.0, 3.7.3.3), or once per EXT_mesh_gpu_instancing
  /// instance, or once at the node.
  Placement node_placement(int node_index) const {
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
    for (const glm::dmat4& instance :
         instance_transforms(reader_, instancing->second, node_index)) {
      placement.worlds.push_back(world * instance);
    }
    return placement;
  }

  /// The primitive's JOINTS_0 / WEIGHTS_0, JOINTS_1 / WEIGHTS_1, ... sets (glTF 2.0, 3.7.3.3).
  std::vector<SkinInfluences> skin_influences(const PrimitiveSource& source,
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
  void check_skin_component_types(const tinygltf::Primitive& primitive, const std::string& suffix,
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
    if (weights != nullptr &&
        !(weights->componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
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
  void place(const PrimitiveVertices& vertices, const std::vector<std::uint32_t>& corners,
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
    add_corner_normals(vertices.normals.empty() ? std::vector<glm::vec3>{}
                                                : world_normals(vertices.normals, world),
                       base, first_index);
    add_corner_texture_attributes(texture_attributes, world, base, first_index);
  }

  /// Counts a primitive whose material samples a UV set the primitive does not have.
  void count_missing_texcoords(const TextureAttributes& attributes, std::uint32_t material) {
    const Material& m = mesh_->materials[material];
    for (const TextureSlot* slot : m.texture_slots()) {
      if (slot->texture && attributes.uv[slot->texcoord].empty()) {
        ++missing_texcoords_;
        return;
      }
    }
  }

  /// TEXCOORD_0 and _1 (VEC2 of float, or of normalized unsigned byte or short, or any type
  /// KHR_mesh_quantization allows: the accessor reader maps each to numbers) and TANGENT
  /// (VEC4), each empty when absent.
  TextureAttributes read_texture_attributes(const PrimitiveSource& source, const std::string& what,
                                            std::size_t vertex_count) const {
    TextureAttributes out;
    int components = 0;
    for (int set = 0; set < kMaxTexcoordSets; ++set) {
      std::string attribute = "TEXCOORD_";
      attribute += char('0' + set);
      auto values = attribute_values(source, attribute, what, components);
      if (!values) continue;
      if (components != 2 || values->size() != 2 * vertex_count) {
        fail(name_, what + ": " + attribute + " must be VEC2 with one value per vertex");
      }
      out.uv[set] = std::move(*values);
    }
    auto tangents = attribute_values(source, "TANGENT", what, components);
    if (tangents) {
      if (components != 4 || tangents->size() != 4 * vertex_count) {
        fail(name_, what + ": TANGENT must be VEC4 with one value per vertex");
      }
      out.tangents = std::move(*tangents);
    }
    return out;
  }

  /// Corner UVs and tangents of the indices from `first_index` on (like add_corner_normals:
  /// a set starts at the first primitive that has it, earlier corners get zeros). Tangents
  /// move with `world`'s 3x3 part as vectors, and their sign turns when it mirrors.
  void add_corner_texture_attributes(const TextureAttributes& attributes, const glm::dmat4& world,
                                     std::size_t base, std::size_t first_index) {
    for (int set = 0; set < kMaxTexcoordSets; ++set) {
      std::vector<glm::vec2>& out = mesh_->corner_texcoords[set];
      const std::vector<double>& uv = attributes.uv[set];
      if (uv.empty() && out.empty()) continue;
      out.resize(first_index, glm::vec2(0.0f));
      for (std::size_t i = first_index; i < mesh_->indices.size(); ++i) {
        const std::size_t v = mesh_->indices[i] - base;
        out.push_back(uv.empty() ? glm::vec2(0.0f)
                                 : glm::vec2(float(uv[2 * v]), float(uv[2 * v + 1])));
      }
    }
    const std::vector<double>& t = attributes.tangents;
    if (t.empty() && mesh_->corner_tangents.empty()) return;
    mesh_->corner_tangents.resize(first_index, glm::vec4(0.0f));
    const glm::dmat3 linear(world);
    const double sign = glm::determinant(linear) < 0.0 ? -1.0 : 1.0;
    for (std::size_t i = first_index; i < mesh_->indices.size(); ++i) {
      const std::size_t v = mesh_->indices[i] - base;
      if (t.empty()) {
        mesh_->corner_tangents.emplace_back(0.0f);
        continue;
      }
      const glm::dvec3 tw = linear * glm::dvec3(t[4 * v], t[4 * v + 1], t[4 * v + 2]);
      mesh_->corner_tangents.emplace_back(glm::vec3(tw),
                                          float((t[4 * v + 3] < 0.0 ? -1.0 : 1.0) * sign));
    }
  }

  /// The primitive's Draco stream decoded, when it has the extension (gltf_draco.hpp).
  std::optional<DracoPrimitive> decode_draco_primitive(const tinygltf::Primitive& primitive,
                                                       const std::string& what) const {
    const auto it = primitive.extensions.find(std::string(kDracoExtension));
    if (it == primitive.extensions.end()) return std::nullopt;
    const tinygltf::Value& extension = it->second;
    const std::string where = what + ": " + std::string(kDracoExtension);
    if (!extension.IsObject() || !extension.Has("bufferView") ||
        !extension.Get("bufferView").IsInt() || !extension.Get("attributes").IsObject()) {
      fail(name_, where + ": needs a bufferView and an attributes object");
    }
    const int view_index = extension.Get("bufferView").GetNumberAsInt();
    const unsigned char* bytes = reader_.view_bytes(where, view_index);
    const std::size_t size = model_.bufferViews[static_cast<std::size_t>(view_index)].byteLength;
    std::map<std::string, DracoAttributeRef> refs;
    const tinygltf::Value& attributes = extension.Get("attributes");
    for (const std::string& key : attributes.Keys()) {
      const tinygltf::Value& id = attributes.Get(key);
      if (!id.IsInt() || id.GetNumberAsInt() < 0) {
        fail(name_, where + ": attribute " + printable(key) + " needs a Draco id");
      }
      const tinygltf::Accessor* accessor = attribute_accessor(primitive, key);
      refs[key] = {static_cast<std::uint32_t>(id.GetNumberAsInt()),
                   accessor != nullptr && accessor->normalized};
    }
    const tinygltf::Accessor* position = attribute_accessor(primitive, "POSITION");
    return decode_draco(
        bytes, size, refs,
        position != nullptr ? std::optional<std::size_t>(position->count) : std::nullopt, name_,
        what);
  }

  /// The accessor of the primitive's attribute `name`, or nullptr when it has none or names
  /// one that does not exist (reading the attribute reports that).
  const tinygltf::Accessor* attribute_accessor(const tinygltf::Primitive& primitive,
                                               const std::string& name) const {
    const auto it = primitive.attributes.find(name);
    if (it == primitive.attributes.end() || it->second < 0 ||
        static_cast<std::size_t>(it->second) >= model_.accessors.size()) {
      return nullptr;
    }
    return &model_.accessors[static_cast<std::size_t>(it->second)];
  }

  /// Attribute `attribute` of the primitive (its Draco values first, else its accessor), or
  /// nullopt when it has none; `components` receives the element width.
  std::optional<std::vector<double>> attribute_values(const PrimitiveSource& source,
                                                      const std::string& attribute,
                                                      const std::string& what,
                                                      int& components) const {
    if (source.draco) {
      const auto it = source.draco->attributes.find(attribute);
      if (it != source.draco->attributes.end()) {
        components = it->second.components;
        return it->second.values;
      }
    }
    const auto it = source.primitive.attributes.find(attribute);
    if (it == source.primitive.attributes.end()) return std::nullopt;
    return reader_.read_accessor(what + " " + attribute, it->second, components);
  }

  /// POSITION and NORMAL (when present) as the file gives them.
  PrimitiveVertices read_vertices(const PrimitiveSource& source, const std::string& what) const {
    PrimitiveVertices vertices;
    int components = 0;
    std::optional<std::vector<double>> positions =
        attribute_values(source, "POSITION", what, components);
    if (!positions) fail(name_, what + ": no POSITION attribute");
    if (components != 3) fail(name_, what + ": POSITION must be VEC3");
    vertices.positions = std::move(*positions);
    std::optional<std::vector<double>> normals =
        attribute_values(source, "NORMAL", what, components);
    if (normals) {
      if (components != 3) fail(name_, what + ": NORMAL must be VEC3");
      if (normals->size() != vertices.positions.size()) {
        fail(name_, what + ": NORMAL and POSITION counts differ");
      }
      vertices.normals = std::move(*normals);
    }
    return vertices;
  }

  /// The primitive's material's baseColorFactor (RGB), or 1 without a material.
  glm::dvec3 base_color_factor(const tinygltf::Primitive& primitive,
                               const std::string& what) const {
    glm::dvec3 factor(1.0);
    if (primitive.material >= 0) {
      if (static_cast<std::size_t>(primitive.material) >= model_.materials.size()) {
        fail(name_, what + ": material " + std::to_string(primitive.material) + " does not exist");
      }
      const std::vector<double>& f = model_.materials[static_cast<std::size_t>(primitive.material)]
                                         .pbrMetallicRoughness.baseColorFactor;
      if (f.size() >= 3) factor = glm::dvec3(f[0], f[1], f[2]);
    }
    return factor;
  }

  /// The primitive's vertex colours: COLOR_0 x baseColorFactor, or the (clamped) factor
  /// alone. Notes what decides the mesh's colour selection (finish()). `alphas`: COLOR_0's
  /// fourth component (clamped to 0..1), or 1 (the factor's alpha is Material::base_alpha).
  std::vector<glm::vec3> vertex_colors(const PrimitiveSource& source, const std::string& what,
                                       std::size_t vertex_count, std::vector<float>& alphas) {
    alphas.assign(vertex_count, 1.0f);
    const glm::dvec3 factor = base_color_factor(source.primitive, what);
    const glm::vec3 factor_clamped(clamp_unit(factor.r), clamp_unit(factor.g),
                                   clamp_unit(factor.b));
    if (!any_primitive_) {
      first_factor_ = factor_clamped;
    } else if (factor_clamped != first_factor_) {
      factors_differ_ = true;
    }
    any_primitive_ = true;
    int components = 0;
    const std::optional<std::vector<double>> values =
        attribute_values(source, "COLOR_0", what, components);
    if (!values) return std::vector<glm::vec3>(vertex_count, factor_clamped);
    any_color_attribute_ = true;
    if (components != 3 && components != 4) fail(name_, what + ": COLOR_0 must be VEC3 or VEC4");
    const auto width = static_cast<std::size_t>(components);
    if (values->size() / width != vertex_count) {
      fail(name_, what + ": COLOR_0 and POSITION counts differ");
    }
    std::vector<glm::vec3> colors;
    colors.reserve(vertex_count);
    if (components == 4) {
      any_color_alpha_ = true;
      for (std::size_t v = 0; v < vertex_count; ++v) {
        alphas[v] = static_cast<float>(clamp_unit((*values)[width * v + 3]));
      }
    }
    for (std::size_t v = 0; v < vertex_count; ++v) {
      colors.emplace_back(clamp_unit((*values)[width * v] * factor.r),
                          clamp_unit((*values)[width * v + 1] * factor.g),
                          clamp_unit((*values)[width * v + 2] * factor.b));
    }
    return colors;
  }

  /// The primitive's vertex sequence: its index accessor, its Draco faces, or 0, 1, ... when
  /// it has neither.
  std::vector<std::uint32_t> vertex_sequence(const PrimitiveSource& source, const std::string& what,
                                             std::size_t vertex_count) const {
    const tinygltf::Primitive& primitive = source.primitive;
    if (source.draco) {
      for (const std::uint32_t corner : source.draco->corners) {
        if (corner >= vertex_count) {
          fail(name_, what + ": Draco corner " + std::to_string(corner) + " out of range (" +
                          std::to_string(vertex_count) + " vertices)");
        }
      }
      return source.draco->corners;
    }
    std::vector<std::uint32_t> sequence;
    if (primitive.indices < 0) {
      sequence.resize(vertex_count);
      for (std::size_t v = 0; v < vertex_count; ++v) sequence[v] = static_cast<std::uint32_t>(v);
      return sequence;
    }
    int index_components = 0;
    const std::vector<double> indices =
        reader_.read_accessor(what + " indices", primitive.indices, index_components);
    const int index_type =
        model_.accessors[static_cast<std::size_t>(primitive.indices)].componentType;
    if (index_components != 1 || (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                  index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                  index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)) {
      fail(name_, what + ": indices must be unsigned byte, short or int scalars");
    }
    for (const double index : indices) {
      if (index >= static_cast<double>(vertex_count)) {
        fail(name_, what + ": index " + std::to_string(static_cast<std::uint64_t>(index)) +
                        " out of range (" + std::to_string(vertex_count) + " vertices)");
      }
      sequence.push_back(static_cast<std::uint32_t>(index));
    }
    return sequence;
  }

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
                                              bool indexed, const std::string& what) const {
    const std::size_t n = sequence.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (n % 3 != 0) {
        fail(name_, what + (indexed ? ": index count " : ": vertex count ") + std::to_string(n) +
                        " is not a multiple of 3");
      }
      return sequence;
    }
    const char* const mode_name =
        mode == TINYGLTF_MODE_TRIANGLE_STRIP ? "TRIANGLE_STRIP" : "TRIANGLE_FAN";
    if (n < 3) {
      fail(name_, what + ": " + mode_name + " needs at least 3 vertices, got " + std::to_string(n));
    }
    std::vector<std::uint32_t> corners;
    corners.reserve(3 * (n - 2));
    for (std::size_t i = 0; i + 2 < n; ++i) {
      if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        corners.insert(corners.end(),
                       {sequence[i], sequence[i + 1 + i % 2], sequence[i + 2 - i % 2]});
      } else {
        corners.insert(corners.end(), {sequence[i + 1], sequence[i + 2], sequence[0]});
      }
    }
    return corners;
  }

  /// Appends triangle corners (primitive vertex numbers) as mesh indices; the primitive's
  /// vertices start at `base`.
  void add_triangles(const std::vector<std::uint32_t>& corners, std::size_t base) {
    for (const std::uint32_t corner : corners) {
      mesh_->indices.push_back(static_cast<std::uint32_t>(base + corner));
    }
  }

  /// Corner normals of the indices from `first_index` on, from the primitive's world normals
  /// (empty: none, face normals). The mesh has corner normals from its first primitive with
  /// NORMAL on; corners before it get none.
  void add_corner_normals(const std::vector<glm::vec3>& normals, std::size_t base,
                          std::size_t first_index) {
    if (!normals.empty() && !any_normals_) {
      mesh_->corner_normals.assign(first_index, glm::vec3(0.0f));
      any_normals_ = true;
    }
    if (!any_normals_) return;
    for (std::size_t i = first_index; i < mesh_->indices.size(); ++i) {
      mesh_->corner_normals.push_back(normals.empty() ? glm::vec3(0.0f)
                                                      : normals[mesh_->indices[i] - base]);
    }
  }

  /// "name: 3 primitives not drawn (POINTS 1, LINES 2): covrast draws triangles only", or
  /// empty when every primitive was a triangle one.
  std::string undrawn_primitives_message() const {
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
  std::vector<int> walk_nodes(const std::vector<int>& roots) {
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

}  // namespace

LoadedMesh parse_gltf(std::string_view bytes, const std::string& display_name,
                      const std::filesystem::path& base_dir, const AnimationTime* pose,
                      std::string_view variant) {
  std::string warn;
  tinygltf::Model model = read_model(bytes, display_name, base_dir, warn);
  check_required_extensions(model, display_name);
  decode_meshopt_views(model, display_name);  // before anything reads an accessor
  std::vector<std::string> pose_warnings;
  if (pose != nullptr) pose_at_time(model, display_name, *pose, pose_warnings);
  const std::vector<int> roots = root_nodes(model, display_name);
  GltfMeshBuilder builder(model, display_name, base_dir, variant);
  builder.add_node_trees(roots);
  LoadedMesh loaded = builder.finish();
  add_loader_warnings(warn, display_name, loaded.warnings);
  drop_notes_on_missing_images(display_name, loaded.warnings);
  loaded.warnings.insert(loaded.warnings.end(), pose_warnings.begin(), pose_warnings.end());
  add_extension_warnings(model, display_name, loaded);
  return loaded;
}

}  // namespace covrast::detail
