// covrast public API: environment maps, the light that surrounds a scene (docs/environments.md).
// An environment is an equirectangular map of linear radiance. Its orientation is the one the
// Khronos glTF Sample Viewer and model-viewer's render-fidelity harness use: texel (x, y) of a
// W x H map, row 0 at the top, is the radiance arriving from direction
//   d(x, y) = (-sin(phi) cos(theta), cos(phi), -sin(phi) sin(theta)),
//   theta = 2 pi (x + 0.5) / W,  phi = pi (y + 0.5) / H,
// so the map's centre is seen looking towards +X, its top row towards +Y, its left and right
// edges towards -X, a quarter of the way across (x = W / 4) towards -Z and three quarters
// towards +Z.
#pragma once

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

namespace covrast {

/// Largest side of an environment map [texels] (docs/limits.md); larger maps are refused
/// before any texel is allocated.
inline constexpr int kMaxEnvironmentSide = 16384;
/// Most texels of one environment map (32 Mi: 8192 x 4096), checked from the header.
inline constexpr std::uint64_t kMaxEnvironmentTexels = std::uint64_t(1) << 25;
/// Largest environment file read [bytes] (1 GiB).
inline constexpr std::uint64_t kMaxEnvironmentFileBytes = std::uint64_t(1) << 30;

/// An equirectangular environment map: `width` x `height` texels of linear RGB radiance
/// [W / (sr m^2), relative], row-major, row 0 the top (+Y) row. Finite and >= 0 everywhere
/// (loaders replace what is not, with a warning).
struct EnvironmentMap {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> radiance_linear;

  const glm::vec3& texel(int x, int y) const {
    return radiance_linear[std::size_t(y) * std::size_t(width) + std::size_t(x)];
  }
};

/// The environment lighting of a scene: a map, turned about +Y by `rotation_deg` (positive:
/// counter-clockwise seen from above: what the map shows towards +X is seen from
/// (cos r, 0, -sin r), the right-handed rotation R_y(r) of +X), and scaled by `intensity`.
struct EnvironmentLight {
  std::shared_ptr<const EnvironmentMap> map;
  double rotation_deg = 0.0;
  double intensity = 1.0;
};

/// The unit direction (in the map's own frame, before rotation) that the point (u, v) of the
/// map looks towards, u = (x + 0.5) / W and v = (y + 0.5) / H for texel centres.
inline glm::dvec3 environment_direction(double u, double v) {
  const double theta = 2.0 * std::numbers::pi * u;
  const double phi = std::numbers::pi * v;
  const double s = std::sin(phi);
  return {-s * std::cos(theta), std::cos(phi), -s * std::sin(theta)};
}

/// The solid angle [sr] of texel row y of a W x H map: (2 pi / W) (cos(pi y / H) -
/// cos(pi (y + 1) / H)), the band between the row's edges split into W texels.
inline double environment_texel_solid_angle(int y, int width, int height) {
  return 2.0 * std::numbers::pi / width *
         (std::cos(std::numbers::pi * y / height) - std::cos(std::numbers::pi * (y + 1) / height));
}

/// The inverse of environment_direction for a unit direction d: u in [0, 1), v in [0, 1].
inline glm::dvec2 environment_uv(const glm::dvec3& d) {
  double theta = std::atan2(-d.z, -d.x);  // in (-pi, pi]
  if (theta < 0.0) theta += 2.0 * std::numbers::pi;
  double u = theta / (2.0 * std::numbers::pi);
  if (u >= 1.0) u = 0.0;
  const double v = std::acos(std::clamp(d.y, -1.0, 1.0)) / std::numbers::pi;
  return {u, v};
}

}  // namespace covrast

namespace covrast {

/// Reads an environment map file, recognised by its first bytes: Radiance .hdr (RGBE, flat or
/// run-length, "-Y H +X W"), OpenEXR (R, G, B as float; any compression libopenexr reads, DWAB
/// included; refused when covrast was built without it), 8-bit PNG or JPEG (sRGB, decoded
/// exactly to linear). Texels that are negative, NaN or infinite become 0 with one warning
/// appended to `warnings`. Throws InputError("FILE: cannot ... environment: why"), one line,
/// for files that cannot be read or decoded or are over the limits above.
EnvironmentMap load_environment(const std::filesystem::path& path,
                                std::vector<std::string>* warnings = nullptr);

/// load_environment of bytes in memory, `name` naming them in messages (the fuzz target's
/// entry point).
EnvironmentMap decode_environment(const std::uint8_t* bytes, std::size_t size,
                                  const std::string& name,
                                  std::vector<std::string>* warnings = nullptr);

/// The built-in neutral studio environment (docs/environments.md has its definition): a
/// 256 x 128 map of a grey room, brighter above than below, with three soft white box lights
/// (key, fill and rim). The same texels on every machine; no file needed.
std::shared_ptr<const EnvironmentMap> studio_environment();

}  // namespace covrast
