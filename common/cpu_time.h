#pragma once

#include <ctime>

namespace mjslam {

/// CPU time (user + system) the calling thread has used so far, seconds
/// (POSIX CLOCK_THREAD_CPUTIME_ID): what a measurement of one piece of code
/// should use on a machine shared with other jobs.
inline double ThreadCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

/// CPU time (user + system) the whole process has used so far, seconds, all
/// threads together (POSIX CLOCK_PROCESS_CPUTIME_ID).
inline double ProcessCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

}  // namespace mjslam
