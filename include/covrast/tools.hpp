// covrast public API, tools: what the command line's golden runner and `compare` use beyond
// rendering (docs/ci.md), public for programs that do the same work (many small renders at
// once, golden images that record what rendered them, difference pictures). Not needed to
// load and render a scene; renderer.hpp, image.hpp and compare.hpp do not include it.
#pragma once

#include <covrast/image.hpp>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace covrast {

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

/// The tEXt records of a PNG file, in file order. Throws InputError when it is not a PNG.
std::vector<PngText> read_png_text(const std::filesystem::path& path);

/// A heat map of the per-pixel maximum channel difference (black = equal, through
/// blue, green, yellow to red = 32/255 or more), same size as the inputs.
Image difference_heatmap(const Image& a, const Image& b);

}  // namespace covrast
