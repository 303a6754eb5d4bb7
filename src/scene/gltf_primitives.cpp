// glTF reader, a primitive's attributes (gltf_builder.hpp): positions and normals, UV sets
// and tangents, vertex colours, Draco streams, and the triangle corners of each topology.
#include "scene/gltf_builder.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <map>
#include <optional>
#include <string_view>
#include <vector>

namespace covrast::detail {

/// Counts a primitive whose material samples a UV set the primitive does not have.
void GltfMeshBuilder::count_missing_texcoords(const TextureAttributes& attributes,
                                              std::uint32_t material) {
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
TextureAttributes GltfMeshBuilder::read_texture_attributes(const PrimitiveSource& source,
                                                           const std::string& what,
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
void GltfMeshBuilder::add_corner_texture_attributes(const TextureAttributes& attributes,
                                                    const glm::dmat4& world, std::size_t base,
                                                    std::size_t first_index) {
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
std::optional<DracoPrimitive> GltfMeshBuilder::decode_draco_primitive(
    const tinygltf::Primitive& primitive, const std::string& what) const {
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
const tinygltf::Accessor* GltfMeshBuilder::attribute_accessor(const tinygltf::Primitive& primitive,
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
std::optional<std::vector<double>> GltfMeshBuilder::attribute_values(const PrimitiveSource& source,
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
PrimitiveVertices GltfMeshBuilder::read_vertices(const PrimitiveSource& source,
                                                 const std::string& what) const {
  PrimitiveVertices vertices;
  int components = 0;
  std::optional<std::vector<double>> positions =
      attribute_values(source, "POSITION", what, components);
  if (!positions) fail(name_, what + ": no POSITION attribute");
  if (components != 3) fail(name_, what + ": POSITION must be VEC3");
  vertices.positions = std::move(*positions);
  std::optional<std::vector<double>> normals = attribute_values(source, "NORMAL", what, components);
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
glm::dvec3 GltfMeshBuilder::base_color_factor(const tinygltf::Primitive& primitive,
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
std::vector<glm::vec3> GltfMeshBuilder::vertex_colors(const PrimitiveSource& source,
                                                      const std::string& what,
                                                      std::size_t vertex_count,
                                                      std::vector<float>& alphas) {
  alphas.assign(vertex_count, 1.0f);
  const glm::dvec3 factor = base_color_factor(source.primitive, what);
  const glm::vec3 factor_clamped(clamp_unit(factor.r), clamp_unit(factor.g), clamp_unit(factor.b));
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
std::vector<std::uint32_t> GltfMeshBuilder::vertex_sequence(const PrimitiveSource& source,
                                                            const std::string& what,
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
std::vector<std::uint32_t> GltfMeshBuilder::triangle_corners(int mode,
                                                             std::vector<std::uint32_t> sequence,
                                                             bool indexed,
                                                             const std::string& what) const {
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
void GltfMeshBuilder::add_triangles(const std::vector<std::uint32_t>& corners, std::size_t base) {
  for (const std::uint32_t corner : corners) {
    mesh_->indices.push_back(static_cast<std::uint32_t>(base + corner));
  }
}

/// Corner normals of the indices from `first_index` on, from the primitive's world normals
/// (empty: none, face normals). The mesh has corner normals from its first primitive with
/// NORMAL on; corners before it get none.
void GltfMeshBuilder::add_corner_normals(const std::vector<glm::vec3>& normals, std::size_t base,
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

}  // namespace covrast::detail
