// Geometry stage, transform (frontend.hpp): each instance's vertices taken to clip space
// once per frame, classified against the clip planes (outcodes) and, when inside all of them,
// snapped to 24.8 fixed point; two vertices per step in two-lane doubles, bit for bit the
// one-vertex path.
#include "geometry/frontend_stages.hpp"

namespace covrast::detail {
namespace {

/// 0 where x, y, z and w are all finite (x - x is 0 for finite x), NaN otherwise; lane by
/// lane for T = Double2.
template <class T>
inline T finite_test(T x, T y, T z, T w) {
  return (x - x) + (y - y) + (z - z) + (w - w);
}

/// Bit `bit` of an outcode where `outside` holds: a bool (T = double) or a lane mask of 0 or
/// -1 (T = Double2).
inline unsigned plane_bit(bool outside, int bit) { return unsigned(outside) << bit; }
template <class Mask>
inline Mask plane_bit(Mask outside, int bit) {
  return outside & (1 << bit);
}

/// The outcode of clip position (x, y, z, w) for GeometryFrontEnd's planes, without their zero
/// terms (valid for finite coordinates; see fast_outcode): near, far, left, right, bottom,
/// top, with guard-band factors gx, gy.
template <class T>
inline auto outcode_bits(T x, T y, T z, T w, double gx, double gy) {
  const T gxw = gx * w, gyw = gy * w;
  return plane_bit(z + w < 0.0, 0) | plane_bit(-z + w < 0.0, 1) | plane_bit(x + gxw < 0.0, 2) |
         plane_bit(-x + gxw < 0.0, 3) | plane_bit(y + gyw < 0.0, 4) | plane_bit(-y + gyw < 0.0, 5);
}
}  // namespace

std::size_t GeometryFrontEnd::vertex_count(std::size_t instance) const {
  return scene_.meshes[instance].mesh->positions.size();
}

inline unsigned GeometryFrontEnd::outcode(const glm::dvec4& clip) const {
  unsigned code = 0;
  for (int p = 0; p < 6; ++p) {
    if (glm::dot(planes_[p], clip) < 0.0) code |= 1u << p;
  }
  return code;
}

// outcode() for the planes the constructor sets, without their zero terms. glm::dot sums
// (a.x b.x + a.y b.y) + (a.z b.z + a.w b.w); a zero coefficient times a finite coordinate
// is +-0, and adding +-0 changes a sum at most in the sign of a zero result, which `< 0`
// does not see. So for finite coordinates each test below is the plane's dot product test,
// e.g. left: (x + 0 y) + (0 z + g_x w) < 0  <=>  x + g_x w < 0. A non-finite coordinate
// (0 * inf = NaN) takes the general loop.
inline unsigned GeometryFrontEnd::fast_outcode(const glm::dvec4& c) const {
  if (!(finite_test(c.x, c.y, c.z, c.w) == 0.0)) return outcode(c);
  return outcode_bits(c.x, c.y, c.z, c.w, guard_x_, guard_y_);
}

void GeometryFrontEnd::transform_vertices(std::size_t instance, std::size_t begin,
                                          std::size_t end) {
  const MeshInstance& inst = scene_.meshes[instance];
  const glm::dmat4 mvp = view_projection_ * inst.model;
  InstanceVertices& out = vertices_[instance];
  const std::vector<glm::vec3>& positions = inst.mesh->positions;
  const double width = width_px_, height = height_px_;
  // Block by block, each block's outcode union into its own slot.
  for (std::size_t block_begin = begin; block_begin < end;) {
    const std::size_t block = block_begin / kVerticesPerTransformBlock;
    const std::size_t block_end = std::min(end, (block + 1) * kVerticesPerTransformBlock);
    unsigned codes = 0;
    const auto one_vertex = [&](std::size_t v) {
      const glm::dvec4 clip = clip_position(mvp, positions[v]);
      const auto code = std::uint8_t(fast_outcode(clip));
      out.outcode[v] = code;
      codes |= code;
      if (code == 0) out.snapped[v] = snap(clip);
    };
    std::size_t v = block_begin;
    // Two vertices per step: lane k runs the one-vertex path's templates (finite_test,
    // outcode_bits, to_screen, snapped_vertex) on vertex v + k.
    for (; v + 2 <= block_end; v += 2) {
      const glm::vec3& p0 = positions[v];
      const glm::vec3& p1 = positions[v + 1];
      const Double2 x = {p0.x, p1.x}, y = {p0.y, p1.y}, z = {p0.z, p1.z};
      const Double2 cx = clip_row(mvp, 0, x, y, z), cy = clip_row(mvp, 1, x, y, z);
      const Double2 cz = clip_row(mvp, 2, x, y, z), cw = clip_row(mvp, 3, x, y, z);
      const Double2 finite = finite_test(cx, cy, cz, cw);
      if (!(finite[0] == 0.0 && finite[1] == 0.0)) {
        one_vertex(v);
        one_vertex(v + 1);
        continue;
      }
      const auto code2 = outcode_bits(cx, cy, cz, cw, guard_x_, guard_y_);
      const ScreenPosition<Double2> p = to_screen(cx, cy, cz, cw, width, height);
      for (int k = 0; k < 2; ++k) {
        const auto code = std::uint8_t(code2[k]);
        out.outcode[v + k] = code;
        codes |= code;
        if (code == 0) {
          out.snapped[v + k] = snapped_vertex(p.x_fx8[k], p.y_fx8[k], p.z_window[k], p.inv_w[k]);
        }
      }
    }
    if (v < block_end) one_vertex(v);
    out.block_outcodes[block] = std::uint8_t(codes);
    block_begin = block_end;
  }
  if (instance_lit(instance)) {
    for (std::size_t v = begin; v < end; ++v) {
      out.position_world[v] = glm::vec3(inst.model * glm::dvec4(glm::dvec3(positions[v]), 1.0));
    }
  }
  if (inst.color_source == ColorSource::Vertex) {
    const auto& colors = inst.mesh->colors_linear;
    for (std::size_t v = begin; v < end; ++v) {
      glm::vec3 c = v < colors.size() ? colors[v] : glm::vec3(1.0f);
      out.color_linear[v] = c * inst.color_factor_linear;
    }
  }
}

}  // namespace covrast::detail
