#include "sim/mujoco_errors.h"

#include <sys/mman.h>

#include <csetjmp>
#include <cstddef>
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

// MuJoCo's allocations as its default allocator makes them (aligned_alloc,
// 64-byte aligned, the size padded to 64 bytes; freed with free(), which
// mju_free still calls), except that the large ones (an mjData's stack of
// 10 MB: MuJoCo 2.2 sizes it from njmax, not from the model, and zeroes it)
// are aligned to 2 MB and advised as huge pages. Zeroing 10 MB of fresh 4 kB
// pages costs 2,560 page faults, about 15 ms of CPU on this machine, and a
// run's setup makes seven such arenas (every mj_loadXML makes one); in huge
// pages, 5 faults. Only memory placement changes, no number.
void* AllocateForMujoco(std::size_t size) {
  constexpr std::size_t kAlign = 64;
  constexpr std::size_t kHugePage = std::size_t{2} << 20;
  if (size >= kHugePage) {
    const std::size_t padded = (size + kHugePage - 1) / kHugePage * kHugePage;
    void* block = std::aligned_alloc(kHugePage, padded);
    // Advice only: where huge pages are unavailable, the block is as before.
    if (block != nullptr) madvise(block, padded, MADV_HUGEPAGE);
    return block;
  }
  return std::aligned_alloc(kAlign, (size + kAlign - 1) / kAlign * kAlign);
}

}  // namespace

void InstallMujocoErrorHandlers() {
  // The hooks are process-wide; scenes may be loaded on several threads.
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  if (mju_user_error != &OnMujocoError) mju_user_error = &OnMujocoError;
  if (mju_user_warning != &OnMujocoWarning) mju_user_warning = &OnMujocoWarning;
  // Blocks from MuJoCo's default allocator and from this one are both freed
  // with free() (mju_user_free stays unset), so installing it at any time is
  // safe.
  if (mju_user_malloc != &AllocateForMujoco) mju_user_malloc = &AllocateForMujoco;
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
