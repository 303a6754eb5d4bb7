// The glTF reader's edits of a file's JSON before tinygltf reads it (mesh_gltf.cpp): what
// tinygltf 2.7 would refuse in files that use an extension covrast decodes itself.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace covrast::detail {

/// For a file (.gltf text or .glb) that names KHR_draco_mesh_compression or
/// EXT_meshopt_compression: the file with its JSON edited (strip_draco_indices,
/// empty_meshopt_fallback_buffers; a .glb's other chunks kept byte for byte); nullopt when
/// nothing changes and for JSON that does not parse (tinygltf then reports the syntax error).
std::optional<std::string> rewritten_for_tinygltf(std::string_view bytes);

}  // namespace covrast::detail
