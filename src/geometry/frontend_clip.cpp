// Geometry stage, clipping (frontend.hpp): a triangle with a vertex outside the near or far
// plane or the guard band (its outcodes), clipped in homogeneous clip space
// (Sutherland-Hodgman) to a convex polygon whose vertices are then snapped; frontend.cpp
// emits the polygon as a fan. The side planes lie kGuardBandPx beyond the image, so few
// triangles come here.
#include "geometry/frontend_stages.hpp"

#include <array>

namespace covrast::detail {
namespace {

struct ClipVertex {
  glm::dvec4 position;
  glm::vec3 color;
  ShadeVertex shade;  ///< lit triangles only
};

/// Up to 3 + 6 planes' worth of vertices after Sutherland-Hodgman.
using ClipPolygon = std::array<ClipVertex, 12>;
}  // namespace

void GeometryFrontEnd::clip_triangle(std::size_t instance, const glm::dmat4& mvp,
                                     const std::uint32_t* idx, const glm::vec3* color,
                                     unsigned out_any, const ShadeVertex* shade,
                                     ClippedPolygon& out) const {
  const std::vector<glm::vec3>& positions = scene_.meshes[instance].mesh->positions;
  ClipPolygon poly, next;
  for (int k = 0; k < 3; ++k) {
    poly[k] = ClipVertex{clip_position(mvp, positions[idx[k]]), color[k],
                         shade != nullptr ? shade[k] : ShadeVertex{}};
  }
  int count = 3;
  // Sutherland-Hodgman. The intersection on an edge is always computed from its inside
  // vertex towards its outside vertex, so that two triangles sharing the edge get the
  // same point bit for bit (watertight clipping).
  for (int p = 0; p < 6 && count >= 3; ++p) {
    if (!(out_any & (1u << p))) continue;
    int n = 0;
    for (int k = 0; k < count; ++k) {
      const ClipVertex& a = poly[k];
      const ClipVertex& b = poly[(k + 1) % count];
      const double da = glm::dot(planes_[p], a.position);
      const double db = glm::dot(planes_[p], b.position);
      if (da >= 0.0) next[n++] = a;
      if ((da >= 0.0) != (db >= 0.0)) {
        const ClipVertex& in = da >= 0.0 ? a : b;
        const ClipVertex& outv = da >= 0.0 ? b : a;
        const double din = da >= 0.0 ? da : db;
        const double dout = da >= 0.0 ? db : da;
        const double t = din / (din - dout);
        next[n].position = in.position + t * (outv.position - in.position);
        next[n].color = in.color + float(t) * (outv.color - in.color);
        // Attributes are affine in clip space, so the same t interpolates them.
        if (shade != nullptr) {
          const ShadeVertex &a_in = in.shade, &a_out = outv.shade;
          next[n].shade.position_world =
              a_in.position_world + float(t) * (a_out.position_world - a_in.position_world);
          next[n].shade.normal_world =
              a_in.normal_world + float(t) * (a_out.normal_world - a_in.normal_world);
          for (int set = 0; set < kMaxTexcoordSets; ++set) {
            next[n].shade.uv[set] = a_in.uv[set] + float(t) * (a_out.uv[set] - a_in.uv[set]);
          }
          next[n].shade.tangent_world =
              a_in.tangent_world + float(t) * (a_out.tangent_world - a_in.tangent_world);
          next[n].shade.alpha = a_in.alpha + float(t) * (a_out.alpha - a_in.alpha);
        }
        ++n;
      }
    }
    std::swap(poly, next);
    count = n;
  }
  out.count = count;
  if (count < 3) return;
  for (int k = 0; k < count; ++k) {
    out.snapped[k] = snap(poly[k].position);
    out.color[k] = poly[k].color;
    if (shade != nullptr) out.shade[k] = poly[k].shade;
  }
}

}  // namespace covrast::detail
