#pragma once

#include <stdexcept>
#include <string>

namespace mjslam {

/// Thrown by ThrowIfInterrupted: the user asked the program to stop (Ctrl-C,
/// SIGTERM). `main` turns it into exit status 130; whatever threw it has
/// written no partial file.
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(const std::string& what) : std::runtime_error(what) {}
};

/// Records a request to stop. Async-signal-safe: `main`'s SIGINT and SIGTERM
/// handler calls it. Long computations notice it at their next
/// ThrowIfInterrupted (each polls often enough to stop within about a
/// second).
void RequestInterrupt();

/// Whether RequestInterrupt was called in this process.
bool InterruptRequested();

/// Throws Interrupted("`what` interrupted") when a stop was requested.
/// Called between the steps of long loops (evaluation, divergence, world
/// setup), so that they stop within about a second.
void ThrowIfInterrupted(const char* what);

}  // namespace mjslam
