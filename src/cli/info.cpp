// `covrast info`: loads a scene and describes it (size, camera, meshes, totals, world-space
// bounding box, warnings) as text or as one JSON line. Renders nothing.
#include "commands.hpp"

#include <covrast/scene.hpp>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>
#include <limits>
#include <set>
#include <string>
#include <vector>

namespace covrast::cli {
namespace {

const char* support_name(GltfExtensionSupport support) {
  switch (support) {
    case GltfExtensionSupport::Honoured:
      return "honoured";
    case GltfExtensionSupport::Ignored:
      return "ignored";
    case GltfExtensionSupport::Unreadable:
      return "cannot read";
  }
  return "ignored";
}

struct Bounds {
  glm::dvec3 min{std::numeric_limits<double>::infinity()};
  glm::dvec3 max{-std::numeric_limits<double>::infinity()};
  bool empty() const { return !(min.x <= max.x); }
};

/// World-space bounds of the vertices that triangles reference (so vertices of triangles
/// dropped at load time, and unused ones, do not count): world = model * (p, 1), divided by
/// w when the model matrix is projective.
Bounds world_bounds(const Scene& scene) {
  Bounds bounds;
  for (const MeshInstance& instance : scene.meshes) {
    if (!instance.mesh) continue;
    const MeshData& mesh = *instance.mesh;
    std::vector<bool> used(mesh.positions.size(), false);
    for (std::uint32_t index : mesh.indices) {
      if (index < used.size()) used[index] = true;
    }
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      if (!used[i]) continue;
      glm::dvec4 world = instance.model * glm::dvec4(glm::dvec3(mesh.positions[i]), 1.0);
      if (world.w != 1.0 && world.w != 0.0) world /= world.w;
      const glm::dvec3 p(world);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
      bounds.min = glm::min(bounds.min, p);
      bounds.max = glm::max(bounds.max, p);
    }
  }
  return bounds;
}

/// The distinct textures the instance's materials use (docs/textures.md).
std::size_t texture_count(const MeshInstance& instance) {
  std::set<const Texture*> textures;
  for (const Material& m : instance.materials) {
    for (const TextureSlot* slot : m.texture_slots()) {
      if (slot->texture) textures.insert(slot->texture.get());
    }
  }
  return textures.size();
}

const char* color_source_name(ColorSource source) {
  switch (source) {
    case ColorSource::Uniform:
      return "uniform";
    case ColorSource::PerTriangle:
      return "per_triangle";
    case ColorSource::Vertex:
      return "vertex";
  }
  return "unknown";
}

nlohmann::ordered_json vec_json(const glm::dvec3& v) {
  return nlohmann::ordered_json::array({v.x, v.y, v.z});
}

std::string vec_text(const glm::dvec3& v) {
  return "(" + format_number(v.x) + ", " + format_number(v.y) + ", " + format_number(v.z) + ")";
}

std::size_t vertex_count(const MeshInstance& instance) {
  return instance.mesh ? instance.mesh->positions.size() : 0;
}

std::size_t triangle_count(const MeshInstance& instance) {
  return instance.mesh ? instance.mesh->triangle_count() : 0;
}

std::string mesh_source(const MeshInstance& instance) {
  return instance.mesh ? instance.mesh->source : std::string();
}

/// How many of an instance's materials are MASK and BLEND.
struct AlphaCounts {
  std::size_t mask = 0;
  std::size_t blend = 0;
};
AlphaCounts alpha_counts(const MeshInstance& instance) {
  AlphaCounts counts;
  for (const Material& m : instance.materials) {
    counts.mask += m.alpha_mode == AlphaMode::Mask;
    counts.blend += m.alpha_mode == AlphaMode::Blend;
  }
  return counts;
}

/// The solid-angle-weighted mean radiance of a map (what a uniform environment of equal power
/// would have).
glm::dvec3 mean_radiance(const EnvironmentMap& map) {
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (int y = 0; y < map.height; ++y) {
    const double w = environment_texel_solid_angle(y, map.width, map.height);
    for (int x = 0; x < map.width; ++x) sum += glm::dvec3(map.texel(x, y)) * w;
    weight += w * map.width;  // 4 pi in all
  }
  return weight > 0.0 ? sum / weight : sum;
}

nlohmann::ordered_json environment_json(const EnvironmentLight& light) {
  return {{"width", light.map->width},
          {"height", light.map->height},
          {"mean_radiance", vec_json(mean_radiance(*light.map))},
          {"rotation_deg", light.rotation_deg},
          {"intensity", light.intensity}};
}

nlohmann::ordered_json info_json(const InfoArgs& args, const Scene& scene, const Bounds& bounds,
                                 std::size_t total_vertices) {
  nlohmann::ordered_json j;
  j["file"] = args.scene;
  j["width"] = scene.width;
  j["height"] = scene.height;
  j["background_linear"] = vec_json(glm::dvec3(scene.background_linear));
  j["camera"] = {{"eye", vec_json(scene.camera.eye)}, {"target", vec_json(scene.camera.target)},
                 {"up", vec_json(scene.camera.up)},   {"fovy_deg", scene.camera.fovy_deg},
                 {"near", scene.camera.near},         {"far", scene.camera.far}};
  if (scene.camera.orthographic) {
    j["camera"].erase("fovy_deg");
    j["camera"]["projection"] = "orthographic";
    j["camera"]["ymag"] = scene.camera.ymag;
  }
  if (scene.environment) {
    j["environment"] = environment_json(*scene.environment);
  }
  j["tone_map"] = to_string(scene.tone_map);
  j["exposure"] = scene.exposure;
  nlohmann::ordered_json meshes = nlohmann::ordered_json::array();
  for (const MeshInstance& instance : scene.meshes) {
    nlohmann::ordered_json m = {{"source", mesh_source(instance)},
                                {"triangles", triangle_count(instance)},
                                {"vertices", vertex_count(instance)},
                                {"color_source", color_source_name(instance.color_source)}};
    if (instance.color_source == ColorSource::Uniform) {
      m["color_linear"] = vec_json(glm::dvec3(instance.color_linear));
    }
    if (const std::size_t textures = texture_count(instance); textures > 0) {
      m["textures"] = textures;
    }
    if (const AlphaCounts a = alpha_counts(instance); a.mask + a.blend > 0) {
      m["alpha_materials"] = {{"mask", a.mask}, {"blend", a.blend}};
    }
    if (!instance.mesh->material_variants.empty()) {
      m["material_variants"] = instance.mesh->material_variants;
    }
    meshes.push_back(std::move(m));
  }
  j["meshes"] = std::move(meshes);
  j["triangles"] = scene.triangle_count();
  j["vertices"] = total_vertices;
  j["dropped_nonfinite_triangles"] = scene.dropped_nonfinite_triangles;
  if (bounds.empty()) {
    j["bounds"] = nullptr;
  } else {
    j["bounds"] = {{"min", vec_json(bounds.min)}, {"max", vec_json(bounds.max)}};
  }
  j["gltf_extensions"] = nlohmann::ordered_json::array();
  for (const std::string& name : scene.gltf_extensions_used) {
    const GltfExtensionStatus status = gltf_extension_support(name);
    j["gltf_extensions"].push_back(
        {{"name", name}, {"support", support_name(status.support)}, {"effect", status.effect}});
  }
  j["warnings"] = scene.warnings;
  return j;
}

void print_info_text(const InfoArgs& args, const Scene& scene, const Bounds& bounds,
                     std::size_t total_vertices) {
  const Camera& c = scene.camera;
  std::cout << "file:        " << args.scene << '\n'
            << "size:        " << scene.width << "x" << scene.height << '\n'
            << "background:  " << vec_text(glm::dvec3(scene.background_linear)) << " (linear)\n"
            << "camera:      eye " << vec_text(c.eye) << ", target " << vec_text(c.target)
            << ", up " << vec_text(c.up) << '\n'
            << "             "
            << (c.orthographic ? "orthographic, ymag " + format_number(c.ymag)
                               : "fovy " + format_number(c.fovy_deg) + " deg")
            << ", near " << format_number(c.near) << ", far " << format_number(c.far) << '\n'
            << "tone map:    " << to_string(scene.tone_map) << ", exposure "
            << format_number(scene.exposure) << '\n';
  if (scene.environment) {
    const nlohmann::ordered_json e = environment_json(*scene.environment);
    std::cout << "environment: " << e["width"] << "x" << e["height"] << ", mean radiance "
              << vec_text(mean_radiance(*scene.environment->map)) << ", rotation "
              << format_number(scene.environment->rotation_deg) << " deg, intensity "
              << format_number(scene.environment->intensity) << '\n';
  }
  std::cout << "meshes:      " << scene.meshes.size() << '\n';
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const MeshInstance& instance = scene.meshes[i];
    std::cout << "  [" << i << "] " << mesh_source(instance) << ": " << triangle_count(instance)
              << " triangles, " << vertex_count(instance) << " vertices, colour "
              << color_source_name(instance.color_source);
    if (instance.color_source == ColorSource::Uniform) {
      std::cout << " " << vec_text(glm::dvec3(instance.color_linear)) << " (linear)";
    }
    if (const std::size_t textures = texture_count(instance); textures > 0) {
      std::cout << " x " << textures << (textures == 1 ? " texture" : " textures");
    }
    if (const AlphaCounts a = alpha_counts(instance); a.mask + a.blend > 0) {
      std::cout << ", alpha materials: " << a.mask << " mask, " << a.blend << " blend";
    }
    if (!instance.mesh->material_variants.empty()) {
      const std::vector<std::string>& variants = instance.mesh->material_variants;
      std::cout << ", material variants: ";
      for (std::size_t v = 0; v < variants.size(); ++v) std::cout << (v ? ", " : "") << variants[v];
    }
    std::cout << '\n';
  }
  std::cout << "triangles:   " << scene.triangle_count();
  if (scene.dropped_nonfinite_triangles > 0) {
    std::cout << " (" << scene.dropped_nonfinite_triangles << " dropped: NaN/Inf coordinates)";
  }
  std::cout << '\n' << "vertices:    " << total_vertices << '\n';
  if (bounds.empty()) {
    std::cout << "bounds:      empty\n";
  } else {
    std::cout << "bounds:      min " << vec_text(bounds.min) << ", max " << vec_text(bounds.max)
              << " (world)\n";
  }
  std::cout << "extensions:  " << (scene.gltf_extensions_used.empty() ? "none" : "") << '\n';
  for (const std::string& name : scene.gltf_extensions_used) {
    const GltfExtensionStatus status = gltf_extension_support(name);
    std::cout << "  " << name << ": " << support_name(status.support) << " (" << status.effect
              << ")\n";
  }
  std::cout << "warnings:    " << (scene.warnings.empty() ? "none" : "") << '\n';
  for (const std::string& warning : scene.warnings) std::cout << "  " << warning << '\n';
}

}  // namespace

CLI::App* add_info_command(CLI::App& app, InfoArgs& args) {
  CLI::App* sub = app.add_subcommand(
      "info",
      "Load a scene, or a mesh file as render frames it, and describe it: image size, "
      "background, camera, meshes (source, triangles, vertices, colour source), totals, "
      "world-space bounding box and warnings.");
  sub->add_option("scene", args.scene,
                  "Scene file (JSON), or a mesh file (.obj, .gltf, .glb) described as 'covrast "
                  "render' frames it without a scene file")
      ->required()
      ->type_name("SCENE.json|MODEL");
  sub->add_flag("--json", args.json, "Print one JSON line instead of text");
  sub->add_flag("--validate", args.validate,
                "List every error and warning the file gives (for glTF, every field of a wrong "
                "type with its JSON path) instead of describing it; exit 2 when there is an "
                "error");
  sub->add_flag("--strict", args.strict, "With --validate: a warning also makes the exit status 2")
      ->needs("--validate");
  add_view_options(sub, args.view);
  return sub;
}

/// `info --validate`: the file's findings, one per line ("error: ..." then "warning: ..."),
/// or one JSON line; exit 2 when there is an error (with --strict, also a warning).
static int run_validate(const InfoArgs& args) {
  const Validation found = validate_file(args.scene, scene_choices(args.view));
  const bool failed = !found.errors.empty() || (args.strict && !found.warnings.empty());
  if (args.json) {
    std::cout << nlohmann::json{{"file", args.scene},
                                {"valid", !failed},
                                {"errors", found.errors},
                                {"warnings", found.warnings}}
                     .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)
              << '\n';
  } else {
    std::cout << args.scene << ": " << found.errors.size()
              << (found.errors.size() == 1 ? " error, " : " errors, ") << found.warnings.size()
              << (found.warnings.size() == 1 ? " warning" : " warnings") << '\n';
    for (const std::string& e : found.errors) std::cout << "error: " << e << '\n';
    for (const std::string& w : found.warnings) std::cout << "warning: " << w << '\n';
  }
  return failed ? 2 : 0;
}

int run_info(const InfoArgs& args) {
  if (args.validate) return run_validate(args);
  Scene scene = load_scene_or_model(args.scene, args.view);
  apply_view_args(scene, args.view);
  const Bounds bounds = world_bounds(scene);
  std::size_t total_vertices = 0;
  for (const MeshInstance& instance : scene.meshes) total_vertices += vertex_count(instance);
  if (args.json) {
    std::cout << info_json(args, scene, bounds, total_vertices).dump() << '\n';
  } else {
    print_info_text(args, scene, bounds, total_vertices);
  }
  return 0;
}

}  // namespace covrast::cli
