// The parts of load_mesh_scene (scene_json.cpp) that a scene file would otherwise give: a
// camera that frames the model (docs/scene-format.md, "Rendering a mesh file without a
// scene"); the light is the studio environment (scene/environment_studio.cpp).
#include "scene/scene_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace covrast::detail {

namespace {

/// The world box of the scene's meshes (each mesh's object box through its model matrix);
/// false when no mesh has a triangle.
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

Camera framing_camera(const Scene& scene) {
  constexpr double kFovyDeg = 40.0;
  constexpr double kMargin = 1.05;
  glm::dvec3 lo, hi;
  world_box(scene, lo, hi);
  const bool empty = !(lo.x <= hi.x);
  const glm::dvec3 centre = empty ? glm::dvec3(0.0) : 0.5 * (lo + hi);
  double radius = empty ? 0.0 : 0.5 * glm::length(hi - lo);
  if (!(radius > 0.0) || !std::isfinite(radius)) radius = 1.0;  // nothing, or one point
  // The sphere fits when its radius subtends at most the smaller half angle of the view.
  const double half_v = 0.5 * kFovyDeg * std::numbers::pi / 180.0;
  const double aspect = double(scene.width) / double(scene.height);
  const double half = std::min(half_v, std::atan(std::tan(half_v) * aspect));
  const double distance = kMargin * radius / std::sin(half);
  Camera camera;
  camera.eye = centre + glm::dvec3(0.0, 0.0, distance);
  camera.target = centre;
  camera.up = glm::dvec3(0.0, 1.0, 0.0);
  camera.fovy_deg = kFovyDeg;
  camera.near = std::max(distance - 1.5 * radius, 1e-3 * distance);
  camera.far = distance + 1.5 * radius;
  return camera;
}

}  // namespace covrast::detail

namespace covrast {

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
  double reach = radius, centre_distance = 0.0, sphere = 0.0;
  if (detail::world_box(scene, lo, hi)) {
    const glm::dvec3 centre = 0.5 * (lo + hi);
    sphere = 0.5 * glm::length(hi - lo);
    centre_distance = glm::length(centre - camera.eye);
    reach = centre_distance + sphere;
  }
  camera.far = std::max(1.01 * reach, 1e-3);
  camera.near = std::max(0.99 * (centre_distance - sphere), 1e-4 * camera.far);
}

}  // namespace covrast
