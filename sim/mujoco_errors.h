#pragma once

// MuJoCo's errors and warnings as C++ exceptions, without any exception
// unwinding through MuJoCo's C frames (see sim/README.md, "MuJoCo errors").
// No MuJoCo type appears here; the code that calls MuJoCo (sim/, renders/)
// wraps each call that can raise an error in TrapMujocoErrors or CallMujoco.

#include <stdexcept>
#include <string>

namespace mjslam::sim {

/// A problem with the simulation's input (world or robot file, start pose) or
/// a physics failure (a MuJoCo error or warning). The message names the file
/// and carries MuJoCo's own text.
class SimError : public std::runtime_error {
 public:
  explicit SimError(const std::string& message) : std::runtime_error(message) {}
};

/// Points MuJoCo's process-wide error and warning hooks (mju_user_error,
/// mju_user_warning) at this module's handlers, replacing any hooks set
/// before (the trapped calls below rely on them); idempotent. The error
/// handler, inside a trapped call, records MuJoCo's message and longjmps back
/// to the trap (it never returns into MuJoCo, which MuJoCo forbids, and never
/// throws through it); outside one, it prints the message to stderr and
/// aborts (MuJoCo's documented contract: the handler must not return). The
/// warning handler records the first warning of a trapped call and returns,
/// as MuJoCo requires; outside a trapped call it prints it to stderr. Also
/// sets MuJoCo's allocation hook (mju_user_malloc): MuJoCo's default
/// allocation, except that blocks of 2 MB or more are advised as huge pages
/// (an mjData's 10 MB stack is zeroed when made: 5 page faults instead of
/// 2,560). Scene and SceneRenderer call this; tests may call it first.
void InstallMujocoErrorHandlers();

/// MuJoCo's version string (for run manifests), e.g. "2.2.2".
std::string MujocoVersion();

namespace internal {

/// Calls `call(context)` with the error handler armed: returns true when the
/// call returned, false when MuJoCo raised an error inside it (its message is
/// then TrappedError()). Precondition: between this frame and MuJoCo's, no
/// object with a non-trivial destructor is alive (a longjmp skips those
/// frames; C++ allows that only when no such destructor is skipped). May be
/// nested: an inner call's warning then counts for the outer call too.
bool RunTrapped(void (*call)(void* context), void* context);

/// The message of the error that ended the last trapped call on this thread.
const char* TrappedError();

/// The first warning raised during the last outermost trapped call on this
/// thread ("" if none).
const char* TrappedWarning();

}  // namespace internal

/// Runs `call` (a callable taking no arguments) with MuJoCo's errors and
/// warnings trapped. Returns "" when it ran without either, else
/// "MuJoCo error: <MuJoCo's message>" (the call was abandoned where MuJoCo
/// raised the error) or "MuJoCo warning: <message>" (the call ran to its
/// end). `call`'s body must only call MuJoCo's C functions and touch plain
/// data (numbers, raw pointers, arrays): no object with a non-trivial
/// destructor may be created inside it, since an error skips its frame. After
/// an error, the MuJoCo data (and for some calls the model) that the call worked
/// on is in an unspecified state and must be discarded.
template <typename Call>
std::string TrapMujocoErrors(Call& call) {
  const bool completed = internal::RunTrapped(
      [](void* context) { (*static_cast<Call*>(context))(); }, &call);
  if (!completed) return std::string("MuJoCo error: ") + internal::TrappedError();
  if (internal::TrappedWarning()[0] != '\0') {
    return std::string("MuJoCo warning: ") + internal::TrappedWarning();
  }
  return std::string();
}

/// TrapMujocoErrors(call), throwing SimError("<what>: MuJoCo error: ...") or
/// ("<what>: MuJoCo warning: ...") when MuJoCo raised either.
template <typename Call>
void CallMujoco(const char* what, Call&& call) {
  const std::string problem = TrapMujocoErrors(call);
  if (!problem.empty()) throw SimError(std::string(what) + ": " + problem);
}

}  // namespace mjslam::sim
