#include "app/jobs/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace mjslam::app {

Progress::Progress(std::string label, double total)
    : label_(std::move(label)), total_(total), enabled_(::isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() { Finish(); }

void Progress::Update(double done) {
  if (!enabled_ || total_ <= 0) return;
  const int percent = std::clamp(static_cast<int>(100.0 * done / total_), 0, 100);
  if (percent == shown_percent_) return;
  shown_percent_ = percent;
  constexpr int kWidth = 40;
  const int filled = percent * kWidth / 100;
  std::fprintf(stderr, "\r%s [%s%s] %3d%%", label_.c_str(), std::string(filled, '#').c_str(),
               std::string(kWidth - filled, ' ').c_str(), percent);
  std::fflush(stderr);
}

void Progress::Finish() {
  if (!enabled_ || finished_) return;
  finished_ = true;
  if (shown_percent_ >= 0) std::fprintf(stderr, "\n");
}

}  // namespace mjslam::app
