// Core: the interface between the pipeline and the raster modes, one rasterizer per mode and
// one instance per worker thread (the modes live in src/raster/<mode>/; raster/rasterizers.hpp
// makes them).
//
// The pipeline hands a tile to a rasterizer as begin_tile, then every binned triangle in
// draw order (one virtual call per triangle, never per pixel), then end_tile, which
// resolves the tile and writes its final 8-bit sRGB pixels into the frame. Everything a
// rasterizer keeps is tile-local scratch, reused from tile to tile.
#pragma once

#include "core/triangle_setup.hpp"

#include <covrast/image.hpp>
#include <covrast/stats.hpp>

#include <cstdint>
#include <memory>

namespace covrast::detail {

struct FrameTarget {
  Image* color = nullptr;
  DepthImage* depth = nullptr;  ///< null when no depth output is wanted
  glm::vec3 background_linear{0.0f};
};

class TileRasterizer {
 public:
  virtual ~TileRasterizer() = default;
  virtual void begin_tile(const PixelRect& rect, const FrameTarget& target) = 0;
  virtual void draw(const TriangleSetup& triangle) = 0;
  /// Resolves the tile and writes it into `target` (only this tile's pixels).
  virtual void end_tile(const FrameTarget& target) = 0;
  /// Bytes of tile-local scratch this instance holds now.
  virtual std::size_t scratch_bytes() const = 0;
  /// Fragments merged or dropped because a pixel's list was full (coverage mode).
  virtual std::uint64_t overflow_count() const { return 0; }
  /// Triangles drawn into a tile and skipped as hidden there, before the kernel (coverage
  /// mode; counted over the instance's life, as overflow_count).
  virtual std::uint64_t hidden_draw_count() const { return 0; }
  /// Pixels per resolve path since the last call (coverage mode; zeros otherwise), and
  /// starts counting again.
  virtual CoverageResolvePaths take_resolve_paths() { return {}; }
  /// Time [ms] this instance has spent so far rasterising inside end_tile(): the banded
  /// sample modes record a large tile's triangles and replay them band by band there
  /// (sample_raster.cpp). The renderer counts it as raster time, not resolve time.
  virtual double deferred_raster_ms() const { return 0.0; }
};

/// Largest tile side the rasterizers accept [pixels].
inline constexpr int kMaxTilePx = 256;  ///< = covrast::kMaxTilePx (pipeline checks)

}  // namespace covrast::detail
