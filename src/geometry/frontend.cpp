// Geometry stage (frontend.hpp): transform, clip, cull and triangle set-up; the shading
// set-up (lights, materials, per-corner shading inputs) is in frontend_shading.cpp.
#include "geometry/frontend.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <new>

#ifdef __linux__
#include <sys/mman.h>
#endif

#if defined(__x86_64__) || defined(_M_X64)
#include <emmintrin.h>
#endif

namespace covrast::detail {
namespace {

struct ClipVertex {
  glm::dvec4 position;
  glm::vec3 color;
  ShadeVertex shade;  ///< lit triangles only
};

/// Up to 3 + 6 planes' worth of vertices after Sutherland-Hodgman.
using ClipPolygon = std::array<ClipVertex, 12>;

/// Homogeneous plane: inside where dot(plane, position) >= 0.
using ClipPlane = glm::dvec4;

/// Outcode bits of the near and far planes (planes_[0] and planes_[1]).
constexpr unsigned kNearFarBits = 1u << 0 | 1u << 1;

/// Two doubles in one SSE2 / NEON register (GCC and Clang vector extension); arithmetic on
/// it is lane-wise IEEE arithmetic, the same results as on each lane alone.
using Double2 = double __attribute__((vector_size(16)));

/// Row r of mvp * (x, y, z, 1): the one expression for a model-space position in clip space.
/// transform_vertices (two vertices at a time, T = Double2, or one, T = double) and
/// clip_triangle both use it, so (with -ffp-contract=off) a vertex gets the same clip
/// position, bit for bit, whichever computes it. The order is glm's for mat4 * vec4,
/// (m0 x + m1 y) + (m2 z + m3 * 1), with m3 * 1 = m3.
template <class T>
inline T clip_row(const glm::dmat4& mvp, int r, T x, T y, T z) {
  return (mvp[0][r] * x + mvp[1][r] * y) + (mvp[2][r] * z + mvp[3][r]);
}

inline glm::dvec4 clip_position(const glm::dmat4& mvp, const glm::vec3& position) {
  const double x = position.x, y = position.y, z = position.z;
  return glm::dvec4(clip_row(mvp, 0, x, y, z), clip_row(mvp, 1, x, y, z), clip_row(mvp, 2, x, y, z),
                    clip_row(mvp, 3, x, y, z));
}

/// std::llrint(v) in the current rounding mode. glibc's x86-64 llrint is the single
/// instruction cvtsd2si (round to nearest even; 0x8000000000000000 for NaN and overflow),
/// but without -fno-math-errno the compiler keeps it an out-of-line call: issued here
/// directly it is the same instruction, inlined. Elsewhere the library call.
inline std::int64_t round_to_int64(double v) {
#if defined(__x86_64__) || defined(_M_X64)
  return _mm_cvtsd_si64(_mm_set_sd(v));
#else
  return std::llrint(v);
#endif
}

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

/// The viewport transform of a clip position, before rounding: x and y in 24.8 units, window
/// z (not yet clamped) and 1 / w.
template <class T>
struct ScreenPosition {
  T x_fx8, y_fx8, z_window, inv_w;
};
template <class T>
inline ScreenPosition<T> to_screen(T x, T y, T z, T w, double width_px, double height_px) {
  const T inv_w = 1.0 / w;
  return ScreenPosition<T>{(x * inv_w + 1.0) * 0.5 * width_px * double(kSubpixelOne),
                           (1.0 - y * inv_w) * 0.5 * height_px * double(kSubpixelOne),
                           z * inv_w * 0.5 + 0.5, inv_w};
}

/// One screen position rounded to the snapped vertex.
inline SnappedVertex snapped_vertex(double x_fx8, double y_fx8, double z_window, double inv_w) {
  return SnappedVertex{std::int32_t(round_to_int64(x_fx8)), std::int32_t(round_to_int64(y_fx8)),
                       std::clamp(z_window, 0.0, 1.0), float(inv_w)};
}
}  // namespace

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

GeometryFrontEnd::GeometryFrontEnd(const Scene& scene, int width_px, int height_px,
                                   bool cull_hidden_backfaces)
    : scene_(scene),
      width_px_(width_px),
      height_px_(height_px),
      cull_hidden_backfaces_(cull_hidden_backfaces),
      eye_(scene.camera.eye) {
  context_.tone_mapping = {ToneMapOperator(int(scene.tone_map)), scene.exposure};
  const Camera& cam = scene.camera;
  glm::dmat4 view = glm::lookAt(cam.eye, cam.target, cam.up);
  const double aspect = double(width_px) / double(height_px);
  // Orthographic: w = 1 for every vertex, so the perspective-correct weights (lambda_i / w_i,
  // renormalised) are the screen barycentrics, as a parallel projection needs.
  glm::dmat4 projection =
      cam.orthographic ? glm::ortho(-cam.ymag * aspect, cam.ymag * aspect, -cam.ymag, cam.ymag,
                                    cam.near, cam.far)
                       : glm::perspective(glm::radians(cam.fovy_deg), aspect, cam.near, cam.far);
  view_projection_ = projection * view;
  guard_x_ = 1.0 + 2.0 * kGuardBandPx / width_px;
  guard_y_ = 1.0 + 2.0 * kGuardBandPx / height_px;
  planes_[0] = ClipPlane(0, 0, 1, 1);          // near: z >= -w
  planes_[1] = ClipPlane(0, 0, -1, 1);         // far: z <= w
  planes_[2] = ClipPlane(1, 0, 0, guard_x_);   // guard band left
  planes_[3] = ClipPlane(-1, 0, 0, guard_x_);  // guard band right
  planes_[4] = ClipPlane(0, 1, 0, guard_y_);   // guard band bottom
  planes_[5] = ClipPlane(0, -1, 0, guard_y_);  // guard band top
  first_triangle_.push_back(0);
  for (const MeshInstance& m : scene.meshes) {
    first_triangle_.push_back(first_triangle_.back() + m.mesh->triangle_count());
  }
  vertices_.resize(scene.meshes.size());
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    vertices_[i].block_outcodes.resize(
        (scene.meshes[i].mesh->positions.size() + kVerticesPerTransformBlock - 1) /
        kVerticesPerTransformBlock);
    vertices_[i].outcode.resize(scene.meshes[i].mesh->positions.size());
    vertices_[i].snapped.resize(scene.meshes[i].mesh->positions.size());
    if (scene.meshes[i].color_source == ColorSource::Vertex) {
      vertices_[i].color_linear.resize(scene.meshes[i].mesh->positions.size());
    }
  }
  bool any_alpha = false;
  for (const MeshInstance& m : scene.meshes) {
    for (const Material& material : m.materials) {
      any_alpha = any_alpha || material.alpha_mode != AlphaMode::Opaque;
    }
  }
  if (scene.lit || any_alpha || shows_textures(scene)) prepare_lighting();
  prepare_single_sided();
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
  // counter-clockwise under a mirroring model matrix (the normal flip in emit_triangle).
  const bool mirrored = glm::determinant(glm::dmat3(scene_.meshes[instance].model)) < 0.0;
  sink.cull_facing = mirrored ? kDropCounterClockwise : kDropClockwise;
  sink.first_primitive = first_triangle_[instance];
  if (single_sided_kind_[instance] == 2) {
    sink.single_sided = single_sided_triangles_[instance].data();
  }
}

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

// Inline, so that transform_vertices writes the snapped vertex in place (a returned copy
// costs a store-forwarding stall per vertex).
inline SnappedVertex GeometryFrontEnd::snap(const glm::dvec4& c) const {
  const ScreenPosition<double> p = to_screen(c.x, c.y, c.z, c.w, width_px_, height_px_);
  return snapped_vertex(p.x_fx8, p.y_fx8, p.z_window, p.inv_w);
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

void GeometryFrontEnd::setup_chunk(std::uint32_t chunk, std::vector<TriangleSetup>& out,
                                   SetupCounters& counters) const {
  Sink sink{&out, nullptr, nullptr, counters};
  setup_range(chunk, sink);
}

void GeometryFrontEnd::setup_chunk(std::uint32_t chunk, ChunkSetups& out,
                                   std::vector<PixelBounds16>& bounds,
                                   SetupCounters& counters) const {
  Sink sink{nullptr, &out, &bounds, counters};
  setup_range(chunk, sink);
}

void advise_huge_pages([[maybe_unused]] void* data, [[maybe_unused]] std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  // The whole huge pages inside the range: [round_up(begin), round_down(end)).
  const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
  const std::uintptr_t last = (begin + bytes) & ~(kHugePageBytes - 1);
  // The result is ignored: without huge pages the memory simply stays in 4 KiB pages.
  if (data != nullptr && first < last) {
    (void)madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
  }
#endif
}

HugePageBuffer::HugePageBuffer(std::size_t bytes)
    // Whole huge pages, so that the last one is advised too.
    : bytes_((std::max<std::size_t>(bytes, 1) + kHugePageBytes - 1) & ~(kHugePageBytes - 1)) {
  data_ = ::operator new(bytes_, std::align_val_t(kHugePageBytes));
  advise_huge_pages(data_, bytes_);
}

HugePageBuffer::~HugePageBuffer() {
  if (data_ != nullptr) ::operator delete(data_, std::align_val_t(kHugePageBytes));
}

TriangleSetup& ChunkSetups::grow() {
  // Twice the room, default-initialised (every field is written by setup), the triangles so
  // far copied over; further growth stays in the own array.
  const std::size_t capacity = std::max<std::size_t>(2 * capacity_, 64);
  std::unique_ptr<TriangleSetup[]> bigger =
      std::make_unique_for_overwrite<TriangleSetup[]>(capacity);
  std::copy(data_, data_ + size_, bigger.get());
  overflow_ = std::move(bigger);
  data_ = overflow_.get();
  capacity_ = capacity;
  return data_[size_++];
}

void GeometryFrontEnd::setup_range(std::uint32_t chunk, Sink& sink) const {
  const std::uint64_t first = std::uint64_t(chunk) * kTrianglesPerChunk;
  const std::uint64_t last = std::min<std::uint64_t>(first + kTrianglesPerChunk, triangle_count());
  if (!chunk_shading_.empty()) {
    chunk_shading_[chunk].clear();
    sink.shading = &chunk_shading_[chunk];
    chunk_textured_[chunk].clear();
    sink.textured = &chunk_textured_[chunk];
  }
  // The instance holding `first`: first_triangle_ is sorted, find the last entry <= first.
  std::size_t instance =
      std::size_t(std::upper_bound(first_triangle_.begin(), first_triangle_.end(), first) -
                  first_triangle_.begin()) -
      1;
  // One run of triangles per instance, with the instance's data looked up once.
  for (std::uint64_t g = first; g < last; ++instance) {
    const std::uint64_t run_end = std::min(last, first_triangle_[instance + 1]);
    if (g >= run_end) continue;  // an instance without triangles
    const MeshInstance& inst = scene_.meshes[instance];
    const InstanceVertices& iv = vertices_[instance];
    const glm::dmat4 mvp = view_projection_ * inst.model;
    sink.drop_facing = drop_facing(instance);
    sink.convex_surface = convex_surface(instance);
    set_single_sided(instance, sink);
    if (instance_lit(instance) || instance_alpha(instance)) {
      setup_lit_run(instance, g, run_end, sink);
      g = run_end;
      continue;
    }
    const std::uint32_t* indices = inst.mesh->indices.data() + (g - first_triangle_[instance]) * 3;
    // A uniform colour is flat unless it is NaN (the per-triangle comparison's result).
    const glm::vec3 uniform = inst.color_linear;
    const bool uniform_flat = uniform == uniform;
    for (; g < run_end; ++g, indices += 3) {
      const auto primitive = std::uint32_t(g);
      // The triangle's vertex colours, by reference: no copies for the common uniform case.
      glm::vec3 triangle_color;
      const glm::vec3* c0;
      const glm::vec3* c1;
      const glm::vec3* c2;
      bool flat;
      switch (inst.color_source) {
        case ColorSource::Uniform:
          c0 = c1 = c2 = &uniform;
          flat = uniform_flat;
          break;
        case ColorSource::PerTriangle: {
          triangle_color = per_triangle_color_linear(primitive);
          c0 = c1 = c2 = &triangle_color;
          flat = triangle_color == triangle_color;
          break;
        }
        case ColorSource::Vertex:
        default:
          c0 = &iv.color_linear[indices[0]];
          c1 = &iv.color_linear[indices[1]];
          c2 = &iv.color_linear[indices[2]];
          flat = *c0 == *c1 && *c0 == *c2;
          break;
      }
      // Outcodes: trivially reject when all three are outside one plane; trivially accept
      // (with the vertices snapped once in transform_vertices) when none is outside any.
      const unsigned o0 = iv.outcode[indices[0]], o1 = iv.outcode[indices[1]],
                     o2 = iv.outcode[indices[2]];
      if ((o0 & o1 & o2) != 0) {
        ++sink.counters.culled;
      } else if ((o0 | o1 | o2) == 0) {
        emit_triangle(iv.snapped[indices[0]], iv.snapped[indices[1]], iv.snapped[indices[2]], *c0,
                      *c1, *c2, flat, primitive, std::uint32_t(instance), sink);
      } else {
        const glm::vec3 color[3] = {*c0, *c1, *c2};
        clip_triangle(instance, mvp, indices, color, flat, o0 | o1 | o2, primitive, sink);
      }
    }
  }
}

// Inlined into setup_range's loop: as a call it spilled its arguments and the caller's
// state on every triangle.
[[gnu::always_inline]] inline void GeometryFrontEnd::emit_triangle(
    const SnappedVertex& v0, const SnappedVertex& v1, const SnappedVertex& v2,
    const glm::vec3& color0, const glm::vec3& color1, const glm::vec3& color2, bool flat,
    std::uint32_t primitive, std::uint32_t surface, Sink& sink, const ShadeVertex* shade,
    const SurfaceShading* lit, const LazyShade* lazy) const {
  const std::int64_t ax = v1.x_fx8 - v0.x_fx8, ay = v1.y_fx8 - v0.y_fx8;
  const std::int64_t bx = v2.x_fx8 - v0.x_fx8, by = v2.y_fx8 - v0.y_fx8;
  const std::int64_t area2 = ax * by - bx * ay;
  if (area2 == 0) {
    ++sink.counters.culled;
    return;
  }
  // Reject triangles wholly outside the image.
  const PixelRect r =
      touched_pixels({v0.x_fx8, v1.x_fx8, v2.x_fx8}, {v0.y_fx8, v1.y_fx8, v2.y_fx8});
  if (r.x1 <= 0 || r.y1 <= 0 || r.x0 >= width_px_ || r.y0 >= height_px_) {
    ++sink.counters.culled;
    return;
  }
  // CCW in NDC (y up) is negative area with y down. Checked after the image test, so that
  // backface_culled counts exactly the triangles that culling keeps from binning.
  const bool front = area2 < 0;
  const unsigned facing = front ? kDropCounterClockwise : kDropClockwise;
  if ((sink.drop_facing & facing) != 0) {
    ++sink.counters.culled;
    ++sink.counters.backface_culled;
    return;
  }
  // glTF 2.0, 3.9.5: the back faces of a single-sided material are not drawn.
  if ((sink.cull_facing & facing) != 0 &&
      (sink.single_sided == nullptr || sink.single_sided[primitive - sink.first_primitive] != 0)) {
    ++sink.counters.culled;
    return;
  }
  if (sink.bounds != nullptr) {
    // Non-empty: a triangle of non-zero area has min < max on both axes.
    sink.bounds->push_back(PixelBounds16{
        std::uint16_t(std::max(r.x0, 0)), std::uint16_t(std::max(r.y0, 0)),
        std::uint16_t(std::min(r.x1, width_px_)), std::uint16_t(std::min(r.y1, height_px_))});
  }
  // Reorder to positive area.
  const SnappedVertex& s0 = v0;
  const SnappedVertex& s1 = front ? v2 : v1;
  const SnappedVertex& s2 = front ? v1 : v2;
  // Written in place: building a copy on the stack and pushing it costs store-forwarding
  // stalls on this hot path.
  TriangleSetup& t = sink.next();
  t.x_fx8[0] = s0.x_fx8;
  t.x_fx8[1] = s1.x_fx8;
  t.x_fx8[2] = s2.x_fx8;
  t.y_fx8[0] = s0.y_fx8;
  t.y_fx8[1] = s1.y_fx8;
  t.y_fx8[2] = s2.y_fx8;
  // Depth plane from the snapped positions.
  const double inv_one = 1.0 / kSubpixelOne;
  const double dx1 = (s1.x_fx8 - s0.x_fx8) * inv_one, dy1 = (s1.y_fx8 - s0.y_fx8) * inv_one;
  const double dx2 = (s2.x_fx8 - s0.x_fx8) * inv_one, dy2 = (s2.y_fx8 - s0.y_fx8) * inv_one;
  const double dz1 = s1.z_window - s0.z_window;
  const double dz2 = s2.z_window - s0.z_window;
  const double det = dx1 * dy2 - dx2 * dy1;
  t.z0 = s0.z_window;
  // Both slopes in one two-lane division (the same IEEE quotients as two scalar ones, at
  // half the divider time on this hot path).
  using Double2 = double __attribute__((vector_size(16)));
  const Double2 numerator = {dz1 * dy2 - dz2 * dy1, dx1 * dz2 - dx2 * dz1};
  const Double2 slope = numerator / Double2{det, det};
  t.dzdx = slope[0];
  t.dzdy = slope[1];
  t.inv_w[0] = s0.inv_w;
  t.inv_w[1] = s1.inv_w;
  t.inv_w[2] = s2.inv_w;
  t.color[0] = color0;
  t.color[1] = front ? color2 : color1;
  t.color[2] = front ? color1 : color2;
  t.primitive = primitive;
  t.surface = surface;
  t.front_facing = front;
  t.flat_color = flat;
  t.convex_surface = sink.convex_surface;
  t.shading = nullptr;
  t.alpha_mode = TriangleAlpha::Opaque;
  if (const ToneMapping& mapping = context_.tone_mapping;
      lit == nullptr && !mapping.is_identity()) {
    // Unlit colours are tone-mapped at the vertices (exact for uniform and per-triangle
    // colours; lit ones are tone-mapped where shade_lit makes them).
    for (glm::vec3& c : t.color) c = glm::vec3(tone_map(mapping, glm::dvec3(c)));
  }
  if (lit != nullptr) {
    // Computed only now, for triangles that survived every cull (half of a closed mesh's
    // are hidden back faces).
    ShadeVertex computed[3];
    if (lazy != nullptr) {
      shade_vertices(lazy->instance, lazy->local, *lazy->normal_matrix, *lazy->linear,
                     lazy->det_sign, *lit, computed);
      shade = computed;
    }
    ShadingRecord& record = sink.shading->emplace_back();
    // A back face (the file's counter-clockwise front turned away: clockwise on screen, or
    // counter-clockwise under a mirroring model matrix) of a double-sided material is lit
    // from the viewer's side: its normals flip (glTF 2.0, 3.9.5 doubleSided).
    const float sign = lit->double_sided && front == sink.mirrored ? -1.0f : 1.0f;
    const ShadeVertex* ordered[3] = {&shade[0], front ? &shade[2] : &shade[1],
                                     front ? &shade[1] : &shade[2]};
    for (int k = 0; k < 3; ++k) {
      record.position_world[k] = ordered[k]->position_world;
      record.normal_world[k] = sign * ordered[k]->normal_world;
      record.vertex_alpha[k] = ordered[k]->alpha;
    }
    record.surface = lit;
    record.textured = nullptr;
    if (lit->textures != nullptr) {
      // The tangent turns with the normal (xyz and the bitangent sign): the whole frame of a
      // back face is the front's mirrored, so its perturbed normal is the front's negated.
      TexturedCorners& corners = sink.textured->emplace_back();
      for (int k = 0; k < 3; ++k) {
        for (int set = 0; set < kMaxTexcoordSets; ++set) corners.uv[set][k] = ordered[k]->uv[set];
        corners.tangent_world[k] = sign * ordered[k]->tangent_world;
      }
      record.textured = &corners;
    }
    t.alpha_mode = lit->alpha_mode;
    t.shading = &record;
    t.flat_color = false;
  }
}

void GeometryFrontEnd::clip_triangle(std::size_t instance, const glm::dmat4& mvp,
                                     const std::uint32_t* idx, const glm::vec3* color, bool flat,
                                     unsigned out_any, std::uint32_t primitive, Sink& sink,
                                     const ShadeVertex* shade, const SurfaceShading* lit) const {
  const std::vector<glm::vec3>& positions = scene_.meshes[instance].mesh->positions;
  ++sink.counters.clipped;
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
  if (count < 3) {
    ++sink.counters.culled;
    return;
  }
  SnappedVertex s[12];
  glm::vec3 pc[12];
  for (int k = 0; k < count; ++k) {
    s[k] = snap(poly[k].position);
    pc[k] = poly[k].color;
  }
  // Fan (0, k, k+1) over the clipped polygon.
  for (int k = 1; k + 1 < count; ++k) {
    if (shade != nullptr) {
      const ShadeVertex fan[3] = {poly[0].shade, poly[k].shade, poly[k + 1].shade};
      emit_triangle(s[0], s[k], s[k + 1], pc[0], pc[k], pc[k + 1], flat, primitive,
                    std::uint32_t(instance), sink, fan, lit);
    } else {
      emit_triangle(s[0], s[k], s[k + 1], pc[0], pc[k], pc[k + 1], flat, primitive,
                    std::uint32_t(instance), sink);
    }
  }
}

void GeometryFrontEnd::setup_lit_run(std::size_t instance, std::uint64_t g, std::uint64_t end,
                                     Sink& sink) const {
  const MeshInstance& inst = scene_.meshes[instance];
  const InstanceVertices& iv = vertices_[instance];
  const glm::dmat4 mvp = view_projection_ * inst.model;
  const glm::dmat3 linear(inst.model);
  const double det = glm::determinant(linear);
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(linear));
  const double det_sign = det < 0.0 ? -1.0 : 1.0;
  sink.mirrored = det < 0.0;
  const std::vector<SurfaceShading>& surfaces = surfaces_[instance];
  const std::vector<std::uint32_t>& materials = inst.mesh->triangle_materials;
  const std::uint64_t first = first_triangle_[instance];
  for (; g < end; ++g) {
    const std::size_t local = std::size_t(g - first);
    const std::uint32_t* indices = inst.mesh->indices.data() + local * 3;
    const auto primitive = std::uint32_t(g);
    const std::size_t m = local < materials.size() ? materials[local] : 0;
    const SurfaceShading* lit = &surfaces[m < surfaces.size() ? m : 0];
    // The colours exactly as on the unlit path: they are the base colour.
    glm::vec3 color[3];
    switch (inst.color_source) {
      case ColorSource::Uniform:
        color[0] = color[1] = color[2] = inst.color_linear;
        break;
      case ColorSource::PerTriangle:
        color[0] = color[1] = color[2] = per_triangle_color_linear(primitive);
        break;
      case ColorSource::Vertex:
      default:
        for (int k = 0; k < 3; ++k) color[k] = iv.color_linear[indices[k]];
        break;
    }
    const bool flat = color[0] == color[1] && color[0] == color[2];
    const unsigned o0 = iv.outcode[indices[0]], o1 = iv.outcode[indices[1]],
                   o2 = iv.outcode[indices[2]];
    if ((o0 & o1 & o2) != 0) {
      ++sink.counters.culled;
      continue;
    }
    // Unlit and untextured: no shading inputs at all, the unlit path bit for bit; unlit
    // non-opaque ones get a record for their alpha (vertex alphas only, no positions or normals).
    const bool unlit = lit->model == LitModel::Unlit && lit->textures == nullptr;
    const bool record = !unlit || lit->alpha_mode != TriangleAlpha::Opaque;
    ShadeVertex shade[3];
    if (unlit && record) vertex_alphas(instance, local, shade);
    if ((o0 | o1 | o2) == 0) {
      const LazyShade lazy{instance, local, &normal_matrix, &linear, det_sign};
      emit_triangle(iv.snapped[indices[0]], iv.snapped[indices[1]], iv.snapped[indices[2]],
                    color[0], color[1], color[2], flat, primitive, std::uint32_t(instance), sink,
                    record && unlit ? shade : nullptr, record ? lit : nullptr,
                    unlit ? nullptr : &lazy);
    } else {
      if (!unlit) shade_vertices(instance, local, normal_matrix, linear, det_sign, *lit, shade);
      clip_triangle(instance, mvp, indices, color, flat, o0 | o1 | o2, primitive, sink,
                    record ? shade : nullptr, record ? lit : nullptr);
    }
  }
}

}  // namespace covrast::detail
