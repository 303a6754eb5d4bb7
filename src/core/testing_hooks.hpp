// Shared layer: the one interface through which tests and benchmarks reach inside the
// renderer. Nothing in the library or the command line sets these switches, and with all of
// them off a render is what it would be without them. Each is process-wide and read at a
// stated moment (when a rasterizer or an A-buffer is made, once per tile, or once per
// pixel), so a test sets it before the render it should change and sets it back after.
#pragma once

#include <atomic>
#include <cstdint>

namespace covrast::detail::testing {

// SIMD targets. Every kernel (coverage rows and column set-up, sample masks, MSAA/SSAA sample
// tests, the aliased depth test, the FXAA rows) is one source compiled for each target in
// HWY_TARGETS, with the same flags, and dispatches through Highway's one chosen target: so one
// switch forces them all, and the tests that compare each kernel with its scalar twin run
// once per target (tests/test_targets.hpp).

/// The Highway targets compiled into this build (HWY_* bit flags; lower bits are better).
std::int64_t compiled_simd_targets();

/// Every kernel dispatches to `target` (one HWY_* bit, compiled and supported by this CPU)
/// from the next call on; 0 goes back to the best supported target.
void force_simd_target(std::int64_t target);

/// The name of the target the kernels dispatch to now (e.g. "AVX3", "AVX2", "NEON").
const char* simd_target_name();

/// Switches and a counter of the coverage modes (src/raster/coverage). Each switch turns a
/// fast path off, or swaps in its reference, so that a test can require the same bytes (or
/// the same bytes within rounding) from both.
struct CoverageHooks {
  /// Read when a coverage rasterizer is made: it adds every pixel one by one, without the
  /// A-buffer's whole-tile and whole-block paths (the same bytes).
  std::atomic<bool> pixel_path_only{false};
  /// Read when a coverage rasterizer is made: its per-group set-up and kernel is the scalar
  /// twin cover_group_scalar instead of cover_group_simd (the same bytes).
  std::atomic<bool> scalar_kernel{false};
  /// Read once per tile: the A-buffer resolves every pixel from its fragment list, never
  /// from the one-layer sums (the same bytes).
  std::atomic<bool> list_resolve{false};
  /// Read once per tile and per pixel: as list_resolve, and every pixel with fragments is
  /// resolved by its sub-pixel samples, never by adding areas (neither the sums nor the
  /// disjoint-set branches of resolve_pixel): the reference that the exact-area paths must
  /// match within rounding. Pixels with transparent fragments then take the per-sample
  /// composite, never the uniform-layer shortcut (docs/transparency.md).
  std::atomic<bool> mask_resolve{false};
  /// Read once per tile: no pixel logs its fragments (raster/coverage/pixel_log.hpp); each
  /// goes to the A-buffer's fragment list at once, as it did before the log (the list's
  /// paths then run on any scene; the log's resolve differs from it within the tests' bounds).
  std::atomic<bool> list_only{false};
  /// Read once per tile: no pixel takes the exact clipping of its fragments' visible parts
  /// (raster/coverage/visible_parts.hpp), and a full list never drops its hidden fragments;
  /// they take the masks and samples instead, the estimate the clipping is measured against.
  std::atomic<bool> no_clipping{false};
  /// Read when an A-buffer is made: it keeps at most this many fragments per pixel (clamped
  /// to 2..kMaxFragmentsPerPixel; 0 = kMaxFragmentsPerPixel), so that small scenes reach the
  /// overflow policy.
  std::atomic<int> fragment_capacity{0};
};

/// The coverage modes' hooks of this process, all off.
inline CoverageHooks coverage_hooks;

}  // namespace covrast::detail::testing
