// The TSan step's own check (scripts/tsan.sh): that the suppressions in tests/tsan.supp and
// the annotations in src/core/fork_join.hpp hide no race in covrast's code.
//   tsan_canary ordered: data handed to the tasks and back as oneTBB orders it, with no race;
//                        must run without a report.
//   tsan_canary racy:    tasks of one loop write one shared counter; must be reported.
#include "core/fork_join.hpp"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/task_arena.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

namespace {

constexpr int kItems = 4096;

/// Each task writes its own elements from what the caller wrote before the loop; the caller
/// reads them after it, then a second loop reads the first loop's results.
int ordered(tbb::task_arena& arena) {
  std::vector<int> input(kItems), doubled(kItems), total(kItems);
  for (int i = 0; i < kItems; ++i) input[i] = i;
  covrast::detail::fork_join_execute(arena, [&] {
    covrast::detail::fork_join_for(0, kItems, [&](int i) { doubled[i] = 2 * input[i]; });
    covrast::detail::fork_join_for(tbb::blocked_range<int>(0, kItems, 16),
                                   [&](const tbb::blocked_range<int>& r) {
                                     for (int i = r.begin(); i < r.end(); ++i) {
                                       total[i] = doubled[i] + input[i];
                                     }
                                   });
  });
  long sum = 0;
  for (int v : total) sum += v;
  return sum == 3L * kItems * (kItems - 1) / 2 ? 0 : 1;
}

/// A bug of the kind the step is for: every task adds to one plain int. Each task sleeps a
/// millisecond so that the worker threads surely take some of them.
int racy(tbb::task_arena& arena) {
  constexpr int kTasks = 64;
  int shared_counter = 0;
  covrast::detail::fork_join_execute(arena, [&] {
    covrast::detail::fork_join_for(0, kTasks, [&](int) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      ++shared_counter;
    });
  });
  std::printf("tsan_canary: counter %d of %d\n", shared_counter, kTasks);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc == 2 ? argv[1] : "";
  tbb::task_arena arena(4);
  if (mode == "ordered") return ordered(arena);
  if (mode == "racy") return racy(arena);
  std::fprintf(stderr, "usage: tsan_canary ordered|racy\n");
  return 2;
}
