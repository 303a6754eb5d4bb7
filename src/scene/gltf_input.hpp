// What the glTF loader checks before tinygltf sees a file (gltf_input.cpp): that it is glTF
// at all, its JSON nesting depth, the JSON types of the fields covrast reads, and its
// buffers' URIs and sizes; and the file-system callbacks through which tinygltf reads
// external buffers and images (regular files only, size-limited).
#pragma once

#include <tiny_gltf.h>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace covrast::detail {

/// Throws InputError("name: ...") when `bytes` are neither glTF JSON nor binary glTF, nest
/// deeper than kMaxJsonDepth, hold a number beyond double's range, give a field covrast reads
/// the wrong JSON type (an array where an object belongs, a string for a number, a negative
/// index or count), or name a buffer that cannot be read as its byteLength says. A
/// KHR_lights_punctual range that is not > 0 is an error for a point or spot light and a
/// line of `warn` (tinygltf's warnings) for a directional one, which has no range.
void check_gltf_input(std::string_view bytes, const std::string& name,
                      const std::filesystem::path& base_dir, std::string& warn);

/// Every finding of check_gltf_input's type check, not only the first: the errors (returned)
/// and the warnings (appended to `warnings`), each "name: JSON path: ...". Nothing for bytes
/// that are not glTF JSON at all (the load reports that). For `covrast info --validate`.
std::vector<std::string> gltf_schema_findings(std::string_view bytes, const std::string& name,
                                              std::vector<std::string>& warnings);

/// tinygltf's file access: FileExists without opening (a FIFO would block), no path
/// expansion, ReadWholeFile through read_whole_file (regular files up to kMaxInputFileBytes).
tinygltf::FsCallbacks gltf_fs_callbacks();

/// tinygltf's warnings (one per line), each as "name: warning" in `out`.
void add_loader_warnings(const std::string& warn, const std::string& name,
                         std::vector<std::string>& out);

}  // namespace covrast::detail
