// Core: run-time checks of invariants, on in debug builds (no NDEBUG) and in builds with
// COVRAST_CHECKS (the CMake option of that name; the sanitizer and fuzz presets have no
// NDEBUG, so the test command runs the whole suite with them). A failed check prints the
// condition, what it means and where, then aborts: an invariant that does not hold is a bug
// in covrast, never a property of the input. Off, a check compiles to nothing and its
// condition is not evaluated.
#pragma once

#if !defined(NDEBUG) || defined(COVRAST_CHECKS)
#define COVRAST_CHECK(condition, what) \
  ((condition) ? static_cast<void>(0)  \
               : ::covrast::detail::check_failed(#condition, what, __FILE__, __LINE__))
#else
#define COVRAST_CHECK(condition, what) static_cast<void>(0)
#endif

namespace covrast::detail {

/// Prints "covrast: invariant failed: WHAT (CONDITION) at FILE:LINE" to stderr and aborts.
[[noreturn]] void check_failed(const char* condition, const char* what, const char* file, int line);

}  // namespace covrast::detail
