// Geometry stage: model-view-projection transform, homogeneous clipping, viewport
// transform, snapping to 24.8 fixed point, and triangle setup.
//
// Work is split into fixed chunks of the global triangle sequence (all meshes in list
// order, faces in file order), so that the output order, and so the image, never depends
// on the thread count.
//
// Hidden back faces of closed meshes are dropped here (see the comment in frontend_cull.cpp
// for why that never changes the image).
//
// One file per stage: frontend.cpp is the outline (the chunk loops and emit_triangle, which
// runs the per-triangle stages); frontend_transform.cpp, frontend_clip.cpp, frontend_cull.cpp
// (per instance; its per-triangle culls inline in frontend_cull.hpp), frontend_setup.hpp
// (inline), frontend_shading.cpp; frontend_stages.hpp declares what they share.
#pragma once

#include "core/triangle_setup.hpp"
#include "shading/environment_lighting.hpp"
#include "shading/shading_inputs.hpp"

#include <covrast/scene.hpp>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace covrast::detail {

struct ClippedPolygon;  // frontend_stages.hpp
struct KeptTriangle;    // frontend_stages.hpp

/// Triangles per setup/binning chunk: large enough to amortise a task, small enough to
/// balance 500k triangles over a few cores.
inline constexpr std::uint32_t kTrianglesPerChunk = 8192;

/// Vertices per transform block: transform_vertices calls must cover whole blocks of an
/// instance (begin a multiple of it, end a multiple of it or the vertex count), since each
/// block records the union of its vertices' outcodes in its own slot.
inline constexpr std::size_t kVerticesPerTransformBlock = 4096;

/// A vertex after the viewport transform, snapped to 24.8 fixed point.
struct SnappedVertex {
  std::int32_t x_fx8;
  std::int32_t y_fx8;
  double z_window;  ///< [0, 1]
  float inv_w;      ///< 1 / clip w
};

/// Per-vertex transform results of one mesh instance: clip outcodes and, for vertices inside
/// every plane, their snapped screen position (shared by all their triangles). Sized, and so
/// first touched, by the constructor; every frame's transform_vertices rewrites them in place,
/// so repeated frames take no page faults here. Clip-space positions are not stored (8 MB per
/// 250k vertices, written every frame): the few triangles that need clipping recompute theirs
/// with clip_position, bit for bit the values the outcodes came from.
struct InstanceVertices {
  std::vector<std::uint8_t> outcode;      ///< bit p set: outside clip plane p
  std::vector<SnappedVertex> snapped;     ///< valid where outcode == 0
  std::vector<glm::vec3> color_linear;    ///< only for ColorSource::Vertex
  std::vector<glm::vec3> position_world;  ///< only for lit instances: model * position
  /// Per kVerticesPerTransformBlock vertices: the union (OR) of their outcodes. Each slot is
  /// written by one transform call, so the per-instance union is race-free and deterministic.
  std::vector<std::uint8_t> block_outcodes;
};

/// Transparent huge page size on x86-64 and most arm64 kernels: the unit madvise works in.
inline constexpr std::size_t kHugePageBytes = std::size_t(2) << 20;

/// Asks the kernel (Linux, MADV_HUGEPAGE; a no-op elsewhere) to back the whole 2 MiB pages
/// inside [data, data + bytes) with transparent huge pages: one fault then maps 2 MiB instead
/// of 4 KiB. A one-frame render faults in tens of MB of fresh buffers, at ~9 us per 4 KiB
/// fault in a VM. Advisory only: contents and behaviour are unchanged if it is refused.
void advise_huge_pages(void* data, std::size_t bytes);

/// An uninitialised, 2 MiB-aligned allocation advised for huge pages; memory is only faulted
/// in where written.
class HugePageBuffer {
 public:
  HugePageBuffer() = default;
  explicit HugePageBuffer(std::size_t bytes);
  HugePageBuffer(const HugePageBuffer&) = delete;
  HugePageBuffer& operator=(const HugePageBuffer&) = delete;
  ~HugePageBuffer();
  void* data() const { return data_; }

 private:
  void* data_ = nullptr;
  std::size_t bytes_ = 0;
};

/// One chunk's ShadingRecords (or TexturedCorners): fixed blocks, so a record's address
/// (TriangleSetup::shading) stays valid while more are added; the blocks are kept from frame
/// to frame.
template <class Record>
class RecordArena {
 public:
  void clear() { size_ = 0; }
  Record& emplace_back() {
    const std::size_t block = size_ / kBlockRecords;
    if (block == blocks_.size()) blocks_.push_back(std::make_unique<Record[]>(kBlockRecords));
    return blocks_[block][size_++ % kBlockRecords];
  }
  std::size_t size() const { return size_; }

 private:
  static constexpr std::size_t kBlockRecords = 4096;  ///< 352 KiB per block of ShadingRecord
  std::vector<std::unique_ptr<Record[]>> blocks_;
  std::size_t size_ = 0;
};
using ShadingArena = RecordArena<ShadingRecord>;
using TexturedArena = RecordArena<TexturedCorners>;

/// The shading inputs of one chunk's lit and textured triangles, which their TriangleSetup's
/// `shading` points into: owned with the chunk's triangles (ChunkSetups, the pipeline's
/// per-frame memory), written only while the chunk is set up, kept until it is set up again.
struct ChunkShading {
  ShadingArena records;
  TexturedArena textured;
};

/// One chunk's set-up triangles as the pipeline keeps them: written into the chunk's fixed
/// slice of a frame-wide buffer (room for one triangle per input triangle, enough unless
/// clipping splits triangles), and moved to an own, growing array if the slice runs full.
/// Without a slice (reset(nullptr, 0), or as constructed) it is a plain growing array.
class ChunkSetups {
 public:
  /// Starts over, writing to `slice` (room for `capacity` triangles).
  void reset(TriangleSetup* slice, std::size_t capacity) {
    data_ = slice;
    capacity_ = capacity;
    size_ = 0;
  }
  /// A new triangle at the end, its fields to be written.
  TriangleSetup& emplace_back() { return size_ < capacity_ ? data_[size_++] : grow(); }
  std::size_t size() const { return size_; }
  const TriangleSetup* data() const { return data_; }
  const TriangleSetup& operator[](std::size_t i) const { return data_[i]; }
  /// Where the chunk's shading records go (setup_chunk starts them over; reset() keeps them).
  ChunkShading& shading() { return shading_; }

 private:
  TriangleSetup& grow();

  TriangleSetup* data_ = nullptr;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
  std::unique_ptr<TriangleSetup[]> overflow_;  ///< data_ once the slice ran full
  ChunkShading shading_;
};

/// A lit triangle's vertex as shading needs it: world position and unit normal (or any
/// length after clipping; shade() renormalises after interpolation).
struct ShadeVertex {
  glm::vec3 position_world;
  glm::vec3 normal_world;
  /// Textured triangles only (TexturedCorners): both UV sets and the world tangent.
  glm::vec2 uv[kMaxTexcoordSets];
  glm::vec4 tangent_world;
  float alpha = 1.0f;  ///< the vertex alpha (MeshData::color_alphas), for non-opaque surfaces
};

struct SetupCounters {
  std::uint64_t culled = 0;           ///< outside the view volume, zero area after snapping, or a
                                      ///< hidden back face
  std::uint64_t clipped = 0;          ///< crossed a clip plane
  std::uint64_t backface_culled = 0;  ///< of culled: hidden back faces of closed meshes
};

class GeometryFrontEnd {
 public:
  /// `cull_hidden_backfaces`: RenderOptions::cull_hidden_backfaces.
  GeometryFrontEnd(const Scene& scene, int width_px, int height_px,
                   bool cull_hidden_backfaces = true);

  std::uint64_t triangle_count() const { return first_triangle_.back(); }
  std::uint32_t chunk_count() const {
    return std::uint32_t((triangle_count() + kTrianglesPerChunk - 1) / kTrianglesPerChunk);
  }
  /// Input triangles of one chunk (kTrianglesPerChunk, fewer in the last one).
  std::uint32_t chunk_triangle_count(std::uint32_t chunk) const {
    return std::uint32_t(std::min<std::uint64_t>(
        kTrianglesPerChunk, triangle_count() - std::uint64_t(chunk) * kTrianglesPerChunk));
  }
  std::size_t instance_count() const { return scene_.meshes.size(); }

  /// Prepares the scene's environment lighting (prefiltering runs in parallel: call it inside
  /// the renderer's arena, before the first set-up). Does nothing without an environment or
  /// when the scene is not shaded; a second call does nothing.
  void prepare_environment();

  /// Transforms the vertices of one instance (vertices [begin, end)) to clip space. The range
  /// covers whole transform blocks (see kVerticesPerTransformBlock).
  void transform_vertices(std::size_t instance, std::size_t begin, std::size_t end);
  std::size_t vertex_count(std::size_t instance) const;
  /// The last transform_vertices results of one instance (for tests).
  const InstanceVertices& instance_vertices(std::size_t instance) const {
    return vertices_[instance];
  }

  /// Whether an instance takes the shaded path (ShadingRecords): the scene has lights and some
  /// material of the instance is not ShadingModel::Unlit, or some material shows a texture
  /// (lit or not). Other instances take the unlit path bit for bit.
  bool instance_lit(std::size_t instance) const { return !lit_.empty() && lit_[instance]; }
  /// Whether some material of an instance is not AlphaMode::Opaque: its triangles take the
  /// lit path's per-material loop, and its non-opaque ones get a ShadingRecord for alpha.
  bool instance_alpha(std::size_t instance) const { return !alpha_.empty() && alpha_[instance]; }

  /// Clips, snaps and sets up the triangles of one chunk, appending to `out` in order, and
  /// their shading records to `shading` (started over), which must outlive their use.
  void setup_chunk(std::uint32_t chunk, std::vector<TriangleSetup>& out, ChunkShading& shading,
                   SetupCounters& counters) const;
  /// The same into a ChunkSetups (the pipeline's form, started over with reset() by the
  /// caller; the records go to its shading()), and appends each emitted triangle's touched
  /// pixels clamped to the image to `bounds` (for binning). A const function: the front end
  /// holds nothing of a frame, so chunks set up on several threads share it safely.
  void setup_chunk(std::uint32_t chunk, ChunkSetups& out, std::vector<PixelBounds16>& bounds,
                   SetupCounters& counters) const;

  /// Whether every instance is a convex surface (convex_surface): no triangle can hide another
  /// of its own mesh, only other instances can, and coverage mode keeps submission order (on
  /// the sphere grid its nearest-first order cost more than it saved; binning/tile_bins.hpp,
  /// sort_nearest_first).
  bool every_instance_convex() const {
    for (std::size_t i = 0; i < instance_count(); ++i) {
      if (!convex_surface(i)) return false;
    }
    return true;
  }

 private:
  /// The viewport transform and 24.8 snap of a clip position (frontend_stages.hpp).
  SnappedVertex snap(const glm::dvec4& clip) const;
  unsigned outcode(const glm::dvec4& clip) const;
  /// outcode(clip), bit for bit, for the planes_ the constructor sets.
  unsigned fast_outcode(const glm::dvec4& clip) const;
  /// Where emitted triangles go: `bounds` may be null.
  struct Sink {
    std::vector<TriangleSetup>* out;  ///< exactly one of out and chunk is set
    ChunkSetups* chunk;
    std::vector<PixelBounds16>* bounds;
    SetupCounters& counters;
    /// Facings dropped as hidden back faces for the current instance: kDropClockwise,
    /// kDropCounterClockwise or 0.
    unsigned drop_facing = 0;
    bool convex_surface = false;        ///< the instance's TriangleSetup::convex_surface
    ShadingArena* shading = nullptr;    ///< where lit triangles' records go
    TexturedArena* textured = nullptr;  ///< where textured triangles' corners go
    /// The instance's model matrix has a negative determinant: its front faces (counter-
    /// clockwise in the file) are clockwise on screen.
    bool mirrored = false;
    /// Back faces of single-sided materials (glTF doubleSided false), culled in every mode:
    /// the instance's back facing (kDropClockwise, or kDropCounterClockwise when mirrored) or
    /// 0; `single_sided`, when not null, flags which of the instance's triangles (indexed
    /// from `first_primitive`) have such a material, else all have.
    unsigned cull_facing = 0;
    const std::uint8_t* single_sided = nullptr;
    std::uint64_t first_primitive = 0;
    /// A new triangle at the end of the output, its fields to be written.
    TriangleSetup& next() { return chunk != nullptr ? chunk->emplace_back() : out->emplace_back(); }
  };
  /// Where emit_triangle computes a lit triangle's ShadeVertex (shade_vertices' arguments).
  struct LazyShade {
    std::size_t instance;
    std::size_t local;
    const glm::dmat3* normal_matrix;
    const glm::dmat3* linear;  ///< the model matrix's 3x3 part (tangents)
    double det_sign;
  };
  /// `lit`: a lit triangle's material, null for unlit ones; its ShadeVertex of v0, v1, v2 are
  /// `shade`, or computed from `lazy` once the triangle has passed the culls.
  void emit_triangle(const SnappedVertex& v0, const SnappedVertex& v1, const SnappedVertex& v2,
                     const glm::vec3& color0, const glm::vec3& color1, const glm::vec3& color2,
                     bool flat, std::uint32_t primitive, std::uint32_t surface, Sink& sink,
                     const ShadeVertex* shade = nullptr, const SurfaceShading* lit = nullptr,
                     const LazyShade* lazy = nullptr) const;
  /// Clips a triangle with a vertex outside some plane and emits the fan of its polygon.
  /// `mvp`: view_projection_ times the instance's model matrix, as in transform_vertices.
  void emit_clipped(std::size_t instance, const glm::dmat4& mvp, const std::uint32_t* idx,
                    const glm::vec3* color, bool flat, unsigned out_any, std::uint32_t primitive,
                    Sink& sink, const ShadeVertex* shade = nullptr,
                    const SurfaceShading* lit = nullptr) const;
  /// The clip stage (frontend_clip.cpp): triangle `idx` of an instance clipped against the
  /// planes in `out_any` (the union of its vertices' outcodes), with its colours and, when
  /// `shade` is not null, its ShadeVertex, into `out` with its vertices snapped (out.count
  /// below 3: nothing is left).
  void clip_triangle(std::size_t instance, const glm::dmat4& mvp, const std::uint32_t* idx,
                     const glm::vec3* color, unsigned out_any, const ShadeVertex* shade,
                     ClippedPolygon& out) const;
  /// The per-triangle culls (frontend_cull.hpp), each counted in sink.counters.culled: zero
  /// area after snapping, wholly outside the image, a hidden back face (also counted in
  /// backface_culled), a back face of a single-sided material. True when the triangle passes;
  /// then `kept` holds its facing and touched pixels.
  bool passes_culls(const SnappedVertex& v0, const SnappedVertex& v1, const SnappedVertex& v2,
                    std::uint32_t primitive, Sink& sink, KeptTriangle& kept) const;
  /// The shading set-up of a lit triangle (frontend_shading.cpp): its ShadingRecord (and
  /// TexturedCorners) from its ShadeVertex (`shade`, or computed from `lazy`), in the order
  /// set_up_triangle gave its vertices (`front`: v1 and v2 swapped), linked from `t`.
  void set_up_shading(const ShadeVertex* shade, const SurfaceShading& lit, const LazyShade* lazy,
                      bool front, Sink& sink, TriangleSetup& t) const;
  void setup_range(std::uint32_t chunk, ChunkShading& shading, Sink& sink) const;
  /// The triangles [g, end) of a lit instance (setup_range's loop with shading inputs).
  void setup_lit_run(std::size_t instance, std::uint64_t g, std::uint64_t end, Sink& sink) const;
  /// The three ShadeVertex of triangle `local` of a lit instance (`normal_matrix`: the
  /// inverse transpose of the model matrix's 3x3 part `linear`, `det_sign` the sign of its
  /// determinant); with UVs and tangents when `surface` is textured.
  void shade_vertices(std::size_t instance, std::size_t local, const glm::dmat3& normal_matrix,
                      const glm::dmat3& linear, double det_sign, const SurfaceShading& surface,
                      ShadeVertex out[3]) const;
  /// The UVs and world tangents of a textured triangle's corners (shade_vertices).
  void texture_vertices(const MeshInstance& inst, std::size_t local, const glm::dmat3& linear,
                        double det_sign, const SurfaceShading& surface, ShadeVertex out[3]) const;
  /// The vertex alphas of triangle `local` of an instance into out[k].alpha.
  void vertex_alphas(std::size_t instance, std::size_t local, ShadeVertex out[3]) const;
  /// Builds context_, surfaces_, lit_ and alpha_ from the scene (constructor: lit scenes,
  /// scenes with textures and scenes with non-opaque materials only).
  void prepare_lighting();
  /// Whether some instance shows a texture: an unlit scene then needs the shaded path too.
  static bool shows_textures(const Scene& scene);
  /// Which facing of an instance to drop this frame (Sink::drop_facing).
  unsigned drop_facing(std::size_t instance) const;
  /// Whether an instance's triangles are of a convex surface
  /// (TriangleSetup::convex_surface): its mesh is convex (current analysis) and
  /// its model matrix affine, which keeps it convex; its faces of one facing
  /// then cover each point of the screen at most once, from any eye (clipping
  /// only cuts them smaller).
  bool convex_surface(std::size_t instance) const;
  /// Conditions (a) and (b) (see frontend_cull.cpp): the facing to drop if no vertex
  /// is clipped by the near or far plane, or 0.
  static unsigned cullable_facing(const MeshInstance& instance, const glm::dvec3& eye);

  /// TriangleSetup::front_facing false (clockwise in NDC) / true
  /// (counter-clockwise).
  static constexpr unsigned kDropClockwise = 1;
  static constexpr unsigned kDropCounterClockwise = 2;

  const Scene& scene_;
  int width_px_;
  int height_px_;
  glm::dmat4 view_projection_;
  double guard_x_;        ///< guard band half-extent in NDC units, x
  double guard_y_;        ///< same, y
  glm::dvec4 planes_[6];  ///< homogeneous clip planes: inside where dot(plane, v) >= 0
  std::vector<std::uint64_t> first_triangle_;  ///< prefix sums of triangle counts
  std::vector<InstanceVertices> vertices_;
  bool cull_hidden_backfaces_;
  glm::dvec3 eye_;  ///< the camera position the view matrix was built from [world]
  // Lighting (empty for unlit scenes). surfaces_[i][m]: instance i's material
  // m, pointing at context_.
  ShadingContext context_;
  std::optional<EnvironmentLighting> environment_;  ///< context_.environment points here
  bool lit_context_ = false;                        ///< prepare_lighting ran
  /// Single-sided materials per instance (set_single_sided): 0 none, 1 all, 2 some, with
  /// single_sided_triangles_[instance] flagging each triangle then.
  void prepare_single_sided();
  void set_single_sided(std::size_t instance, Sink& sink) const;
  std::vector<std::uint8_t> single_sided_kind_;
  std::vector<std::vector<std::uint8_t>> single_sided_triangles_;
  std::vector<std::vector<SurfaceShading>> surfaces_;
  /// textures_[i][m]: instance i's material m's slots, where
  /// surfaces_[i][m].textures points.
  std::vector<std::vector<SurfaceTextures>> textures_;
  std::vector<bool> lit_;
  std::vector<bool> alpha_;
};

}  // namespace covrast::detail
