#pragma once

#include <string>
#include <sys/types.h>

#include "renders/image.h"

namespace mjslam::renders {

/// An H.264 MP4 video written by Debian's ffmpeg, fed raw RGB frames through a
/// pipe. The video goes to a temporary file beside `path`, renamed to `path`
/// by Finish(); a writer destroyed before Finish() (an error, an interrupt)
/// stops ffmpeg and removes the temporary file, so `path` is never partial.
class VideoWriter {
 public:
  /// Starts `ffmpeg` (found on PATH) for frames of `width` x `height` pixels
  /// (even numbers) at `fps` frames per second, x264 `crf` (0..51), preset
  /// veryfast, yuv420p, no metadata that varies between runs. Throws
  /// std::runtime_error when ffmpeg cannot be started.
  VideoWriter(const std::string& path, int width, int height, double fps, int crf);
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  /// Sends one frame; its size must be the video's (checked). Throws
  /// std::runtime_error when ffmpeg has stopped reading.
  void AddFrame(const Image& frame);
  /// Closes the pipe, waits for ffmpeg and renames the temporary file to
  /// `path`. Throws std::runtime_error (with ffmpeg's exit status) when
  /// ffmpeg failed; then nothing is left at `path`'s temporary name.
  void Finish();

  int frames() const { return frames_; }

 private:
  void Abort();

  std::string path_;
  std::string temp_path_;
  int width_;
  int height_;
  int pipe_fd_ = -1;
  pid_t pid_ = -1;
  int frames_ = 0;
};

}  // namespace mjslam::renders
