// covrast public API: rendering a loaded scene into an image.
//
// The pipeline: geometry (transform, clip, snap, setup) -> binning into tiles -> tile
// raster in one of the modes below -> resolve -> image. Tiles run in parallel with oneTBB;
// the output is byte-identical for every thread count and tile size.
#pragma once

#include <covrast/image.hpp>
#include <covrast/options.hpp>
#include <covrast/scene.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

namespace covrast {

/// True for the presets FxaaOptions::quality_preset accepts.
bool valid_fxaa_preset(int quality_preset);

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

/// Runs work(i) for every i in [0, count), several at once on up to `threads` worker threads
/// (0: all hardware threads; at most kMaxThreads), each call on one thread, and returns when
/// all have run: for programs that render many small frames at once (covrast test renders one
/// case per call, with RenderOptions::threads = 1). When a call throws, the calls not yet
/// started are skipped and the first exception is rethrown here.
void for_each_in_parallel(std::size_t count, int threads,
                          const std::function<void(std::size_t)>& work);

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
