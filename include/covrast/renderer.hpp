// covrast public API: rendering a loaded scene into an image.
//
// The pipeline: geometry (transform, clip, snap, setup) -> binning into tiles -> tile
// raster in one of the modes below -> resolve -> image. Tiles run in parallel with oneTBB;
// the output is byte-identical for every thread count and tile size.
#pragma once

#include <covrast/image.hpp>
#include <covrast/options.hpp>
#include <covrast/scene.hpp>
#include <covrast/stats.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace covrast {

/// True for the presets FxaaOptions::quality_preset accepts.
bool valid_fxaa_preset(int quality_preset);

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
  /// The Renderer keeps a reference to `scene`, not a copy: the scene must outlive it and stay
  /// unchanged while it exists (meshes, instances, textures, environment). It does not
  /// validate the scene in release builds (check_scene is O(triangles)): load_scene and
  /// load_mesh_scene give valid scenes; for a scene built in code call check_scene first,
  /// since here an index out of range or arrays whose sizes do not match are undefined
  /// behaviour. Debug builds and builds with COVRAST_CHECKS call check_scene here and throw
  /// its InputError.
  Renderer(const Scene& scene, const RenderOptions& options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  RenderResult render_frame();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One frame, convenience: Renderer(scene, options).render_frame(), with the same
/// preconditions and exceptions.
RenderResult render(const Scene& scene, const RenderOptions& options);

}  // namespace covrast
