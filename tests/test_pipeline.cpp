// Pipeline tests through the public Renderer API: homogeneous and guard-band clipping,
// watertightness and the top-left fill rule, order independence, the equal-depth rule,
// byte-identical output for every thread count and tile size, and the bundled scenes.
//
// Most scenes are built in code with pixel_scene(), whose camera maps the world plane z = 0
// to the image one unit to one pixel: eye at (0, 0, h/2) looking down -z with fovy = 90 deg,
// so x_px = x + w/2 and y_px = h/2 - y. The references are computed here, independently of
// src/: a Sutherland-Hodgman clip in homogeneous space, and a brute-force top-left rule on the
// 24.8 fixed-point vertices.
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <glm/gtc/matrix_transform.hpp>
#include "test_meshes.hpp"
#include "test_splits.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

using namespace covrast;

namespace {

constexpr int kSubpixel = 256;  // 24.8 fixed point, as the renderer snaps

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb&) const = default;
};

Rgb pixel_at(const Image& image, int x, int y) {
  const std::uint8_t* p = image.pixel(x, y);
  return {p[0], p[1], p[2]};
}

std::string describe(Rgb c) {
  std::ostringstream s;
  s << "(" << int(c.r) << ", " << int(c.g) << ", " << int(c.b) << ")";
  return s.str();
}

using covrast::test::pixel_scene;

/// World point on z = 0 of pixel_scene() for pixel coordinates given in 24.8 fixed point.
glm::vec3 world_of_fx8(const Scene& scene, std::int64_t x_fx8, std::int64_t y_fx8) {
  return glm::vec3(float(double(x_fx8) / kSubpixel - scene.width / 2.0),
                   float(scene.height / 2.0 - double(y_fx8) / kSubpixel), 0.0f);
}

std::shared_ptr<MeshData> make_mesh(std::vector<glm::vec3> positions,
                                    std::vector<std::uint32_t> indices,
                                    std::vector<glm::vec3> colors = {}) {
  auto mesh = std::make_shared<MeshData>();
  mesh->source = "test_pipeline";
  mesh->positions = std::move(positions);
  mesh->indices = std::move(indices);
  mesh->colors_linear = std::move(colors);
  return mesh;
}

void add_instance(Scene& scene, std::shared_ptr<const MeshData> mesh, ColorSource source,
                  glm::vec3 color_linear = glm::vec3(1.0f)) {
  MeshInstance instance;
  instance.mesh = std::move(mesh);
  instance.color_source = source;
  instance.color_linear = color_linear;
  scene.meshes.push_back(std::move(instance));
}

RenderResult render_with(const Scene& scene, const char* mode, int threads = 0, int tile = 64,
                         bool want_depth = false) {
  RenderOptions options;
  options.mode = parse_render_mode(mode);
  options.threads = threads;
  options.tile = tile;
  options.want_depth = want_depth;
  return render(scene, options);
}

/// Number of pixels that differ, and the first one, for INFO.
struct ImageDiff {
  std::size_t count = 0;
  std::string first;
};

ImageDiff diff_images(const Image& a, const Image& b) {
  ImageDiff d;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      if (pixel_at(a, x, y) == pixel_at(b, x, y)) continue;
      if (d.count++ == 0) {
        d.first = "first difference at (" + std::to_string(x) + ", " + std::to_string(y) +
                  "): " + describe(pixel_at(a, x, y)) + " vs " + describe(pixel_at(b, x, y));
      }
    }
  }
  return d;
}

// ---- Reference clipping: world -> clip space -> Sutherland-Hodgman -> pixels ----

glm::dmat4 view_projection(const Scene& scene) {
  const Camera& c = scene.camera;
  return glm::perspective(glm::radians(c.fovy_deg), double(scene.width) / scene.height, c.near,
                          c.far) *
         glm::lookAt(c.eye, c.target, c.up);
}

std::vector<glm::dvec4> clip_against(const std::vector<glm::dvec4>& poly, glm::dvec4 plane) {
  std::vector<glm::dvec4> out;
  for (std::size_t k = 0; k < poly.size(); ++k) {
    const glm::dvec4& a = poly[k];
    const glm::dvec4& b = poly[(k + 1) % poly.size()];
    double da = glm::dot(plane, a), db = glm::dot(plane, b);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) out.push_back(a + (da / (da - db)) * (b - a));
  }
  return out;
}

/// The exact screen polygon [pixels] of a convex world polygon: clipped against the near and
/// far planes (z = -w and z = w) in homogeneous space, then projected. Empty when invisible.
std::vector<glm::dvec2> reference_polygon(const Scene& scene, const std::vector<glm::dvec3>& v) {
  glm::dmat4 vp = view_projection(scene);
  std::vector<glm::dvec4> poly;
  for (const glm::dvec3& p : v) poly.push_back(vp * glm::dvec4(p, 1.0));
  poly = clip_against(poly, glm::dvec4(0, 0, 1, 1));
  poly = clip_against(poly, glm::dvec4(0, 0, -1, 1));
  std::vector<glm::dvec2> screen;
  if (poly.size() < 3) return screen;
  for (const glm::dvec4& c : poly) {
    screen.emplace_back((c.x / c.w + 1.0) * 0.5 * scene.width,
                        (1.0 - c.y / c.w) * 0.5 * scene.height);
  }
  return screen;
}

std::vector<glm::dvec2> reference_polygon(const Scene& scene, const std::array<glm::dvec3, 3>& v) {
  return reference_polygon(scene, std::vector<glm::dvec3>(v.begin(), v.end()));
}

double cross2(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }

/// Distance from p to the segment ab.
double segment_distance(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
  glm::dvec2 d = b - a;
  double len2 = glm::dot(d, d);
  double t = len2 > 0 ? std::clamp(glm::dot(p - a, d) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * d));
}

/// Inside a convex polygon of either winding (strictly, boundary excluded).
bool inside_convex(const std::vector<glm::dvec2>& poly, glm::dvec2 p) {
  bool pos = false, neg = false;
  for (std::size_t k = 0; k < poly.size(); ++k) {
    double c = cross2(poly[(k + 1) % poly.size()] - poly[k], p - poly[k]);
    pos |= c > 0;
    neg |= c < 0;
    if (c == 0) return false;
  }
  return pos != neg;
}

/// Pixel-by-pixel check of a rendered single flat triangle against its exact polygon.
/// Pixels whose centre is within `eps_px` of the polygon's boundary are not judged: snapping
/// to 1/256 pixel may legitimately move an edge across them.
struct PolygonCheck {
  std::size_t inside = 0;
  std::size_t outside = 0;
  std::size_t undecided = 0;
  std::size_t wrong = 0;
  std::string first_wrong;
};

PolygonCheck check_polygon(const Image& image, const std::vector<glm::dvec2>& poly, Rgb fill,
                           Rgb background, double eps_px) {
  PolygonCheck r;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      glm::dvec2 c(x + 0.5, y + 0.5);
      double distance = 1e300;
      for (std::size_t k = 0; k < poly.size(); ++k) {
        distance = std::min(distance, segment_distance(c, poly[k], poly[(k + 1) % poly.size()]));
      }
      if (distance < eps_px) {
        ++r.undecided;
        continue;
      }
      bool in = poly.size() >= 3 && inside_convex(poly, c);
      (in ? r.inside : r.outside)++;
      Rgb expected = in ? fill : background;
      Rgb got = pixel_at(image, x, y);
      if (got != expected && r.wrong++ == 0) {
        r.first_wrong = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is " +
                        describe(got) + ", expected " + describe(expected);
      }
    }
  }
  return r;
}

// ---- Reference fill rule on 24.8 vertices ----

struct Fx8 {
  std::int64_t x, y;
};

std::int64_t cross_fx8(Fx8 o, Fx8 a, Fx8 b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/// Does the triangle own the point p [fx8] under the top-left rule? Derived from the
/// geometry only: p on an edge belongs to the triangle iff the edge is a top edge
/// (horizontal, interior below it, y down) or a left edge (interior to its right).
bool owns_top_left(const std::array<Fx8, 3>& v, Fx8 p) {
  if (cross_fx8(v[0], v[1], v[2]) == 0) return false;
  for (int k = 0; k < 3; ++k) {
    Fx8 a = v[k], b = v[(k + 1) % 3], opposite = v[(k + 2) % 3];
    std::int64_t side = cross_fx8(a, b, p);
    std::int64_t interior = cross_fx8(a, b, opposite);
    if (side == 0) {
      // Normal of ab pointing into the triangle.
      std::int64_t nx = -(b.y - a.y), ny = b.x - a.x;
      if (nx * (opposite.x - a.x) + ny * (opposite.y - a.y) < 0) {
        nx = -nx;
        ny = -ny;
      }
      bool top = nx == 0 && ny > 0;
      bool left = nx > 0;
      if (!top && !left) return false;
    } else if ((side > 0) != (interior > 0)) {
      return false;
    }
  }
  return true;
}

/// What the renderer's front end computes for a world point: x_px = (x/w + 1) w_px / 2,
/// rounded to 1/256 pixel (mirrors the viewport transform; identity model matrix).
Fx8 snap_world(const Scene& scene, glm::vec3 p) {
  glm::dvec4 c = view_projection(scene) * glm::dvec4(glm::dvec3(p), 1.0);
  double inv_w = 1.0 / c.w;
  double x_px = (c.x * inv_w + 1.0) * 0.5 * scene.width;
  double y_px = (1.0 - c.y * inv_w) * 0.5 * scene.height;
  return {std::llrint(x_px * kSubpixel), std::llrint(y_px * kSubpixel)};
}

/// A tessellation given by its vertices in 24.8 pixel coordinates and 3 indices per triangle.
struct Tessellation {
  std::vector<Fx8> vertices;
  std::vector<std::uint32_t> indices;
  std::size_t triangle_count() const { return indices.size() / 3; }
};

/// For each pixel: how many triangles own its centre, and the last one that does.
struct Ownership {
  std::vector<int> count;
  std::vector<int> owner;
};

Ownership reference_ownership(const Tessellation& t, int width_px, int height_px) {
  Ownership o;
  o.count.assign(std::size_t(width_px) * height_px, 0);
  o.owner.assign(std::size_t(width_px) * height_px, -1);
  for (std::size_t tri = 0; tri < t.triangle_count(); ++tri) {
    std::array<Fx8, 3> v = {t.vertices[t.indices[3 * tri]], t.vertices[t.indices[3 * tri + 1]],
                            t.vertices[t.indices[3 * tri + 2]]};
    std::int64_t x0 = std::min({v[0].x, v[1].x, v[2].x}) / kSubpixel - 1;
    std::int64_t x1 = std::max({v[0].x, v[1].x, v[2].x}) / kSubpixel + 1;
    std::int64_t y0 = std::min({v[0].y, v[1].y, v[2].y}) / kSubpixel - 1;
    std::int64_t y1 = std::max({v[0].y, v[1].y, v[2].y}) / kSubpixel + 1;
    for (std::int64_t y = std::max<std::int64_t>(y0, 0);
         y <= std::min<std::int64_t>(y1, height_px - 1); ++y) {
      for (std::int64_t x = std::max<std::int64_t>(x0, 0);
           x <= std::min<std::int64_t>(x1, width_px - 1); ++x) {
        if (owns_top_left(v, {x * kSubpixel + kSubpixel / 2, y * kSubpixel + kSubpixel / 2})) {
          std::size_t i = std::size_t(y) * width_px + std::size_t(x);
          ++o.count[i];
          o.owner[i] = int(tri);
        }
      }
    }
  }
  return o;
}

Rgb per_triangle_rgb(std::uint32_t index) {
  std::uint32_t h = lowbias32(index);
  return {std::uint8_t(h & 255), std::uint8_t(h >> 8 & 255), std::uint8_t(h >> 16 & 255)};
}

/// A rows x cols grid over the pixel rectangle [x0, x1] x [y0, y1] (24.8), each cell split
/// along an alternating diagonal, interior vertices moved by up to `jitter` of a cell. The
/// triangles keep their orientation (a valid tessellation) only for jitter < 0.25: at 0.25,
/// a = (.25, .25), d = (-.25, .75), b = (.75, -.25) (cell units) are collinear.
Tessellation make_grid(Fx8 lo, Fx8 hi, int cols, int rows, double jitter, std::uint32_t seed) {
  Tessellation t;
  std::mt19937 rng(seed);
  std::int64_t cell_w = (hi.x - lo.x) / cols, cell_h = (hi.y - lo.y) / rows;
  std::uniform_int_distribution<std::int64_t> jx(-std::int64_t(jitter * cell_w),
                                                 std::int64_t(jitter * cell_w));
  std::uniform_int_distribution<std::int64_t> jy(-std::int64_t(jitter * cell_h),
                                                 std::int64_t(jitter * cell_h));
  for (int r = 0; r <= rows; ++r) {
    for (int c = 0; c <= cols; ++c) {
      Fx8 p{c == cols ? hi.x : lo.x + c * cell_w, r == rows ? hi.y : lo.y + r * cell_h};
      if (c > 0 && c < cols && r > 0 && r < rows) {
        p.x += jx(rng);
        p.y += jy(rng);
      }
      t.vertices.push_back(p);
    }
  }
  auto at = [&](int r, int c) { return std::uint32_t(r * (cols + 1) + c); };
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      std::uint32_t a = at(r, c), b = at(r, c + 1), d = at(r + 1, c), e = at(r + 1, c + 1);
      if ((r + c) % 2 == 0) {
        t.indices.insert(t.indices.end(), {a, d, e, a, e, b});
      } else {
        t.indices.insert(t.indices.end(), {a, d, b, b, d, e});
      }
    }
  }
  return t;
}

/// A fan around `centre` over `spokes` rim points on a circle of radius_px, closed.
Tessellation make_fan(Fx8 centre, double radius_px, int spokes, bool rim_on_pixel_centres) {
  Tessellation t;
  t.vertices.push_back(centre);
  for (int k = 0; k < spokes; ++k) {
    double a = 2.0 * 3.14159265358979323846 * k / spokes;
    double x = centre.x / double(kSubpixel) + radius_px * std::cos(a);
    double y = centre.y / double(kSubpixel) - radius_px * std::sin(a);
    if (rim_on_pixel_centres) {
      t.vertices.push_back({std::int64_t(std::floor(x)) * kSubpixel + kSubpixel / 2,
                            std::int64_t(std::floor(y)) * kSubpixel + kSubpixel / 2});
    } else {
      t.vertices.push_back({std::llrint(x * kSubpixel), std::llrint(y * kSubpixel)});
    }
  }
  for (int k = 0; k < spokes; ++k) {
    t.indices.insert(t.indices.end(),
                     {0u, std::uint32_t(1 + k), std::uint32_t(1 + (k + 1) % spokes)});
  }
  return t;
}

/// The tessellation as a mesh of pixel_scene(); checks that the front end's snapping of
/// every vertex is the intended 24.8 position, so the reference sees the same vertices.
std::shared_ptr<MeshData> tessellation_mesh(const Scene& scene, const Tessellation& t) {
  std::vector<glm::vec3> positions;
  for (const Fx8& v : t.vertices) {
    positions.push_back(world_of_fx8(scene, v.x, v.y));
    Fx8 s = snap_world(scene, positions.back());
    REQUIRE(s.x == v.x);
    REQUIRE(s.y == v.y);
  }
  return make_mesh(std::move(positions), t.indices);
}

/// The same triangles as a soup (own vertices each) with a distinct flat vertex colour per
/// triangle, optionally in reverse order: colours travel with the triangles.
std::shared_ptr<MeshData> colored_soup(const Scene& scene, const Tessellation& t, bool reversed) {
  std::vector<glm::vec3> positions, colors;
  std::vector<std::uint32_t> indices;
  std::size_t n = t.triangle_count();
  for (std::size_t k = 0; k < n; ++k) {
    std::size_t tri = reversed ? n - 1 - k : k;
    std::uint32_t hash = lowbias32(std::uint32_t(tri) + 1000u);
    glm::vec3 color(float(hash & 255) / 255.0f, float(hash >> 8 & 255) / 255.0f,
                    float(hash >> 16 & 255) / 255.0f);
    for (int j = 0; j < 3; ++j) {
      const Fx8& v = t.vertices[t.indices[3 * tri + j]];
      indices.push_back(std::uint32_t(positions.size()));
      positions.push_back(world_of_fx8(scene, v.x, v.y));
      colors.push_back(color);
    }
  }
  return make_mesh(std::move(positions), std::move(indices), std::move(colors));
}

/// Every check of section 2 on one tessellation that covers a region whose interior is
/// given by `inside_region` (pixel centre, in pixels).
template <class InsideRegion>
void check_watertight(const Tessellation& t, InsideRegion inside_region) {
  const int w = 160, h = 96;
  Scene scene = pixel_scene(w, h);
  auto mesh = tessellation_mesh(scene, t);
  Ownership ref = reference_ownership(t, w, h);

  // The reference itself: a tessellation owns each interior pixel centre exactly once.
  std::size_t interior = 0, double_owned = 0, holes = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      int c = ref.count[std::size_t(y) * w + x];
      double_owned += c > 1;
      if (inside_region(glm::dvec2(x + 0.5, y + 0.5))) {
        ++interior;
        holes += c == 0;
      }
    }
  }
  REQUIRE(interior > 1000);
  REQUIRE(double_owned == 0);
  REQUIRE(holes == 0);

  // (i) One colour on a contrasting background: no cracks, no overdraw outside.
  Scene uniform = scene;
  add_instance(uniform, mesh, ColorSource::Uniform, glm::vec3(1.0f));
  Image white = render_with(uniform, "aliased").color;
  std::size_t wrong_uniform = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      Rgb expected = ref.count[std::size_t(y) * w + x] ? Rgb{255, 255, 255} : Rgb{0, 0, 0};
      wrong_uniform += pixel_at(white, x, y) != expected;
    }
  }
  CHECK(wrong_uniform == 0);

  // (ii) Per-triangle colours against the brute-force top-left rule, pixel by pixel.
  Scene per_triangle = scene;
  add_instance(per_triangle, mesh, ColorSource::PerTriangle);
  Image ids = render_with(per_triangle, "aliased").color;
  std::size_t wrong_owner = 0;
  std::string first_wrong;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      int owner = ref.owner[std::size_t(y) * w + x];
      Rgb expected = owner < 0 ? Rgb{0, 0, 0} : per_triangle_rgb(std::uint32_t(owner));
      Rgb got = pixel_at(ids, x, y);
      if (got != expected && wrong_owner++ == 0) {
        first_wrong = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is " +
                      describe(got) + ", expected " + describe(expected) + " (triangle " +
                      std::to_string(owner) + ")";
      }
    }
  }
  INFO(first_wrong);
  CHECK(wrong_owner == 0);

  // (iii) Draw order reversed: a pixel owned twice would change colour.
  Scene forward = scene, backward = scene;
  add_instance(forward, colored_soup(scene, t, false), ColorSource::Vertex);
  add_instance(backward, colored_soup(scene, t, true), ColorSource::Vertex);
  ImageDiff d =
      diff_images(render_with(forward, "aliased").color, render_with(backward, "aliased").color);
  INFO(d.first);
  CHECK(d.count == 0);
}

}  // namespace

// ---------------------------------------------------------------------------------------
// 1. Clipping
// ---------------------------------------------------------------------------------------

TEST_CASE("near and far plane clipping matches a homogeneous-space reference", "[pipeline]") {
  Scene base;
  base.width = 160;
  base.height = 90;
  base.background_linear = glm::vec3(0.0f);
  base.camera.eye = glm::dvec3(0.0);
  base.camera.target = glm::dvec3(0.0, 0.0, -1.0);
  base.camera.up = glm::dvec3(0.0, 1.0, 0.0);
  base.camera.fovy_deg = 60.0;
  base.camera.near = 0.5;
  base.camera.far = 20.0;

  struct Case {
    const char* name;
    std::array<glm::dvec3, 3> v;
  };
  const Case cases[] = {
      {"one vertex behind the eye (w < 0)",
       {{{0.4, -0.3, 2.0}, {-4.0, -1.5, -6.0}, {3.0, 2.0, -9.0}}}},
      {"two vertices behind the eye", {{{0.2, 0.1, -5.0}, {-3.0, -1.0, 3.0}, {3.0, -2.0, 1.5}}}},
      {"a vertex in the eye plane (w = 0)",
       {{{1.5, -1.2, 0.0}, {-3.0, -1.0, -6.0}, {3.0, -1.5, -5.0}}}},
      {"floor crossing the near plane",
       {{{0.0, -0.5, 3.0}, {6.0, -0.5, -12.0}, {-6.0, -0.5, -12.0}}}},
      {"crossing the far plane", {{{-6.0, -3.0, -8.0}, {7.0, -2.0, -30.0}, {0.0, 4.0, -14.0}}}},
      {"crossing near and far", {{{0.3, -0.4, 1.0}, {-9.0, -3.0, -40.0}, {8.0, 5.0, -35.0}}}},
  };
  for (const Case& c : cases) {
    SECTION(c.name) {
      Scene scene = base;
      std::vector<glm::vec3> positions;
      for (const glm::dvec3& p : c.v) positions.emplace_back(p);
      add_instance(scene, make_mesh(positions, {0, 1, 2}), ColorSource::Uniform,
                   glm::vec3(1.0f, 0.0f, 0.0f));
      RenderResult result = render_with(scene, "aliased");
      CHECK(result.stats.triangles_in == 1);
      CHECK(result.stats.triangles_clipped == 1);

      std::vector<glm::dvec2> poly = reference_polygon(scene, c.v);
      PolygonCheck check = check_polygon(result.color, poly, {255, 0, 0}, {0, 0, 0}, 1.0 / 128);
      INFO(check.first_wrong);
      CHECK(check.wrong == 0);
      CHECK(check.inside > 300);
      CHECK(check.outside > 300);
      CHECK(check.undecided < 40);
    }
  }

  SECTION("a triangle wholly behind the eye is culled and draws nothing") {
    Scene scene = base;
    add_instance(scene, make_mesh({{-3, -1, 2}, {3, -1, 3}, {0, 2, 1}}, {0, 1, 2}),
                 ColorSource::Uniform);
    RenderResult result = render_with(scene, "aliased");
    CHECK(result.stats.triangles_culled == 1);
    CHECK(result.stats.triangles_setup == 0);
    CHECK(std::all_of(result.color.rgb.begin(), result.color.rgb.end(),
                      [](std::uint8_t v) { return v == 0; }));
  }
}

TEST_CASE("guard-band clipping: huge triangles render like moderate ones", "[pipeline]") {
  Scene base = pixel_scene(160, 90);  // z = 0: x_px = x + 80, y_px = 45 - y
  auto render_triangle = [&](std::array<glm::vec3, 3> v) {
    Scene scene = base;
    add_instance(scene, make_mesh({v[0], v[1], v[2]}, {0, 1, 2}), ColorSource::Uniform,
                 glm::vec3(0.0f, 1.0f, 0.0f));
    return render_with(scene, "aliased");
  };

  SECTION("axis-aligned wedge: bit-identical") {
    // Legs along +x and +y from (29.7, 65.7) px: only the legs are on screen.
    glm::vec3 corner(-50.3046875f, -20.703125f, 0.0f);
    RenderResult moderate =
        render_triangle({corner, corner + glm::vec3(400, 0, 0), corner + glm::vec3(0, 400, 0)});
    RenderResult huge =
        render_triangle({corner, corner + glm::vec3(4e6f, 0, 0), corner + glm::vec3(0, 4e6f, 0)});
    CHECK(moderate.stats.triangles_clipped == 0);
    CHECK(huge.stats.triangles_clipped == 1);
    ImageDiff d = diff_images(moderate.color, huge.color);
    INFO(d.first);
    CHECK(d.count == 0);
    // Columns 30.. and rows ..65 are covered: pixel centres x + 0.5 > 29.70, y + 0.5 < 65.70.
    std::size_t green = 0;
    for (int y = 0; y < 90; ++y) {
      for (int x = 0; x < 160; ++x) {
        bool in = x >= 30 && y <= 65;
        green += in;
        CHECK((pixel_at(huge.color, x, y) == (in ? Rgb{0, 255, 0} : Rgb{0, 0, 0})));
      }
    }
    CHECK(green == 130 * 66);
  }

  SECTION("oblique wedges and a screen-covering triangle") {
    struct Wedge {
      glm::dvec2 apex;  // world, z = 0
      double angle1_deg, angle2_deg;
    };
    const Wedge wedges[] = {{{-10.3, 7.1}, 20.0, 95.0},
                            {{33.2, -15.9}, 170.0, 250.0},
                            {{0.1, 0.2}, 300.0, 371.0},
                            {{-70.0, 40.0}, -80.0, 5.0}};
    for (const Wedge& w : wedges) {
      glm::dvec2 d1(std::cos(glm::radians(w.angle1_deg)), std::sin(glm::radians(w.angle1_deg)));
      glm::dvec2 d2(std::cos(glm::radians(w.angle2_deg)), std::sin(glm::radians(w.angle2_deg)));
      auto tri = [&](double reach) {
        std::array<glm::vec3, 3> v = {glm::vec3(glm::dvec3(w.apex, 0.0)),
                                      glm::vec3(glm::dvec3(w.apex + reach * d1, 0.0)),
                                      glm::vec3(glm::dvec3(w.apex + reach * d2, 0.0))};
        return v;
      };
      std::array<glm::vec3, 3> vm = tri(400.0), vh = tri(3e6);
      RenderResult moderate = render_triangle(vm);
      RenderResult huge = render_triangle(vh);
      CHECK(huge.stats.triangles_clipped == 1);
      std::array<glm::dvec3, 3> dv = {glm::dvec3(vh[0]), glm::dvec3(vh[1]), glm::dvec3(vh[2])};
      std::vector<glm::dvec2> poly = reference_polygon(base, dv);
      for (const RenderResult* r : {&moderate, &huge}) {
        PolygonCheck check = check_polygon(r->color, poly, {0, 255, 0}, {0, 0, 0}, 1.0 / 128);
        INFO("apex (" << w.apex.x << ", " << w.apex.y << "): " << check.first_wrong);
        CHECK(check.wrong == 0);
        CHECK(check.inside > 500);
        CHECK(check.undecided < 40);
      }
    }
    // All three vertices far outside, beyond the guard band on every side.
    RenderResult cover = render_triangle(
        {glm::vec3(-3e6f, -3e6f, 0), glm::vec3(3e6f, -3e6f, 0), glm::vec3(0, 3e6f, 0)});
    CHECK(cover.stats.triangles_clipped == 1);
    CHECK(std::all_of(cover.color.rgb.begin(), cover.color.rgb.end(),
                      [i = 0](std::uint8_t v) mutable { return v == (i++ % 3 == 1 ? 255 : 0); }));
  }
}

TEST_CASE("a tessellated floor crossing the near plane stays watertight", "[pipeline]") {
  // The camera of scenes/near_plane.json; a 12 x 15 floor at y = -0.5 from behind the eye
  // (z = 3) to z = -12, as a jittered grid: many shared edges are clipped by the near plane.
  Scene scene;
  scene.width = 160;
  scene.height = 90;
  scene.background_linear = glm::vec3(0.0f);
  scene.camera.eye = glm::dvec3(0.0);
  scene.camera.target = glm::dvec3(0.0, -0.15, -1.0);
  scene.camera.fovy_deg = 60.0;
  scene.camera.near = 0.1;
  scene.camera.far = 50.0;
  const int cols = 12, rows = 15;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> jitter(-0.2f, 0.2f);
  std::vector<glm::vec3> positions;
  for (int r = 0; r <= rows; ++r) {
    for (int c = 0; c <= cols; ++c) {
      glm::vec3 p(-6.0f + float(c), -0.5f, 3.0f - float(r));
      if (c > 0 && c < cols && r > 0 && r < rows) {
        p.x += jitter(rng);
        p.z += jitter(rng);
      }
      positions.push_back(p);
    }
  }
  std::vector<std::uint32_t> indices;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      std::uint32_t a = std::uint32_t(r * (cols + 1) + c), b = a + 1, d = a + cols + 1, e = d + 1;
      indices.insert(indices.end(), {a, d, e, a, e, b});
    }
  }
  auto mesh = make_mesh(positions, indices);
  std::vector<glm::dvec2> poly = reference_polygon(
      scene, {{-6.0, -0.5, 3.0}, {-6.0, -0.5, -12.0}, {6.0, -0.5, -12.0}, {6.0, -0.5, 3.0}});
  REQUIRE(poly.size() >= 3);

  SECTION("aliased: one colour, no cracks, nothing outside") {
    Scene uniform = scene;
    add_instance(uniform, mesh, ColorSource::Uniform, glm::vec3(1.0f));
    RenderResult result = render_with(uniform, "aliased");
    CHECK(result.stats.triangles_clipped > 10);
    PolygonCheck check = check_polygon(result.color, poly, {255, 255, 255}, {0, 0, 0}, 1.0 / 128);
    INFO(check.first_wrong);
    CHECK(check.wrong == 0);
    CHECK(check.inside > 3000);
    CHECK(check.undecided < 40);
  }

  SECTION("aliased: no pixel owned twice (draw order reversed)") {
    std::vector<glm::vec3> soup, colors;
    std::vector<std::uint32_t> forward, backward;
    const std::size_t n = indices.size() / 3;
    for (std::size_t t = 0; t < n; ++t) {
      std::uint32_t hash = lowbias32(std::uint32_t(t));
      glm::vec3 color(float(hash & 255) / 255.0f, float(hash >> 8 & 255) / 255.0f,
                      float(hash >> 16 & 255) / 255.0f);
      for (int j = 0; j < 3; ++j) {
        soup.push_back(positions[indices[3 * t + j]]);
        colors.push_back(color);
      }
    }
    for (std::size_t t = 0; t < n; ++t) {
      for (int j = 0; j < 3; ++j) {
        forward.push_back(std::uint32_t(3 * t + j));
        backward.push_back(std::uint32_t(3 * (n - 1 - t) + j));
      }
    }
    Scene a = scene, b = scene;
    add_instance(a, make_mesh(soup, forward, colors), ColorSource::Vertex);
    add_instance(b, make_mesh(soup, backward, colors), ColorSource::Vertex);
    ImageDiff d = diff_images(render_with(a, "aliased").color, render_with(b, "aliased").color);
    INFO(d.first);
    CHECK(d.count == 0);
  }

  SECTION("coverage: pixels wholly inside are exactly the surface colour") {
    Scene uniform = scene;
    add_instance(uniform, mesh, ColorSource::Uniform, glm::vec3(1.0f));
    Image image = render_with(uniform, "coverage").color;
    // A pixel square lies wholly inside (outside) when its centre is inside (outside) and
    // more than half a diagonal, 0.7072 px, from the boundary.
    const PolygonCheck r = check_polygon(image, poly, Rgb{255, 255, 255}, Rgb{0, 0, 0}, 0.7072);
    INFO(r.first_wrong);
    CHECK(r.wrong == 0);
    CHECK(r.inside > 3000);
    CHECK(r.outside > 3000);
  }
}

// ---------------------------------------------------------------------------------------
// 2. Watertightness and the top-left rule (aliased)
// ---------------------------------------------------------------------------------------

TEST_CASE("aliased tessellations are watertight and follow the top-left rule", "[pipeline]") {
  // Grid region [6.5, 150.5] x [5.5, 85.5] px: its borders pass through pixel centres.
  const Fx8 lo{6 * kSubpixel + 128, 5 * kSubpixel + 128};
  const Fx8 hi{150 * kSubpixel + 128, 85 * kSubpixel + 128};
  auto in_rect = [&](glm::dvec2 p) {
    return p.x * kSubpixel > lo.x + 1 && p.x * kSubpixel < hi.x - 1 && p.y * kSubpixel > lo.y + 1 &&
           p.y * kSubpixel < hi.y - 1;
  };
  SECTION("regular grid, every edge through pixel centres") {
    check_watertight(make_grid(lo, hi, 18, 10, 0.0, 1), in_rect);
  }
  SECTION("jittered grid") { check_watertight(make_grid(lo, hi, 17, 9, 0.2, 7), in_rect); }
  SECTION("jittered grid, other seed") {
    check_watertight(make_grid(lo, hi, 23, 13, 0.24, 12345), in_rect);
  }
  for (bool on_centres : {true, false}) {
    SECTION(on_centres ? "fan, rim on pixel centres" : "fan, rim at sub-pixel positions") {
      Fx8 centre{80 * kSubpixel + 128, 48 * kSubpixel + 128};
      Tessellation fan = make_fan(centre, 42.0, 37, on_centres);
      // Strictly inside the rim polygon (star-shaped around the centre).
      auto in_fan = [&](glm::dvec2 p) {
        glm::dvec2 c(centre.x / double(kSubpixel), centre.y / double(kSubpixel));
        for (std::size_t k = 1; k < fan.vertices.size(); ++k) {
          std::size_t n = k + 1 == fan.vertices.size() ? 1 : k + 1;
          glm::dvec2 a(fan.vertices[k].x / double(kSubpixel),
                       fan.vertices[k].y / double(kSubpixel));
          glm::dvec2 b(fan.vertices[n].x / double(kSubpixel),
                       fan.vertices[n].y / double(kSubpixel));
          // Inside the wedge c-a-b (clockwise on screen here) and strictly inside edge ab.
          double s1 = cross2(a - c, p - c), s2 = cross2(p - c, b - c), s3 = cross2(b - a, p - a);
          double orient = cross2(a - c, b - c);
          if (orient < 0) {
            s1 = -s1;
            s2 = -s2;
            s3 = -s3;
          }
          if (s1 >= 0 && s2 >= 0 && s3 > 1e-6 * glm::length(b - a)) return true;
        }
        return false;
      };
      check_watertight(fan, in_fan);
    }
  }

  SECTION("mixed winding gives the same image as consistent winding") {
    Tessellation t = make_grid(lo, hi, 17, 9, 0.24, 99);
    Tessellation flipped = t;
    for (std::size_t k = 0; k < flipped.triangle_count(); k += 2) {
      std::swap(flipped.indices[3 * k + 1], flipped.indices[3 * k + 2]);
    }
    Scene a = pixel_scene(160, 96), b = pixel_scene(160, 96);
    add_instance(a, tessellation_mesh(a, t), ColorSource::PerTriangle);
    add_instance(b, tessellation_mesh(b, flipped), ColorSource::PerTriangle);
    ImageDiff d = diff_images(render_with(a, "aliased").color, render_with(b, "aliased").color);
    INFO(d.first);
    CHECK(d.count == 0);
  }
}

TEST_CASE("coverage mode: a tessellated surface has no seams", "[pipeline]") {
  // One surface, consistent winding: the exact areas of adjacent triangles add up to one
  // pixel, so every pixel wholly inside the region is exactly the surface colour.
  const Fx8 lo{6 * kSubpixel + 77, 5 * kSubpixel + 200};
  const Fx8 hi{150 * kSubpixel + 31, 85 * kSubpixel + 9};
  for (double jitter : {0.0, 0.24}) {
    Tessellation t = make_grid(lo, hi, 19, 11, jitter, 4242);
    Scene scene = pixel_scene(160, 96);
    add_instance(scene, tessellation_mesh(scene, t), ColorSource::Uniform, glm::vec3(1.0f));
    Image image = render_with(scene, "coverage").color;
    std::size_t interior = 0, seams = 0, background_wrong = 0;
    std::string first;
    for (int y = 0; y < 96; ++y) {
      for (int x = 0; x < 160; ++x) {
        bool inside = x * kSubpixel >= lo.x && (x + 1) * kSubpixel <= hi.x &&
                      y * kSubpixel >= lo.y && (y + 1) * kSubpixel <= hi.y;
        bool outside = (x + 1) * kSubpixel <= lo.x || x * kSubpixel >= hi.x ||
                       (y + 1) * kSubpixel <= lo.y || y * kSubpixel >= hi.y;
        Rgb got = pixel_at(image, x, y);
        if (inside) {
          ++interior;
          if (got != Rgb{255, 255, 255} && seams++ == 0) {
            first =
                "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is " + describe(got);
          }
        }
        if (outside) background_wrong += got != Rgb{0, 0, 0};
      }
    }
    INFO("jitter " << jitter << ": " << first);
    CHECK(interior == 143 * 79);
    CHECK(seams == 0);
    CHECK(background_wrong == 0);
  }
}

// ---------------------------------------------------------------------------------------
// 3. Order independence, 5. equal depth
// ---------------------------------------------------------------------------------------

TEST_CASE("opaque triangles at distinct depths render the same in any order", "[pipeline]") {
  const int w = 160, h = 96;
  // Eight overlapping triangles, each its own instance and colour, parallel to the image at
  // clearly different depths (z = 0, -6, -12, ...), all covering the image centre.
  struct Layer {
    std::shared_ptr<MeshData> mesh;
    glm::vec3 color;
  };
  std::vector<Layer> layers;
  std::mt19937 rng(2024);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 8; ++i) {
    float z = -6.0f * float(i);
    float cx = 12.0f * u(rng), cy = 8.0f * u(rng), r = 30.0f + 8.0f * u(rng);
    float a = 3.0f * u(rng);
    std::vector<glm::vec3> p;
    for (int k = 0; k < 3; ++k) {
      float ak = a + 2.0943951f * float(k);
      p.emplace_back(cx + r * std::cos(ak), cy + r * std::sin(ak), z);
    }
    if (i % 2) std::swap(p[1], p[2]);  // both windings
    layers.push_back(
        {make_mesh(p, {0, 1, 2}),
         glm::vec3(0.1f + 0.1f * float(i), float(i % 3) / 2.0f, 1.0f - 0.12f * float(i))});
  }
  auto render_order = [&](const std::vector<int>& order, const char* mode) {
    Scene scene = pixel_scene(w, h);
    for (int i : order) add_instance(scene, layers[i].mesh, ColorSource::Uniform, layers[i].color);
    return render_with(scene, mode).color;
  };
  std::vector<int> order(layers.size());
  std::iota(order.begin(), order.end(), 0);
  for (const char* mode : {"aliased", "coverage"}) {
    Image reference = render_order(order, mode);
    // The nearest layer is visible: the image is not all background.
    std::set<std::array<std::uint8_t, 3>> colors;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::uint8_t* p = reference.pixel(x, y);
        colors.insert({p[0], p[1], p[2]});
      }
    CHECK(colors.size() >= 4);
    std::vector<int> shuffled = order;
    std::mt19937 shuffle_rng(7);
    for (int round = 0; round < 6; ++round) {
      if (round == 0) {
        std::reverse(shuffled.begin(), shuffled.end());
      } else {
        std::shuffle(shuffled.begin(), shuffled.end(), shuffle_rng);
      }
      ImageDiff d = diff_images(reference, render_order(shuffled, mode));
      INFO(mode << ", round " << round << ": " << d.first);
      CHECK(d.count == 0);
    }
  }

  SECTION("one mesh, triangles shuffled inside it (aliased)") {
    std::vector<glm::vec3> positions, colors;
    for (std::size_t i = 0; i < layers.size(); ++i) {
      for (const glm::vec3& p : layers[i].mesh->positions) {
        positions.push_back(p);
        colors.push_back(layers[i].color);
      }
    }
    std::vector<int> tri_order(layers.size());
    std::iota(tri_order.begin(), tri_order.end(), 0);
    auto mesh_in_order = [&](const std::vector<int>& ord) {
      std::vector<std::uint32_t> idx;
      for (int t : ord) {
        for (int j = 0; j < 3; ++j) idx.push_back(std::uint32_t(3 * t + j));
      }
      Scene scene = pixel_scene(w, h);
      add_instance(scene, make_mesh(positions, idx, colors), ColorSource::Vertex);
      return render_with(scene, "aliased").color;
    };
    Image reference = mesh_in_order(tri_order);
    std::mt19937 shuffle_rng(11);
    for (int round = 0; round < 4; ++round) {
      std::shuffle(tri_order.begin(), tri_order.end(), shuffle_rng);
      ImageDiff d = diff_images(reference, mesh_in_order(tri_order));
      INFO(d.first);
      CHECK(d.count == 0);
    }
  }
}

TEST_CASE("aliased: at equal depth the earlier triangle wins", "[pipeline]") {
  const int w = 160, h = 90;
  const glm::vec3 red(1, 0, 0), green(0, 1, 0);
  auto count_color = [&](const Image& image, Rgb c) {
    std::size_t n = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) n += pixel_at(image, x, y) == c;
    return n;
  };

  SECTION("the same triangle twice, parallel to the image and tilted") {
    for (bool tilted : {false, true}) {
      float dz = tilted ? 0.4f : 0.0f;
      auto mesh = make_mesh(
          {{-50.2f, -30.1f, -dz * 50.0f}, {60.3f, -20.7f, dz * 60.0f}, {-5.1f, 38.9f, 0.0f}},
          {0, 1, 2});
      for (bool red_first : {true, false}) {
        Scene scene = pixel_scene(w, h);
        add_instance(scene, mesh, ColorSource::Uniform, red_first ? red : green);
        add_instance(scene, mesh, ColorSource::Uniform, red_first ? green : red);
        Image image = render_with(scene, "aliased").color;
        INFO("tilted " << tilted << ", red first " << red_first);
        Rgb first = red_first ? Rgb{255, 0, 0} : Rgb{0, 255, 0};
        Rgb second = red_first ? Rgb{0, 255, 0} : Rgb{255, 0, 0};
        CHECK(count_color(image, first) > 2000);
        CHECK(count_color(image, second) == 0);
      }
    }
  }

  SECTION("two different coplanar triangles: the overlap goes to the earlier") {
    // Both at z = 0, so their depth is identical everywhere; they overlap in the middle.
    const std::array<glm::dvec2, 3> a = {{{-60, -40}, {70, -40}, {-60, 44}}};
    const std::array<glm::dvec2, 3> b = {{{60, 40}, {-70, 40}, {60, -44}}};
    auto strictly_inside = [](const std::array<glm::dvec2, 3>& t, glm::dvec2 p) {
      double s0 = cross2(t[1] - t[0], p - t[0]), s1 = cross2(t[2] - t[1], p - t[1]);
      double s2 = cross2(t[0] - t[2], p - t[2]);
      return (s0 > 1e-6 && s1 > 1e-6 && s2 > 1e-6) || (s0 < -1e-6 && s1 < -1e-6 && s2 < -1e-6);
    };
    std::vector<glm::vec3> p;
    for (const auto& v : a) p.emplace_back(float(v.x), float(v.y), 0.0f);
    for (const auto& v : b) p.emplace_back(float(v.x), float(v.y), 0.0f);
    std::vector<glm::vec3> colors = {red, red, red, green, green, green};
    for (bool a_first : {true, false}) {
      std::vector<std::uint32_t> idx = a_first ? std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5}
                                               : std::vector<std::uint32_t>{3, 4, 5, 0, 1, 2};
      Scene scene = pixel_scene(w, h);
      add_instance(scene, make_mesh(p, idx, colors), ColorSource::Vertex);
      Image image = render_with(scene, "aliased").color;
      const Rgb color_a{255, 0, 0}, color_b{0, 255, 0};
      std::size_t overlap = 0, wrong = 0;
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          glm::dvec2 world(x + 0.5 - w / 2.0, h / 2.0 - (y + 0.5));
          bool in_a = strictly_inside(a, world), in_b = strictly_inside(b, world);
          overlap += in_a && in_b;
          if (in_a && in_b) wrong += pixel_at(image, x, y) != (a_first ? color_a : color_b);
          if (in_a && !in_b) wrong += pixel_at(image, x, y) != color_a;
          if (in_b && !in_a) wrong += pixel_at(image, x, y) != color_b;
        }
      }
      INFO("a first " << a_first);
      CHECK(overlap > 1000);
      CHECK(wrong == 0);
    }
  }

  SECTION("per_triangle colours in one mesh: triangle 0 covers triangle 1") {
    std::vector<glm::vec3> p = {
        {-50.2f, -30.1f, 0.0f}, {60.3f, -20.7f, 0.0f}, {-5.1f, 38.9f, 0.0f}};
    Scene scene = pixel_scene(w, h);
    add_instance(scene, make_mesh(p, {0, 1, 2, 0, 1, 2}), ColorSource::PerTriangle);
    Image image = render_with(scene, "aliased").color;
    CHECK(count_color(image, per_triangle_rgb(0)) > 2000);
    CHECK(count_color(image, per_triangle_rgb(1)) == 0);
  }
}

// ---------------------------------------------------------------------------------------
// 4. Determinism over threads and tiles
// ---------------------------------------------------------------------------------------

TEST_CASE("images are byte-identical for every thread count and tile size", "[pipeline][threads]") {
  const int w = 333, h = 207;  // not a multiple of any tile size
  Scene scene = pixel_scene(w, h);
  std::mt19937 rng(31337);
  std::uniform_real_distribution<float> ux(-w / 2.0f - 20.0f, w / 2.0f + 20.0f);
  std::uniform_real_distribution<float> uy(-h / 2.0f - 20.0f, h / 2.0f + 20.0f);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (ColorSource source : {ColorSource::Uniform, ColorSource::PerTriangle, ColorSource::Vertex}) {
    std::vector<glm::vec3> positions, colors;
    std::vector<std::uint32_t> indices;
    for (int t = 0; t < 120; ++t) {
      // Triangles up to ~140 px across at depths in [-40, 40], tilted, so they cross tile
      // borders and interpenetrate.
      float cx = ux(rng), cy = uy(rng), size = 4.0f + 70.0f * unit(rng) * unit(rng);
      float z = 80.0f * unit(rng) - 40.0f;
      for (int k = 0; k < 3; ++k) {
        indices.push_back(std::uint32_t(positions.size()));
        positions.emplace_back(cx + size * (2 * unit(rng) - 1), cy + size * (2 * unit(rng) - 1),
                               z + 10.0f * (2 * unit(rng) - 1));
        colors.emplace_back(unit(rng), unit(rng), unit(rng));
      }
    }
    add_instance(scene, make_mesh(positions, indices, colors), source, glm::vec3(0.9f, 0.5f, 0.2f));
  }
  REQUIRE(scene.triangle_count() == 360);

  for (const char* mode : {"aliased", "coverage", "coverage-blend"}) {
    RenderOptions options;
    options.mode = parse_render_mode(mode);
    options.want_depth = true;  // the depth bytes are compared too
    const RenderResult reference = covrast::test::expect_same_bytes_for_every_split(
        scene, options, covrast::test::every_split({1, 2}, {8, 16, 64, 256}),
        [](const RenderResult& r, const RenderResult& base, covrast::test::Split split) {
          CHECK(r.stats.threads == split.threads);
          CHECK(r.stats.tile == split.tile);
          CHECK(r.stats.triangles_setup == base.stats.triangles_setup);
        });
    CHECK(reference.stats.bin_entries > reference.stats.triangles_setup);
  }

  SECTION("a Renderer gives the same image frame after frame") {
    RenderOptions options;
    options.mode = parse_render_mode("coverage");
    options.threads = 2;
    options.tile = 16;
    Renderer renderer(scene, options);
    RenderResult first = renderer.render_frame();
    for (int i = 0; i < 3; ++i) {
      RenderResult again = renderer.render_frame();
      CHECK(again.color.rgb == first.color.rgb);
      CHECK(again.stats.triangles_in == first.stats.triangles_in);
      CHECK(again.stats.triangles_culled == first.stats.triangles_culled);
      CHECK(again.stats.triangles_clipped == first.stats.triangles_clipped);
      CHECK(again.stats.triangles_setup == first.stats.triangles_setup);
      CHECK(again.stats.bin_entries == first.stats.bin_entries);
      CHECK(again.stats.fragment_overflows == first.stats.fragment_overflows);
    }
  }
}

TEST_CASE("odd image sizes render the same for every tile size", "[pipeline]") {
  for (auto [w, h] : {std::pair{1, 1}, std::pair{7, 300}, std::pair{300, 9}, std::pair{257, 65}}) {
    Scene scene = pixel_scene(w, h);
    std::mt19937 rng(std::uint32_t(w * 1000 + h));
    std::uniform_real_distribution<float> ux(-w / 2.0f - 5.0f, w / 2.0f + 5.0f);
    std::uniform_real_distribution<float> uy(-h / 2.0f - 5.0f, h / 2.0f + 5.0f);
    std::vector<glm::vec3> positions;
    std::vector<std::uint32_t> indices;
    for (std::uint32_t k = 0; k < 3 * 40; ++k) {
      positions.emplace_back(ux(rng), uy(rng), 0.0f);
      indices.push_back(k);
    }
    add_instance(scene, make_mesh(positions, indices), ColorSource::PerTriangle);
    for (const char* mode : {"aliased", "coverage"}) {
      INFO(w << "x" << h);
      const Image reference =
          covrast::test::expect_same_bytes_for_every_split(
              scene, mode, {{2, 16}, {2, 64}, {2, 256}}, covrast::test::NoExtraCheck{}, {1, 8})
              .color;
      CHECK(reference.rgb.size() == std::size_t(w) * h * 3);
    }
  }
}

TEST_CASE("an empty scene renders the background", "[pipeline]") {
  Scene scene = pixel_scene(50, 30);
  scene.background_linear = glm::vec3(1.0f, 0.0f, 1.0f);
  for (const char* mode : {"aliased", "coverage", "coverage-blend"}) {
    RenderResult r = render_with(scene, mode, 0, 16, true);
    INFO(mode);
    CHECK(r.stats.triangles_in == 0);
    CHECK(r.stats.bin_entries == 0);
    CHECK(r.color.rgb.size() == 50u * 30u * 3u);
    bool all_magenta = true;
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 50; ++x) all_magenta &= pixel_at(r.color, x, y) == Rgb{255, 0, 255};
    CHECK(all_magenta);
    CHECK(r.depth.depth == std::vector<float>(50 * 30, 1.0f));
  }
}

TEST_CASE("per_triangle colours use the global triangle index over all meshes", "[pipeline]") {
  Scene scene = pixel_scene(160, 90);
  // Mesh 0: two small triangles on the left; mesh 1: one triangle on the right.
  add_instance(
      scene,
      make_mesh(
          {{-70, -10, 0}, {-50, -10, 0}, {-70, 10, 0}, {-40, 30, 0}, {-30, 30, 0}, {-40, 40, 0}},
          {0, 1, 2, 3, 4, 5}),
      ColorSource::Uniform);
  add_instance(scene, make_mesh({{20, -20, 0}, {60, -20, 0}, {20, 20, 0}}, {0, 1, 2}),
               ColorSource::PerTriangle);
  Image image = render_with(scene, "aliased").color;
  // World (25, 0) is pixel (105, 45), inside mesh 1's triangle, global index 2.
  CHECK(pixel_at(image, 105, 45) == per_triangle_rgb(2));
  CHECK(pixel_at(image, 105, 45) != per_triangle_rgb(0));
}

// ---------------------------------------------------------------------------------------
// 6. The bundled scenes
// ---------------------------------------------------------------------------------------

TEST_CASE("every bundled scene renders at 160x90 with consistent statistics", "[pipeline]") {
  std::vector<std::filesystem::path> files;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(COVRAST_SOURCE_DIR) / "scenes")) {
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  REQUIRE(files.size() >= 7);
  for (const auto& file : files) {
    INFO(file.filename().string());
    Scene scene = load_scene(file);
    RenderOptions options;
    options.mode = parse_render_mode("aliased");
    options.width = 160;
    options.height = 90;
    RenderResult r = render(scene, options);
    const RenderStats& st = r.stats;
    CHECK(r.color.width == 160);
    CHECK(r.color.height == 90);
    CHECK(r.color.rgb.size() == 160u * 90u * 3u);
    CHECK(r.depth.depth.empty());
    CHECK(st.triangles_in == scene.triangle_count());
    CHECK(st.triangles_setup + st.triangles_culled >= st.triangles_in);
    CHECK(st.triangles_clipped <= st.triangles_in);
    CHECK(st.bin_entries >= st.triangles_setup);
    CHECK(st.tile == 64);
    CHECK(st.threads >= 1);
    CHECK(st.render_ms >= 0.0);
    CHECK(st.render_ms >= st.setup_ms);
    std::set<std::array<std::uint8_t, 3>> colors;
    for (int y = 0; y < 90; ++y)
      for (int x = 0; x < 160; ++x) {
        const std::uint8_t* p = r.color.pixel(x, y);
        colors.insert({p[0], p[1], p[2]});
      }
    if (file.filename() == "sphere_closed.json") {
      // The sphere is drawn in the background colour: one flat colour, in both modes.
      CHECK(colors.size() == 1);
      options.mode = parse_render_mode("coverage");
      Image coverage = render(scene, options).color;
      CHECK(coverage.rgb == r.color.rgb);
    } else {
      CHECK(colors.size() >= 2);
      CHECK(st.triangles_setup > 0);
    }
    if (file.filename() == "near_plane.json") CHECK(st.triangles_clipped == 1);
    if (file.filename() == "sphere_grid.json") CHECK(st.triangles_in == 500000);
  }
}
