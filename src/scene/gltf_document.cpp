// glTF reader, the document: tinygltf reads the file (its messages made one printable line),
// the extensions the file requires and uses are checked and reported, and the node walk's
// roots are found. parse_gltf (mesh_gltf.cpp) runs these around the mesh builder.
#include "scene/gltf_document.hpp"

#include "scene/gltf_accessors.hpp"
#include "scene/gltf_draco.hpp"
#include "scene/gltf_lights.hpp"
#include "scene/gltf_meshopt.hpp"
#include "scene/gltf_textures.hpp"
#include "scene/gltf_variants.hpp"

#include "scene/gltf_input.hpp"
#include "scene/gltf_materials.hpp"
#include "scene/gltf_rewrite.hpp"
#include "scene/scene_internal.hpp"

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

/// tinygltf's messages can span several lines and quote raw bytes; ours are one printable
/// line. A JSON syntax error ("... parse error at line L, column C: detail") becomes
/// "name:L:C: detail", like the scene file's own syntax errors.
std::string loader_error_message(const std::string& name, std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) {
    text.pop_back();
  }
  if (text.empty()) return name + ": cannot parse glTF";
  std::string position;
  const std::string marker = "parse error at line ";
  if (const std::size_t at = text.find(marker); at != std::string::npos) {
    const std::size_t comma = text.find(", column ", at);
    const std::size_t colon = comma == std::string::npos ? comma : text.find(": ", comma);
    if (colon != std::string::npos) {
      const std::size_t line_begin = at + marker.size();
      const std::size_t column_begin = comma + 9;
      position = ":" + text.substr(line_begin, comma - line_begin) + ":" +
                 text.substr(column_begin, colon - column_begin);
      text = text.substr(colon + 2);
    }
  }
  std::string out = name + position + ": ";
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "; ";
    } else if (c != '\r') {
      out += (byte < 0x20 || byte >= 0x7f) ? '?' : c;
    }
  }
  return out;
}

/// The glTF extensions covrast implements: a file may require these (extensionsRequired).
/// KHR_mesh_quantization only widens the accessor types of the attributes, which the accessor
/// reader takes in every type anyway.
constexpr std::array<std::string_view, 19> kImplementedExtensions = {
    kDracoExtension,
    "EXT_mesh_gpu_instancing",
    "KHR_materials_emissive_strength",
    "KHR_materials_unlit",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    kLightsExtension,
    "EXT_texture_webp",
    kMeshoptExtension,
    kVariantsExtension,
    kIorExtension,
    kSpecularExtension,
    kClearcoatExtension,
    kSheenExtension,
    kIridescenceExtension,
    kAnisotropyExtension,
    kTransmissionExtension,
    kVolumeExtension,
    kDispersionExtension};

}  // namespace

/// The file as tinygltf reads it (images kept as bytes, keep_image_bytes; decoded later by
/// covrast's decoder, never by stb_image); its message on failure.
tinygltf::Model read_model(std::string_view bytes, const std::string& name,
                           const std::filesystem::path& base_dir, std::string& warn) {
  check_gltf_input(bytes, name, base_dir, warn);
  const std::optional<std::string> rewritten = rewritten_for_tinygltf(bytes);
  if (rewritten) bytes = *rewritten;
  if (bytes.size() > UINT_MAX) fail(name, "file too large");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&keep_image_bytes, nullptr);
  loader.SetFsCallbacks(gltf_fs_callbacks());
  tinygltf::Model model;
  std::string err;
  const bool ok =
      is_glb(bytes)
          ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                        reinterpret_cast<const unsigned char*>(bytes.data()),
                                        static_cast<unsigned>(bytes.size()), base_dir.string())
          : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                       static_cast<unsigned>(bytes.size()), base_dir.string());
  if (!ok) throw InputError(loader_error_message(name, err));
  return model;
}

/// glTF 2.0, 3.12: a file that requires an extension the loader does not implement must not
/// load, since drawing it without would be wrong.
void check_required_extensions(const tinygltf::Model& model, const std::string& name) {
  for (const std::string& extension : model.extensionsRequired) {
    if (std::find(kImplementedExtensions.begin(), kImplementedExtensions.end(), extension) ==
        kImplementedExtensions.end()) {
      fail(name, "requires the glTF extension " + printable(extension) +
                     ", which covrast does not implement");
    }
  }
}

/// tinygltf notes an image file it cannot open twice ("File not found : URI", "Failed to load
/// external 'uri' for image[N] ..."); where covrast has reported that image itself ("image N
/// (URI): no such file", gltf_textures.cpp), its notes say nothing more and are dropped. Notes
/// on images no material uses stay: they are the only word on them.
void drop_notes_on_missing_images(const std::string& name, std::vector<std::string>& warnings) {
  const std::string file_note = name + ": File not found : ";
  const std::string load_note = name + ": Failed to load external 'uri' for image[";
  const std::vector<std::string> all = warnings;  // looked up while `warnings` shrinks
  auto reported = [&](const std::string& fragment) {
    return std::any_of(all.begin(), all.end(), [&](const std::string& w) {
      return w.find(fragment) != std::string::npos &&
             w.find("): no such file") != std::string::npos;
    });
  };
  std::erase_if(warnings, [&](const std::string& w) {
    if (w.rfind(file_note, 0) == 0) {
      // Appended rather than "(" + ... + ")": g++ 12 warns falsely (-Wrestrict, GCC bug
      // 105329) on a string literal prepended to a temporary string.
      std::string fragment = "(";
      fragment.append(w, file_note.size()).append(")");
      return reported(fragment);
    }
    if (w.rfind(load_note, 0) == 0) {
      const std::size_t end = w.find(']', load_note.size());
      return end != std::string::npos &&
             reported(": image " + w.substr(load_note.size(), end - load_note.size()) + " (");
    }
    return false;
  });
}

/// Records the file's extensionsUsed, and a warning for each one covrast does not honour
/// (a material extension only matters, and warns, in a lit scene): nothing is left out
/// without a word.
void add_extension_warnings(const tinygltf::Model& model, const std::string& name,
                            LoadedMesh& loaded) {
  for (const std::string& extension : model.extensionsUsed) {
    loaded.extensions_used.push_back(extension);
    const GltfExtensionStatus status = gltf_extension_support(extension);
    if (status.support == GltfExtensionSupport::Honoured) continue;
    const bool material = extension.rfind("KHR_materials_", 0) == 0;
    (material ? loaded.lit_warnings : loaded.warnings)
        .push_back(name + ": uses the glTF extension " + printable(extension) + ", which covrast " +
                   (status.support == GltfExtensionSupport::Ignored ? "ignores" : "cannot read") +
                   ": " + status.effect);
  }
}

/// Where the node walk starts: the chosen scene's nodes, or every node that is nobody's child
/// when the file has no scene.
std::vector<int> root_nodes(const tinygltf::Model& model, const std::string& name) {
  std::vector<int> roots;
  if (!model.scenes.empty()) {
    const int scene_index = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (static_cast<std::size_t>(scene_index) >= model.scenes.size()) {
      fail(name, "scene " + std::to_string(scene_index) + " does not exist");
    }
    return model.scenes[static_cast<std::size_t>(scene_index)].nodes;
  }
  const std::size_t node_count = model.nodes.size();
  std::vector<bool> is_child(node_count, false);
  for (const tinygltf::Node& node : model.nodes) {
    for (const int child : node.children) {
      if (child >= 0 && static_cast<std::size_t>(child) < node_count) {
        is_child[static_cast<std::size_t>(child)] = true;
      }
    }
  }
  for (std::size_t i = 0; i < node_count; ++i) {
    if (!is_child[i]) roots.push_back(static_cast<int>(i));
  }
  return roots;
}

}  // namespace covrast::detail
