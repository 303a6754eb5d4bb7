// Test helper: a scene renders to the same bytes however the frame is split into worker
// threads and tiles. Renders a base (1 thread, 64-pixel tiles unless the caller says otherwise)
// and each split, and requires every split's bytes to be the base's, naming the mode, thread
// count and tile on a failure.
#pragma once

#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <cstddef>
#include <initializer_list>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace covrast::test {

/// One way to split a frame: worker threads and tile side [pixels].
struct Split {
  int threads = 1;
  int tile = 64;
};

/// Every pair of `threads` and `tiles`, threads in the outer loop. Under AddressSanitizer
/// (COVRAST_TESTS_UNDER_ASAN: the fuzz and asan presets) only the first thread count with every
/// tile: a memory error depends on where the tiles cut the frame, not on which thread draws a
/// tile, and the release build runs every pair (docs/testing.md, "Tests left out under
/// sanitizers").
inline std::vector<Split> every_split(std::initializer_list<int> threads,
                                      std::initializer_list<int> tiles) {
  std::vector<Split> splits;
  for (const int t : threads) {
    for (const int tile : tiles) splits.push_back({t, tile});
#ifdef COVRAST_TESTS_UNDER_ASAN
    break;
#endif
  }
  return splits;
}

/// The splits compared with the base when the caller names none: 2 and 3 threads with tiles
/// of 8, 16, 24 (off the 16-pixel grid) and 256 pixels (larger than most test images).
inline std::vector<Split> default_splits() { return every_split({2, 3}, {8, 16, 24, 256}); }

/// "the same", or how two buffers differ: their sizes, or how many values differ and the first.
template <class T>
std::string describe_difference(const std::vector<T>& got, const std::vector<T>& base) {
  std::ostringstream out;
  if (got.size() != base.size()) {
    out << got.size() << " values against the base's " << base.size();
    return out.str();
  }
  std::size_t count = 0, first = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    if (got[i] == base[i]) continue;
    if (count++ == 0) first = i;
  }
  if (count == 0) return "the same";
  out << count << " of " << got.size() << " values differ, the first at index " << first << ": "
      << +got[first] << " against the base's " << +base[first];
  return out.str();
}

/// No checks beyond the bytes.
struct NoExtraCheck {
  void operator()(const RenderResult&, const RenderResult&, Split) const {}
};

/// Renders `scene` with `options` on `base`, then on each of `splits`, and REQUIREs each
/// split's colour bytes (rgb and alpha), and its depth when options.want_depth, to equal the
/// base's; a failure names the mode and the split (INFO) and the first difference. Then
/// `extra(result, base, split)` runs for the caller's own checks on each split (its stats, say).
/// Returns the base render.
template <class Extra = NoExtraCheck>
RenderResult expect_same_bytes_for_every_split(const Scene& scene, RenderOptions options,
                                               const std::vector<Split>& splits = default_splits(),
                                               Extra extra = {}, Split base = {}) {
  options.threads = base.threads;
  options.tile = base.tile;
  const RenderResult base_result = render(scene, options);
  for (const Split split : splits) {
    INFO("mode " << to_string(options.mode) << ", " << split.threads << " threads, tile "
                 << split.tile << " against " << base.threads << " threads, tile " << base.tile);
    options.threads = split.threads;
    options.tile = split.tile;
    const RenderResult result = render(scene, options);
    REQUIRE(describe_difference(result.color.rgb, base_result.color.rgb) == "the same");
    REQUIRE(describe_difference(result.color.alpha, base_result.color.alpha) == "the same");
    if (options.want_depth) {
      REQUIRE(describe_difference(result.depth.depth, base_result.depth.depth) == "the same");
    }
    extra(result, base_result, split);
  }
  return base_result;
}

/// The same for `mode` ("coverage", "msaa:4", ...) with the other options at their defaults.
template <class Extra = NoExtraCheck>
RenderResult expect_same_bytes_for_every_split(const Scene& scene, const std::string& mode,
                                               const std::vector<Split>& splits = default_splits(),
                                               Extra extra = {}, Split base = {}) {
  RenderOptions options;
  options.mode = parse_render_mode(mode);
  return expect_same_bytes_for_every_split(scene, options, splits, std::move(extra), base);
}

}  // namespace covrast::test
