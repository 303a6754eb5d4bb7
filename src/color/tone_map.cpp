// The tone-mapping operators of color/tone_map.hpp, each as its source publishes it.
#include "color/tone_map.hpp"

#include <algorithm>

namespace covrast::detail {
namespace {

glm::dvec3 khronos_pbr_neutral(glm::dvec3 c) {
  constexpr double kStartCompression = 0.8 - 0.04;
  constexpr double kDesaturation = 0.15;
  const double m = std::min({c.r, c.g, c.b});
  const double offset = m < 0.08 ? m - 6.25 * m * m : 0.04;
  c -= offset;
  const double peak = std::max({c.r, c.g, c.b});
  if (peak < kStartCompression) return c;
  const double d = 1.0 - kStartCompression;
  const double new_peak = 1.0 - d * d / (peak + d - kStartCompression);
  c *= new_peak / peak;
  const double g = 1.0 - 1.0 / (kDesaturation * (peak - new_peak) + 1.0);
  return c * (1.0 - g) + glm::dvec3(new_peak) * g;
}

glm::dvec3 aces_hill(const glm::dvec3& x) {
  // sRGB -> ACES AP1-ish with the RRT's saturation, and back (row-major).
  const glm::dvec3 v(0.59719 * x.r + 0.35458 * x.g + 0.04823 * x.b,
                     0.07600 * x.r + 0.90834 * x.g + 0.01566 * x.b,
                     0.02840 * x.r + 0.13383 * x.g + 0.83777 * x.b);
  const auto fit = [](double a) {
    return (a * (a + 0.0245786) - 0.000090537) / (a * (0.983729 * a + 0.4329510) + 0.238081);
  };
  const glm::dvec3 f(fit(v.r), fit(v.g), fit(v.b));
  const glm::dvec3 out(1.60475 * f.r - 0.53108 * f.g - 0.07367 * f.b,
                       -0.10208 * f.r + 1.10813 * f.g - 0.00605 * f.b,
                       -0.00327 * f.r - 0.07276 * f.g + 1.07602 * f.b);
  return glm::clamp(out, glm::dvec3(0.0), glm::dvec3(1.0));
}

double narkowicz(double x) {
  return std::clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

}  // namespace

glm::dvec3 tone_map(const ToneMapping& mapping, const glm::dvec3& linear) {
  const glm::dvec3 x = linear * mapping.exposure;
  switch (mapping.op) {
    case ToneMap::KhronosPbrNeutral:
      return khronos_pbr_neutral(x);
    case ToneMap::AcesHill:
      return aces_hill(x);
    case ToneMap::AcesNarkowicz:
      return {narkowicz(x.r), narkowicz(x.g), narkowicz(x.b)};
    case ToneMap::None:
    default:
      return x;
  }
}

}  // namespace covrast::detail
