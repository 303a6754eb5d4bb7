// Core: reading a whole input file, bounded and without blocking, for every loader (scene
// JSON, OBJ, glTF and its buffers, images): one policy for what may be read and one wording
// of why not.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace covrast::detail {

/// Reads a whole regular file of at most `max_bytes`. On failure returns false and sets
/// `error` to the reason (the system's, e.g. "No such file or directory" or "Is a directory",
/// or "not a regular file" for FIFOs and devices, a size over the limit, a NUL byte in the
/// path). Never blocks on a FIFO or device.
bool read_whole_file(const std::filesystem::path& path, std::string& contents, std::string& error,
                     std::uint64_t max_bytes);
/// The same into bytes (tinygltf's buffers and images: read once, not copied).
bool read_whole_file(const std::filesystem::path& path, std::vector<unsigned char>& contents,
                     std::string& error, std::uint64_t max_bytes);

/// Why a path whose status is `status` is not read, in read_whole_file's words: "Is a
/// directory", or "not a regular file" for FIFOs, devices and sockets; empty for a regular
/// file (and for one that does not exist, which opening reports).
std::string unreadable_kind(const std::filesystem::file_status& status);

/// `path`'s extension in lower case (".glb" for "Model.GLB"): how the loaders and writers tell
/// formats apart.
std::string lower_extension(const std::filesystem::path& path);

/// "1 GiB", "64 MiB" or "N bytes".
std::string size_text(std::uint64_t bytes);

}  // namespace covrast::detail
