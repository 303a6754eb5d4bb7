// The parts of load_mesh_scene (scene_json.cpp) that a scene file would otherwise give: a
// camera that frames the model (docs/scene-format.md, "Rendering a mesh file without a
// scene"); the light is the studio environment (scene/environment_studio.cpp).
#include "scene/scene_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace covrast::detail {

Camera framing_camera(const Scene& scene) {
  constexpr double kFovyDeg = 40.0;
  constexpr double kMargin = 1.05;
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
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
