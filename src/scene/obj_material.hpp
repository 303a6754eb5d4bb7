// Wavefront material libraries (.mtl, named by an OBJ file's mtllib): the statements covrast
// maps onto its materials (docs/scene-format.md, "OBJ materials").
#pragma once

#include "scene/scene_internal.hpp"

#include <covrast/scene.hpp>

#include <cstdint>

#include <filesystem>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace covrast::detail {

/// One newmtl entry: its material and its diffuse colour (Kd), which becomes the base colour
/// through the mesh's colour selection (MeshData has no per-material base colour).
struct ObjMaterial {
  std::string name;
  Material material;
  glm::vec3 diffuse_linear{1.0f};
};

/// The materials of the libraries an OBJ file names, in the order read (a later newmtl of an
/// existing name replaces it), and what they hold that covrast does not use.
struct MtlLibrary {
  std::vector<ObjMaterial> materials;
  std::vector<std::string> warnings;
  /// The index of material `name` in `materials`, or -1. A hash lookup: a file of 100,000
  /// newmtl or usemtl statements must not cost 100,000 scans of the materials (issue 28).
  long find(std::string_view name) const;
  /// Adds `material`, or replaces the one of its name.
  void add(ObjMaterial material);

 private:
  std::unordered_map<std::string, std::size_t> index_;  ///< name -> position in `materials`
};

/// Reads one .mtl file's text into `library`. `display_name` prefixes every message
/// ("name:LINE: ..."), `directory` resolves map_Kd's file. Throws InputError for a malformed
/// value; statements covrast does not use are counted in one warning.
void parse_mtl(std::string_view text, const std::string& display_name,
               const std::filesystem::path& directory, MtlLibrary& library);

/// A triangle whose face came before any usemtl.
inline constexpr std::uint32_t kNoObjMaterial = 0xffffffffu;

/// Gives `loaded.data` (triangles read, vertex colours linear or empty) the materials that
/// its usemtl statements name: `names` in order of first use, `triangle_names` one index into
/// them per triangle (or kNoObjMaterial). Unknown names get the default material, counted in
/// a warning. Without any known name the mesh keeps no materials, as before materials. The
/// diffuse colours become the uniform colour when all triangles share one and the file has no
/// vertex colours, else vertex colours (vertex colour x Kd; a vertex shared by materials of
/// different colours is copied once per material).
void apply_obj_materials(const MtlLibrary& library, const std::vector<std::string>& names,
                         const std::vector<std::uint32_t>& triangle_names,
                         const std::string& obj_name, LoadedMesh& loaded);

}  // namespace covrast::detail
