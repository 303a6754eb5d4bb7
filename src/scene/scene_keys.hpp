// Scene loading: the keys of a scene file that covrast does not read. A misspelt key
// ("clearcot") would otherwise change nothing without a word; each one is a warning naming
// its JSON path and the nearest known key, which --strict makes an error.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace covrast::detail {

/// One warning per key of `root` (the parsed scene file `file`) that no part of the scene
/// format reads, at every level docs/scene-format.md describes: "file: meshes[0].material.x:
/// unknown key, ignored (did you mean 'y'?)". Keys starting with '_' and "extras" are the
/// file's own notes and are never reported.
std::vector<std::string> unknown_scene_keys(const nlohmann::json& root, const std::string& file);

}  // namespace covrast::detail
