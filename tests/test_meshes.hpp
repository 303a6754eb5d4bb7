// Small meshes and scene helpers shared by the test files (test-only code).
#pragma once

#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <string>

namespace covrast::test {

/// The colour image of `scene` rendered in `mode` ("coverage", "msaa:4", ...).
inline Image render_mode(const Scene& scene, const std::string& mode, int threads = 2,
                         int tile = 64) {
  RenderOptions options;
  options.mode = parse_render_mode(mode);
  options.threads = threads;
  options.tile = tile;
  return render(scene, options).color;
}

/// The largest difference of one channel code between two images of the same size.
inline int max_difference(const Image& a, const Image& b) {
  int worst = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    worst = std::max(worst, std::abs(int(a.rgb[i]) - int(b.rgb[i])));
  }
  return worst;
}

/// The camera that maps the world plane z = 0 one unit to one pixel: x_px = x + w/2,
/// y_px = h/2 - y (a 90-degree field of view at distance h/2), on a black background.
inline Scene pixel_scene(int width_px, int height_px) {
  Scene scene;
  scene.width = width_px;
  scene.height = height_px;
  scene.background_linear = glm::vec3(0.0f);
  scene.camera.eye = glm::dvec3(0.0, 0.0, height_px / 2.0);
  scene.camera.target = glm::dvec3(0.0);
  scene.camera.up = glm::dvec3(0.0, 1.0, 0.0);
  scene.camera.fovy_deg = 90.0;
  scene.camera.near = 1.0;
  scene.camera.far = 8.0 * height_px;
  return scene;
}

/// Closed UV sphere of radius 1 at the origin, poles on y: `rings` bands from pole to pole,
/// `segments` around. Single-vertex poles with triangle fans, and the seam reuses segment 0,
/// so every edge is shared by exactly two triangles; outward faces counter-clockwise.
inline std::shared_ptr<MeshData> uv_sphere(int rings, int segments) {
  constexpr double kPi = std::numbers::pi;
  auto m = std::make_shared<MeshData>();
  m->source = "uv sphere";
  m->positions.push_back(glm::vec3(0, 1, 0));
  for (int r = 1; r < rings; ++r) {
    const double theta = kPi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * kPi * s / segments;
      m->positions.push_back(glm::vec3(float(std::sin(theta) * std::cos(phi)),
                                       float(std::cos(theta)),
                                       float(-std::sin(theta) * std::sin(phi))));
    }
  }
  m->positions.push_back(glm::vec3(0, -1, 0));
  const std::uint32_t south = std::uint32_t(m->positions.size() - 1);
  auto ring = [&](int r, int s) { return std::uint32_t(1 + (r - 1) * segments + s % segments); };
  auto tri = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    m->indices.insert(m->indices.end(), {a, b, c});
  };
  for (int s = 0; s < segments; ++s) tri(0, ring(1, s), ring(1, s + 1));
  for (int r = 1; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      tri(ring(r, s), ring(r + 1, s), ring(r + 1, s + 1));
      tri(ring(r, s), ring(r + 1, s + 1), ring(r, s + 1));
    }
  }
  for (int s = 0; s < segments; ++s) tri(ring(rings - 1, s), south, ring(rings - 1, s + 1));
  return m;
}

/// Appends an instance of `mesh` (identity model matrix) to the scene.
inline void add_instance(Scene& scene, std::shared_ptr<const MeshData> mesh, glm::vec3 color,
                         ColorSource source = ColorSource::Uniform) {
  MeshInstance instance;
  instance.mesh = std::move(mesh);
  instance.color_source = source;
  instance.color_linear = color;
  scene.meshes.push_back(instance);
}

}  // namespace covrast::test
