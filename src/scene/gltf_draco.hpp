// KHR_draco_mesh_compression for the glTF reader (mesh_gltf.cpp), on top of Debian's libdraco:
// the JSON rewrite that lets tinygltf read such files, and the decoding of one compressed
// primitive into per-vertex attribute values and triangle corners.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace covrast::detail {

inline constexpr std::string_view kDracoExtension = "KHR_draco_mesh_compression";

/// tinygltf 2.7 without its Draco option refuses a primitive whose "indices" accessor has no
/// bufferView, which is how a Draco primitive says its indices live in the compressed stream.
/// Removes "indices" from every Draco primitive of the document (the decoded faces replace
/// them) before tinygltf reads it (gltf_rewrite.hpp); false when none had them.
bool strip_draco_indices(nlohmann::json& document);

/// One glTF attribute of a decoded primitive: `components` values per vertex.
struct DracoAttribute {
  int components = 0;
  std::vector<double> values;
};

struct DracoPrimitive {
  std::size_t vertex_count = 0;
  std::map<std::string, DracoAttribute> attributes;  ///< by glTF name ("POSITION", ...)
  std::vector<std::uint32_t> corners;                ///< 3 per triangle, vertex numbers
};

/// What the glTF file says about one attribute of a Draco primitive: its unique id in the
/// Draco stream, and whether its accessor is a normalized integer type (glTF 2.0, 3.11).
struct DracoAttributeRef {
  std::uint32_t unique_id = 0;
  bool normalized = false;
};

/// Decodes the Draco mesh in `bytes` (the extension's bufferView). Throws InputError naming
/// `name` and `what` (the primitive) when the stream does not decode, lacks an attribute, holds
/// a number of points other than `position_count` (the POSITION accessor's count, when the
/// primitive has one: the extension requires them equal) or more triangle corners than an
/// accessor may hold (kMaxAccessorElements), checked before covrast copies anything.
DracoPrimitive decode_draco(const unsigned char* bytes, std::size_t size,
                            const std::map<std::string, DracoAttributeRef>& attributes,
                            std::optional<std::size_t> position_count, const std::string& name,
                            const std::string& what);

}  // namespace covrast::detail
