// Post: transparent and skybox backgrounds (formulas in post/background.hpp).
#include "post/background.hpp"

#include "color/srgb.hpp"
#include "color/srgb8.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>

namespace covrast::detail {
namespace {

/// The background's share w of one pixel from its codes over black and over white.
double background_share(const std::uint8_t* black, const std::uint8_t* white) {
  if (black[0] == white[0] && black[1] == white[1] && black[2] == white[2]) return 0.0;
  if (black[0] == 0 && black[1] == 0 && black[2] == 0 && white[0] == 255 && white[1] == 255 &&
      white[2] == 255) {
    return 1.0;
  }
  const std::array<double, 256>& dec = srgb8_decode_table();
  double sum = 0.0;
  for (int c = 0; c < 3; ++c) sum += dec[white[c]] - dec[black[c]];
  return std::clamp(sum / 3.0, 0.0, 1.0);
}

std::uint8_t unit_code(double x) {
  return std::uint8_t(std::lround(std::clamp(x, 0.0, 1.0) * 255.0));
}

}  // namespace

SkyView::SkyView(const Scene& scene, int width_px, int height_px)
    : sky_(*scene.environment),
      mapping_{scene.tone_map, scene.exposure},
      orthographic_(scene.camera.orthographic),
      forward_(glm::normalize(scene.camera.target - scene.camera.eye)),
      right_(glm::normalize(glm::cross(forward_, scene.camera.up))),
      up_(glm::cross(right_, forward_)),
      width_px_(width_px),
      height_px_(height_px) {
  half_h_ = std::tan(0.5 * scene.camera.fovy_deg * (std::numbers::pi / 180.0));
  half_w_ = half_h_ * double(width_px) / double(height_px);
}

glm::dvec3 SkyView::at(int x, int y) const {
  glm::dvec3 d = forward_;
  if (!orthographic_) {
    const double ndc_x = 2.0 * (x + 0.5) / width_px_ - 1.0;
    const double ndc_y = 1.0 - 2.0 * (y + 0.5) / height_px_;
    d = glm::normalize(forward_ + right_ * (ndc_x * half_w_) + up_ * (ndc_y * half_h_));
  }
  const glm::dvec3 radiance = sky_.radiance(d);
  return mapping_.is_identity() ? radiance : tone_map(mapping_, radiance);
}

void key_transparent(Image& frame, const Image& over_white) {
  const std::array<double, 256>& dec = srgb8_decode_table();
  frame.alpha.assign(std::size_t(frame.width) * std::size_t(frame.height), 0);
  for (std::size_t i = 0; i < frame.alpha.size(); ++i) {
    std::uint8_t* rgb = &frame.rgb[3 * i];  // over black in, the keyed colour out
    const double alpha = 1.0 - background_share(rgb, &over_white.rgb[3 * i]);
    frame.alpha[i] = unit_code(alpha);
    if (frame.alpha[i] == 0) {
      std::fill(rgb, rgb + 3, std::uint8_t(0));  // colour 0 where nothing shows
    } else if (alpha < 1.0) {
      for (int c = 0; c < 3; ++c) rgb[c] = encode_srgb8(float(std::min(1.0, dec[rgb[c]] / alpha)));
    }
  }
}

bool has_transmission(const Scene& scene) {
  if (!scene.lit) return false;
  for (const MeshInstance& instance : scene.meshes) {
    for (const Material& m : instance.materials) {
      if (m.model == ShadingModel::Pbr && m.transmission > 0.0f) return true;
    }
  }
  return false;
}

void key_skybox(Image& frame, const Image& over_white, const SkyView& sky, bool per_channel) {
  const std::array<double, 256>& dec = srgb8_decode_table();
  frame.alpha.clear();
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(frame.width) + std::size_t(x);
      std::uint8_t* rgb = &frame.rgb[3 * i];  // over black in, composited out
      const std::uint8_t* white = &over_white.rgb[3 * i];
      const double w = background_share(rgb, white);
      if (w == 0.0) continue;
      const glm::dvec3 k = sky.at(x, y);
      for (int c = 0; c < 3; ++c) {
        const double w_c = per_channel ? std::clamp(dec[white[c]] - dec[rgb[c]], 0.0, 1.0) : w;
        rgb[c] = encode_srgb8(float(dec[rgb[c]] + w_c * k[c]));
      }
    }
  }
}

}  // namespace covrast::detail
