#pragma once

#include <cstdio>
#include <cstdlib>

/// Always-on invariant check: a broken invariant is a bug, so it aborts with
/// the condition, file and line, in every build type. Bad input must throw
/// instead (see common/params.h).
#define MJSLAM_CHECK(condition)                                             \
  do {                                                                      \
    if (!(condition)) {                                                     \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, \
                   #condition);                                             \
      std::abort();                                                         \
    }                                                                       \
  } while (false)
