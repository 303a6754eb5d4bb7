// The analytic shading tests' scene: a finely tessellated unit sphere with exact vertex
// normals, and the comparison of every interior pixel with a formula evaluated on the exact
// sphere at the pixel centre's ray (test_shading_analytic.cpp, test_environment_lighting.cpp).
#pragma once

#include <covrast/image.hpp>
#include <covrast/scene.hpp>

#include "color/srgb8.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <vector>

#include "test_meshes.hpp"

namespace covrast::test {

/// A 96 x 96 lit scene of the unit sphere (`rings` x 2 `rings` quads, exact normals: the
/// positions) with base colour `base` and `material`, seen from `eye` towards the origin, fovy
/// 40, no lights.
inline Scene lit_sphere_scene(const glm::vec3& base, const Material& material,
                              const glm::dvec3& eye = {0.0, 0.0, 3.0}, int rings = 96) {
  Scene scene;
  scene.width = scene.height = 96;
  scene.camera.eye = eye;
  scene.camera.target = {0.0, 0.0, 0.0};
  scene.camera.fovy_deg = 40.0;
  scene.camera.near = 0.5;
  scene.camera.far = 10.0;
  auto sphere = uv_sphere(rings, 2 * rings);
  std::vector<glm::vec3> normals;
  for (const std::uint32_t i : sphere->indices) normals.push_back(sphere->positions[i]);
  analyze_mesh_topology(*sphere);
  add_instance(scene, sphere, base);
  scene.meshes[0].materials = {material};
  scene.meshes[0].corner_normals = std::make_shared<const std::vector<glm::vec3>>(normals);
  scene.lit = true;
  return scene;
}

/// The largest difference, over the interior pixels (the ray meets the sphere with n . -d >
/// 0.3), between `image` of a scene seen from (0, 0, 3) and the 8-bit code of `expected(n, v)`
/// (linear) at the exact hit point p (= n) with v = -d; `checked` counts those pixels.
inline int worst_sphere_difference(
    const Image& image, const Scene& scene,
    const std::function<glm::dvec3(const glm::dvec3&, const glm::dvec3&)>& expected, int& checked) {
  const double t = std::tan(scene.camera.fovy_deg * std::numbers::pi / 360.0);
  int worst = 0;
  checked = 0;
  for (int y = 0; y < scene.height; ++y) {
    for (int x = 0; x < scene.width; ++x) {
      const glm::dvec3 d =
          glm::normalize(glm::dvec3((2.0 * (x + 0.5) / scene.width - 1.0) * t,
                                    (1.0 - 2.0 * (y + 0.5) / scene.height) * t, -1.0));
      const glm::dvec3 o = scene.camera.eye;
      const double b = glm::dot(o, d), c = glm::dot(o, o) - 1.0;
      const double disc = b * b - c;
      if (disc <= 0.0) continue;
      const glm::dvec3 n = o + (-b - std::sqrt(disc)) * d;
      if (glm::dot(n, -d) < 0.3) continue;
      const glm::dvec3 value = expected(n, -d);
      const std::uint8_t* p = image.pixel(x, y);
      for (int ch = 0; ch < 3; ++ch) {
        const int code = covrast::detail::encode_srgb8(float(value[ch]));
        worst = std::max(worst, std::abs(int(p[ch]) - code));
      }
      ++checked;
    }
  }
  return worst;
}

/// Calls f(d, omega, radiance) for every texel of `map`: its centre direction, solid angle and
/// radiance (the texel-by-texel sums the environment tests hold the lighting against).
template <typename F>
void for_each_texel(const EnvironmentMap& map, F&& f) {
  for (int y = 0; y < map.height; ++y) {
    const double omega = environment_texel_solid_angle(y, map.width, map.height);
    for (int x = 0; x < map.width; ++x) {
      f(environment_direction((x + 0.5) / map.width, (y + 0.5) / map.height), omega,
        glm::dvec3(map.texel(x, y)));
    }
  }
}

}  // namespace covrast::test
