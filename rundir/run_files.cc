#include "rundir/run_files.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace mjslam::rundir {

namespace {

// Writes all of `contents` to `fd`; on failure returns the reason.
std::string WriteAll(int fd, const std::string& contents) {
  std::size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = ::write(fd, contents.data() + written, contents.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return std::strerror(errno);
    written += static_cast<std::size_t>(n);
  }
  return "";
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  const std::string temporary = path + ".tmp";
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(path + ": cannot write: " + std::strerror(errno));
  const std::string reason = WriteAll(fd, contents);
  ::close(fd);
  if (!reason.empty()) {
    std::remove(temporary.c_str());
    throw std::runtime_error(path + ": write failed: " + reason);
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string rename_reason = std::strerror(errno);
    std::remove(temporary.c_str());
    throw std::runtime_error(path + ": cannot replace: " + rename_reason);
  }
}

void OverwriteFile(const std::string& path, const std::string& contents) {
  // What was there, to put back when the new contents do not fit.
  const bool existed = std::filesystem::exists(path);
  const std::string old = existed ? ReadTextFile(path) : std::string();
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(path + ": cannot write: " + std::strerror(errno));
  std::string reason = WriteAll(fd, contents);
  if (reason.empty() && ::ftruncate(fd, static_cast<off_t>(contents.size())) != 0) {
    reason = std::strerror(errno);
  }
  if (!reason.empty() && existed) {
    // The old contents fit in the blocks they had: best effort, nothing half-written.
    if (::lseek(fd, 0, SEEK_SET) == 0 && WriteAll(fd, old).empty()) {
      (void)::ftruncate(fd, static_cast<off_t>(old.size()));
    }
  }
  ::close(fd);
  if (!reason.empty()) {
    if (!existed) std::remove(path.c_str());
    throw std::runtime_error(path + ": write failed: " + reason);
  }
}

std::string JsonText(const nlohmann::json& value) {
  // A byte that is not UTF-8 (a path, an argument) becomes U+FFFD instead of
  // an exception.
  return value.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

void WriteJsonAtomically(const std::string& path, const nlohmann::json& value) {
  WriteFileAtomically(path, JsonText(value));
}

std::string ReadTextFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string HashFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  char buffer[1 << 14];
  while (in) {
    in.read(buffer, sizeof(buffer));
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      hash ^= static_cast<unsigned char>(buffer[i]);
      hash *= 0x100000001b3ULL;
    }
  }
  char text[40];
  std::snprintf(text, sizeof(text), "fnv1a64:%016llx", static_cast<unsigned long long>(hash));
  return text;
}

std::string UtcNow() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

void MakeRunDirectory(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error || !std::filesystem::is_directory(dir)) {
    throw std::runtime_error(dir + ": cannot create the run directory" +
                             (error ? ": " + error.message() : std::string()));
  }
}

RunDirectoryLock::RunDirectoryLock(const std::string& dir) {
  MakeRunDirectory(dir);
  fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error(dir + ": cannot open the run directory: " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    ::close(fd_);
    fd_ = -1;
    if (error == EWOULDBLOCK) {
      throw std::runtime_error(dir + ": in use by another mjslam process (a run, replay or sweep "
                               "writing there); wait for it to end or use another --out");
    }
    throw std::runtime_error(dir + ": cannot lock the run directory: " + std::strerror(error));
  }
}

RunDirectoryLock::~RunDirectoryLock() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace mjslam::rundir
