// covrast public API: what a rendered frame measured (RenderResult::stats).
#pragma once

#include <cstdint>
#include <utility>

namespace covrast {

/// Coverage mode: how many pixels of a frame each resolve path of the A-buffer resolved
/// (docs/coverage.md, "Resolve paths"). Every pixel of a coverage frame is counted once, so
/// the fields add up to width x height; in the other modes all are 0. Tests assert these to
/// prove that the path they test ran.
struct CoverageResolvePaths {
  std::uint64_t uniform_tile = 0;   ///< a tile showed one opaque triangle (or nothing) throughout
  std::uint64_t uniform_block = 0;  ///< the same for an 8x8 block of a tile
  std::uint64_t opaque = 0;         ///< no fragments: the pixel's opaque surface or background
  std::uint64_t layer_sums = 0;     ///< one disjoint layer over the background, from its sums
  std::uint64_t disjoint = 0;       ///< list: pairwise disjoint fragments in front of all else
  std::uint64_t front_layer = 0;    ///< list: a disjoint front layer hides what lies behind
  std::uint64_t clipped = 0;        ///< list: one triangle crossing the opaque one, clipped
  std::uint64_t samples = 0;        ///< list: 256-sample visibility, exact-area weights
  std::uint64_t overflowed = 0;     ///< the list overflowed into 256 depth-tested samples
  std::uint64_t transparent = 0;    ///< BLEND fragments composited in depth order
  std::uint64_t proven_layer = 0;   ///< log: fragments proven to tile the pixel, from their areas
  std::uint64_t masked = 0;         ///< log: sample masks front to back, exact-area weights

  std::uint64_t total() const;
  CoverageResolvePaths& operator+=(const CoverageResolvePaths& o);
};

/// Every field of CoverageResolvePaths with its name (as `covrast render --stats` prints it):
/// the one list that sums, totals and prints go through.
inline constexpr std::pair<const char*, std::uint64_t CoverageResolvePaths::*>
    kCoverageResolvePathFields[] = {{"uniform_tile", &CoverageResolvePaths::uniform_tile},
                                    {"uniform_block", &CoverageResolvePaths::uniform_block},
                                    {"opaque", &CoverageResolvePaths::opaque},
                                    {"layer_sums", &CoverageResolvePaths::layer_sums},
                                    {"disjoint", &CoverageResolvePaths::disjoint},
                                    {"front_layer", &CoverageResolvePaths::front_layer},
                                    {"clipped", &CoverageResolvePaths::clipped},
                                    {"samples", &CoverageResolvePaths::samples},
                                    {"overflowed", &CoverageResolvePaths::overflowed},
                                    {"transparent", &CoverageResolvePaths::transparent},
                                    {"proven_layer", &CoverageResolvePaths::proven_layer},
                                    {"masked", &CoverageResolvePaths::masked}};
static_assert(sizeof(CoverageResolvePaths) == sizeof(kCoverageResolvePathFields) /
                                                  sizeof(kCoverageResolvePathFields[0]) *
                                                  sizeof(std::uint64_t),
              "kCoverageResolvePathFields lists every field");

inline std::uint64_t CoverageResolvePaths::total() const {
  std::uint64_t sum = 0;
  for (const auto& field : kCoverageResolvePathFields) sum += this->*field.second;
  return sum;
}

inline CoverageResolvePaths& CoverageResolvePaths::operator+=(const CoverageResolvePaths& o) {
  for (const auto& field : kCoverageResolvePathFields) this->*field.second += o.*field.second;
  return *this;
}

/// Counts and stage times of one frame. Times are wall-clock milliseconds on the calling
/// process; counts are exact.
struct RenderStats {
  std::uint64_t triangles_in = 0;               ///< triangles submitted (after load-time drops)
  std::uint64_t triangles_culled = 0;           ///< wholly outside the view volume, zero area, or
                                                ///< a hidden back face (every dropped triangle)
  std::uint64_t triangles_backface_culled = 0;  ///< of triangles_culled: hidden back faces
  std::uint64_t triangles_clipped = 0;          ///< that needed clipping against a plane
  std::uint64_t triangles_setup = 0;            ///< screen triangles that reached binning
  std::uint64_t bin_entries = 0;                ///< (triangle, tile) pairs
  /// Coverage mode: bin entries of small opaque triangles skipped before the area kernel,
  /// every pixel they touch being one that would drop their fragment as hidden.
  std::uint64_t hidden_bin_entries = 0;
  std::uint64_t fragment_overflows = 0;  ///< coverage mode: fragments merged on list overflow
  CoverageResolvePaths resolve_paths;    ///< coverage mode: pixels per resolve path
  /// Tile-local scratch the per-thread rasterizers hold after the frame: the sum over threads
  /// of each one's capacity (a tile's scratch is reused, so this is also its high-water mark).
  std::uint64_t scratch_bytes = 0;
  double setup_ms = 0;  ///< transform, clip, snap, setup
  double binning_ms = 0;
  /// Tile raster: the time of the tile pass less resolve_ms (the tile pass interleaves the
  /// two per tile).
  double raster_ms = 0;
  /// Per-tile resolve (the A-buffer's, or the sample modes'), summed over the threads and
  /// divided by the thread count.
  double resolve_ms = 0;
  double post_ms = 0;    ///< frame post-process (fxaa mode; 0 otherwise)
  double render_ms = 0;  ///< the whole frame, without scene loading or PNG encoding
  int threads = 0;
  int tile = 0;
};

}  // namespace covrast
