// Shared layer: which Highway target the SIMD kernels run on. Every kernel (coverage rows and
// column set-up, sample masks, MSAA/SSAA sample tests, the aliased depth test) is one source
// compiled for each target in HWY_TARGETS, with the same flags, and dispatches through
// Highway's one chosen target: so one switch here forces them all, and the tests that compare
// each kernel with its scalar twin run once per target (tests/test_targets.hpp).
#pragma once

#include <cstdint>

namespace covrast::detail {

/// The Highway targets compiled into this build (HWY_* bit flags; lower bits are better).
std::int64_t compiled_simd_targets();

/// Tests and benchmarks: every kernel dispatches to `target` (one HWY_* bit, compiled and
/// supported by this CPU) from the next call on; 0 goes back to the best supported target.
void force_simd_target(std::int64_t target);

/// The name of the target the kernels dispatch to now (e.g. "AVX3", "AVX2", "NEON").
const char* simd_target_name();

}  // namespace covrast::detail
