// Load-time topology analysis for back-face culling: is a mesh a closed, consistently oriented
// surface, and which way do its counter-clockwise faces point? (analyze_mesh_topology in
// include/covrast/scene.hpp; the renderer's use of it is in src/geometry/frontend_cull.cpp.)
//
// Steps, O(n log n) in the vertex and triangle counts, all by sorting:
// 1. weld: referenced vertices sorted by the bits of their position, equal positions get one
//    id;
// 2. edges: each non-degenerate triangle's three directed edges, filed under their lower
//    welded id (a counting sort), each bucket sorted by the higher id and direction; every
//    edge must appear exactly twice, once in each direction, and its two triangles are united
//    (union-find): the components are the edge-connected pieces of the surface;
// 3. volume: per component, V = sum over its triangles of dot(p0, cross(p1, p2)) / 6 (in
//    double, relative to a point of the component, which changes nothing for a closed surface
//    but keeps the terms small). Every component must have |V| clearly above the rounding of
//    that sum and all the same sign. One sign per component matters: a closed mesh made of an
//    outward sphere and a separate inward one passes the edge test, but culling by the sign of
//    the total volume would drop the visible faces of the inward one.
#include "scene/scene_internal.hpp"

#include <covrast/scene.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>

namespace covrast {
namespace {

/// |V| of a component must exceed this share of sum |term| (terms as in V): far above the
/// rounding of the double sum, below any solid that is not flat to a millionth of its size.
constexpr double kMinRelativeVolume = 1e-6;

/// Welded ids are stored shifted left by one next to a direction bit.
constexpr std::size_t kMaxWeldedVertices = std::size_t(1) << 31;

/// One use of an edge by a triangle, filed under the edge's lower welded id: the higher id,
/// and whether the triangle runs high -> low.
struct EdgeUse {
  std::uint32_t high_dir;  ///< high << 1 | direction
  std::uint32_t triangle;  ///< index into MeshData::indices / 3
};

/// A position as exact bits (with -0 as +0, so that the positions that compare equal weld).
struct WeldKey {
  std::uint64_t xy;
  std::uint32_t z;
  std::uint32_t vertex;
  bool same_position(const WeldKey& o) const { return xy == o.xy && z == o.z; }
  bool operator<(const WeldKey& o) const { return xy != o.xy ? xy < o.xy : z < o.z; }
};

std::uint32_t float_key(float f) { return f == 0.0f ? 0u : std::bit_cast<std::uint32_t>(f); }

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  std::uint32_t root = x;
  while (parent[root] != root) root = parent[root];
  while (parent[x] != root) {  // path compression
    const std::uint32_t next = parent[x];
    parent[x] = root;
    x = next;
  }
  return root;
}

/// Step 1 of closed_orientation_of, the weld: each referenced vertex's id among the distinct
/// referenced positions (sorted by their bits: any total order groups equal ones); returns
/// the number of distinct positions.
std::uint32_t weld_positions(const MeshData& mesh, const std::vector<std::uint8_t>& used,
                             std::vector<std::uint32_t>& weld) {
  const std::size_t vertex_count = mesh.positions.size();
  std::vector<WeldKey> keys;
  keys.reserve(vertex_count);
  for (std::size_t v = 0; v < vertex_count; ++v) {
    if (!used[v]) continue;
    const glm::vec3& p = mesh.positions[v];
    keys.push_back(WeldKey{std::uint64_t(float_key(p.x)) << 32 | float_key(p.y), float_key(p.z),
                           std::uint32_t(v)});
  }
  std::sort(keys.begin(), keys.end());
  weld.assign(vertex_count, 0);
  std::uint32_t welded_count = 0;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    if (k > 0 && !keys[k].same_position(keys[k - 1])) ++welded_count;
    weld[keys[k].vertex] = welded_count;
  }
  return welded_count + 1;
}

/// Step 2: the edge uses of the non-degenerate triangles (`degenerate` marks the others),
/// filed by their lower welded id with a counting sort (two passes: count, then place), then
/// each (short) bucket sorted; every edge must be used exactly twice, once each way, and
/// `parent` joins the triangles across each edge (union-find). False when some edge is not.
bool join_across_edges(const MeshData& mesh, const std::vector<std::uint32_t>& weld,
                       std::uint32_t welded_count, std::vector<std::uint8_t>& degenerate,
                       std::vector<std::uint32_t>& parent) {
  const std::size_t triangle_count = mesh.triangle_count();
  degenerate.assign(triangle_count, 0);
  std::vector<std::uint32_t> bucket(std::size_t(welded_count) + 1, 0);
  const auto welded = [&](std::size_t t, int k) { return weld[mesh.indices[3 * t + k]]; };
  for (std::size_t t = 0; t < triangle_count; ++t) {
    const std::uint32_t w0 = welded(t, 0), w1 = welded(t, 1), w2 = welded(t, 2);
    if (w0 == w1 || w1 == w2 || w0 == w2) {
      degenerate[t] = 1;  // zero area in any transform: it never covers a pixel
      continue;
    }
    ++bucket[std::min(w0, w1) + 1];
    ++bucket[std::min(w1, w2) + 1];
    ++bucket[std::min(w2, w0) + 1];
  }
  for (std::size_t b = 1; b < bucket.size(); ++b) bucket[b] += bucket[b - 1];
  if (bucket.back() == 0) return false;
  std::vector<EdgeUse> edges(bucket.back());
  std::vector<std::uint32_t> fill(bucket.begin(), bucket.end() - 1);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    if (degenerate[t]) continue;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t from = welded(t, k), to = welded(t, (k + 1) % 3);
      const std::uint32_t low = std::min(from, to), high = std::max(from, to);
      edges[fill[low]++] = EdgeUse{high << 1 | (from > to ? 1u : 0u), std::uint32_t(t)};
    }
  }
  fill = {};
  parent.resize(triangle_count);
  std::iota(parent.begin(), parent.end(), 0u);
  for (std::size_t low = 0; low < welded_count; ++low) {
    const auto first = edges.begin() + bucket[low], last = edges.begin() + bucket[low + 1];
    std::sort(first, last,
              [](const EdgeUse& a, const EdgeUse& b) { return a.high_dir < b.high_dir; });
    // Sorted, a valid pair is (high, direction 0) then (high, direction 1), and the same high
    // does not follow.
    for (auto e = first; e != last; e += 2) {
      if (last - e < 2) return false;  // used once
      const EdgeUse& a = e[0];
      const EdgeUse& b = e[1];
      if ((a.high_dir >> 1) != (b.high_dir >> 1)) return false;                     // used once
      if ((a.high_dir & 1u) != 0 || (b.high_dir & 1u) != 1) return false;           // twice one way
      if (last - e > 2 && (e[2].high_dir >> 1) == (a.high_dir >> 1)) return false;  // > twice
      const std::uint32_t ra = find_root(parent, a.triangle), rb = find_root(parent, b.triangle);
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  return true;
}

/// Step 3: the signed volume of each component `parent` joins, relative to the first vertex
/// of its root triangle; their common sign, or 0 when one is too flat or two disagree.
int components_orientation(const MeshData& mesh, const std::vector<std::uint8_t>& degenerate,
                           std::vector<std::uint32_t>& parent) {
  const std::size_t triangle_count = mesh.triangle_count();
  std::vector<std::uint32_t> component(triangle_count, std::numeric_limits<std::uint32_t>::max());
  std::vector<double> volume, magnitude;
  for (std::size_t t = 0; t < triangle_count; ++t) {
    if (degenerate[t]) continue;
    const std::uint32_t root = find_root(parent, std::uint32_t(t));
    if (component[root] == std::numeric_limits<std::uint32_t>::max()) {
      component[root] = std::uint32_t(volume.size());
      volume.push_back(0.0);
      magnitude.push_back(0.0);
    }
    const std::uint32_t c = component[root];
    const glm::dvec3 origin(mesh.positions[mesh.indices[3 * std::size_t(root)]]);
    const glm::dvec3 p0 = glm::dvec3(mesh.positions[mesh.indices[3 * t]]) - origin;
    const glm::dvec3 p1 = glm::dvec3(mesh.positions[mesh.indices[3 * t + 1]]) - origin;
    const glm::dvec3 p2 = glm::dvec3(mesh.positions[mesh.indices[3 * t + 2]]) - origin;
    const double term = glm::dot(p0, glm::cross(p1, p2));
    volume[c] += term;
    magnitude[c] += std::abs(term);
  }
  int sign = 0;
  for (std::size_t c = 0; c < volume.size(); ++c) {
    if (!(std::abs(volume[c]) > kMinRelativeVolume * magnitude[c])) return 0;
    const int s = volume[c] > 0.0 ? 1 : -1;
    if (sign != 0 && s != sign) return 0;
    sign = s;
  }
  return sign;
}

/// The orientation (+1, -1, or 0 when not closed) of a mesh whose indices are all in range and
/// whose referenced positions are finite; `used` marks the referenced vertices.
int closed_orientation_of(const MeshData& mesh, const std::vector<std::uint8_t>& used) {
  std::vector<std::uint32_t> weld;
  const std::uint32_t welded_count = weld_positions(mesh, used, weld);
  std::vector<std::uint8_t> degenerate;
  std::vector<std::uint32_t> parent;
  if (!join_across_edges(mesh, weld, welded_count, degenerate, parent)) return 0;
  weld = {};
  return components_orientation(mesh, degenerate, parent);
}

/// Whether a closed mesh of orientation `orientation` is convex: for every non-degenerate face,
/// with its normal turned outwards, no used vertex lies in front of its plane by more than
/// 1e-6 of the box diagonal. Positions are floats, so a convex surface written out loses
/// convexity by their rounding (8e-8 of the radius on scenes/sphere5k.obj); a dent of 1e-6 of
/// the mesh's size overlaps neighbouring faces on screen by far less than the 1/256-pixel
/// snapping moves them. O(faces x vertices).
bool convex_of(const MeshData& mesh, const std::vector<std::uint8_t>& used, int orientation,
               double diagonal) {
  std::vector<glm::dvec3> points;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    if (used[v]) points.emplace_back(mesh.positions[v]);
  }
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const glm::dvec3 p0(mesh.positions[mesh.indices[3 * t]]);
    const glm::dvec3 p1(mesh.positions[mesh.indices[3 * t + 1]]);
    const glm::dvec3 p2(mesh.positions[mesh.indices[3 * t + 2]]);
    const glm::dvec3 n = double(orientation) * glm::cross(p1 - p0, p2 - p0);
    const double length = glm::length(n);
    if (!(length > 0.0)) continue;  // degenerate: covers nothing
    const double margin = 1e-6 * length * diagonal;
    for (const glm::dvec3& p : points) {
      if (glm::dot(n, p - p0) > margin) return false;
    }
  }
  return true;
}

}  // namespace

namespace detail {

MeshTopologyFacts mesh_topology_facts(const MeshData& mesh) {
  MeshTopologyFacts facts;
  const std::size_t vertex_count = mesh.positions.size();
  const std::size_t triangle_count = mesh.triangle_count();
  if (vertex_count >= kMaxWeldedVertices ||
      triangle_count >= std::numeric_limits<std::uint32_t>::max()) {
    return facts;  // beyond what the packed edge keys hold: leave the mesh unculled
  }
  std::vector<std::uint8_t> used(vertex_count, 0);
  bool all_finite = true;
  bool any_used = false;
  glm::vec3 lo(std::numeric_limits<float>::infinity());
  glm::vec3 hi(-std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < triangle_count * 3; ++i) {
    const std::uint32_t v = mesh.indices[i];
    if (v >= vertex_count) return facts;  // a mesh built in code with a bad index: never culled
    if (used[v]) continue;
    used[v] = 1;
    const glm::vec3& p = mesh.positions[v];
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) {
      all_finite = false;
      continue;
    }
    any_used = true;
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  if (any_used) {
    facts.bounds_min = lo;
    facts.bounds_max = hi;
  }
  if (!all_finite || !any_used) return facts;
  facts.closed_orientation = closed_orientation_of(mesh, used);
  if (facts.closed_orientation != 0 && vertex_count <= kMaxConvexTestVertices) {
    const double diagonal = glm::length(glm::dvec3(hi) - glm::dvec3(lo));
    facts.convex = convex_of(mesh, used, facts.closed_orientation, diagonal);
  }
  return facts;
}

bool mesh_topology_is_current(const MeshData& mesh) {
  if (mesh.analyzed_triangle_count != mesh.triangle_count() || mesh.closed_orientation == 0) {
    return true;  // the renderer culls nothing of it, whatever the mesh holds now
  }
  const MeshTopologyFacts facts = mesh_topology_facts(mesh);
  return facts.closed_orientation == mesh.closed_orientation && facts.convex == mesh.convex &&
         facts.bounds_min == mesh.bounds_min && facts.bounds_max == mesh.bounds_max;
}

}  // namespace detail

void analyze_mesh_topology(MeshData& mesh) {
  const detail::MeshTopologyFacts facts = detail::mesh_topology_facts(mesh);
  mesh.closed_orientation = facts.closed_orientation;
  mesh.convex = facts.convex;
  mesh.bounds_min = facts.bounds_min;
  mesh.bounds_max = facts.bounds_max;
  mesh.analyzed_triangle_count = mesh.triangle_count();
}

}  // namespace covrast
