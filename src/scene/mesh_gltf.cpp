// glTF 2.0 reader (.gltf with embedded or external buffers, .glb) on top of tinygltf. Collects
// every triangle primitive (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN) of every mesh reachable
// from the default scene (scene 0 when none is marked, every root node when the file has no
// scene at all), posed in the file's static pose: morph targets at their default weights,
// skins by their joints' node transforms, EXT_mesh_gpu_instancing instances; bakes the node
// transforms (matrix, or T * R * S) into the positions, and COLOR_0 x baseColorFactor into
// colors_linear. Points and lines are counted in a warning; Draco streams are decoded by
// gltf_draco.cpp; the file's cameras are kept for the scene (FileCamera).
// glTF colours are linear already (glTF 2.0 spec, 3.7.2.1 and 5.19.3). Every buffer access goes
// through gltf_accessors.hpp, bounds-checked, so a broken file is an InputError, never a crash.
// This file is the outline: the document (gltf_document.cpp), the pose (gltf_pose.cpp), the
// mesh builder's node walk (gltf_builder.cpp) and primitives (gltf_primitives.cpp).
#include "scene/gltf_animation.hpp"
#include "scene/gltf_builder.hpp"
#include "scene/gltf_document.hpp"
#include "scene/gltf_input.hpp"
#include "scene/gltf_meshopt.hpp"
#include "scene/gltf_pose.hpp"
#include "scene/scene_internal.hpp"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <map>
#include <optional>
#include <string_view>
#include <vector>

namespace covrast::detail {
namespace {

/// Draco's static archive (CMakeLists.txt) holds its own copies of tinygltf and stb, in one
/// object file. GNU ld takes an archive member to define a symbol that only shared libraries
/// refer to, even when another shared library defines it: libtinygltf's calls into stb would
/// pull Draco's copy, and with it a second tinygltf whose structures differ from the one
/// covrast is compiled against (a crash on the first glTF file with an image). These
/// references from covrast's own code bind stb's functions to libstb before the archive is
/// searched; the ctest link_has_no_second_tinygltf checks the executable.
[[maybe_unused]] __attribute__((used)) const void* const kStbFunctionsTinygltfCalls[] = {
    reinterpret_cast<const void*>(&stbi_image_free),
    reinterpret_cast<const void*>(&stbi_is_16_bit_from_memory),
    reinterpret_cast<const void*>(&stbi_load_16_from_memory),
    reinterpret_cast<const void*>(&stbi_load_from_memory),
    reinterpret_cast<const void*>(&stbi_write_bmp_to_func),
    reinterpret_cast<const void*>(&stbi_write_jpg_to_func),
    reinterpret_cast<const void*>(&stbi_write_png_to_func),
};

}  // namespace

LoadedMesh parse_gltf(std::string_view bytes, const std::string& display_name,
                      const std::filesystem::path& base_dir, const AnimationTime* pose,
                      std::string_view variant) {
  std::string warn;
  tinygltf::Model model = read_model(bytes, display_name, base_dir, warn);
  check_required_extensions(model, display_name);
  decode_meshopt_views(model, display_name);  // before anything reads an accessor
  std::vector<std::string> pose_warnings;
  if (pose != nullptr) pose_at_time(model, display_name, *pose, pose_warnings);
  const std::vector<int> roots = root_nodes(model, display_name);
  GltfMeshBuilder builder(model, display_name, base_dir, variant);
  builder.add_node_trees(roots);
  LoadedMesh loaded = builder.finish();
  add_loader_warnings(warn, display_name, loaded.warnings);
  drop_notes_on_missing_images(display_name, loaded.warnings);
  loaded.warnings.insert(loaded.warnings.end(), pose_warnings.begin(), pose_warnings.end());
  add_extension_warnings(model, display_name, loaded);
  return loaded;
}

}  // namespace covrast::detail
