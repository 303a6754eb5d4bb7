// covrast public API: how to render (the mode, its parameters, size, threads, tiles). The
// shared vocabulary of the renderer (renderer.hpp) and of the stages that implement a mode,
// so it includes nothing of covrast; src/core/render_options.cpp parses and names modes.
#pragma once

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

}  // namespace covrast
