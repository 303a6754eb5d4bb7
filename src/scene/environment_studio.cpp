// The built-in neutral studio environment (docs/environments.md): what `covrast render
// model.glb` lights a model with when the file has no lights and no environment is given.
#include <covrast/environment.hpp>

#include <algorithm>
#include <cmath>

namespace covrast {
namespace {

constexpr int kStudioWidth = 256;
constexpr int kStudioHeight = 128;

/// A soft round box light: full radiance within `inner_cos` of its axis, none beyond
/// `outer_cos`, smoothstep between.
struct SoftBox {
  glm::dvec3 axis;  ///< unit direction towards the light
  double radiance;
  double inner_cos;
  double outer_cos;
};

double smoothstep01(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

/// The room: 0.35 at the floor rising to 0.65 at the ceiling, L = 0.5 + 0.15 d_y; then the
/// boxes: key (upper left, in front), fill (right, lower, dimmer) and rim (behind, above).
glm::dvec3 studio_radiance(const glm::dvec3& d) {
  static const SoftBox kBoxes[] = {
      {glm::normalize(glm::dvec3(-0.55, 0.6, 0.58)), 8.0, 0.978, 0.956},  // ~12 and 17 degrees
      {glm::normalize(glm::dvec3(0.8, 0.2, 0.55)), 3.0, 0.966, 0.940},
      {glm::normalize(glm::dvec3(0.1, 0.55, -0.83)), 5.0, 0.985, 0.966},
  };
  double radiance = 0.5 + 0.15 * d.y;
  for (const SoftBox& box : kBoxes) {
    const double c = glm::dot(d, box.axis);
    radiance += box.radiance * smoothstep01((c - box.outer_cos) / (box.inner_cos - box.outer_cos));
  }
  return glm::dvec3(radiance);
}

}  // namespace

std::shared_ptr<const EnvironmentMap> studio_environment() {
  static const std::shared_ptr<const EnvironmentMap> map = [] {
    auto m = std::make_shared<EnvironmentMap>();
    m->width = kStudioWidth;
    m->height = kStudioHeight;
    m->radiance_linear.reserve(std::size_t(kStudioWidth) * kStudioHeight);
    for (int y = 0; y < kStudioHeight; ++y) {
      for (int x = 0; x < kStudioWidth; ++x) {
        const glm::dvec3 d =
            environment_direction((x + 0.5) / kStudioWidth, (y + 0.5) / kStudioHeight);
        m->radiance_linear.push_back(glm::vec3(studio_radiance(d)));
      }
    }
    return m;
  }();
  return map;
}

}  // namespace covrast
