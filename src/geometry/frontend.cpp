// Geometry stage (frontend.hpp), the outline: the constructor, the chunk loops (setup_range,
// and setup_lit_run for instances with shading inputs) and emit_triangle, which runs the
// per-triangle stages in order: the culls (frontend_cull.hpp), the set-up (frontend_setup.hpp)
// and the shading set-up (frontend_shading.cpp). A triangle with a vertex outside a clip plane
// is clipped first (frontend_clip.cpp) and its polygon emitted as a fan. The vertices come from
// the transform (frontend_transform.cpp). Also the chunks' output buffers.
#include "geometry/frontend_cull.hpp"
#include "geometry/frontend_setup.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <new>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace covrast::detail {

GeometryFrontEnd::GeometryFrontEnd(const Scene& scene, int width_px, int height_px,
                                   bool cull_hidden_backfaces)
    : scene_(scene),
      width_px_(width_px),
      height_px_(height_px),
      cull_hidden_backfaces_(cull_hidden_backfaces),
      eye_(scene.camera.eye) {
  context_.tone_mapping = {scene.tone_map, scene.exposure};
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

void GeometryFrontEnd::setup_chunk(std::uint32_t chunk, std::vector<TriangleSetup>& out,
                                   ChunkShading& shading, SetupCounters& counters) const {
  Sink sink{&out, nullptr, nullptr, counters};
  setup_range(chunk, shading, sink);
}

void GeometryFrontEnd::setup_chunk(std::uint32_t chunk, ChunkSetups& out,
                                   std::vector<PixelBounds16>& bounds,
                                   SetupCounters& counters) const {
  Sink sink{nullptr, &out, &bounds, counters};
  setup_range(chunk, out.shading(), sink);
}

// Inlined into setup_range's loop: as a call it spilled its arguments and the caller's
// state on every triangle.
[[gnu::always_inline]] inline void GeometryFrontEnd::emit_triangle(
    const SnappedVertex& v0, const SnappedVertex& v1, const SnappedVertex& v2,
    const glm::vec3& color0, const glm::vec3& color1, const glm::vec3& color2, bool flat,
    std::uint32_t primitive, std::uint32_t surface, Sink& sink, const ShadeVertex* shade,
    const SurfaceShading* lit, const LazyShade* lazy) const {
  KeptTriangle kept;
  if (!passes_culls(v0, v1, v2, primitive, sink, kept)) return;
  if (sink.bounds != nullptr) {
    // Non-empty: a triangle of non-zero area has min < max on both axes.
    const PixelRect& r = kept.pixels;
    sink.bounds->push_back(PixelBounds16{
        std::uint16_t(std::max(r.x0, 0)), std::uint16_t(std::max(r.y0, 0)),
        std::uint16_t(std::min(r.x1, width_px_)), std::uint16_t(std::min(r.y1, height_px_))});
  }
  // Written in place: building a copy on the stack and pushing it costs store-forwarding
  // stalls on this hot path.
  TriangleSetup& t = sink.next();
  set_up_triangle(v0, v1, v2, color0, color1, color2, kept.front, flat, sink.convex_surface,
                  primitive, surface, lit == nullptr ? &context_.tone_mapping : nullptr, t);
  if (lit != nullptr) set_up_shading(shade, *lit, lazy, kept.front, sink, t);
}

void GeometryFrontEnd::emit_clipped(std::size_t instance, const glm::dmat4& mvp,
                                    const std::uint32_t* idx, const glm::vec3* color, bool flat,
                                    unsigned out_any, std::uint32_t primitive, Sink& sink,
                                    const ShadeVertex* shade, const SurfaceShading* lit) const {
  ++sink.counters.clipped;
  ClippedPolygon poly;
  clip_triangle(instance, mvp, idx, color, out_any, shade, poly);
  if (poly.count < 3) {
    ++sink.counters.culled;
    return;
  }
  const SnappedVertex* s = poly.snapped;
  const glm::vec3* pc = poly.color;
  // Fan (0, k, k+1) over the clipped polygon.
  for (int k = 1; k + 1 < poly.count; ++k) {
    if (shade != nullptr) {
      const ShadeVertex fan[3] = {poly.shade[0], poly.shade[k], poly.shade[k + 1]};
      emit_triangle(s[0], s[k], s[k + 1], pc[0], pc[k], pc[k + 1], flat, primitive,
                    std::uint32_t(instance), sink, fan, lit);
    } else {
      emit_triangle(s[0], s[k], s[k + 1], pc[0], pc[k], pc[k + 1], flat, primitive,
                    std::uint32_t(instance), sink);
    }
  }
}

void GeometryFrontEnd::setup_range(std::uint32_t chunk, ChunkShading& shading, Sink& sink) const {
  const std::uint64_t first = std::uint64_t(chunk) * kTrianglesPerChunk;
  const std::uint64_t last = std::min<std::uint64_t>(first + kTrianglesPerChunk, triangle_count());
  if (lit_context_) {
    shading.records.clear();
    sink.shading = &shading.records;
    shading.textured.clear();
    sink.textured = &shading.textured;
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
        emit_clipped(instance, mvp, indices, color, flat, o0 | o1 | o2, primitive, sink);
      }
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
    const bool unlit = lit->model == ShadingModel::Unlit && lit->textures == nullptr;
    const bool record = !unlit || lit->alpha_mode != AlphaMode::Opaque;
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
      emit_clipped(instance, mvp, indices, color, flat, o0 | o1 | o2, primitive, sink,
                   record ? shade : nullptr, record ? lit : nullptr);
    }
  }
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

}  // namespace covrast::detail
