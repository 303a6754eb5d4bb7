// Load-time normals for NormalSource::Smooth: at each position (vertices welded when their
// coordinates are equal, so that a file's split vertices share one normal), the sum of the
// face normals cross(p1 - p0, p2 - p0) of its triangles: each face weighted by twice its area
// (Gouraud's average, weighted as in Max 1999, "Weights for computing vertex normals from
// facet normals", the area variant). Summed in double in triangle order: deterministic.
#include <covrast/scene.hpp>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

namespace covrast {
namespace {

/// Welded id of every vertex: equal positions (with -0 as +0) get one id.
std::vector<std::uint32_t> weld_by_position(const std::vector<glm::vec3>& positions) {
  struct Key {
    std::uint32_t x, y, z, vertex;
  };
  const auto bits = [](float f) { return f == 0.0f ? 0u : std::bit_cast<std::uint32_t>(f); };
  std::vector<Key> keys(positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const glm::vec3& p = positions[v];
    keys[v] = Key{bits(p.x), bits(p.y), bits(p.z), std::uint32_t(v)};
  }
  const auto position_less = [](const Key& a, const Key& b) {
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.z < b.z;
  };
  std::sort(keys.begin(), keys.end(), [&](const Key& a, const Key& b) {
    return position_less(a, b) || (!position_less(b, a) && a.vertex < b.vertex);
  });
  std::vector<std::uint32_t> welded(positions.size());
  std::uint32_t id = 0;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (i > 0 && position_less(keys[i - 1], keys[i])) ++id;
    welded[keys[i].vertex] = id;
  }
  return welded;
}

}  // namespace

std::vector<glm::vec3> smooth_corner_normals(const MeshData& mesh) {
  const std::vector<std::uint32_t> welded = weld_by_position(mesh.positions);
  std::vector<glm::dvec3> sum(mesh.positions.size(), glm::dvec3(0.0));
  const std::vector<std::uint32_t>& idx = mesh.indices;
  for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
    const glm::dvec3 p0(mesh.positions[idx[t]]), p1(mesh.positions[idx[t + 1]]),
        p2(mesh.positions[idx[t + 2]]);
    const glm::dvec3 face = glm::cross(p1 - p0, p2 - p0);  // |face| = 2 x area
    for (int k = 0; k < 3; ++k) sum[welded[idx[t + std::size_t(k)]]] += face;
  }
  std::vector<glm::vec3> corners(idx.size(), glm::vec3(0.0f));
  for (std::size_t c = 0; c < idx.size(); ++c) {
    const glm::dvec3& n = sum[welded[idx[c]]];
    const double length = glm::length(n);
    // A zero sum (degenerate neighbourhood) stays zero: "use the face normal".
    if (length > 0.0) corners[c] = glm::vec3(n / length);
  }
  return corners;
}

}  // namespace covrast
