// covrast::validate_file (covrast/scene.hpp): every problem of a scene or mesh file, for
// `covrast info --validate`. The loaders stop at the first error; for glTF files the type check
// of the fields covrast reads (gltf_input.cpp) runs on its own first, so that every wrong field
// is listed with its JSON path.
#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include "scene/gltf_input.hpp"
#include "scene/scene_internal.hpp"

#include <string>

namespace covrast {

Validation validate_file(const std::filesystem::path& path, const SceneChoices& choices) {
  Validation out;
  const std::string ext = detail::lower_extension(path);
  const bool mesh = ext == ".obj" || ext == ".gltf" || ext == ".glb";
  if (ext == ".gltf" || ext == ".glb") {
    std::string bytes, error;
    if (detail::read_whole_file(path, bytes, error)) {
      // The name the mesh loader gives the file (load_mesh_scene reads parent / filename).
      const std::string name = (path.parent_path() / path.filename()).lexically_normal().string();
      std::vector<std::string> warnings;
      out.errors = detail::gltf_schema_findings(bytes, name, warnings);
      if (!out.errors.empty()) {
        out.warnings = std::move(warnings);
        return out;
      }
    }
  }
  try {
    // The size is the default framing's (it changes no finding).
    const Scene scene = mesh ? load_mesh_scene(path, 640, 360, choices) : load_scene(path, choices);
    out.warnings = scene.warnings;
  } catch (const InputError& e) {
    out.errors.push_back(e.what());
  }
  return out;
}

}  // namespace covrast
