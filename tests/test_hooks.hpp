// Test helper: the renderer's testing switches (core/testing_hooks.hpp) set for one scope and
// put back when it ends, even when an assertion inside throws, so that a failing test cannot
// leave a switch on for the tests after it.
#pragma once

#include "core/testing_hooks.hpp"

#include <atomic>
#include <cstdint>

namespace covrast::test {

/// Sets one of testing::coverage_hooks' switches to `value` for the scope.
template <class T>
class ScopedHook {
 public:
  ScopedHook(std::atomic<T>& hook, T value) : hook_(hook), before_(hook.load()) { hook_ = value; }
  ~ScopedHook() { hook_ = before_; }
  ScopedHook(const ScopedHook&) = delete;
  ScopedHook& operator=(const ScopedHook&) = delete;

 private:
  std::atomic<T>& hook_;
  T before_;
};

/// Every kernel dispatches to `target` (one HWY_* bit) for the scope, then to the best
/// supported target again.
class ScopedSimdTarget {
 public:
  explicit ScopedSimdTarget(std::int64_t target) {
    covrast::detail::testing::force_simd_target(target);
  }
  ~ScopedSimdTarget() { covrast::detail::testing::force_simd_target(0); }
  ScopedSimdTarget(const ScopedSimdTarget&) = delete;
  ScopedSimdTarget& operator=(const ScopedSimdTarget&) = delete;
};

}  // namespace covrast::test
