// Tests of lighting (docs/shading.md; src/shading/shading.cpp, the front end's shading inputs,
// the scene keys "lights", "material", "normals", glTF NORMAL and materials, OBJ vn): analytic
// images of a sphere and a cube against their formulas, the pbr BRDF against an independent
// evaluation of the glTF specification's Appendix B and an energy bound, determinism across
// threads and tiles, and every bad value of the new keys. Content is generated here.
#include <covrast/error.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include "color/srgb8.hpp"
#include "shading/shading_inputs.hpp"

#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <sys/wait.h>

#include "test_meshes.hpp"
#include "test_splits.hpp"
#include "test_tempdir.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using covrast::Light;
using covrast::LightType;
using covrast::Material;
using covrast::Scene;
using covrast::ShadingModel;
using nlohmann::json;

namespace {

constexpr double kPi = std::numbers::pi;

/// A scene with the camera at (0, 0, 3) looking at the origin, fovy 40 degrees.
Scene camera_scene(int width, int height) {
  Scene scene;
  scene.width = width;
  scene.height = height;
  scene.camera.eye = {0.0, 0.0, 3.0};
  scene.camera.target = {0.0, 0.0, 0.0};
  scene.camera.up = {0.0, 1.0, 0.0};
  scene.camera.fovy_deg = 40.0;
  scene.camera.near = 0.5;
  scene.camera.far = 10.0;
  scene.background_linear = glm::vec3(0.0f);
  return scene;
}

/// The world-space ray through pixel centre (x + 0.5, y + 0.5) of camera_scene's camera.
glm::dvec3 pixel_ray(const Scene& scene, int x, int y) {
  const double t = std::tan(scene.camera.fovy_deg * kPi / 360.0);
  const double aspect = double(scene.width) / scene.height;
  const double ndc_x = 2.0 * (x + 0.5) / scene.width - 1.0;
  const double ndc_y = 1.0 - 2.0 * (y + 0.5) / scene.height;
  return glm::normalize(glm::dvec3(ndc_x * t * aspect, ndc_y * t, -1.0));
}

Light directional(glm::dvec3 direction, double intensity) {
  Light l;
  l.type = LightType::Directional;
  l.direction = glm::normalize(direction);
  l.intensity = intensity;
  return l;
}

Light point_light(glm::dvec3 position, double intensity, double range) {
  Light l;
  l.type = LightType::Point;
  l.position = position;
  l.intensity = intensity;
  l.range = range;
  return l;
}

/// A spot light at `position` shining along `direction` (normalised here), cone angles in
/// degrees.
Light spot_light(glm::dvec3 position, glm::dvec3 direction, double inner_deg, double outer_deg,
                 double intensity) {
  Light l;
  l.type = LightType::Spot;
  l.position = position;
  l.direction = glm::normalize(direction);
  l.inner_cone_deg = inner_deg;
  l.outer_cone_deg = outer_deg;
  l.intensity = intensity;
  return l;
}

Light ambient(double intensity) {
  Light l;
  l.type = LightType::Ambient;
  l.intensity = intensity;
  return l;
}

Material lambert() {
  Material m;
  m.model = ShadingModel::Lambert;
  return m;
}

covrast::RenderResult render(const Scene& scene, const std::string& mode, int threads = 2,
                             int tile = 64) {
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode(mode);
  options.threads = threads;
  options.tile = tile;
  return covrast::render(scene, options);
}

const std::uint8_t* pixel(const covrast::Image& image, int x, int y) {
  return &image.rgb[(std::size_t(y) * image.width + x) * 3];
}

/// The 8-bit code of a linear value, as the resolve writes it.
int code(double linear) { return covrast::detail::encode_srgb8(float(linear)); }

}  // namespace

TEST_CASE("lit sphere with exact normals matches base * (ambient + max(0, n . l))", "[shading]") {
  Scene scene = camera_scene(96, 96);
  auto sphere = covrast::test::uv_sphere(96, 192);
  // Exact normals: on the unit sphere the normal is the position.
  std::vector<glm::vec3> normals;
  for (const std::uint32_t i : sphere->indices) normals.push_back(sphere->positions[i]);
  covrast::analyze_mesh_topology(*sphere);
  const glm::vec3 base(0.8f, 0.5f, 0.3f);
  covrast::test::add_instance(scene, sphere, base);
  scene.meshes[0].materials = {lambert()};
  scene.meshes[0].corner_normals = std::make_shared<const std::vector<glm::vec3>>(normals);
  scene.lit = true;
  const glm::dvec3 travel(-0.3, -0.4, -1.0);
  scene.lights = {directional(travel, 1.0), ambient(0.1)};
  const glm::dvec3 l = -glm::normalize(travel);

  for (const char* mode : {"coverage", "msaa:4", "aliased", "ssaa:2"}) {
    INFO("mode " << mode);
    const covrast::Image image = render(scene, mode).color;
    int checked = 0, worst = 0;
    for (int y = 0; y < scene.height; ++y) {
      for (int x = 0; x < scene.width; ++x) {
        // Ray o + s d against |p| = 1; interior: the ray meets the sphere well inside its
        // silhouette (n . -d > 0.3), so the whole pixel lies on the surface.
        const glm::dvec3 o = scene.camera.eye, d = pixel_ray(scene, x, y);
        const double b = glm::dot(o, d), c = glm::dot(o, o) - 1.0;
        const double disc = b * b - c;
        if (disc <= 0.0) continue;
        const glm::dvec3 n = o + (-b - std::sqrt(disc)) * d;  // unit: the hit point
        if (glm::dot(n, -d) < 0.3) continue;
        const double e = 0.1 + std::max(0.0, glm::dot(n, l));
        const std::uint8_t* p = pixel(image, x, y);
        for (int ch = 0; ch < 3; ++ch) {
          const int diff = std::abs(int(p[ch]) - code(base[ch] * e));
          worst = std::max(worst, diff);
        }
        ++checked;
      }
    }
    CHECK(checked > 3000);
    CHECK(worst <= 1);
  }
}

namespace {

/// Axis-aligned cube [-0.5, 0.5]^3, 12 counter-clockwise outward triangles (no normals).
std::shared_ptr<covrast::MeshData> cube() {
  auto m = std::make_shared<covrast::MeshData>();
  m->source = "cube";
  for (int i = 0; i < 8; ++i) {
    m->positions.emplace_back(i & 1 ? 0.5f : -0.5f, i & 2 ? 0.5f : -0.5f, i & 4 ? 0.5f : -0.5f);
  }
  // Faces as quads a b c d, counter-clockwise seen from outside.
  const int quads[6][4] = {{1, 3, 7, 5}, {0, 4, 6, 2}, {2, 6, 7, 3},
                           {0, 1, 5, 4}, {4, 5, 7, 6}, {0, 2, 3, 1}};
  for (const auto& q : quads) {
    for (const int k : {q[0], q[1], q[2], q[0], q[2], q[3]}) m->indices.push_back(std::uint32_t(k));
  }
  covrast::analyze_mesh_topology(*m);
  return m;
}

}  // namespace

TEST_CASE("a cube with flat normals gives each face exactly its lambert value", "[shading]") {
  Scene scene = camera_scene(128, 128);
  // Seen from (1.6, 1.3, 2.2): the +x, +y and +z faces are visible.
  scene.camera.eye = {1.6, 1.3, 2.2};
  const glm::vec3 base(0.9f, 0.6f, 0.2f);
  covrast::test::add_instance(scene, cube(), base);
  scene.meshes[0].materials = {lambert()};
  scene.meshes[0].normals = covrast::NormalSource::Flat;
  scene.lit = true;
  const glm::dvec3 travel(-0.2, -0.5, -0.7);
  scene.lights = {directional(travel, 0.8), ambient(0.15)};
  const glm::dvec3 l = -glm::normalize(travel);
  const covrast::Image image = render(scene, "coverage").color;
  // Which face a pixel shows: ray from the eye against the three visible face planes.
  const glm::dvec3 eye = scene.camera.eye, forward = glm::normalize(-eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0)));
  const glm::dvec3 up = glm::cross(right, forward);
  const double t = std::tan(scene.camera.fovy_deg * kPi / 360.0);
  int counts[3] = {0, 0, 0};
  for (int y = 0; y < scene.height; ++y) {
    for (int x = 0; x < scene.width; ++x) {
      const double sx = (2.0 * (x + 0.5) / scene.width - 1.0) * t;
      const double sy = (1.0 - 2.0 * (y + 0.5) / scene.height) * t;
      const glm::dvec3 d = glm::normalize(forward + sx * right + sy * up);
      for (int axis = 0; axis < 3; ++axis) {
        const double s = (0.5 - eye[axis]) / d[axis];
        const glm::dvec3 hit = eye + s * d;
        // Well inside the face (a pixel is about 0.02 units here): no edge in the pixel.
        bool inside = true;
        for (int other = 0; other < 3; ++other) {
          if (other != axis && std::abs(hit[other]) > 0.45) inside = false;
        }
        if (!inside) continue;
        glm::dvec3 n(0.0);
        n[axis] = 1.0;
        const double e = 0.15 + 0.8 * std::max(0.0, glm::dot(n, l));
        const std::uint8_t* p = pixel(image, x, y);
        INFO("pixel " << x << "," << y << " face " << axis);
        for (int ch = 0; ch < 3; ++ch) REQUIRE(int(p[ch]) == code(base[ch] * e));
        ++counts[axis];
      }
    }
  }
  for (const int c : counts) CHECK(c > 200);
}

namespace {

/// The glTF 2.0 BRDF written out independently, in the specification's mix form (Appendix
/// B.3.2 and B.3.3, per colour channel): dielectric = mix(diffuse, specular, F_d) with
/// F_d = 0.04 + 0.96 (1 - |v.h|)^5, metal = specular x (base + (1 - base) (1 - |v.h|)^5).
double appendix_b(double base, double metallic, double roughness, const glm::dvec3& n,
                  const glm::dvec3& v, const glm::dvec3& l) {
  const double a = roughness * roughness;
  const glm::dvec3 h = glm::normalize(l + v);
  const double nh = glm::dot(n, h), nl = glm::dot(n, l), nv = glm::dot(n, v);
  const double hl = glm::dot(h, l), hv = glm::dot(h, v);
  const double d = nh > 0 ? a * a / (kPi * std::pow(nh * nh * (a * a - 1) + 1, 2)) : 0.0;
  const double g1l = std::abs(nl) + std::sqrt(a * a + (1 - a * a) * nl * nl);
  const double g1v = std::abs(nv) + std::sqrt(a * a + (1 - a * a) * nv * nv);
  const double vis = (hl > 0 && hv > 0) ? 1.0 / (g1l * g1v) : 0.0;
  const double specular = vis * d;
  const double s5 = std::pow(1.0 - std::abs(hv), 5);
  const double dielectric = (1 - (0.04 + 0.96 * s5)) * base / kPi + (0.04 + 0.96 * s5) * specular;
  const double metal = specular * (base + (1 - base) * s5);
  return (1 - metallic) * dielectric + metallic * metal;
}

glm::dvec3 from_angles(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

}  // namespace

TEST_CASE("pbr BRDF equals an independent evaluation of glTF Appendix B", "[shading]") {
  const glm::dvec3 n(0, 0, 1);
  const glm::dvec3 base(0.9, 0.5, 0.1);
  int compared = 0;
  for (const double metallic : {0.0, 1.0}) {
    for (const double roughness : {0.05, 0.3, 0.6, 1.0}) {
      for (const double theta_v : {0.0, 0.4, 1.1, 1.5}) {
        for (const double theta_l : {0.1, 0.7, 1.3}) {
          for (const double phi : {0.0, 1.0, 2.5}) {
            const glm::dvec3 v = from_angles(theta_v, 0.0), l = from_angles(theta_l, phi);
            const glm::dvec3 f = covrast::detail::pbr_brdf(base, metallic, roughness, n, v, l);
            for (int c = 0; c < 3; ++c) {
              const double expected = appendix_b(base[c], metallic, roughness, n, v, l);
              INFO("m " << metallic << " r " << roughness << " tv " << theta_v << " tl " << theta_l
                        << " phi " << phi);
              CHECK(f[c] == Approx(expected).epsilon(1e-12).margin(1e-15));
              ++compared;
            }
          }
        }
      }
    }
  }
  CHECK(compared == 2 * 4 * 4 * 3 * 3 * 3);
}

namespace {

/// Directional albedo A(v) = integral over the hemisphere of f(l, v) (n . l) dl for a white
/// base, midpoint rule in (cos theta, phi) with `steps` x `steps` cells.
double white_albedo(double metallic, double roughness, double theta_v, int steps) {
  const glm::dvec3 n(0, 0, 1), white(1.0), v = from_angles(theta_v, 0.0);
  double sum = 0.0;
  for (int i = 0; i < steps; ++i) {
    const double cos_theta = (i + 0.5) / steps;
    for (int j = 0; j < steps; ++j) {
      const glm::dvec3 l = from_angles(std::acos(cos_theta), 2 * kPi * (j + 0.5) / steps);
      sum += covrast::detail::pbr_brdf(white, metallic, roughness, n, v, l).r * cos_theta;
    }
  }
  return sum * (1.0 / steps) * (2 * kPi / steps);
}

}  // namespace

TEST_CASE("pbr BRDF: white furnace albedo, exact at roughness 1", "[shading]") {
  // Roughness 1 (alpha = 1): D = 1/pi, V = 1 / ((1 + n.l)(1 + n.v)); a white metal seen
  // head-on reflects integral_0^1 mu / (1 + mu) dmu = 1 - ln 2 of the light.
  CHECK(white_albedo(1.0, 1.0, 0.0, 400) == Approx(1.0 - std::log(2.0)).epsilon(1e-4));
  for (const double roughness : {0.4, 0.7, 1.0}) {
    for (const double theta_v : {0.0, 0.6, 1.2}) {
      INFO("roughness " << roughness << " theta_v " << theta_v);
      // A white metal (F = 1): single-scattering GGX loses energy, never gains it.
      const double metal = white_albedo(1.0, roughness, theta_v, 400);
      CHECK(metal <= 1.0);
      CHECK(metal >= 0.3);
      // Dielectric: (1 - F) Lambert plus F x specular (B.3.5) is not exactly conserving:
      // where the lobe exceeds the diffuse value, F weights it more. Measured: 0.97..1.0,
      // but 1.055 at roughness 0.4 seen at 69 degrees; the bound catches a lost 1/pi or a
      // doubled lobe.
      const double dielectric = white_albedo(0.0, roughness, theta_v, 400);
      CHECK(dielectric <= (roughness == 0.4 && theta_v == 1.2 ? 1.06 : 1.0));
      CHECK(dielectric >= 0.85);
    }
  }
}

TEST_CASE("point and spot lights: inverse square, range window and cone on a plane", "[shading]") {
  Scene scene = camera_scene(100, 100);
  auto plane = std::make_shared<covrast::MeshData>();
  plane->positions = {{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}};
  plane->indices = {0, 1, 2, 0, 2, 3};
  const glm::vec3 base(0.9f, 0.7f, 0.5f);
  covrast::test::add_instance(scene, plane, base);
  scene.meshes[0].materials = {lambert()};
  scene.lit = true;
  scene.lights = {point_light({-0.3, 0.2, 0.8}, 0.6, 1.6),
                  spot_light({0.4, -0.3, 1.0}, {0.1, 0.2, -1.0}, 12.0, 25.0, 0.5)};
  // KHR_lights_punctual: E = I / d^2 x clamp(1 - (d / range)^4, 0, 1) x cone^2.
  const auto expected = [&](const glm::dvec3& p) {
    double e = 0.0;
    for (const Light& light : scene.lights) {
      const glm::dvec3 to = light.position - p;
      const double d = glm::length(to);
      const glm::dvec3 l = to / d;
      double a = light.intensity / (d * d) * std::max(0.0, l.z);  // n = +z
      if (light.range > 0.0) a *= std::clamp(1.0 - std::pow(d / light.range, 4), 0.0, 1.0);
      if (light.type == LightType::Spot) {
        const double c_outer = std::cos(light.outer_cone_deg * kPi / 180.0);
        const double c_inner = std::cos(light.inner_cone_deg * kPi / 180.0);
        const double cone =
            std::clamp((glm::dot(light.direction, -l) - c_outer) / (c_inner - c_outer), 0.0, 1.0);
        a *= cone * cone;
      }
      e += a;
    }
    return e;
  };
  const covrast::Image image = render(scene, "aliased").color;
  int worst = 0, lit_pixels = 0, dark_pixels = 0;
  for (int y = 0; y < scene.height; ++y) {
    for (int x = 0; x < scene.width; ++x) {
      const glm::dvec3 d = pixel_ray(scene, x, y);
      const glm::dvec3 p = scene.camera.eye + (-scene.camera.eye.z / d.z) * d;  // z = 0
      const double e = expected(p);
      const std::uint8_t* px = pixel(image, x, y);
      for (int ch = 0; ch < 3; ++ch)
        worst = std::max(worst, std::abs(int(px[ch]) - code(base[ch] * e)));
      (e > 0.05 ? lit_pixels : dark_pixels) += 1;
    }
  }
  CHECK(worst <= 1);
  CHECK(lit_pixels > 1000);
  CHECK(dark_pixels > 1000);  // beyond the range and outside the cone
}

namespace {

/// Sphere, cube and a double-sided open quad under every light type, each model once.
Scene lit_test_scene() {
  Scene scene = camera_scene(120, 80);
  auto sphere = covrast::test::uv_sphere(24, 48);
  covrast::analyze_mesh_topology(*sphere);
  covrast::test::add_instance(scene, sphere, glm::vec3(0.7f, 0.4f, 0.2f));
  scene.meshes[0].materials = {Material{}};  // pbr
  scene.meshes[0].materials[0].metallic = 0.3f;
  scene.meshes[0].materials[0].roughness = 0.4f;
  scene.meshes[0].corner_normals =
      std::make_shared<const std::vector<glm::vec3>>(covrast::smooth_corner_normals(*sphere));
  covrast::test::add_instance(scene, cube(), glm::vec3(0.2f, 0.6f, 0.3f),
                              covrast::ColorSource::PerTriangle);
  scene.meshes[1].model = glm::translate(glm::dmat4(1.0), glm::dvec3(1.3, -0.3, 0.0));
  scene.meshes[1].materials = {Material{}};
  scene.meshes[1].materials[0].model = ShadingModel::BlinnPhong;
  scene.meshes[1].materials[0].emissive_linear = glm::vec3(0.05f, 0.0f, 0.0f);
  // A quad cut by the near plane (clipped triangles) seen partly from behind.
  auto quad = std::make_shared<covrast::MeshData>();
  quad->positions = {{-2, -1, -1}, {-1, -1, 3}, {-1, 1, 3}, {-2, 1, -1}};
  quad->indices = {0, 1, 2, 0, 2, 3};
  covrast::test::add_instance(scene, quad, glm::vec3(0.9f));
  scene.meshes[2].materials = {lambert()};
  scene.lit = true;
  Light spot = spot_light({1.5, 2.0, 1.0}, {-1.0, -2.0, -1.0}, 10.0, 30.0, 8.0);
  spot.color_linear = {0.4f, 0.6f, 1.0f};
  scene.lights = {directional({0.3, -1.0, -0.5}, 2.0), point_light({-1.0, 1.5, 2.0}, 4.0, 6.0),
                  spot, ambient(0.05)};
  return scene;
}

}  // namespace

TEST_CASE("lit images are byte-identical across thread counts and tile sizes",
          "[shading][threads]") {
  const Scene scene = lit_test_scene();
  for (const char* mode : {"coverage", "msaa:4", "aliased", "ssaa:3", "coverage-blend"}) {
    INFO("mode " << mode);
    const covrast::RenderResult a =
        covrast::test::expect_same_bytes_for_every_split(scene, mode, {{2, 8}, {2, 256}, {1, 24}});
    CHECK(a.stats.triangles_clipped > 0);
  }
}

TEST_CASE("lit coverage is close to the lit reference", "[shading]") {
  Scene scene = lit_test_scene();
  scene.width = 60;
  scene.height = 40;
  const covrast::Image ref = render(scene, "reference").color;
  const covrast::Image cov = render(scene, "coverage").color;
  // Shading once per fragment at the clamped pixel centre differs from the mean over the
  // pixel only where the lighting bends within a pixel (highlights, silhouettes).
  double sum2 = 0;
  int worst = 0;
  for (std::size_t i = 0; i < ref.rgb.size(); ++i) {
    const int d = std::abs(int(ref.rgb[i]) - int(cov.rgb[i]));
    worst = std::max(worst, d);
    sum2 += double(d) * d;
  }
  // Measured: RMSE 0.37, largest 3 (8-bit units).
  CHECK(std::sqrt(sum2 / double(ref.rgb.size())) < 0.75);
  CHECK(worst <= 6);
}

TEST_CASE("a scene without lights renders exactly as unlit", "[shading]") {
  Scene scene = lit_test_scene();
  scene.lit = false;
  const covrast::Image unlit = render(scene, "coverage").color;
  // The same scene with every material unlit, lights given: the unlit path, bit for bit.
  Scene all_unlit = lit_test_scene();
  for (auto& m : all_unlit.meshes) m.materials[0].model = ShadingModel::Unlit;
  CHECK(render(all_unlit, "coverage").color.rgb == unlit.rgb);
}

namespace {

class Dir : public covrast::test::TempDir {
 public:
  Dir() : covrast::test::TempDir("covrast-test-shading") {}
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(path() / name, std::ios::binary) << text;
    return path() / name;
  }
};

json base_scene() {
  return json::parse(R"({
    "width": 48, "height": 32,
    "camera": {"eye": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0],
               "fovy_deg": 45.0, "near": 0.5, "far": 10.0},
    "lights": [{"type": "directional", "direction": [0, 0, -1]}],
    "meshes": [{"obj": "quad.obj"}]
  })");
}

/// A unit quad in z = 0 facing +z whose vn all point (0, 0.6, 0.8): not the face normal.
const char* const kQuadObj =
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
    "vn 0 0.6 0.8\n"
    "f 1//1 2//-1 3//1 4//1\n";

std::string load_error(const Dir& dir, const json& scene) {
  const fs::path file = dir.write("scene.json", scene.dump());
  try {
    covrast::load_scene(file);
  } catch (const covrast::InputError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("bad values of lights, material and normals are errors naming the key", "[shading]") {
  Dir dir;
  dir.write("quad.obj", kQuadObj);
  dir.write("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  using P = json::json_pointer;
  struct Case {
    std::string pointer;
    json value;
    std::string key;
  };
  const std::vector<Case> cases = {
      {"/lights", json::object(), "lights: expected an array"},
      {"/lights/0", 3, "lights[0]: expected an object"},
      {"/lights/0/type", "laser", "lights[0].type"},
      {"/lights/0/direction", {0, 0, 0}, "lights[0].direction: must not be zero"},
      {"/lights/0/direction", {0, 1}, "lights[0].direction"},
      {"/lights/0/color", {1, -1, 1}, "lights[0].color[1]"},
      {"/lights/0/color", "white", "lights[0].color"},
      {"/lights/0/intensity", -2, "lights[0].intensity"},
      {"/lights/0/intensity", "bright", "lights[0].intensity"},
      {"/lights/1", {{"type", "point"}}, "lights[1].position: missing"},
      {"/lights/1", {{"type", "point"}, {"position", {0, 0, 1}}, {"range", 0}}, "lights[1].range"},
      {"/lights/1", {{"type", "spot"}, {"position", {0, 0, 1}}}, "lights[1].direction: missing"},
      {"/lights/1",
       {{"type", "spot"},
        {"position", {0, 0, 1}},
        {"direction", {0, 0, -1}},
        {"inner_cone_deg", 30},
        {"outer_cone_deg", 20}},
       "lights[1].outer_cone_deg"},
      {"/lights/1",
       {{"type", "spot"},
        {"position", {0, 0, 1}},
        {"direction", {0, 0, -1}},
        {"outer_cone_deg", 120}},
       "lights[1].outer_cone_deg"},
      {"/lights/1", {{"type", "ambient"}, {"intensity", -1}}, "lights[1].intensity"},
      {"/meshes/0/material", "shiny", "meshes[0].material: expected an object"},
      {"/meshes/0/material", {{"model", "toon"}}, "meshes[0].material.model"},
      {"/meshes/0/material", {{"metallic", 2}}, "meshes[0].material.metallic"},
      {"/meshes/0/material", {{"roughness", -0.1}}, "meshes[0].material.roughness"},
      {"/meshes/0/material", {{"emissive", {2, 0, 0}}}, "meshes[0].material.emissive[0]"},
      {"/meshes/0/material", {{"shininess", 0}}, "meshes[0].material.shininess"},
      {"/meshes/0/material", {{"specular", 1.5}}, "meshes[0].material.specular"},
      {"/meshes/0/material", {{"double_sided", "yes"}}, "meshes[0].material.double_sided"},
      {"/meshes/0/material", {{"ior", 0.5}}, "meshes[0].material.ior: expected 0 or a number >= 1"},
      {"/meshes/0/material", {{"specular_factor", 2}}, "meshes[0].material.specular_factor"},
      {"/meshes/0/material", {{"clearcoat", "full"}}, "meshes[0].material.clearcoat"},
      {"/meshes/0/material",
       {{"clearcoat_roughness", -1}},
       "meshes[0].material.clearcoat_roughness"},
      {"/meshes/0/material", {{"base_color", {1, 0}}}, "meshes[0].material.base_color"},
      {"/meshes/0/normals", "bumpy", "meshes[0].normals"},
      {"/meshes/0/normals", 1, "meshes[0].normals"},
  };
  for (const Case& c : cases) {
    json scene = base_scene();
    scene[P(c.pointer)] = c.value;
    INFO(c.pointer << " = " << c.value.dump());
    CHECK_THAT(load_error(dir, scene), Contains("scene.json: " + c.key));
  }
  json both = base_scene();
  both["meshes"][0]["color"] = {1, 1, 1};
  both["meshes"][0]["material"] = {{"base_color", {1, 0, 0}}};
  CHECK_THAT(load_error(dir, both), Contains("meshes[0].material.base_color: give either"));
  json no_normals = base_scene();
  no_normals["meshes"][0] = {{"obj", "plain.obj"}, {"normals", "file"}};
  CHECK_THAT(load_error(dir, no_normals), Contains("meshes[0].normals: \"file\" but"));
}

TEST_CASE("the command line exits 2 on a bad light", "[shading][cli]") {
  Dir dir;
  dir.write("quad.obj", kQuadObj);
  json scene = base_scene();
  scene["lights"][0]["type"] = "laser";
  dir.write("scene.json", scene.dump());
  const std::string command = std::string("'") + COVRAST_CLI_PATH + "' render '" +
                              (dir / "scene.json").string() + "' -o '" +
                              (dir / "out.png").string() + "' 2>/dev/null";
  const int status = std::system(command.c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 2);
  CHECK(!fs::exists(dir / "out.png"));
}

TEST_CASE("OBJ vn become corner normals and light the surface", "[shading][scene]") {
  Dir dir;
  dir.write("quad.obj", kQuadObj);
  json scene_json = base_scene();
  // Light travelling down -y: the face normal (0, 0, 1) gets none of it, the vn 0.6.
  scene_json["lights"] = {{{"type", "directional"}, {"direction", {0, -1, 0}}}};
  scene_json["meshes"][0]["color"] = {1, 1, 1};
  const Scene scene = covrast::load_scene(dir.write("scene.json", scene_json.dump()));
  const covrast::MeshData& mesh = *scene.meshes[0].mesh;
  REQUIRE(mesh.corner_normals.size() == 6);  // the quad's fan: two triangles
  for (const glm::vec3& n : mesh.corner_normals) CHECK(n == glm::vec3(0.0f, 0.6f, 0.8f));
  CHECK(scene.meshes[0].normals == covrast::NormalSource::File);
  CHECK(scene.meshes[0].materials[0].model == ShadingModel::Lambert);
  const covrast::Image lit = render(scene, "coverage").color;
  const std::uint8_t* centre = pixel(lit, 24, 16);
  CHECK(int(centre[0]) == code(0.6f));
  // "flat" ignores the vn: no light reaches the face.
  scene_json["meshes"][0]["normals"] = "flat";
  const Scene flat = covrast::load_scene(dir.write("scene.json", scene_json.dump()));
  CHECK(int(pixel(render(flat, "coverage").color, 24, 16)[0]) == 0);
  // A reference to a missing normal is a warning; that face uses its face normal.
  dir.write("quad.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nf 1//3 2//3 3//3\n");
  const Scene missing = covrast::load_scene(dir.write("scene.json", scene_json.dump()));
  REQUIRE(missing.warnings.size() == 1);
  CHECK_THAT(missing.warnings[0], Contains("3 face corners reference normals that do not exist"));
}

namespace {

void put_f32(std::string& out, float value) {
  char bytes[4];
  std::memcpy(bytes, &value, 4);
  out.append(bytes, 4);
}

std::string base64(const std::string& data) {
  static const char* const kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < data.size(); i += 3) {
    std::uint32_t n = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      n = n << 8 | (i + k < data.size() ? std::uint8_t(data[i + k]) : 0u);
    }
    const std::size_t chars = std::min<std::size_t>(4, (data.size() - i) * 4 / 3 + 1);
    for (std::size_t k = 0; k < 4; ++k)
      out += k < chars ? kAlphabet[(n >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

/// A glTF triangle in z = 0 (facing +z) with NORMAL (0, 0.6, 0.8) and a material, node 0
/// mirrored by scale (1, 1, -1) in `mirrored`.
json gltf_triangle(bool mirrored) {
  std::string buffer;
  for (const float v : {-1.0f, -1.0f, 0.0f, 1.0f, -1.0f, 0.0f, 0.0f, 1.0f, 0.0f})
    put_f32(buffer, v);
  for (int k = 0; k < 3; ++k) {
    for (const float v : {0.0f, 0.6f, 0.8f}) put_f32(buffer, v);
  }
  json node = {{"mesh", 0}};
  if (mirrored) node["scale"] = {1, 1, -1};
  return {
      {"asset", {{"version", "2.0"}}},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {node}},
      {"meshes",
       {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"material", 0}}}}}}},
      {"materials",
       {{{"pbrMetallicRoughness",
          {{"baseColorFactor", {0.5, 1, 1, 1}},
           {"metallicFactor", 0.25},
           {"roughnessFactor", 0.75}}},
         {"emissiveFactor", {0.5, 0.25, 0}},
         {"doubleSided", true},
         {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}}},
        {{"extensions", {{"KHR_materials_unlit", json::object()}}}}}},
      {"buffers",
       {{{"byteLength", buffer.size()},
         {"uri", "data:application/octet-stream;base64," + base64(buffer)}}}},
      {"bufferViews",
       {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
        {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 36}}}},
      {"accessors",
       {{{"bufferView", 0},
         {"componentType", 5126},
         {"count", 3},
         {"type", "VEC3"},
         {"min", {-1, -1, 0}},
         {"max", {1, 1, 0}}},
        {{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}}}},
  };
}

}  // namespace

TEST_CASE("glTF NORMAL and materials are read and shade the surface", "[shading][scene]") {
  Dir dir;
  dir.write("tri.gltf", gltf_triangle(false).dump());
  json scene_json = base_scene();
  scene_json["meshes"][0] = {{"gltf", "tri.gltf"}};
  const Scene scene = covrast::load_scene(dir.write("scene.json", scene_json.dump()));
  const covrast::MeshData& mesh = *scene.meshes[0].mesh;
  REQUIRE(mesh.corner_normals.size() == 3);
  CHECK(mesh.corner_normals[1] == glm::vec3(0.0f, 0.6f, 0.8f));
  REQUIRE(mesh.materials.size() == 3);  // two of the file, glTF's default
  REQUIRE(mesh.triangle_materials == std::vector<std::uint32_t>{0});
  const Material& m = scene.meshes[0].materials[0];
  CHECK(m.model == ShadingModel::Pbr);
  CHECK(m.metallic == 0.25f);
  CHECK(m.roughness == 0.75f);
  CHECK(m.emissive_linear == glm::vec3(2.0f, 1.0f, 0.0f));
  CHECK(m.double_sided);
  CHECK(mesh.materials[1].model == ShadingModel::Unlit);
  CHECK(mesh.materials[2].metallic == 1.0f);
  CHECK_FALSE(mesh.materials[2].double_sided);
  // Overridden to lambert without emission, lit from +y: base 0.5 x n . l = 0.6 in red.
  scene_json["lights"] = {{{"type", "directional"}, {"direction", {0, -1, 0}}}};
  scene_json["meshes"][0]["material"] = {{"model", "lambert"}, {"emissive", {0, 0, 0}}};
  const Scene lambert_scene = covrast::load_scene(dir.write("scene.json", scene_json.dump()));
  CHECK(lambert_scene.meshes[0].materials[0].metallic == 0.25f);  // kept from the file
  const covrast::Image image = render(lambert_scene, "coverage").color;
  CHECK(int(pixel(image, 24, 16)[0]) == code(0.5f * 0.6f));
  CHECK(int(pixel(image, 24, 16)[1]) == code(1.0f * 0.6f));
  // A mirroring node keeps counter-clockwise = front: its two corners swap.
  dir.write("mirrored.gltf", gltf_triangle(true).dump());
  const auto mirrored = covrast::load_mesh(dir / "mirrored.gltf");
  CHECK(mirrored->indices == std::vector<std::uint32_t>{0, 2, 1});
  CHECK(mirrored->corner_normals[0] == glm::vec3(0.0f, 0.6f, -0.8f));
}
