// EXT_meshopt_compression for the glTF reader (mesh_gltf.cpp), on top of Debian's
// libmeshoptimizer: the buffer views the extension compresses are decoded once, after tinygltf
// has read the file, into buffers of their own, so that every accessor reads them as it reads
// any other view.
#pragma once

#include <tiny_gltf.h>
#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <string>
#include <string_view>

namespace covrast::detail {

inline constexpr std::string_view kMeshoptExtension = "EXT_meshopt_compression";

/// Most bytes the decoded views of one file may hold together (docs/limits.md).
inline constexpr std::uint64_t kMaxMeshoptDecodedBytes = std::uint64_t(1) << 30;

/// A buffer that the extension marks {"fallback": true} may have no data at all (its views
/// are read only by viewers without the extension); tinygltf 2.7 would read a .glb's binary
/// chunk into it, or refuse a .gltf buffer without a URI. Each such buffer becomes a data: URI
/// of one zero byte (tinygltf refuses an empty one) before tinygltf reads the file
/// (gltf_rewrite.hpp); nothing reads it, since decode_meshopt_views points every compressed
/// view elsewhere. False when the document has none.
bool empty_meshopt_fallback_buffers(nlohmann::json& document);

/// Decodes every buffer view of `model` that has EXT_meshopt_compression (its "buffer",
/// "byteOffset", "byteLength", "byteStride", "count", "mode" and "filter", as the extension's
/// specification defines them) with meshopt_decodeVertexBuffer, _decodeIndexBuffer or
/// _decodeIndexSequence and the filter's meshopt_decodeFilter*, appends the result to
/// model.buffers, and points the view at it (the view's fallback data, which may be absent,
/// is never read). Every field is checked before the decoder sees it (libmeshoptimizer only
/// asserts its preconditions): an error names the view and the field. Throws InputError.
void decode_meshopt_views(tinygltf::Model& model, const std::string& name);

}  // namespace covrast::detail
