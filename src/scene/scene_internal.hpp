// Internal interface of the scene loader (src/scene): the mesh parsers work on bytes already
// read into memory, so that the caller decides how an unopenable file is reported (load_scene
// names the JSON key, load_mesh names the file).
#pragma once

#include <covrast/scene.hpp>

#include "core/file_read.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace covrast::detail {

/// A camera of a glTF file (glTF 2.0, 3.10), where the scene's {"gltf": N} camera comes from.
struct FileCamera {
  bool orthographic = false;
  double yfov_rad = 0.0;  ///< perspective: vertical field of view [radians]
  double ymag = 0.0;      ///< orthographic: half the view's height [file units]
  double znear = 0.0;     ///< [file units]
  double zfar = 0.0;      ///< [file units]; 0: infinite
  /// Placed by a node of the walked scene (the first one in the walk that names it); its
  /// world transform then is `world` (the camera looks down its -z, +y up).
  bool placed = false;
  glm::dmat4 world{1.0};
};

/// A glTF KHR_lights_punctual light on a node of the walked scene (gltf_lights.cpp): type,
/// colour, intensity, range and cone angles [degrees] as the file gives them; it sits at the
/// origin of `world` (the node's world transform) and shines down its -z.
struct FileLight {
  Light light;
  glm::dmat4 world{1.0};
  int index = 0;  ///< in the file's lights
  int node = 0;   ///< the node that places it
};

/// A parsed mesh file plus what MeshData cannot carry.
struct LoadedMesh {
  std::shared_ptr<MeshData> data;
  /// glTF without COLOR_0 whose primitives all share one baseColorFactor: that factor (linear),
  /// to be used as the uniform colour when the scene gives none.
  bool has_uniform_color = false;
  glm::vec3 uniform_color_linear{1.0f};
  /// Triangles removed because one of their vertices had a NaN or infinite coordinate.
  std::size_t dropped_nonfinite_triangles = 0;
  /// What the file holds that covrast does not render, one line each (Scene::warnings).
  std::vector<std::string> warnings;
  /// The same, for what matters only when the scene is lit (materials).
  std::vector<std::string> lit_warnings;
  /// glTF: the file's cameras, in file order.
  std::vector<FileCamera> cameras;
  /// glTF: the lights on the walked nodes, in walk order.
  std::vector<FileLight> lights;
  /// glTF: the file's extensionsUsed, as listed.
  std::vector<std::string> extensions_used;
};

/// core/file_read.hpp's readers, with the loaders' limit as the default (a later
/// declaration may add default arguments).
bool read_whole_file(const std::filesystem::path& path, std::string& contents, std::string& error,
                     std::uint64_t max_bytes = kMaxInputFileBytes);
bool read_whole_file(const std::filesystem::path& path, std::vector<unsigned char>& contents,
                     std::string& error, std::uint64_t max_bytes = kMaxInputFileBytes);

/// The deepest nesting of arrays and objects in JSON text (strings and comments skipped),
/// scanning no further than the first place where it exceeds `limit`; there `offset` is set
/// to the byte of the opening bracket. Returns true when the depth stays within `limit`.
bool json_depth_within(std::string_view text, int limit, std::size_t& offset);

/// Wavefront OBJ: v (optionally with r g b sRGB colours), vn, f, mtllib and usemtl lines;
/// convex polygons become the fan (0, k, k + 1), concave ones are ear-clipped. `display_name`
/// prefixes every error message ("name:LINE: ..."); material libraries are found in
/// `base_dir`.
LoadedMesh parse_obj(std::string_view text, const std::string& display_name,
                     const std::filesystem::path& base_dir);

/// glTF 2.0, either JSON (.gltf) or binary (.glb, recognised by its magic). External buffers
/// are resolved against `base_dir`. `pose`: a moment of an animation to pose the file at
/// (null: the static pose). `variant`: the KHR_materials_variants variant to draw (empty: the
/// default materials; a name the file lacks is an InputError listing its variants).
LoadedMesh parse_gltf(std::string_view bytes, const std::string& display_name,
                      const std::filesystem::path& base_dir, const AnimationTime* pose = nullptr,
                      std::string_view variant = {});

/// An image file as a texture (docs/textures.md): read_image, then make_texture with `srgb`
/// (true for colour maps: glTF baseColor and emissive, OBJ map_Kd). `name` names it in
/// messages, e.g. "model.obj: map_Kd wood.png". Throws InputError when it is missing or
/// cannot be decoded, or when it takes `texels_used` (the file's so far) past
/// kMaxTextureTexels. The hook for OBJ materials: each distinct map_Kd path of a file loaded
/// once, its Texture shared by the materials that name it.
std::shared_ptr<const Texture> load_texture_file(const std::filesystem::path& path,
                                                 const std::string& name, bool srgb,
                                                 std::uint64_t& texels_used);

/// Level-0 texels of the decoded images of one mesh file (glTF images, OBJ map_Kd), all
/// together: 2^27, two of the largest images (kMaxPngPixels), 512 MiB as RGBA8. Checked as
/// each image is decoded, before its mipmaps are built (docs/limits.md).
inline constexpr std::uint64_t kMaxTextureTexels = std::uint64_t(1) << 27;

/// Adds a decoded image of width x height to `texels_used`, the texels of the file's images
/// so far; throws InputError("name: ...") when that passes kMaxTextureTexels.
void count_texture_texels(int width, int height, const std::string& name,
                          std::uint64_t& texels_used);

/// load_mesh_scene's camera for a file without one (scene_auto.cpp): looking down -z at the
/// centre of the world box of the scene's meshes from the distance where the box's bounding
/// sphere fits the view with a 5% margin (docs/scene-format.md).
Camera framing_camera(const Scene& scene);

/// Removes every triangle that uses a vertex with a non-finite coordinate and sets such
/// vertices to the origin (nothing references them any more). Returns the number removed.
std::size_t drop_nonfinite_triangles(MeshData& mesh);

/// Throws InputError("name: ...") when `text` is not OBJ text: binary (a NUL byte, the glTF
/// magic) or JSON.
void check_obj_text(std::string_view text, const std::string& name);

/// True if the bytes start with the binary glTF magic "glTF".
bool is_glb(std::string_view bytes);

/// What analyze_mesh_topology stores in a MeshData, computed from its positions and indices.
struct MeshTopologyFacts {
  int closed_orientation = 0;
  bool convex = false;
  glm::vec3 bounds_min{0.0f};
  glm::vec3 bounds_max{0.0f};
};
MeshTopologyFacts mesh_topology_facts(const MeshData& mesh);

/// Whether what the renderer reads of a mesh's analysis still holds: a mesh analysed as closed
/// (closed_orientation != 0, analyzed_triangle_count = triangle_count()) gives the same facts
/// again. O(n log n) for a closed mesh, O(1) otherwise (check_scene calls it).
bool mesh_topology_is_current(const MeshData& mesh);

}  // namespace covrast::detail
