// covrast public API: rendering a loaded scene into an image.
//
// The pipeline: geometry (transform, clip, snap, setup) -> binning into tiles -> tile
// raster in one of the modes below -> resolve -> image. Tiles run in parallel with oneTBB;
// the output is byte-identical for every thread count and tile size.
#pragma once

#include <covrast/image.hpp>
#include <covrast/scene.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace covrast {

enum class ModeKind {
  Aliased,        ///< one sample at the pixel centre, top-left fill rule
  Coverage,       ///< exact analytic area, A-buffer resolve (the default)
  CoverageBlend,  ///< exact analytic area blended over the frame buffer (seams show)
  Ssaa,           ///< N x N samples, per-sample shading: the ordered grid (as SsaaGrid)
  SsaaGrid,       ///< N x N ordered grid samples
  SsaaCmj,        ///< N x N correlated multi-jittered (n-rooks) samples
  Msaa,           ///< K samples (D3D standard positions), shading once per pixel
  Reference,      ///< high-count supersampling in double precision: ground truth
  Fxaa,           ///< aliased, then the FXAA 3.11 post-process (RenderOptions::fxaa)
};

struct RenderMode {
  ModeKind kind = ModeKind::Coverage;
  int samples = 1;  ///< N for ssaa (N x N), K for msaa; 1 otherwise
};

/// Largest N of the ssaa modes (N x N samples per pixel); N starts at 1.
inline constexpr int kMaxSsaaSide = 16;

/// Parses "aliased", "coverage", "coverage-blend", "ssaa:N", "ssaa-grid:N", "ssaa-cmj:N"
/// (N = 1..kMaxSsaaSide), "msaa:K" (K = 2, 4, 8, 16), "reference", "fxaa". Throws InputError
/// listing the accepted forms.
RenderMode parse_render_mode(std::string_view text);
std::string to_string(const RenderMode& mode);

/// Tile sides RenderOptions::tile accepts [pixels]: kMinTilePx..kMaxTilePx, a multiple of
/// kTileStepPx (the coverage mode's column groups and A-buffer blocks are 8 pixels wide).
inline constexpr int kMinTilePx = 8;
inline constexpr int kMaxTilePx = 256;
inline constexpr int kTileStepPx = 8;
constexpr bool valid_tile_px(int tile_px) {
  return tile_px >= kMinTilePx && tile_px <= kMaxTilePx && tile_px % kTileStepPx == 0;
}
/// The accepted tile sides in words, for messages and help texts.
std::string tile_px_rule();

/// Largest RenderOptions::threads [worker threads]; more are refused as bad input.
inline constexpr int kMaxThreads = 4096;

/// The tuning knobs of FXAA 3.11's quality variant (docs/fxaa.md), with its defaults. Luma is
/// dot((r, g, b), (0.299, 0.587, 0.114)) of the 8-bit sRGB-encoded colour, in [0, 1].
struct FxaaOptions {
  /// Steps of the search along an edge: 10..15 (medium dither), 20..29 (less dither), 39
  /// (no dither); the last digit grows with the cost. 12 is FXAA's default.
  int quality_preset = 12;
  /// A pixel is processed when the luma range of its 4-neighbour cross is at least
  /// max(edge_threshold_min, edge_threshold * the largest luma of the cross) [luma].
  float edge_threshold = 0.166f;
  float edge_threshold_min = 0.0833f;
  /// Share of the sub-pixel aliasing removal, 0 (off) .. 1 (softest) [blend weight].
  float subpix = 0.75f;
};
/// True for the presets FxaaOptions::quality_preset accepts.
bool valid_fxaa_preset(int quality_preset);

struct RenderOptions {
  RenderMode mode;
  int width = 0;    ///< 0: the scene's width
  int height = 0;   ///< 0: the scene's height
  int threads = 0;  ///< 0: all hardware threads; at most kMaxThreads
  int tile = 64;    ///< tile side [pixels], see valid_tile_px
  bool want_depth = false;
  /// Drop the back faces of closed meshes wherever that provably cannot change the image
  /// (eye outside the mesh, no vertex clipped by the near or far plane; see
  /// docs/architecture.md). false keeps every triangle, to debug or measure the effect.
  bool cull_hidden_backfaces = true;
  FxaaOptions fxaa;  ///< used by ModeKind::Fxaa only
};

struct RenderStats {
  std::uint64_t triangles_in = 0;               ///< triangles submitted (after load-time drops)
  std::uint64_t triangles_culled = 0;           ///< wholly outside the view volume, zero area, or
                                                ///< a hidden back face (every dropped triangle)
  std::uint64_t triangles_backface_culled = 0;  ///< of triangles_culled: hidden back faces
  std::uint64_t triangles_clipped = 0;          ///< that needed clipping against a plane
  std::uint64_t triangles_setup = 0;            ///< screen triangles that reached binning
  std::uint64_t bin_entries = 0;                ///< (triangle, tile) pairs
  std::uint64_t fragment_overflows = 0;  ///< coverage mode: fragments merged on list overflow
  std::uint64_t scratch_bytes = 0;       ///< peak tile-local scratch over all threads
  double setup_ms = 0;                   ///< transform, clip, snap, setup
  double binning_ms = 0;
  double raster_ms = 0;   ///< tile raster including per-tile resolve
  double resolve_ms = 0;  ///< frame-level resolve (linear -> sRGB, copy-out)
  double post_ms = 0;     ///< frame post-process (fxaa mode; 0 otherwise)
  double render_ms = 0;   ///< the whole frame, without scene loading or PNG encoding
  int threads = 0;
  int tile = 0;
};

struct RenderResult {
  Image color;
  DepthImage depth;  ///< empty unless RenderOptions::want_depth
  RenderStats stats;
};

/// Keeps per-frame memory between frames, so repeated frames (benchmarks, --repeat)
/// do not reallocate. Not thread-safe: one frame at a time per Renderer.
class Renderer {
 public:
  /// Throws InputError for bad options (size, tile, mode parameters).
  Renderer(const Scene& scene, const RenderOptions& options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  RenderResult render_frame();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One frame, convenience.
RenderResult render(const Scene& scene, const RenderOptions& options);

/// What this build of covrast is and runs on: what golden images record and test reports
/// print, so that a mismatch says what rendered each side.
struct BuildInfo {
  std::string version;      ///< covrast's version (project() in CMakeLists.txt)
  std::string compiler;     ///< e.g. "g++ 12.2.0"
  std::string simd_target;  ///< the Highway target the kernels run on, e.g. "AVX3"
  std::string cpu;          ///< the processor's model name
};
BuildInfo build_info();

}  // namespace covrast
