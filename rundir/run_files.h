#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace mjslam::rundir {

/// Writes `value` to `path` through a temporary file in the same folder and a
/// rename, so readers see either the old file or the whole new one. Throws
/// std::runtime_error naming the file on failure.
void WriteFileAtomically(const std::string& path, const std::string& contents);

/// Writes `contents` over the file at `path` in place (no truncation first,
/// then cut to the new size): the blocks the old file holds are reused, so on
/// a full disk a file no larger than the old one's blocks is still written.
/// Not atomic: for recording an outcome when WriteFileAtomically failed.
/// Throws std::runtime_error naming the file on failure.
void OverwriteFile(const std::string& path, const std::string& contents);

/// Pretty-printed JSON, written atomically.
void WriteJsonAtomically(const std::string& path, const nlohmann::json& value);

/// `value` as the run directory's JSON files hold it: indented by 2, a line
/// end at the end; bytes that are not UTF-8 replaced by U+FFFD.
std::string JsonText(const nlohmann::json& value);

/// The whole text of a file; empty when it cannot be read.
std::string ReadTextFile(const std::string& path);

/// Content hash of a file: "fnv1a64:<16 hex digits>". Throws if unreadable.
std::string HashFile(const std::string& path);

/// Current UTC time as ISO 8601 ("2026-11-23T09:00:00Z").
std::string UtcNow();

/// Creates `dir` (and parents). Throws std::runtime_error naming it if it
/// cannot, or if it exists and is not a folder.
void MakeRunDirectory(const std::string& dir);

/// A run (or replay, or sweep) directory held by this process: created if
/// missing (MakeRunDirectory), then locked with an exclusive flock on the
/// folder itself (no lock file is left behind) until the object is
/// destroyed or the process ends, however it ends. Child processes do not
/// inherit the lock. Throws std::runtime_error naming the folder when
/// another process (another `mjslam run` with the same --out, say) holds
/// it: two writers into one folder would interleave rows and mix files.
class RunDirectoryLock {
 public:
  explicit RunDirectoryLock(const std::string& dir);
  ~RunDirectoryLock();
  RunDirectoryLock(const RunDirectoryLock&) = delete;
  RunDirectoryLock& operator=(const RunDirectoryLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace mjslam::rundir
