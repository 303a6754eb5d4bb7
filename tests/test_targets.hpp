// Test helper shared by the SIMD kernel tests: which Highway targets to force, and a loop
// that runs a check once per target with the target's name on every failure.
#pragma once

#include "core/testing_hooks.hpp"

#include <hwy/targets.h>

#include <catch2/catch.hpp>

#include "test_hooks.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace covrast::test {

/// The compiled Highway targets that this CPU supports, best first. Read before forcing any
/// target: hwy::SupportedTargets() reports the mock once one is set.
inline std::vector<std::int64_t> usable_targets() {
  std::vector<std::int64_t> targets;
  const std::int64_t usable =
      covrast::detail::testing::compiled_simd_targets() & hwy::SupportedTargets();
  for (std::int64_t bits = usable; bits != 0; bits &= bits - 1) targets.push_back(bits & -bits);
  return targets;
}

/// Runs `check(target)` with each usable target forced in turn (every assertion inside names
/// the target), then goes back to the best supported target.
template <class Check>
void for_each_target(Check check) {
  const std::int64_t supported = hwy::SupportedTargets();
  for (const std::int64_t target : usable_targets()) {
    const ScopedSimdTarget forced(target);
    INFO("SIMD target " << hwy::TargetName(target));
    REQUIRE(std::string(covrast::detail::testing::simd_target_name()) == hwy::TargetName(target));
    check(target);
  }
  CHECK(hwy::SupportedTargets() == supported);
}

}  // namespace covrast::test
