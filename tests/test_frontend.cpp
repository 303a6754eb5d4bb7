// Geometry front end against a plain reference: every vertex transformed with glm's
// mat4 * vec4, classified with glm::dot against the six clip planes and snapped with
// std::llrint, exactly as the stage is specified. The stage computes the same values by
// faster routes (two vertices per step, the planes' zero terms dropped, an inlined rounding
// instruction); these tests hold them to the reference bit for bit, including vertices
// whose clip coordinates overflow to infinity or are NaN.
#include "geometry/frontend.hpp"

#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <vector>

namespace {

using covrast::ColorSource;
using covrast::MeshData;
using covrast::MeshInstance;
using covrast::Scene;
using covrast::detail::GeometryFrontEnd;
using covrast::detail::PixelBounds16;
using covrast::detail::SetupCounters;
using covrast::detail::TriangleSetup;

struct RefVertex {
  unsigned code;  ///< bit p: outside plane p (near, far, left, right, bottom, top)
  std::int32_t x_fx8, y_fx8;
  double z_window;
  float inv_w;
};

/// The reference transform of one vertex (planes and snapping as in GeometryFrontEnd).
RefVertex reference_vertex(const Scene& s, const MeshInstance& inst, const glm::vec3& p) {
  const covrast::Camera& cam = s.camera;
  const glm::dmat4 view = glm::lookAt(cam.eye, cam.target, cam.up);
  const glm::dmat4 projection = glm::perspective(
      glm::radians(cam.fovy_deg), double(s.width) / double(s.height), cam.near, cam.far);
  const glm::dmat4 mvp = (projection * view) * inst.model;
  const glm::dvec4 c = mvp * glm::dvec4(glm::dvec3(p), 1.0);
  const double gx = 1.0 + 2.0 * covrast::detail::kGuardBandPx / s.width;
  const double gy = 1.0 + 2.0 * covrast::detail::kGuardBandPx / s.height;
  const glm::dvec4 planes[6] = {{0, 0, 1, 1},   {0, 0, -1, 1}, {1, 0, 0, gx},
                                {-1, 0, 0, gx}, {0, 1, 0, gy}, {0, -1, 0, gy}};
  RefVertex r{};
  for (int k = 0; k < 6; ++k) {
    if (glm::dot(planes[k], c) < 0.0) r.code |= 1u << k;
  }
  const double inv_w = 1.0 / c.w;
  const double x_px = (c.x * inv_w + 1.0) * 0.5 * s.width;
  const double y_px = (1.0 - c.y * inv_w) * 0.5 * s.height;
  r.x_fx8 = std::int32_t(std::llrint(x_px * covrast::detail::kSubpixelOne));
  r.y_fx8 = std::int32_t(std::llrint(y_px * covrast::detail::kSubpixelOne));
  r.z_window = std::clamp(c.z * inv_w * 0.5 + 0.5, 0.0, 1.0);
  r.inv_w = float(inv_w);
  return r;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// 9001 vertices (an odd count over three transform blocks) spread well beyond the view
/// volume, including behind the camera, plus special positions: the eye itself, the target,
/// an infinite and a NaN coordinate, each next to a vertex outside one plane. Random
/// triangles over them, and vertex colours.
std::shared_ptr<MeshData> scattered_mesh() {
  auto m = std::make_shared<MeshData>();
  m->source = "scattered";
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> coord(-6.0f, 6.0f);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  constexpr int kVertices = 9001;
  for (int i = 0; i < kVertices; ++i) {
    m->positions.push_back(glm::vec3(coord(rng), coord(rng), coord(rng)));
    m->colors_linear.push_back(glm::vec3(unit(rng), unit(rng), unit(rng)));
  }
  m->positions[10] = glm::vec3(0.0f, 0.0f, 3.0f);  // the default eye
  m->positions[11] = glm::vec3(0.0f);              // the default target
  // Vertices are transformed in pairs (v even, v + 1); a pair with a non-finite clip
  // coordinate takes the one-vertex path for both, so give those partners outcodes.
  m->positions[12] = glm::vec3(std::numeric_limits<float>::infinity(), 0.0f, 0.0f);
  m->positions[13] = glm::vec3(0.0f, 0.0f, -200.0f);  // beyond the far plane
  m->positions[14] = glm::vec3(0.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f);
  m->positions[15] = glm::vec3(1e4f, 0.0f, 0.0f);             // beyond the right guard band
  m->positions[kVertices - 1] = glm::vec3(0.1f, 0.2f, 0.3f);  // the odd tail vertex, in view
  std::uniform_int_distribution<std::uint32_t> index(0, kVertices - 1);
  for (int t = 0; t < 30000; ++t) {
    m->indices.insert(m->indices.end(), {index(rng), index(rng), index(rng)});
  }
  // Triangles through the special vertices and the tail vertex.
  m->indices.insert(m->indices.end(),
                    {10, 11, 20, 12, 11, 21, 13, 11, 22, 14, 11, 23, 15, 11, 24, 11, 9000, 25});
  return m;
}

}  // namespace

TEST_CASE("front end: vertices, outcodes and set-ups match the glm reference bit for bit",
          "[frontend]") {
  Scene s;
  s.width = 320;
  s.height = 180;
  const auto mesh = scattered_mesh();
  MeshInstance plain;
  plain.mesh = mesh;
  plain.color_linear = glm::vec3(0.25f, 0.5f, 0.75f);
  s.meshes.push_back(plain);
  MeshInstance coloured = plain;  // mirrored and turned, with vertex colours
  coloured.color_source = ColorSource::Vertex;
  coloured.model = glm::rotate(glm::scale(glm::dmat4(1.0), glm::dvec3(-1.0, 0.5, 1.0)), 0.7,
                               glm::dvec3(0.0, 1.0, 0.0));
  s.meshes.push_back(coloured);
  MeshInstance huge = plain;  // clip coordinates overflow to +-infinity
  huge.model = glm::scale(glm::dmat4(1.0), glm::dvec3(1e307));
  s.meshes.push_back(huge);

  GeometryFrontEnd fe(s, s.width, s.height, /*cull_hidden_backfaces=*/false);
  // As the pipeline calls it: block by block.
  for (std::size_t i = 0; i < fe.instance_count(); ++i) {
    for (std::size_t v = 0; v < fe.vertex_count(i);
         v += covrast::detail::kVerticesPerTransformBlock) {
      fe.transform_vertices(
          i, v, std::min(fe.vertex_count(i), v + covrast::detail::kVerticesPerTransformBlock));
    }
  }
  // Every chunk's triangles and bounds in order, each chunk set up without a slice (its own
  // growing array from the start).
  std::vector<TriangleSetup> setups;
  std::vector<PixelBounds16> bounds;
  SetupCounters counters;
  for (std::uint32_t c = 0; c < fe.chunk_count(); ++c) {
    covrast::detail::ChunkSetups own;
    fe.setup_chunk(c, own, bounds, counters);
    setups.insert(setups.end(), own.data(), own.data() + own.size());
  }
  REQUIRE(bounds.size() == setups.size());

  // The pipeline's slices give the same triangles and bounds, both within a slice of one per
  // input triangle and when a 1-triangle slice forces the move to an own array.
  auto same_setup = [](const TriangleSetup& a, const TriangleSetup& b) {
    bool same = same_bits(a.z0, b.z0) && same_bits(a.dzdx, b.dzdx) && same_bits(a.dzdy, b.dzdy) &&
                a.primitive == b.primitive && a.surface == b.surface &&
                a.front_facing == b.front_facing && a.flat_color == b.flat_color;
    for (int k = 0; k < 3; ++k) {
      same = same && a.x_fx8[k] == b.x_fx8[k] && a.y_fx8[k] == b.y_fx8[k] &&
             same_bits(a.inv_w[k], b.inv_w[k]) && std::memcmp(&a.color[k], &b.color[k], 12) == 0;
    }
    return same;
  };
  for (std::size_t slice_triangles :
       {std::size_t(covrast::detail::kTrianglesPerChunk), std::size_t(1)}) {
    covrast::detail::HugePageBuffer storage(fe.chunk_count() * slice_triangles *
                                            sizeof(TriangleSetup));
    std::size_t k = 0, mismatches = 0, overflowed = 0, expect_overflowed = 0;
    for (std::uint32_t c = 0; c < fe.chunk_count(); ++c) {
      TriangleSetup* slice = static_cast<TriangleSetup*>(storage.data()) + c * slice_triangles;
      covrast::detail::ChunkSetups chunk;
      const std::size_t capacity =
          std::min<std::size_t>(slice_triangles, fe.chunk_triangle_count(c));
      chunk.reset(slice, capacity);
      std::vector<PixelBounds16> chunk_bounds;
      SetupCounters chunk_counters;
      fe.setup_chunk(c, chunk, chunk_bounds, chunk_counters);
      REQUIRE(chunk_bounds.size() == chunk.size());
      if (chunk.data() != slice) ++overflowed;
      if (chunk.size() > capacity) ++expect_overflowed;
      for (std::size_t j = 0; j < chunk.size(); ++j, ++k) {
        REQUIRE(k < setups.size());
        if (!same_setup(chunk[j], setups[k]) ||
            std::memcmp(&chunk_bounds[j], &bounds[k], sizeof(PixelBounds16)) != 0) {
          ++mismatches;
        }
      }
    }
    CHECK(k == setups.size());
    CHECK(mismatches == 0);
    // Moved to an own array exactly when the slice ran full; 1-triangle slices must do so.
    CHECK(overflowed == expect_overflowed);
    if (slice_triangles == 1) CHECK(overflowed > 0);
  }

  std::multimap<std::uint32_t, std::size_t> by_primitive;
  for (std::size_t k = 0; k < setups.size(); ++k) by_primitive.emplace(setups[k].primitive, k);

  std::uint64_t expect_clipped = 0, compared = 0, rejected = 0;
  std::uint32_t primitive = 0;
  for (std::size_t i = 0; i < s.meshes.size(); ++i) {
    const MeshInstance& inst = s.meshes[i];
    std::vector<RefVertex> ref;
    for (const glm::vec3& p : mesh->positions) ref.push_back(reference_vertex(s, inst, p));
    // Every vertex: outcode, and the snapped vertex where it is inside every plane.
    const covrast::detail::InstanceVertices& iv = fe.instance_vertices(i);
    std::uint64_t mismatches = 0;
    for (std::size_t v = 0; v < ref.size(); ++v) {
      const covrast::detail::SnappedVertex& sv = iv.snapped[v];
      if (iv.outcode[v] != ref[v].code ||
          (ref[v].code == 0 &&
           (sv.x_fx8 != ref[v].x_fx8 || sv.y_fx8 != ref[v].y_fx8 ||
            !same_bits(sv.z_window, ref[v].z_window) || !same_bits(sv.inv_w, ref[v].inv_w)))) {
        ++mismatches;
      }
    }
    CHECK(mismatches == 0);
    for (std::size_t t = 0; t < mesh->triangle_count(); ++t, ++primitive) {
      const std::uint32_t* idx = &mesh->indices[3 * t];
      const RefVertex& a = ref[idx[0]];
      const RefVertex& b = ref[idx[1]];
      const RefVertex& c = ref[idx[2]];
      const auto [first, last] = by_primitive.equal_range(primitive);
      if ((a.code & b.code & c.code) != 0) {
        CHECK(first == last);  // trivially rejected: nothing emitted
        ++rejected;
        continue;
      }
      if ((a.code | b.code | c.code) != 0) {
        ++expect_clipped;
        continue;
      }
      // Trivially accepted: at most one set-up, from exactly the reference vertices.
      const std::int64_t area2 = std::int64_t(b.x_fx8 - a.x_fx8) * (c.y_fx8 - a.y_fx8) -
                                 std::int64_t(c.x_fx8 - a.x_fx8) * (b.y_fx8 - a.y_fx8);
      const int minx = std::min({a.x_fx8, b.x_fx8, c.x_fx8}) >> 8;
      const int maxx = (std::max({a.x_fx8, b.x_fx8, c.x_fx8}) + 255) >> 8;
      const int miny = std::min({a.y_fx8, b.y_fx8, c.y_fx8}) >> 8;
      const int maxy = (std::max({a.y_fx8, b.y_fx8, c.y_fx8}) + 255) >> 8;
      const bool visible = area2 != 0 && maxx > 0 && maxy > 0 && minx < s.width && miny < s.height;
      REQUIRE(std::distance(first, last) == (visible ? 1 : 0));
      if (!visible) continue;
      const std::size_t k = first->second;
      const TriangleSetup& st = setups[k];
      const bool front = area2 < 0;
      const RefVertex* v[3] = {&a, front ? &c : &b, front ? &b : &c};
      const glm::vec3* col[3] = {&inst.color_linear, &inst.color_linear, &inst.color_linear};
      if (inst.color_source == ColorSource::Vertex) {
        col[0] = &mesh->colors_linear[idx[0]];
        col[1] = &mesh->colors_linear[idx[front ? 2 : 1]];
        col[2] = &mesh->colors_linear[idx[front ? 1 : 2]];
      }
      for (int j = 0; j < 3; ++j) {
        CHECK(st.x_fx8[j] == v[j]->x_fx8);
        CHECK(st.y_fx8[j] == v[j]->y_fx8);
        CHECK(same_bits(st.inv_w[j], v[j]->inv_w));
        CHECK(st.color[j] == *col[j]);
      }
      CHECK(st.front_facing == front);
      CHECK(st.surface == i);
      CHECK(same_bits(st.z0, a.z_window));
      // Depth plane of the snapped vertices.
      const double dx1 = (v[1]->x_fx8 - v[0]->x_fx8) / 256.0;
      const double dy1 = (v[1]->y_fx8 - v[0]->y_fx8) / 256.0;
      const double dx2 = (v[2]->x_fx8 - v[0]->x_fx8) / 256.0;
      const double dy2 = (v[2]->y_fx8 - v[0]->y_fx8) / 256.0;
      const double dz1 = v[1]->z_window - v[0]->z_window;
      const double dz2 = v[2]->z_window - v[0]->z_window;
      const double det = dx1 * dy2 - dx2 * dy1;
      CHECK(same_bits(st.dzdx, (dz1 * dy2 - dz2 * dy1) / det));
      CHECK(same_bits(st.dzdy, (dx1 * dz2 - dx2 * dz1) / det));
      const PixelBounds16 bb = bounds[k];
      CHECK(bb.x0 == std::max(minx, 0));
      CHECK(bb.y0 == std::max(miny, 0));
      CHECK(bb.x1 == std::min(maxx, s.width));
      CHECK(bb.y1 == std::min(maxy, s.height));
      ++compared;
    }
  }
  CHECK(counters.clipped == expect_clipped);
  // The scene exercises every path: accepted, rejected and clipped triangles.
  CHECK(compared > 1000);
  CHECK(rejected > 1000);
  CHECK(expect_clipped > 1000);
}
