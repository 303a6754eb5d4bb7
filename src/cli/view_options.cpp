// The viewer options of `covrast render` (and `covrast scenario`): the camera as the glTF
// viewers' harnesses give it (orbit, target, field of view), the environment and the tone
// mapping, applied to a loaded scene. docs/environments.md and docs/scene-format.md.
#include "commands.hpp"

#include <covrast/environment.hpp>
#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

namespace covrast::cli {
namespace {

/// "A,B,C" as three finite numbers; throws InputError naming the option.
glm::dvec3 parse_triple(const std::string& text, const char* option) {
  std::istringstream in(text);
  double v[3];
  char comma1 = 0, comma2 = 0;
  if (!(in >> v[0] >> comma1 >> v[1] >> comma2 >> v[2]) || comma1 != ',' || comma2 != ',' ||
      !(in >> std::ws).eof() || !std::isfinite(v[0]) || !std::isfinite(v[1]) ||
      !std::isfinite(v[2])) {
    throw InputError(std::string(option) + ": expected three finite numbers A,B,C, got '" + text +
                     "'");
  }
  return {v[0], v[1], v[2]};
}

/// The world box of the scene's meshes (each mesh's box through its model matrix).
bool world_box(const Scene& scene, glm::dvec3& lo, glm::dvec3& hi) {
  lo = glm::dvec3(std::numeric_limits<double>::max());
  hi = glm::dvec3(std::numeric_limits<double>::lowest());
  for (const MeshInstance& instance : scene.meshes) {
    if (instance.mesh->triangle_count() == 0) continue;
    const glm::dvec3 a(instance.mesh->bounds_min), b(instance.mesh->bounds_max);
    for (int corner = 0; corner < 8; ++corner) {
      const glm::dvec3 p(instance.model * glm::dvec4(corner & 1 ? b.x : a.x, corner & 2 ? b.y : a.y,
                                                     corner & 4 ? b.z : a.z, 1.0));
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  }
  return lo.x <= hi.x;
}

}  // namespace

glm::dvec3 orbit_eye(const glm::dvec3& target, double theta_deg, double phi_deg, double radius) {
  const double theta = theta_deg * std::numbers::pi / 180.0;
  const double phi = phi_deg * std::numbers::pi / 180.0;
  return target + radius * glm::dvec3(std::sin(phi) * std::sin(theta), std::cos(phi),
                                      std::sin(phi) * std::cos(theta));
}

void place_orbit_camera(Scene& scene, const glm::dvec3& target, double theta_deg, double phi_deg,
                        double radius) {
  Camera& camera = scene.camera;
  camera.orthographic = false;
  camera.target = target;
  camera.eye = orbit_eye(target, theta_deg, phi_deg, radius);
  const double phi = phi_deg * std::numbers::pi / 180.0;
  const double theta = theta_deg * std::numbers::pi / 180.0;
  // +Y up, except looking straight up or down, where the up is the direction of smaller phi
  // on the orbit: (-cos(phi) sin(theta), sin(phi), -cos(phi) cos(theta)).
  camera.up = std::abs(std::sin(phi)) > 1e-9 ? glm::dvec3(0.0, 1.0, 0.0)
                                             : glm::dvec3(-std::cos(phi) * std::sin(theta), 0.0,
                                                          -std::cos(phi) * std::cos(theta));
  // Near and far from the model's bounding sphere around the eye: nothing of it is clipped.
  glm::dvec3 lo, hi;
  double reach = radius;
  double centre_distance = 0.0, sphere = 0.0;
  if (world_box(scene, lo, hi)) {
    const glm::dvec3 centre = 0.5 * (lo + hi);
    sphere = 0.5 * glm::length(hi - lo);
    centre_distance = glm::length(centre - camera.eye);
    reach = centre_distance + sphere;
  }
  camera.far = std::max(1.01 * reach, 1e-3);
  camera.near = std::max(0.99 * (centre_distance - sphere), 1e-4 * camera.far);
}

void apply_view_args(Scene& scene, const ViewArgs& args) {
  if (!args.environment.empty()) {
    EnvironmentLight light;
    light.map = args.environment == "studio"
                    ? studio_environment()
                    : std::make_shared<const EnvironmentMap>(
                          load_environment(args.environment, &scene.warnings));
    light.rotation_deg = args.environment_rotation_deg;
    light.intensity = args.environment_intensity;
    if (!(light.intensity >= 0.0) || !std::isfinite(light.intensity)) {
      throw InputError("--environment-intensity: expected a finite number >= 0");
    }
    scene.environment = light;
    scene.lit = true;
  }
  if (!args.tone_map.empty()) {
    try {
      scene.tone_map = parse_tone_map(args.tone_map);
    } catch (const InputError& e) {
      throw InputError(std::string("--tone-map: ") + e.what());
    }
  }
  if (args.exposure) {
    if (!(*args.exposure > 0.0) || !std::isfinite(*args.exposure)) {
      throw InputError("--exposure: expected a finite number > 0");
    }
    scene.exposure = *args.exposure;
  }
  if (args.fov_deg) {
    if (!(*args.fov_deg > 0.0 && *args.fov_deg < 180.0)) {
      throw InputError("--fov: expected degrees in (0, 180)");
    }
    scene.camera.fovy_deg = *args.fov_deg;
    scene.camera.orthographic = false;
  }
  const glm::dvec3 target =
      args.target.empty() ? scene.camera.target : parse_triple(args.target, "--target");
  if (!args.orbit.empty()) {
    const glm::dvec3 orbit = parse_triple(args.orbit, "--orbit");
    if (!(orbit.z > 0.0)) throw InputError("--orbit: the radius must be > 0");
    place_orbit_camera(scene, target, orbit.x, orbit.y, orbit.z);
  } else if (!args.target.empty()) {
    // A new target keeps the eye's offset from the old one.
    const glm::dvec3 offset = scene.camera.eye - scene.camera.target;
    scene.camera.target = target;
    scene.camera.eye = target + offset;
  }
}

void add_view_options(CLI::App* sub, ViewArgs& args) {
  sub->add_option("--environment", args.environment,
                  "Light with an equirectangular environment map (.hdr, .exr, .png, .jpg), or "
                  "'studio' for the built-in one (docs/environments.md)")
      ->type_name("FILE|studio");
  sub->add_option("--environment-rotation", args.environment_rotation_deg,
                  "Turn the environment about +Y by DEG (counter-clockwise seen from above)")
      ->type_name("DEG");
  sub->add_option("--environment-intensity", args.environment_intensity,
                  "Scale the environment's radiance (default 1)")
      ->type_name("X");
  sub->add_option("--orbit", args.orbit,
                  "Camera at target + RADIUS (sin(PHI) sin(THETA), cos(PHI), sin(PHI) cos(THETA)), "
                  "degrees, +Y up, looking at the target (model-viewer's camera-orbit)")
      ->type_name("THETA,PHI,RADIUS");
  sub->add_option("--target", args.target, "The point the camera looks at")->type_name("X,Y,Z");
  sub->add_option("--fov", args.fov_deg, "Vertical field of view")->type_name("DEG");
  sub->add_option("--tone-map", args.tone_map,
                  "none, khronos-pbr-neutral, aces-hill or aces-narkowicz (docs/shading.md)")
      ->type_name("NAME");
  sub->add_option("--exposure", args.exposure,
                  "Multiply linear radiance by X before the tone map (default 1)")
      ->type_name("X");
}

}  // namespace covrast::cli
