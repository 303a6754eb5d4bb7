// The oneTBB loops of the pipeline and of set-up work (the environment's prefiltering), with the
// ordering they guarantee told to ThreadSanitizer, and the allowance that lets an explicit
// thread count exceed the cores. Low layer: it depends on oneTBB alone.
//
// oneTBB guarantees fork-join order: everything the caller did before a parallel_for (or a
// task_arena::execute) happens before every task of it, and every task happens before the
// call returns. Tasks of one loop are not ordered among themselves. That order is made by
// the scheduler inside libtbb.so, and Debian's libtbb.so is not built with TSan, so a TSan
// build sees none of it and reports every value handed to or from a task as a race. Here the
// two edges are announced by hand:
// - fork: the caller releases `fork_sync` once the tasks' closure is built, just before the
//   loop; each task acquires it before it reads anything of the caller's. There is one fork
//   object for the whole program because a task could learn a per-call address only by
//   reading the caller's closure, and that read is what needs the edge: a new worker thread
//   that had synchronised with nothing yet read the closure on the caller's stack first, and
//   TSan reported it (CI, 2026-12-04).
// - join: one sync object per call, released at the end of each task (after its acquire of
//   `fork_sync`, so reading the closure is ordered) and acquired by the caller after the loop.
// No task acquires `join`, so the tasks of one loop are not ordered among themselves and a
// real race between them (two tiles writing one pixel) is still reported. The one exception
// is the price of the single fork object: a task that starts a nested loop releases it, so
// its writes so far are ordered before every task that starts after that, and a race with
// such a task can go unreported. Outside a TSan build the annotations are empty.
#pragma once

#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <cstddef>
#include <optional>

#if defined(__SANITIZE_THREAD__)
#define COVRAST_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define COVRAST_TSAN 1
#endif
#endif

#ifdef COVRAST_TSAN
#include <sanitizer/tsan_interface.h>
#endif

namespace covrast::detail {

/// The sync object of every call's fork edge (see above).
inline char fork_sync = 0;

/// The two happens-before edges of one fork-join call (see above).
class ForkJoinOrder {
 public:
  ForkJoinOrder() = default;
  ForkJoinOrder(const ForkJoinOrder&) = delete;
  ForkJoinOrder& operator=(const ForkJoinOrder&) = delete;
  /// Just before the loop, after the tasks' closure is built: the caller's writes so far
  /// reach every task.
  static void fork() { release(&fork_sync); }
  /// At the start of a task, before it reads the closure: static, so that calling it reads
  /// nothing of the caller's.
  static void enter_task() { acquire(&fork_sync); }
  /// At the end of a task.
  void leave_task() const { release(&join_); }
  /// After the call returned: every task's writes reach the caller.
  void joined() const { acquire(&join_); }

 private:
#ifdef COVRAST_TSAN
  static void release(const void* sync) { __tsan_release(const_cast<void*>(sync)); }
  static void acquire(const void* sync) { __tsan_acquire(const_cast<void*>(sync)); }
#else
  static void release(const void*) {}
  static void acquire(const void*) {}
#endif
  char join_ = 0;
};

/// While it lives, oneTBB may run `threads` threads in all when that is more than the
/// hardware threads, its default limit: an arena of `threads` (an explicit `--threads`)
/// then gets them, where oneTBB would otherwise give fewer and print "TBB Warning: The number
/// of workers is currently limited" to stderr. oneTBB keeps the smallest of the limits in
/// force, so a limit the embedding program set stays in force.
class ThreadAllowance {
 public:
  explicit ThreadAllowance(int threads) {
    if (threads > tbb::info::default_concurrency()) {
      limit_.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    }
  }

 private:
  std::optional<tbb::global_control> limit_;
};

/// tbb::parallel_for(range, body), with its order told to TSan.
template <class Range, class Body>
void fork_join_for(const Range& range, const Body& body) {
  const ForkJoinOrder order;
  const auto task = [&](const Range& r) {
    ForkJoinOrder::enter_task();
    body(r);
    order.leave_task();
  };
  ForkJoinOrder::fork();
  tbb::parallel_for(range, task);
  order.joined();
}

/// tbb::parallel_for(first, last, body): body(i) for each index, with its order told to TSan.
template <class Index, class Body>
void fork_join_for(Index first, Index last, const Body& body) {
  const ForkJoinOrder order;
  const auto task = [&](Index i) {
    ForkJoinOrder::enter_task();
    body(i);
    order.leave_task();
  };
  ForkJoinOrder::fork();
  tbb::parallel_for(first, last, task);
  order.joined();
}

/// arena.execute(work), which may hand `work` to a worker of the arena, with its order told
/// to TSan.
template <class Work>
void fork_join_execute(tbb::task_arena& arena, const Work& work) {
  const ForkJoinOrder order;
  const auto task = [&] {
    ForkJoinOrder::enter_task();
    work();
    order.leave_task();
  };
  ForkJoinOrder::fork();
  arena.execute(task);
  order.joined();
}

}  // namespace covrast::detail
