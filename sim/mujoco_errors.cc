#include "sim/mujoco_errors.h"

#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <mutex>

#include <mujoco/mujoco.h>

namespace mjslam::sim {
namespace {

// The trap of the innermost trapped call on this thread (nullptr outside
// one), and what MuJoCo said during it. Plain data only: the error handler
// runs inside MuJoCo's C frames.
thread_local std::jmp_buf* active_trap = nullptr;
thread_local char trapped_error[1024] = "";
thread_local char trapped_warning[1024] = "";

void CopyMessage(const char* message, char (&buffer)[1024]) {
  std::snprintf(buffer, sizeof(buffer), "%s", message != nullptr ? message : "(no message)");
}

// MuJoCo calls this from mju_error and assumes it does not return.
void OnMujocoError(const char* message) {
  if (active_trap == nullptr) {
    std::fprintf(stderr, "MuJoCo error outside a trapped call (aborting): %s\n",
                 message != nullptr ? message : "(no message)");
    std::abort();
  }
  CopyMessage(message, trapped_error);
  std::longjmp(*active_trap, 1);
}

// MuJoCo calls this from mju_warning and continues after it returns.
void OnMujocoWarning(const char* message) {
  if (active_trap == nullptr) {
    std::fprintf(stderr, "MuJoCo warning outside a trapped call: %s\n",
                 message != nullptr ? message : "(no message)");
    return;
  }
  if (trapped_warning[0] == '\0') CopyMessage(message, trapped_warning);
}

}  // namespace

void InstallMujocoErrorHandlers() {
  // The hooks are process-wide; scenes may be loaded on several threads.
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  if (mju_user_error != &OnMujocoError) mju_user_error = &OnMujocoError;
  if (mju_user_warning != &OnMujocoWarning) mju_user_warning = &OnMujocoWarning;
}

std::string MujocoVersion() { return mj_versionString(); }

namespace internal {

bool RunTrapped(void (*call)(void* context), void* context) {
  std::jmp_buf trap;
  std::jmp_buf* volatile outer = active_trap;
  if (outer == nullptr) trapped_warning[0] = '\0';
  if (setjmp(trap) != 0) {
    // MuJoCo raised an error inside `call`: its frames are abandoned.
    active_trap = outer;
    return false;
  }
  active_trap = &trap;
  call(context);
  active_trap = outer;
  return true;
}

const char* TrappedError() { return trapped_error; }
const char* TrappedWarning() { return trapped_warning; }

}  // namespace internal
}  // namespace mjslam::sim
