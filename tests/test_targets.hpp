// Test helper shared by the SIMD kernel tests: which Highway targets to force.
#pragma once

#include <hwy/targets.h>

#include <cstdint>
#include <vector>

namespace covrast::test {

/// The Highway targets among `compiled` (HWY_* bit flags) that this CPU supports, best first.
/// Call before forcing any target: hwy::SupportedTargets() reports the mock once one is set.
inline std::vector<std::int64_t> usable_targets(std::int64_t compiled) {
  std::vector<std::int64_t> targets;
  for (std::int64_t bits = compiled & hwy::SupportedTargets(); bits != 0; bits &= bits - 1) {
    targets.push_back(bits & -bits);
  }
  return targets;
}

}  // namespace covrast::test
