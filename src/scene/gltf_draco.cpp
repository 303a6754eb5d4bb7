// KHR_draco_mesh_compression (github.com/KhronosGroup/glTF, extensions/2.0/Khronos/
// KHR_draco_mesh_compression): the primitive's attributes and indices are one Draco stream in
// a bufferView; each glTF attribute names a Draco attribute by unique id. Decoded with Debian's
// libdraco; the values then go the same way as an accessor's (mesh_gltf.cpp).
#include "scene/gltf_draco.hpp"

#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#include <nlohmann/json.hpp>

#include <memory>

namespace covrast::detail {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& what,
                       const std::string& message) {
  throw InputError(name + ": " + what + ": " + std::string(kDracoExtension) + ": " + message);
}

/// Largest value of an unsigned or signed integer Draco type, for normalized attributes
/// whose stream does not say so itself; 0 for float types.
double integer_range(draco::DataType type) {
  switch (type) {
    case draco::DT_UINT8:
      return 255.0;
    case draco::DT_INT8:
      return 127.0;
    case draco::DT_UINT16:
      return 65535.0;
    case draco::DT_INT16:
      return 32767.0;
    default:
      return 0.0;
  }
}

DracoAttribute read_attribute(const draco::Mesh& mesh, const DracoAttributeRef& ref,
                              const std::string& name, const std::string& what,
                              const std::string& attribute_name) {
  const draco::PointAttribute* attribute = mesh.GetAttributeByUniqueId(ref.unique_id);
  if (attribute == nullptr) {
    fail(name, what,
         attribute_name + " names Draco attribute " + std::to_string(ref.unique_id) +
             ", which the stream does not hold");
  }
  DracoAttribute out;
  out.components = attribute->num_components();
  if (out.components < 1 || out.components > 4) {
    fail(name, what, attribute_name + " has " + std::to_string(out.components) + " components");
  }
  // ConvertValue maps integers to [0, 1] itself only when the stream marks them normalized.
  const double range =
      ref.normalized && !attribute->normalized() ? integer_range(attribute->data_type()) : 0.0;
  out.values.reserve(mesh.num_points() * static_cast<std::size_t>(out.components));
  float value[4] = {};
  for (draco::PointIndex point(0); point < mesh.num_points(); ++point) {
    if (!attribute->ConvertValue<float>(attribute->mapped_index(point), value)) {
      fail(name, what, attribute_name + ": a value does not convert to a number");
    }
    for (int c = 0; c < out.components; ++c) {
      out.values.push_back(range > 0.0 ? std::max(value[c] / range, -1.0) : value[c]);
    }
  }
  return out;
}

}  // namespace

bool strip_draco_indices(nlohmann::json& document) {
  using nlohmann::json;
  bool changed = false;
  const auto meshes = document.find("meshes");
  if (meshes == document.end() || !meshes->is_array()) return false;
  for (json& mesh : *meshes) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) {
      continue;
    }
    for (json& primitive : mesh["primitives"]) {
      if (!primitive.is_object()) continue;
      const auto extensions = primitive.find("extensions");
      if (extensions == primitive.end() || !extensions->is_object() ||
          !extensions->contains(kDracoExtension)) {
        continue;
      }
      changed = primitive.erase("indices") > 0 || changed;
    }
  }
  return changed;
}

DracoPrimitive decode_draco(const unsigned char* bytes, std::size_t size,
                            const std::map<std::string, DracoAttributeRef>& attributes,
                            std::optional<std::size_t> position_count, const std::string& name,
                            const std::string& what) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes), size);
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) fail(name, what, "cannot decode: " + decoded.status().error_msg_string());
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (position_count && mesh->num_points() != *position_count) {
    fail(name, what,
         "the stream holds " + std::to_string(mesh->num_points()) +
             " points, the POSITION accessor's count is " + std::to_string(*position_count) +
             " (they must be equal)");
  }
  if (std::uint64_t{mesh->num_faces()} * 3 > kMaxAccessorElements) {
    fail(name, what,
         "the stream holds " + std::to_string(mesh->num_faces()) + " triangles, more than the " +
             std::to_string(kMaxAccessorElements / 3) + " an index accessor may hold");
  }
  DracoPrimitive out;
  out.vertex_count = mesh->num_points();
  for (const auto& [attribute_name, ref] : attributes) {
    out.attributes[attribute_name] = read_attribute(*mesh, ref, name, what, attribute_name);
  }
  out.corners.reserve(std::size_t{mesh->num_faces()} * 3);
  for (draco::FaceIndex face(0); face < mesh->num_faces(); ++face) {
    for (int corner = 0; corner < 3; ++corner)
      out.corners.push_back(mesh->face(face)[corner].value());
  }
  return out;
}

}  // namespace covrast::detail
