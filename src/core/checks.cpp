// Core: the failure report of COVRAST_CHECK (checks.hpp).
#include "core/checks.hpp"

#include <cstdio>
#include <cstdlib>

namespace covrast::detail {

void check_failed(const char* condition, const char* what, const char* file, int line) {
  std::fprintf(stderr, "covrast: invariant failed: %s (%s) at %s:%d\n", what, condition, file,
               line);
  std::abort();
}

}  // namespace covrast::detail
