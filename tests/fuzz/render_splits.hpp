// Shared by the render fuzz target (fuzz_render.cpp) and the Catch2 test that rebuilds its
// findings (tests/test_fuzz_regressions.cpp): the two splits of one frame whose results must
// be the same bytes.
#pragma once

#include <covrast/options.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <utility>

namespace covrast::fuzz {

/// `scene` rendered with `options` twice: 8-pixel tiles on one thread, then 24-pixel tiles on
/// two (tiles that split the frame differently, and work that changes threads).
inline std::pair<RenderResult, RenderResult> render_two_splits(const Scene& scene,
                                                               RenderOptions options) {
  options.tile = 8;
  options.threads = 1;
  RenderResult a = render(scene, options);
  options.tile = 24;
  options.threads = 2;
  RenderResult b = render(scene, options);
  return {std::move(a), std::move(b)};
}

}  // namespace covrast::fuzz
