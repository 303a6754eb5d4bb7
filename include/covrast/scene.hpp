// covrast public API: the scene, as loaded from a JSON scene file (see docs/scene-format.md)
// or built in code (make_mesh, add_instance, add_light).
// Loading is the first stage of the pipeline: scene -> geometry -> binning -> raster ->
// resolve -> image. Everything here is in world units and linear-light colour; nothing
// here knows about pixels except the requested image size.
#pragma once

#include <covrast/environment.hpp>
#include <covrast/error.hpp>
#include <covrast/shading.hpp>
#include <covrast/texture.hpp>

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace covrast {

/// Largest accepted image side [pixels]. Larger requests are refused as bad input.
inline constexpr int kMaxImageSide = 16384;

/// Input limits (docs/limits.md): a file over one of them is refused with an InputError
/// naming it, before anything is allocated for its content.
/// Largest mesh file or glTF buffer/image file read [bytes] (1 GiB).
inline constexpr std::uint64_t kMaxInputFileBytes = std::uint64_t(1) << 30;
/// Largest scene file [bytes] (64 MiB).
inline constexpr std::uint64_t kMaxSceneFileBytes = std::uint64_t(1) << 26;
/// Deepest nesting of arrays and objects in a scene file or a glTF JSON chunk: deeper
/// values would make the parsers and the message printer recurse without bound.
inline constexpr int kMaxJsonDepth = 128;
/// Most triangles one scene may draw, summed over its instances (and over the copies a glTF
/// file makes of its meshes: nodes, EXT_mesh_gpu_instancing).
inline constexpr std::uint64_t kMaxSceneTriangles = std::uint64_t(1) << 25;
/// Most elements one glTF accessor may hold (vertices, indices, instances).
inline constexpr std::uint64_t kMaxAccessorElements = std::uint64_t(1) << 24;
/// Most instances one EXT_mesh_gpu_instancing node may make of its mesh.
inline constexpr std::uint64_t kMaxGltfInstances = std::uint64_t(1) << 20;
/// Most lights of one scene file: each is evaluated at every shaded pixel or sample.
inline constexpr std::uint64_t kMaxSceneLights = 1024;
/// Most corners of one OBJ face (polygons become triangle fans).
inline constexpr std::uint64_t kMaxObjFaceCorners = std::uint64_t(1) << 16;

/// OpenGL conventions: view = lookAt(eye, target, up), projection =
/// perspective(fovy, width / height of the output image, near, far), or for an orthographic
/// camera ortho(-ymag x aspect, ymag x aspect, -ymag, ymag, near, far); clip z in [-w, w].
struct Camera {
  glm::dvec3 eye{0.0, 0.0, 3.0};
  glm::dvec3 target{0.0, 0.0, 0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
  double fovy_deg = 45.0;     ///< vertical field of view [degrees], in (0, 180); perspective
  double near = 0.1;          ///< near plane distance [world units], > 0 (orthographic: >= 0)
  double far = 100.0;         ///< far plane distance [world units], > near
  bool orthographic = false;  ///< parallel projection: ymag instead of fovy_deg
  double ymag = 1.0;          ///< orthographic: half the view's height [world units], > 0
};

/// A surface's material. The base colour is not here: it is the mesh's colour selection
/// (uniform, per-triangle, vertex colours, glTF baseColorFactor x COLOR_0), as unlit.
struct Material {
  ShadingModel model = ShadingModel::Pbr;
  float metallic = 1.0f;            ///< pbr, 0..1 (glTF default 1)
  float roughness = 1.0f;           ///< pbr perceptual roughness, 0..1 (glTF default 1)
  glm::vec3 emissive_linear{0.0f};  ///< added radiance, linear (x emissive strength)
  float shininess = 32.0f;          ///< blinn-phong exponent, > 0
  glm::vec3 specular_linear{0.5f};  ///< blinn-phong specular colour, linear
  /// Back faces are lit with the flipped normal (glTF doubleSided). A single-sided
  /// material's back faces are not drawn, lit or unlit, in every mode (glTF 2.0, 3.9.5).
  bool double_sided = true;
  // Textures (docs/textures.md); an empty slot changes nothing. baseColor multiplies the base
  // colour (its alpha is kept for alpha modes); metallicRoughness: B x metallic, G x
  // roughness; normal: tangent-space normal x (scale, scale, 1); occlusion: 1 + strength (R -
  // 1) multiplies the ambient term only; emissive multiplies emissive_linear.
  TextureSlot base_color_texture;  ///< sRGB texels
  TextureSlot metallic_roughness_texture;
  TextureSlot normal_texture;
  TextureSlot occlusion_texture;
  TextureSlot emissive_texture;  ///< sRGB texels
  // The glTF material extensions covrast honours (docs/shading.md, "Material extensions"), for
  // the pbr model; at these defaults each changes nothing.
  /// KHR_materials_ior: the dielectric's index of refraction, f0 = ((ior - 1) / (ior + 1))^2;
  /// 1.5 gives glTF's 0.04. 0 or >= 1 (0 gives f0 = 1, as infinity would).
  float ior = 1.5f;
  /// KHR_materials_specular: the dielectric specular's strength (0..1; x the texture's A) and
  /// its F0 colour (linear, >= 0; x the texture's RGB, sRGB texels):
  /// dielectric F0 = min(f0(ior) x colour, 1) x strength, F90 = strength.
  float specular_factor = 1.0f;
  glm::vec3 specular_color_factor{1.0f};
  TextureSlot specular_texture;
  TextureSlot specular_color_texture;  ///< sRGB texels
  /// KHR_materials_clearcoat: a clear GGX layer (f0 0.04) over the whole material, weighted by
  /// clearcoat (0..1; x the texture's R) times its Fresnel term at n_c . v; its roughness
  /// (0..1; x the texture's G) and normal (the clearcoat normal texture, else the surface's
  /// normal without the normal texture) are its own.
  float clearcoat = 0.0f;
  float clearcoat_roughness = 0.0f;
  TextureSlot clearcoat_texture;
  TextureSlot clearcoat_roughness_texture;
  TextureSlot clearcoat_normal_texture;  ///< scale as normal_texture's
  /// KHR_materials_sheen: the sheen of fabrics, a "Charlie" lobe (Conty Estevez and Kulla 2017)
  /// over the material, which it dims by the sheen's albedo; colour (linear, 0..1; x the
  /// texture's RGB, sRGB texels; black: no sheen) and roughness (0..1; x the texture's A).
  glm::vec3 sheen_color_factor{0.0f};
  float sheen_roughness = 0.0f;
  TextureSlot sheen_color_texture;  ///< sRGB texels
  TextureSlot sheen_roughness_texture;
  /// KHR_materials_iridescence: a thin film over the material whose interference colours its
  /// Fresnel term (Belcour and Barla 2017): strength (0..1; x the texture's R), the film's ior
  /// (>= 1) and thickness [nm] (the maximum, or mix(minimum, maximum, the texture's G)).
  float iridescence = 0.0f;
  float iridescence_ior = 1.3f;
  float iridescence_thickness_min_nm = 100.0f;
  float iridescence_thickness_max_nm = 400.0f;
  TextureSlot iridescence_texture;
  TextureSlot iridescence_thickness_texture;
  /// KHR_materials_anisotropy: the specular lobe stretched along a direction in the surface:
  /// strength (0..1; x the texture's B) raises the alpha roughness along it to mix(alpha, 1,
  /// strength^2); the direction is the tangent turned by `anisotropy_rotation` [radians,
  /// counter-clockwise towards the bitangent], or the texture's RG in [-1, 1] tangent space
  /// turned alike. Needs a tangent frame (the mesh's tangents, else computed from UVs).
  float anisotropy = 0.0f;
  float anisotropy_rotation = 0.0f;
  TextureSlot anisotropy_texture;
  /// KHR_materials_transmission (thin-walled, without refraction): the share (0..1; x the
  /// texture's R) of the dielectric's diffuse that is light passing through instead: what is
  /// behind shows through, tinted by the base colour, less the specular's reflectance; lights
  /// behind shine through a GGX lobe (docs/shading.md, "Transmission"). Such a material is
  /// composited as a transparent layer in every mode (docs/transparency.md).
  float transmission = 0.0f;
  TextureSlot transmission_texture;
  /// KHR_materials_volume: what passes is attenuated over the thickness (object units, x the
  /// texture's G, x the instance's scale) as attenuation_color^(thickness / distance);
  /// distance 0 means infinite (no attenuation).
  float thickness = 0.0f;
  TextureSlot thickness_texture;
  glm::vec3 attenuation_color{1.0f};  ///< linear, 0..1
  float attenuation_distance = 0.0f;  ///< world units, > 0; 0: infinite
  /// KHR_materials_dispersion: read and kept; without refraction there is no spread to draw.
  float dispersion = 0.0f;
  AlphaMode alpha_mode = AlphaMode::Opaque;
  double alpha_cutoff = 0.5;  ///< Mask: kept where alpha >= alpha_cutoff (glTF default 0.5)
  /// The base colour's alpha (glTF baseColorFactor[3], OBJ d), 0..1; multiplies the vertex
  /// alpha (MeshData::color_alphas) and the base colour texture's alpha.
  double base_alpha = 1.0;
  /// The base colour texture's file (OBJ's MTL `map_Kd`, resolved against the .mtl file's
  /// directory); empty if none. The OBJ loader turns it into base_color_texture.
  std::string base_color_texture_path;

  /// Every texture slot, in one order (for checks and listings that treat them alike).
  std::array<const TextureSlot*, 17> texture_slots() const {
    return {&base_color_texture,
            &metallic_roughness_texture,
            &normal_texture,
            &occlusion_texture,
            &emissive_texture,
            &specular_texture,
            &specular_color_texture,
            &clearcoat_texture,
            &clearcoat_roughness_texture,
            &clearcoat_normal_texture,
            &sheen_color_texture,
            &sheen_roughness_texture,
            &iridescence_texture,
            &iridescence_thickness_texture,
            &anisotropy_texture,
            &transmission_texture,
            &thickness_texture};
  }
};

enum class LightType : std::uint8_t { Directional, Point, Spot, Ambient };

/// "none", "khronos-pbr-neutral", "aces-hill", "aces-narkowicz"; throws InputError naming the
/// accepted names for anything else.
ToneMap parse_tone_map(const std::string& name);
const char* to_string(ToneMap tone_map);

/// A light in world space (KHR_lights_punctual units: directional lux, point and spot
/// candela; ambient is a uniform radiance). Colours are linear RGB.
struct Light {
  LightType type = LightType::Directional;
  glm::dvec3 direction{0.0, 0.0, -1.0};  ///< where the light travels (directional, spot)
  glm::dvec3 position{0.0};              ///< point, spot [world units]
  glm::vec3 color_linear{1.0f};
  double intensity = 1.0;
  double range = 0.0;            ///< point, spot: distance where the light ends; 0 = infinite
  double inner_cone_deg = 0.0;   ///< spot: full intensity inside this angle from the axis
  double outer_cone_deg = 45.0;  ///< spot: no light outside it
};

/// Where a lit mesh's normals come from.
enum class NormalSource : std::uint8_t {
  File,    ///< the file's (glTF NORMAL, OBJ vn); per face where a corner has none
  Flat,    ///< the face normal of every triangle
  Smooth,  ///< area-weighted average of the face normals at each welded position
};

/// Triangle geometry shared by every instance that names the same file.
struct MeshData {
  std::string source;                    ///< file it came from (for messages)
  std::vector<glm::vec3> positions;      ///< object space
  std::vector<glm::vec3> colors_linear;  ///< per vertex, linear light; empty if none
  /// Per vertex alpha (glTF COLOR_0 with four components), 0..1; empty: 1 everywhere. Used by
  /// materials whose alpha_mode is not Opaque, whatever the instance's colour selection.
  std::vector<float> color_alphas;
  std::vector<std::uint32_t> indices;  ///< 3 per triangle, in file order after fan split
  std::size_t triangle_count() const { return indices.size() / 3; }
  /// Object-space normals, 3 per triangle in index order (a corner of one position may
  /// differ between faces, as OBJ's vn allows); empty if the file has none. A zero vector
  /// means "no normal here": that triangle uses its face normal.
  std::vector<glm::vec3> corner_normals;
  /// UV sets (glTF TEXCOORD_0 and _1, OBJ vt), 3 per triangle in index order like
  /// corner_normals; empty if the file has none. glTF's convention: (0, 0) is the top-left
  /// texel of the image (OBJ's v is flipped at load).
  std::vector<glm::vec2> corner_texcoords[kMaxTexcoordSets];
  /// Object-space tangents with the bitangent sign in w (glTF TANGENT), 3 per triangle in
  /// index order; empty: computed per triangle from the normal texture's UVs.
  std::vector<glm::vec4> corner_tangents;
  /// The file's materials (glTF materials; empty for OBJ) and each triangle's index into
  /// them (empty: every triangle uses materials[0], or the default material if none).
  std::vector<Material> materials;
  std::vector<std::uint32_t> triangle_materials;
  /// The file's KHR_materials_variants names (empty: none); a scene's "variant" key or
  /// SceneChoices::material_variant picks the one drawn (docs/scene-format.md).
  std::vector<std::string> material_variants;

  // Filled by analyze_mesh_topology (load_mesh and load_scene call it); the defaults mean
  // "not known to be closed", which disables back-face culling for the mesh.
  /// +1: closed, consistently oriented, counter-clockwise faces point outwards; -1: the same
  /// with clockwise faces outwards; 0: not (known to be) closed.
  int closed_orientation = 0;
  /// Closed as above, and convex: every vertex on or behind the plane of every face (tested
  /// for meshes of up to kMaxConvexTestVertices vertices; larger ones stay false). The faces
  /// of one facing of a convex mesh never overlap on screen, which the coverage mode uses.
  bool convex = false;
  glm::vec3 bounds_min{0.0f};  ///< object-space box of the vertices the triangles use
  glm::vec3 bounds_max{0.0f};
  /// triangle_count() when analysed: the renderer ignores closed_orientation if the indices
  /// changed since. Re-run analyze_mesh_topology after editing positions or indices:
  /// check_scene refuses a closed mesh whose analysis no longer holds.
  std::size_t analyzed_triangle_count = 0;
};

/// Sets MeshData::closed_orientation, bounds_min/max and analyzed_triangle_count. Closed
/// means: after welding vertices with equal positions, every edge is used by exactly two
/// triangles, once in each direction (triangles with two equal welded vertices are ignored),
/// and every edge-connected component has a clearly non-zero signed volume, all of one sign
/// (that sign is closed_orientation). O(n log n) in the triangle count; call it on meshes built
/// in code to enable culling for them.
void analyze_mesh_topology(MeshData& mesh);
/// Area-weighted vertex normals over the positions welded by equality, as corner normals
/// (3 per triangle): what NormalSource::Smooth uses.
std::vector<glm::vec3> smooth_corner_normals(const MeshData& mesh);

/// Largest vertex count analyze_mesh_topology tests for convexity (the test is O(faces x
/// vertices)).
inline constexpr std::size_t kMaxConvexTestVertices = 4096;

enum class ColorSource {
  Uniform,      ///< MeshInstance::color_linear for every triangle
  PerTriangle,  ///< lowbias32(global triangle index) debug colouring
  Vertex,       ///< MeshData::colors_linear, interpolated
};

struct MeshInstance {
  std::shared_ptr<const MeshData> mesh;  ///< shared between instances of one file
  glm::dmat4 model{1.0};                 ///< object -> world (GLM is column-major)
  ColorSource color_source = ColorSource::Uniform;
  glm::vec3 color_linear{1.0f};  ///< for ColorSource::Uniform
  /// For Vertex colours coming from glTF: baseColorFactor, multiplied in (linear).
  glm::vec3 color_factor_linear{1.0f};
  /// The instance's materials: the file's (or one default) with the scene's "material" keys
  /// applied; one per MeshData::materials entry (empty: one Material{}). Used only when
  /// Scene::lit.
  std::vector<Material> materials;
  NormalSource normals = NormalSource::File;
  /// The corner normals this instance uses (MeshData::corner_normals, or the smoothed ones),
  /// 3 per triangle; null: each triangle's face normal, whatever `normals` says.
  std::shared_ptr<const std::vector<glm::vec3>> corner_normals;
};

/// What shows where no surface covers a pixel (docs/scene-format.md, "background").
enum class BackgroundKind : std::uint8_t {
  Color,        ///< Scene::background_linear, a display colour (not tone-mapped)
  Transparent,  ///< nothing: RGBA output whose alpha is the share of each pixel surfaces cover
  Skybox,       ///< the environment through the pixel's centre, tone-mapped as surfaces are
};

struct Scene {
  std::filesystem::path source;  ///< the JSON file (empty when built in code)
  int width = 640;               ///< [pixels], 1..kMaxImageSide
  int height = 360;              ///< [pixels], 1..kMaxImageSide
  glm::vec3 background_linear{0.0f};
  /// Transparent and Skybox render the frame twice (post/background.hpp); Skybox needs an
  /// environment.
  BackgroundKind background_kind = BackgroundKind::Color;
  Camera camera;
  std::vector<MeshInstance> meshes;
  /// A scene with a "lights" key is lit (even with an empty list: then only emission
  /// shows); without one every mesh renders unlit, exactly as before lighting existed.
  bool lit = false;
  std::vector<Light> lights;
  /// Image-based lighting (docs/environments.md); lights the lit meshes of a lit scene.
  std::optional<EnvironmentLight> environment;
  ToneMap tone_map = ToneMap::None;
  double exposure = 1.0;  ///< multiplies linear radiance before the tone map, finite, > 0
  /// Triangles dropped at load time because a vertex had a NaN or infinite coordinate.
  std::size_t dropped_nonfinite_triangles = 0;
  /// One line each, e.g. "meshes/a.obj: dropped 3 triangles with NaN/Inf coordinates".
  std::vector<std::string> warnings;
  /// The glTF extensions the scene's files list in extensionsUsed, sorted, each once
  /// (gltf_extension_support says what covrast does with each).
  std::vector<std::string> gltf_extensions_used;

  std::size_t triangle_count() const;
};

/// What covrast does with a glTF extension a file uses (docs/scene-format.md, "glTF
/// extensions"): Honoured (read and drawn as its specification says), Ignored (the file is
/// drawn without it, as `effect` says, with a warning), Unreadable (a file that requires it is
/// refused; one that uses it optionally is drawn without it, with a warning).
enum class GltfExtensionSupport : std::uint8_t { Honoured, Ignored, Unreadable };
struct GltfExtensionStatus {
  GltfExtensionSupport support;
  std::string effect;  ///< what a file using it gets, one line
};
GltfExtensionStatus gltf_extension_support(const std::string& name);

/// A moment of a glTF file's animations to pose its meshes at (docs/scene-format.md,
/// "Animation"); a scene file's "animation" and "time" keys. Without one, glTF files are drawn
/// in their static pose.
struct AnimationTime {
  int index = -1;       ///< >= 0: the animation with this index
  std::string name{};   ///< index < 0 and non-empty: the animation with this name; else the first
  double time_s = 0.0;  ///< seconds, finite, >= 0; before the first keyframe the first values
};

/// What to draw of the glTF files of a scene, in the place of the scene file's keys: a moment
/// of their animations ("animation" and "time") and a material variant ("variant" of every
/// glTF mesh: each file must have it).
struct SceneChoices {
  std::optional<AnimationTime> pose;
  std::string material_variant;  ///< KHR_materials_variants name; empty: the scene's own
};

/// Every problem covrast finds in a scene file or a mesh file (`covrast info --validate`).
struct Validation {
  /// What stops the load, one line each naming the file: for a glTF file, every field covrast
  /// reads that has the wrong JSON type, each with its JSON path (the load stops at the
  /// first); otherwise the load's own error, if any. Empty: the file loads.
  std::vector<std::string> errors;
  /// What the load ignores or leaves out (the scene's warnings, or the glTF type check's
  /// warnings for fields covrast does not use when it has errors).
  std::vector<std::string> warnings;
};

/// Validates a scene file (JSON) or a mesh file (.obj, .gltf, .glb, framed as
/// load_mesh_scene frames it) with `choices` as load_scene takes them. Never throws
/// InputError: each becomes an error line.
Validation validate_file(const std::filesystem::path& path, const SceneChoices& choices = {});

/// Loads a scene file. Throws InputError with a one-line message naming the file and the
/// problem (with line and column for malformed JSON).
Scene load_scene(const std::filesystem::path& json_path);
/// load_scene with `choices` in the place of the file's keys.
Scene load_scene(const std::filesystem::path& json_path, const SceneChoices& choices);

/// load_scene with `pose` in the place of the file's "animation" and "time" keys.
Scene load_scene(const std::filesystem::path& json_path, const AnimationTime& pose);

/// Mesh files that load_scene has loaded, kept for later scenes that use the same files: a
/// program that loads many scenes (covrast test) then reads and parses each file once. Files
/// are known by their canonical path; a file changed on disk in between is not read again.
/// Not thread-safe: one load_scene at a time per cache.
class MeshFileCache {
 public:
  MeshFileCache();
  ~MeshFileCache();
  MeshFileCache(const MeshFileCache&) = delete;
  MeshFileCache& operator=(const MeshFileCache&) = delete;
  /// How many mesh files have been loaded into the cache.
  std::size_t files_loaded() const;

 private:
  friend Scene load_scene(const std::filesystem::path& json_path, MeshFileCache& mesh_files);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// load_scene, taking the meshes from `mesh_files` and adding the ones it loads. Each scene
/// gets the warnings of the files it uses, whether loaded now or before.
Scene load_scene(const std::filesystem::path& json_path, MeshFileCache& mesh_files);

/// A lit scene of one mesh file without a scene file (`covrast render model.glb`): the file's
/// first camera that a node places, else a camera framing the model from +z (fovy 40 degrees);
/// the file's KHR_lights_punctual lights, else the built-in studio environment
/// (studio_environment()); the file's materials (OBJ without materials: lambert).
/// docs/scene-format.md, "Rendering a mesh file without a scene", has the numbers. Throws
/// InputError as load_scene.
Scene load_mesh_scene(const std::filesystem::path& mesh_path, int width = 640, int height = 360,
                      const std::optional<AnimationTime>& pose = std::nullopt);
/// load_mesh_scene drawing `choices` (a material variant the file lacks is an InputError).
Scene load_mesh_scene(const std::filesystem::path& mesh_path, int width, int height,
                      const SceneChoices& choices);

/// The orbit camera of the glTF viewers (model-viewer's camera-orbit, the render-fidelity
/// harness): target + radius (sin(phi) sin(theta), cos(phi), sin(phi) cos(theta)), angles in
/// degrees (theta = 0, phi = 90 looks from +Z).
glm::dvec3 orbit_eye(const glm::dvec3& target, double theta_deg, double phi_deg, double radius);
/// Places scene.camera there, looking at `target`, +Y up (looking straight up or down: the
/// direction of smaller phi on the orbit), perspective, with near and far planes that clip
/// nothing of the bounding sphere of the meshes' world box (1% to spare).
void place_orbit_camera(Scene& scene, const glm::dvec3& target, double theta_deg, double phi_deg,
                        double radius);

/// Loads one mesh file (.obj, .gltf, .glb) by itself; used by load_scene and tests.
/// For glTF the node transforms are baked into the positions and COLOR_0 x
/// baseColorFactor into colors_linear.
std::shared_ptr<MeshData> load_mesh(const std::filesystem::path& path);

// Building a scene in code (no files): what load_scene does for a scene file's entries,
// with the same checks, for programs and C++ test suites. A typical use:
//   Scene scene;  // set width, height, camera, background_linear
//   auto quad = make_mesh({.positions = {...}, .indices = {0, 1, 2, 0, 2, 3}});
//   add_instance(scene, quad, {.color_srgb = glm::vec3(1.0f, 0.2f, 0.0f)});
//   check_scene(scene);
//   Image image = render(scene, {}).color;  (covrast/renderer.hpp)

/// A mesh's arrays, as an OBJ file with "v x y z r g b", "vn" and "f" lines would give them.
/// Every member of MeshArrays and InstanceDesc has an initializer, so that a designated
/// initializer may leave any of them out (g++ 12 -Wextra warns otherwise).
struct MeshArrays {
  std::string name = "mesh";  ///< MeshData::source, the prefix of every error message
  /// Object space [world units], each coordinate finite.
  std::vector<glm::vec3> positions{};
  /// 3 per triangle, each < positions.size(); counter-clockwise seen from the front.
  std::vector<std::uint32_t> indices{};
  /// Optional vertex colours: one per position, sRGB display values, each in 0..1.
  std::vector<glm::vec3> colors_srgb{};
  /// Optional vertex alphas (MeshData::color_alphas): one per position, each in 0..1.
  std::vector<float> alphas{};
  /// Optional normals: 3 per triangle in index order, finite; a zero vector means "use the
  /// face normal here" (MeshData::corner_normals).
  std::vector<glm::vec3> corner_normals{};
  /// Optional UV sets 0 and 1: 3 per triangle in index order, finite (MeshData::
  /// corner_texcoords).
  std::vector<glm::vec2> corner_texcoords{};
  std::vector<glm::vec2> corner_texcoords1{};
  /// Optional materials and each triangle's index into them (MeshData::materials and
  /// triangle_materials; checked like a scene file's "material": metallic and roughness in
  /// 0..1, shininess in 0.001..10000, colours finite and >= 0).
  std::vector<Material> materials{};
  std::vector<std::uint32_t>
      triangle_materials{};  ///< empty or one per triangle, < materials.size()
};

/// A MeshData from arrays, checked and analysed the way load_mesh does it (colours to linear
/// light, analyze_mesh_topology for back-face culling). Share the result between instances.
/// Throws InputError ("NAME: problem") for: indices not a multiple of 3, an index out of
/// range, a non-finite coordinate or normal, a colour outside 0..1, array sizes that do not
/// match, a bad material or material index. (A file's NaN vertices drop their triangles with
/// a warning; here they are refused, since the caller can fix them.)
std::shared_ptr<const MeshData> make_mesh(MeshArrays arrays);

/// How add_instance places and colours a mesh: the keys of a scene file's "meshes" entry.
struct InstanceDesc {
  /// Object -> world (GLM is column-major: translation in model[3]); finite and affine (last
  /// row 0, 0, 0, 1).
  glm::dmat4 model{1.0};
  /// Uniform colour, sRGB display values in 0..1 ("color": [r,g,b]). Unset: the mesh's vertex
  /// colours when it has them, else white.
  std::optional<glm::vec3> color_srgb{};
  /// "color": "per_triangle", the debug colouring (color_srgb must then be unset).
  bool per_triangle_colors = false;
  /// Lit scenes: the material of every triangle. Unset: the mesh's materials, or one Lambert
  /// material when it has none (as for an OBJ file).
  std::optional<Material> material{};
  /// Unset: File when the mesh has corner normals, else Flat. File for a mesh without
  /// normals is an error.
  std::optional<NormalSource> normals{};
};

/// Appends an instance of `mesh` to scene.meshes, filled as load_scene fills one (colour to
/// linear light, materials, normals; Smooth normals are computed here, once per call), and
/// returns it. Throws InputError for a null mesh or a bad InstanceDesc.
MeshInstance& add_instance(Scene& scene, std::shared_ptr<const MeshData> mesh,
                           const InstanceDesc& desc = {});

/// Appends a light and makes the scene lit (Scene::lit), as a scene file's "lights" entry:
/// the direction (directional, spot) must be non-zero and is normalised here; colour and
/// intensity finite and >= 0; range 0 (infinite) or > 0; 0 <= inner < outer <= 90 degrees.
/// Throws InputError otherwise.
void add_light(Scene& scene, Light light);

/// Checks what load_scene would have refused in a scene built in code: the size (1..
/// kMaxImageSide), the camera (Camera's comments; eye != target, up not parallel to the view
/// direction), a background in 0..1, an exposure > 0, an environment as load_environment
/// makes one (a map of width x height finite texels >= 0 within the limits, a finite rotation,
/// an intensity >= 0), and each instance (a mesh, indices in range, array sizes that match, a
/// finite affine model matrix, one material per mesh material), and for each mesh analysed as
/// closed that its analysis still holds (analyze_mesh_topology gives the same closed_orientation,
/// convex and bounds: positions edited afterwards would make the renderer cull wrongly). Throws
/// InputError naming the first problem. O(triangles), and O(n log n) for each closed mesh; the
/// renderer calls it only in debug builds and builds with COVRAST_CHECKS.
void check_scene(const Scene& scene);

/// The per_triangle debug colour: h = lowbias32(index), r = (h & 255) / 255, g = (h >> 8 &
/// 255) / 255, b = (h >> 16 & 255) / 255, as sRGB display values.
std::uint32_t lowbias32(std::uint32_t x);
glm::vec3 per_triangle_color_srgb(std::uint32_t global_triangle_index);
/// The same colour in linear light: srgb_to_linear of each channel, bit for bit, from a
/// 256-entry table (the set-up asks for one per triangle).
glm::vec3 per_triangle_color_linear(std::uint32_t global_triangle_index);

/// sRGB transfer function (IEC 61966-2-1), both directions, on [0, 1].
float srgb_to_linear(float encoded);
float linear_to_srgb(float linear);

}  // namespace covrast
