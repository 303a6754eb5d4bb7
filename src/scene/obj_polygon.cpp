// OBJ polygons to triangles. A convex polygon keeps the fan (0, k, k + 1) that covrast has
// always used (so that existing meshes load to the same triangles); a concave one is ear-clipped
// (Meisters 1975, "Polygons have ears"; the O(n)-per-ear-test form of Eberly, "Triangulation by
// Ear Clipping", 2002, with each corner's blocking corner remembered so that a failed test is
// not repeated: O(n^2) in all) in the plane it is flattest in: the coordinate plane orthogonal
// to the largest component of its Newell normal (Newell's method, Sutherland, Sproull and
// Schumacker 1974: N = sum_i (p_i - p_{i+1}) x ... componentwise, see newell_normal). All in
// double.
#include "scene/obj_polygon.hpp"

#include <cmath>

namespace covrast::detail {
namespace {

/// N_x = sum_i (y_i - y_j)(z_i + z_j), N_y = sum_i (z_i - z_j)(x_i + x_j), N_z = sum_i (x_i -
/// x_j)(y_i + y_j), j = i + 1 mod n: twice the vector area of the polygon.
glm::dvec3 newell_normal(const std::vector<glm::dvec3>& ring) {
  glm::dvec3 n(0.0);
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const glm::dvec3& p = ring[i];
    const glm::dvec3& q = ring[(i + 1) % ring.size()];
    n.x += (p.y - q.y) * (p.z + q.z);
    n.y += (p.z - q.z) * (p.x + q.x);
    n.z += (p.x - q.x) * (p.y + q.y);
  }
  return n;
}

/// The ring projected onto the coordinate plane orthogonal to the normal's largest component,
/// mirrored when that component is negative, so that the polygon runs counter-clockwise
/// (positive area) in the projection.
std::vector<glm::dvec2> project(const std::vector<glm::dvec3>& ring, const glm::dvec3& normal) {
  const glm::dvec3 a = glm::abs(normal);
  const int k = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
  const int u = (k + 1) % 3, v = (k + 2) % 3;  // (y, z), (z, x) or (x, y): right-handed
  const double sign = normal[k] > 0.0 ? 1.0 : -1.0;
  std::vector<glm::dvec2> out;
  out.reserve(ring.size());
  for (const glm::dvec3& p : ring) out.emplace_back(p[u], sign * p[v]);
  return out;
}

/// Twice the signed area of (a, b, c): > 0 counter-clockwise.
double orient(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/// Convex: every corner turns left or goes straight, and the ring winds once (the signs of
/// the edges' x and y steps change at most twice each around it, which a star does not meet).
bool is_convex(const std::vector<glm::dvec2>& p) {
  const std::size_t n = p.size();
  int x_changes = 0, y_changes = 0;
  double last_dx = 0.0, last_dy = 0.0;
  for (std::size_t i = 0; i <= n; ++i) {  // one edge past the start closes the sign count
    const glm::dvec2& a = p[i % n];
    const glm::dvec2& b = p[(i + 1) % n];
    const glm::dvec2& c = p[(i + 2) % n];
    if (i < n && orient(a, b, c) < 0.0) return false;
    const double dx = b.x - a.x, dy = b.y - a.y;
    if (dx != 0.0) {
      if (last_dx != 0.0 && (dx > 0.0) != (last_dx > 0.0)) ++x_changes;
      last_dx = dx;
    }
    if (dy != 0.0) {
      if (last_dy != 0.0 && (dy > 0.0) != (last_dy > 0.0)) ++y_changes;
      last_dy = dy;
    }
  }
  return x_changes <= 2 && y_changes <= 2;
}

/// p inside or on the boundary of the counter-clockwise triangle (a, b, c).
bool inside_or_on(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b,
                  const glm::dvec2& c) {
  return orient(a, b, p) >= 0.0 && orient(b, c, p) >= 0.0 && orient(c, a, p) >= 0.0;
}

void append_fan(std::size_t n, std::vector<std::uint32_t>& out) {
  for (std::size_t k = 1; k + 1 < n; ++k) {
    out.insert(out.end(), {0u, static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(k + 1)});
  }
}

/// Ear clipping of a counter-clockwise ring. Corner b (between a and c) is an ear when it
/// turns left and no other remaining corner lies in or on triangle (a, b, c) (corners at the
/// same point as a, b or c do not count, so rings that touch themselves still clip); a corner
/// that goes straight (zero area) is clipped as well. False when a whole round finds no ear
/// (self-intersecting ring); `out` is then unchanged.
bool clip_ears(const std::vector<glm::dvec2>& p, std::vector<std::uint32_t>& out) {
  const std::size_t n = p.size();
  std::vector<std::uint32_t> prev(n), next(n);
  for (std::size_t i = 0; i < n; ++i) {
    prev[i] = static_cast<std::uint32_t>((i + n - 1) % n);
    next[i] = static_cast<std::uint32_t>((i + 1) % n);
  }
  // Per corner, the remaining corner last found in or on its triangle and the neighbours it
  // had then: while the neighbours are the same and that corner has not been clipped, the
  // same point lies in the same triangle, so the corner is still no ear and is not scanned
  // again. The result is the same as scanning every time; without this, the rounds that find
  // no ear rescan all corners and a 4096-corner face took seconds (issue 28).
  constexpr std::uint32_t kNone = 0xffffffffu;
  std::vector<std::uint32_t> witness(n, kNone), witness_prev(n), witness_next(n);
  std::vector<bool> clipped(n, false);
  std::vector<std::uint32_t> triangles;
  std::size_t remaining = n;
  std::uint32_t b = 0;
  std::size_t tried = 0;  // corners tried since the last ear
  while (remaining > 3) {
    const std::uint32_t a = prev[b], c = next[b];
    const double turn = orient(p[a], p[b], p[c]);
    bool ear = turn == 0.0;
    if (turn > 0.0) {
      const std::uint32_t w = witness[b];
      ear = !(w != kNone && !clipped[w] && witness_prev[b] == a && witness_next[b] == c);
      // A point in or on the triangle lies in its bounding box: the box is the cheap test.
      const glm::dvec2 lo = glm::min(p[a], glm::min(p[b], p[c]));
      const glm::dvec2 hi = glm::max(p[a], glm::max(p[b], p[c]));
      for (std::uint32_t q = next[c]; q != a && ear; q = next[q]) {
        const glm::dvec2& pq = p[q];
        if (pq.x < lo.x || pq.x > hi.x || pq.y < lo.y || pq.y > hi.y) continue;
        if (pq == p[a] || pq == p[b] || pq == p[c]) continue;
        if (inside_or_on(p[q], p[a], p[b], p[c])) {
          ear = false;
          witness[b] = q;
          witness_prev[b] = a;
          witness_next[b] = c;
        }
      }
    }
    if (ear) {
      triangles.insert(triangles.end(), {a, b, c});
      next[a] = c;
      prev[c] = a;
      clipped[b] = true;
      --remaining;
      tried = 0;
      b = c;
    } else {
      if (++tried > remaining) return false;
      b = c;
    }
  }
  triangles.insert(triangles.end(), {prev[b], b, next[b]});
  out.insert(out.end(), triangles.begin(), triangles.end());
  return true;
}

}  // namespace

PolygonSplit triangulate_polygon(const std::vector<glm::dvec3>& ring,
                                 std::vector<std::uint32_t>& out) {
  const std::size_t n = ring.size();
  if (n <= 3) {
    append_fan(n, out);
    return PolygonSplit::Fan;
  }
  const glm::dvec3 normal = newell_normal(ring);
  const double length = glm::length(normal);
  if (!(length > 0.0) || !std::isfinite(length)) {
    append_fan(n, out);  // no plane: all corners on one line or point, or non-finite
    return PolygonSplit::Fallback;
  }
  const std::vector<glm::dvec2> flat = project(ring, normal);
  if (is_convex(flat)) {
    append_fan(n, out);
    return PolygonSplit::Fan;
  }
  if (n > kMaxEarClipCorners || !clip_ears(flat, out)) {
    append_fan(n, out);
    return PolygonSplit::Fallback;
  }
  return PolygonSplit::EarClipped;
}

}  // namespace covrast::detail
