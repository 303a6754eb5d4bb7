// Shared layer: the SIMD target switch of the testing interface (testing_hooks.hpp).
#include "core/testing_hooks.hpp"

#include <hwy/highway.h>
#include <hwy/targets.h>

namespace covrast::detail::testing {

std::int64_t compiled_simd_targets() { return HWY_TARGETS; }

void force_simd_target(std::int64_t target) {
  hwy::SetSupportedTargetsForTest(target);
  // Makes the next dispatch pick again among the (now mocked) supported targets.
  hwy::GetChosenTarget().Update(hwy::SupportedTargets());
}

const char* simd_target_name() {
  // Dispatch takes the best target that is both compiled and supported (the lowest bit).
  const std::int64_t usable = HWY_TARGETS & hwy::SupportedTargets();
  return hwy::TargetName(usable & -usable);
}

}  // namespace covrast::detail::testing
