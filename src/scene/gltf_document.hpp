// glTF reader, the document (gltf_document.cpp): reading the file with tinygltf, the
// extensions it requires and uses, and where the node walk starts. Private to the scene stage.
#pragma once

#include "scene/scene_internal.hpp"

#include <tiny_gltf.h>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace covrast::detail {

/// The file as tinygltf reads it (images kept as bytes, keep_image_bytes; decoded later by
/// covrast's decoder, never by stb_image); its message on failure. `warn`: tinygltf's notes.
tinygltf::Model read_model(std::string_view bytes, const std::string& name,
                           const std::filesystem::path& base_dir, std::string& warn);

/// glTF 2.0, 3.12: a file that requires an extension the loader does not implement must not
/// load, since drawing it without would be wrong.
void check_required_extensions(const tinygltf::Model& model, const std::string& name);

/// Drops tinygltf's notes on image files that covrast has reported itself
/// (gltf_document.cpp says which).
void drop_notes_on_missing_images(const std::string& name, std::vector<std::string>& warnings);

/// Records the file's extensionsUsed, and a warning for each one covrast does not honour.
void add_extension_warnings(const tinygltf::Model& model, const std::string& name,
                            LoadedMesh& loaded);

/// Where the node walk starts: the chosen scene's nodes, or every node that is nobody's child
/// when the file has no scene.
std::vector<int> root_nodes(const tinygltf::Model& model, const std::string& name);

}  // namespace covrast::detail
