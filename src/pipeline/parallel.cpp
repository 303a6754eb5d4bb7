// Pipeline: running independent pieces of work at once (renderer.hpp, for_each_in_parallel),
// so that programs on the public API, like covrast test, need no scheduler of their own.
#include "core/fork_join.hpp"

#include <covrast/renderer.hpp>
#include <covrast/tools.hpp>

#include <oneapi/tbb/info.h>
#include <oneapi/tbb/task_arena.h>

#include <atomic>
#include <exception>
#include <mutex>

namespace covrast {

void for_each_in_parallel(std::size_t count, int threads,
                          const std::function<void(std::size_t)>& work) {
  if (threads < 0 || threads > kMaxThreads) {
    throw InputError("thread count must be 0..." + std::to_string(kMaxThreads));
  }
  const detail::ThreadAllowance thread_allowance(threads);
  tbb::task_arena arena(threads > 0 ? threads : tbb::info::default_concurrency());
  std::atomic<bool> failed{false};
  std::exception_ptr first;
  std::mutex first_mutex;
  detail::fork_join_execute(arena, [&] {
    // One index per task: each piece is a whole frame or more, far above the scheduling cost.
    detail::fork_join_for(tbb::blocked_range<std::size_t>(0, count, 1),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                            for (std::size_t i = range.begin(); i < range.end(); ++i) {
                              if (failed.load(std::memory_order_relaxed)) return;
                              try {
                                work(i);
                              } catch (...) {
                                const std::lock_guard<std::mutex> lock(first_mutex);
                                if (!failed.exchange(true)) first = std::current_exception();
                              }
                            }
                          });
  });
  if (first) std::rethrow_exception(first);
}

}  // namespace covrast
