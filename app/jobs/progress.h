#pragma once

#include <string>

namespace mjslam::app {

/// A one-line progress bar on stderr, drawn only when stderr is a terminal.
class Progress {
 public:
  /// `label` precedes the bar; `total` is the amount of work (e.g. steps).
  Progress(std::string label, double total);
  ~Progress();
  /// Redraws when the shown percentage changes.
  void Update(double done);
  /// Ends the line.
  void Finish();

 private:
  std::string label_;
  double total_;
  bool enabled_;
  int shown_percent_ = -1;
  bool finished_ = false;
};

}  // namespace mjslam::app
