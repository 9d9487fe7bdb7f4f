#include "common/interrupt.h"

#include <csignal>

namespace mjslam {
namespace {

// The one flag a signal handler may set (a sig_atomic_t; volatile so that
// every poll reads it).
volatile std::sig_atomic_t interrupt_requested = 0;

}  // namespace

void RequestInterrupt() { interrupt_requested = 1; }

bool InterruptRequested() { return interrupt_requested != 0; }

void ThrowIfInterrupted(const char* what) {
  if (interrupt_requested != 0) throw Interrupted(std::string(what) + " interrupted");
}

}  // namespace mjslam
