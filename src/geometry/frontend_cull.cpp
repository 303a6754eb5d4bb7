// Geometry stage, culling (frontend.hpp): which triangles never reach set-up. Per instance
// and frame: the hidden back faces of closed meshes (drop_facing; the argument below says why
// dropping them never changes the image) and the back faces of single-sided materials
// (set_single_sided); from the same mesh analysis, whether the surface is convex
// (convex_surface, a set-up flag). The per-triangle culls that apply them are in
// frontend_cull.hpp.
#include "geometry/frontend_stages.hpp"

#include <cmath>

namespace covrast::detail {

// Hidden back-face culling. The back faces of an instance are dropped when all of these hold:
//  (a) its mesh is closed and consistently oriented, every edge-connected component with a
//      clearly non-zero signed volume of one sign s_mesh (analyze_mesh_topology);
//  (b) the model matrix is affine with det != 0, and the eye, taken into object space, lies
//      strictly outside the mesh's bounding box;
//  (c) this frame, no vertex of the instance is outside the near or the far plane.
// Why the image cannot change: orient every face by s_world = s_mesh * sign(det(model)) (a
// mirroring model matrix flips it), so that all components face outwards. The winding number
// of the surface is then 0 outside it and >= 0 everywhere (for a surface that does not pass
// through itself), and it changes by +1 where a ray crosses a face from its outer side. A ray
// from the eye starts at winding 0 ((b): the eye is outside the box, so outside the surface),
// so the first face it meets is crossed from the outside: a front face. By (c) no clip plane
// cuts the surface open (the side planes act only beyond the guard band, outside the image),
// so every triangle reaches the screen whole, and along every ray through the image a front
// face of the instance lies in front of each of its back faces: no back face is ever the
// nearest surface. An outward face seen from outside is counter-clockwise on screen when
// s_world > 0, so the dropped facing is clockwise (front_facing false) for s_world > 0 and
// counter-clockwise for s_world < 0.
// With a perspective camera, (c) alone already puts the eye outside the mesh's convex hull
// (every vertex is at least `near` in front of it); (b) is a cheap second guard. With an
// orthographic camera the rays are parallel and start on the near plane, and (c) puts every
// vertex beyond it, so every ray starts outside the surface by (c) alone; (b), still tested,
// can then only keep back faces that could have been dropped.
// Snapping keeps shared vertices shared, so the snapped surface is closed too; the only place
// where a back face can tie with (or, by a rounding step, beat) a front face is an edge where
// the two meet, both of the same instance: with a uniform colour the pixel is the same either
// way. Not detected: a single surface that passes through itself with part of it turned
// inside out (negative winding); such a mesh is not a valid solid.

unsigned GeometryFrontEnd::cullable_facing(const MeshInstance& instance, const glm::dvec3& eye) {
  const MeshData& mesh = *instance.mesh;
  if (mesh.closed_orientation == 0 || mesh.analyzed_triangle_count != mesh.triangle_count()) {
    return 0;  // (a) fails, or the analysis is stale
  }
  const glm::dmat4& m = instance.model;
  // (b). Affine: the bottom row (GLM: m[column][3]) is (0, 0, 0, 1), so w stays 1 and the
  // orientation in world space is the sign of the 3x3 part's determinant.
  if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0) return 0;
  const double det = glm::determinant(glm::dmat3(m));
  if (!std::isfinite(det) || det == 0.0) return 0;
  const glm::dvec3 e = glm::dvec3(glm::inverse(m) * glm::dvec4(eye, 1.0));
  const glm::dvec3 lo(mesh.bounds_min), hi(mesh.bounds_max);
  // Written so that NaN (a degenerate inverse) counts as inside.
  const bool outside =
      e.x < lo.x || e.x > hi.x || e.y < lo.y || e.y > hi.y || e.z < lo.z || e.z > hi.z;
  if (!outside) return 0;
  const int world_sign = det > 0.0 ? mesh.closed_orientation : -mesh.closed_orientation;
  return world_sign > 0 ? kDropClockwise : kDropCounterClockwise;
}

unsigned GeometryFrontEnd::drop_facing(std::size_t instance) const {
  // A MASK or BLEND surface may show its back faces through its front ones.
  if (!cull_hidden_backfaces_ || instance_alpha(instance)) return 0;
  // (a) and (b) from the instance as it is now (its model matrix may change between frames).
  // Once per instance and chunk; meshes that are not closed stop at the first test.
  const unsigned facing = cullable_facing(scene_.meshes[instance], eye_);
  if (facing == 0) return 0;
  // (c), from this frame's outcodes (unreferenced vertices included: conservative).
  unsigned codes = 0;
  for (const std::uint8_t block : vertices_[instance].block_outcodes) codes |= block;
  return (codes & kNearFarBits) != 0 ? 0 : facing;
}

bool GeometryFrontEnd::convex_surface(std::size_t instance) const {
  const MeshInstance& inst = scene_.meshes[instance];
  const MeshData& mesh = *inst.mesh;
  const glm::dmat4& m = inst.model;
  return mesh.convex && mesh.analyzed_triangle_count == mesh.triangle_count() && m[0][3] == 0.0 &&
         m[1][3] == 0.0 && m[2][3] == 0.0 && m[3][3] == 1.0;
}

void GeometryFrontEnd::prepare_single_sided() {
  single_sided_kind_.assign(scene_.meshes.size(), 0);
  single_sided_triangles_.resize(scene_.meshes.size());
  for (std::size_t i = 0; i < scene_.meshes.size(); ++i) {
    const std::vector<Material>& materials = scene_.meshes[i].materials;
    std::size_t single = 0;
    for (const Material& m : materials) single += m.double_sided ? 0 : 1;
    if (single == 0) continue;
    const MeshData& mesh = *scene_.meshes[i].mesh;
    // All single-sided, or one material for every triangle (triangle_materials empty: all
    // use materials[0]): the whole instance; else a flag per triangle from its material.
    if (single == materials.size()) {
      single_sided_kind_[i] = 1;
      continue;
    }
    if (mesh.triangle_materials.empty()) {
      single_sided_kind_[i] = materials[0].double_sided ? 0 : 1;
      continue;
    }
    single_sided_kind_[i] = 2;
    std::vector<std::uint8_t>& flags = single_sided_triangles_[i];
    flags.resize(mesh.triangle_count());
    for (std::size_t t = 0; t < flags.size(); ++t) {
      flags[t] = materials[mesh.triangle_materials[t]].double_sided ? 0 : 1;
    }
  }
}

void GeometryFrontEnd::set_single_sided(std::size_t instance, Sink& sink) const {
  sink.cull_facing = 0;
  sink.single_sided = nullptr;
  if (single_sided_kind_[instance] == 0) return;
  // A back face is the file's counter-clockwise front turned away: clockwise on screen, or
  // counter-clockwise under a mirroring model matrix (the normal flip in set_up_shading).
  const bool mirrored = glm::determinant(glm::dmat3(scene_.meshes[instance].model)) < 0.0;
  sink.cull_facing = mirrored ? kDropCounterClockwise : kDropClockwise;
  sink.first_primitive = first_triangle_[instance];
  if (single_sided_kind_[instance] == 2) {
    sink.single_sided = single_sided_triangles_[instance].data();
  }
}

}  // namespace covrast::detail
