#include "renders/video_writer.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "common/check.h"

extern char** environ;

namespace mjslam::renders {

namespace {

std::string NumberText(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", value);
  return buffer;
}

}  // namespace

VideoWriter::VideoWriter(const std::string& path, int width, int height, double fps, int crf)
    : path_(path), temp_path_(path + ".tmp.mp4"), width_(width), height_(height) {
  MJSLAM_CHECK(width > 0 && height > 0 && width % 2 == 0 && height % 2 == 0);
  MJSLAM_CHECK(fps > 0 && crf >= 0 && crf <= 51);
  // A write to a pipe whose reader died must fail with EPIPE, not kill us.
  std::signal(SIGPIPE, SIG_IGN);

  const std::vector<std::string> arguments = {
      "ffmpeg", "-nostdin", "-hide_banner", "-loglevel", "error", "-y",
      // Input: raw RGB frames on stdin.
      "-f", "rawvideo", "-pix_fmt", "rgb24", "-s",
      std::to_string(width) + "x" + std::to_string(height), "-framerate", NumberText(fps),
      "-i", "pipe:0",
      // Output: H.264 that every browser plays, without varying metadata.
      "-c:v", "libx264", "-preset", "ultrafast", "-crf", std::to_string(crf), "-pix_fmt",
      "yuv420p", "-movflags", "+faststart", "-map_metadata", "-1", "-fflags", "+bitexact",
      "-flags:v", "+bitexact", "-f", "mp4", temp_path_};
  std::vector<char*> argv;
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    throw std::runtime_error(std::string("cannot create a pipe to ffmpeg: ") + std::strerror(errno));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  const int status = ::posix_spawnp(&pid_, "ffmpeg", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  if (status != 0) {
    ::close(fds[1]);
    pid_ = -1;
    throw std::runtime_error("cannot start ffmpeg to write '" + path + "': " +
                             std::strerror(status) + " (install Debian's ffmpeg package)");
  }
  pipe_fd_ = fds[1];
}

VideoWriter::~VideoWriter() { Abort(); }

void VideoWriter::Abort() {
  if (pipe_fd_ >= 0) ::close(pipe_fd_);
  pipe_fd_ = -1;
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }
  std::error_code ignored;
  std::filesystem::remove(temp_path_, ignored);
}

void VideoWriter::AddFrame(const Image& frame) {
  MJSLAM_CHECK(frame.width == width_ && frame.height == height_);
  MJSLAM_CHECK(pipe_fd_ >= 0);
  const std::uint8_t* data = frame.rgb.data();
  std::size_t left = frame.rgb.size();
  while (left > 0) {
    const ssize_t written = ::write(pipe_fd_, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      const std::string reason = std::strerror(errno);
      Abort();
      throw std::runtime_error("ffmpeg stopped reading frames for '" + path_ + "': " + reason);
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  ++frames_;
}

void VideoWriter::Finish() {
  MJSLAM_CHECK(pipe_fd_ >= 0 && pid_ > 0);
  ::close(pipe_fd_);
  pipe_fd_ = -1;
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    Abort();
    throw std::runtime_error("ffmpeg failed to write '" + path_ + "' (exit status " +
                             std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
  }
  std::error_code error;
  std::filesystem::rename(temp_path_, path_, error);
  if (error) {
    Abort();
    throw std::runtime_error("cannot rename '" + temp_path_ + "' to '" + path_ +
                             "': " + error.message());
  }
}

}  // namespace mjslam::renders
