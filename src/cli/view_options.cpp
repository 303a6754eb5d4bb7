// The viewer options of `covrast render` (and `covrast scenario`): the camera as the glTF
// viewers' harnesses give it (orbit, target, field of view), the environment and the tone
// mapping, applied to a loaded scene. docs/environments.md and docs/scene-format.md.
#include "commands.hpp"

#include <covrast/environment.hpp>
#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <cmath>
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

}  // namespace

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
  if (args.transparent) scene.background_kind = BackgroundKind::Transparent;
  if (args.skybox) {
    if (!scene.environment) {
      throw InputError("--skybox needs an environment: --environment FILE|studio, or the scene's");
    }
    scene.background_kind = BackgroundKind::Skybox;
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
  CLI::Option* transparent =
      sub->add_flag("--transparent", args.transparent,
                    "Transparent background: an RGBA PNG whose alpha is the share of each pixel "
                    "the model covers (the frame is rendered twice; docs/scene-format.md)");
  sub->add_option("--time", args.time_s,
                  "Pose glTF files at this moment of an animation (seconds; the static pose "
                  "without it; docs/scene-format.md, \"Animation\")")
      ->type_name("SECONDS");
  sub->add_option("--animation", args.animation,
                  "Which animation --time samples: an index or a name (default: the first)")
      ->type_name("INDEX|NAME");
  sub->add_option("--variant", args.variant,
                  "Draw every glTF file with this KHR_materials_variants material variant (`info` "
                  "lists a file's variants; a file without it is an error)")
      ->type_name("NAME");
  sub->add_flag("--skybox", args.skybox,
                "Show the environment behind the model, tone-mapped (the frame is rendered twice)")
      ->excludes(transparent);
}

}  // namespace covrast::cli
