// Resolve stage, coverage mode: a per-tile A-buffer (Carpenter 1984) whose weights are the
// exact analytic areas of the coverage kernel.
//
// Fully covered pixels take a fast path: an ordinary depth test against one opaque
// surface per pixel (depth planes compared at the pixel's four corners, so a plane that
// crosses the opaque one inside the pixel is kept as a fragment instead). Partly covered
// pixels keep a short list of fragments (triangle, 8.8 coverage), resolved front to back
// when the tile is done:
//  - one layer (fragments of one mesh instance and facing, connected through shared
//    vertices) in front of everything else, alone or filling the pixel:
//    colour = sum(coverage_i * colour_i) + (1 - sum coverage) * behind; adjacent triangles of
//    a tessellation add to exactly one pixel, so no background leaks through seams;
//  - otherwise, per 8x8 sub-pixel samples from the same fixed-point edge functions, with
//    per-sample depth from each triangle's plane: a fragment's weight is its coverage times
//    the share of its samples where it is the nearest; what remains goes to the opaque
//    surface behind, or the background.
#pragma once

#include "geometry/triangle_setup.hpp"
#include "raster/tile_raster.hpp"

#include <cstdint>
#include <vector>

namespace covrast::detail {

/// Fragments one pixel keeps. Beyond it (counted in overflow_count()): drop fragments the
/// opaque surface hides; else merge the new fragment into one of the same surface and facing
/// (preferably an adjacent one): areas add, sample masks are united, the older triangle's
/// plane and colour stand for both; else merge two such fragments already in the list; only
/// when 32 different surfaces meet in one pixel is the fragment of least area dropped.
inline constexpr int kMaxFragmentsPerPixel = 32;

/// How one triangle's depth plane lies against another's over a pixel.
enum class DepthOrder { InFront, Behind, Crossing };

class ABufferTile {
 public:
  explicit ABufferTile(int tile_px);

  void begin_tile(const PixelRect& rect);
  /// Coverage 8.8 (kCoverageOne = full) of triangle `t` at pixel (x, y) of this tile.
  void add(int x, int y, const TriangleSetup* t, std::uint32_t coverage);
  /// Resolves every pixel and writes the tile into the frame.
  void resolve(const FrameTarget& target);

  std::size_t scratch_bytes() const;
  std::uint64_t overflow_count() const { return overflows_; }

 private:
  struct Fragment {
    const TriangleSetup* triangle;
    std::uint32_t next;      ///< index into pool_, or kEnd
    std::uint32_t coverage;  ///< 8.8, 1/255 units
    std::uint64_t mask;      ///< 8x8 sample mask, valid only when merged
    glm::vec3 color;         ///< when merged: coverage-weighted mean colour (linear)
    std::uint32_t weight;    ///< when merged: summed coverage behind `color` (unclamped)
    bool merged;             ///< stands for several triangles of one surface
  };
  static constexpr std::uint32_t kEnd = 0xffffffffu;

  DepthOrder order_against_opaque(const TriangleSetup& t, double t_centre_z, std::size_t pixel,
                                  int x, int y) const;
  void add_fragment(std::size_t pixel, int x, int y, const TriangleSetup* t,
                    std::uint32_t coverage);
  /// Makes room in a full list, or absorbs the new fragment; true when it was absorbed.
  bool handle_overflow(std::size_t pixel, int x, int y, const TriangleSetup* t,
                       std::uint32_t coverage);
  /// Merges a piece (coverage, sample mask, colour at the pixel centre) into `f`.
  void merge_into(Fragment& f, std::uint32_t coverage, std::uint64_t mask, glm::vec3 color, int x,
                  int y);
  glm::vec3 resolve_pixel(std::size_t pixel, int x, int y, glm::vec3 background, float& depth);

  int stride_;
  PixelRect rect_;
  std::vector<const TriangleSetup*> opaque_;  ///< per pixel, null = background
  std::vector<double> opaque_z_;              ///< per pixel, the opaque plane at the centre
  std::vector<std::uint32_t> head_;           ///< per pixel, first fragment (newest last)
  std::vector<std::uint32_t> tail_;           ///< per pixel, last fragment
  std::vector<std::uint8_t> count_;           ///< per pixel, fragments in the list
  std::vector<Fragment> pool_;
  std::vector<glm::vec3> color_;  ///< resolved linear colour
  std::vector<float> depth_;      ///< resolved window depth
  std::uint64_t overflows_ = 0;
};

}  // namespace covrast::detail
