#include "app/slam_pair.h"

#include <chrono>
#include <cmath>
#include <string>

#include "app/map_csv.h"
#include "eval/pose_metrics.h"
#include "slam/feature_extraction.h"

namespace mjslam::app {
namespace {

using Clock = std::chrono::steady_clock;

double MicrosecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::micro>(Clock::now() - start).count();
}

}  // namespace

SlamPair::SlamPair(const slam::SlamParams& params, const ControlParams& control, double dt_s,
                   const Pose2& X_WR0, const Pose2& X_RS)
    : params_(params), control_(control), dt_s_(dt_s) {
  filters_.emplace_back(
      "classical", slam::EkfSlam(params.ekf, slam::CorrectionMode::kClassical, X_WR0, X_RS));
  filters_.emplace_back(
      "selective", slam::EkfSlam(params.ekf, slam::CorrectionMode::kSelective, X_WR0, X_RS));
}

void SlamPair::Step(const SensorRecord& record) {
  slam::ScanFeatures features;
  double extraction_us = 0.0;
  if (record.has_scan) {
    const Clock::time_point start = Clock::now();
    features = slam::ExtractFeatures(record.scan, params_.features);
    extraction_us = MicrosecondsSince(start);
  }
  for (Filter& f : filters_) {
    const Clock::time_point start = Clock::now();
    f.report = f.filter.Step(record, record.has_scan ? &features : nullptr);
    f.processing_us = extraction_us + MicrosecondsSince(start);
    f.processing_s = ProcessingSeconds(control_, f.report, record.has_scan, f.processing_us);
    f.period_steps = CommandPeriodSteps(f.processing_s, dt_s_);
    f.total_processing_s += f.processing_s;
    if (f.steps_to_next_command <= 0) {
      f.open_loop_s += (f.period_steps - 1) * dt_s_;
      f.steps_to_next_command = f.period_steps;
    }
    --f.steps_to_next_command;
  }
}

std::vector<std::string> SlamPair::Columns() {
  std::vector<std::string> columns;
  for (const char* prefix : {"classical", "selective"}) {
    for (const char* name : {"x", "y", "th", "pxx", "pxy", "pxth", "pyy", "pyth", "pthth",
                             "nfeat", "nmatched", "nupdated", "us", "period", "open_loop",
                             "nees"}) {
      columns.push_back(std::string(prefix) + "_" + name);
    }
  }
  return columns;
}

void SlamPair::AddColumns(const Pose2& X_WR_true, CsvWriter* writer) const {
  for (const Filter& f : filters_) {
    const Pose2 X_WR = f.filter.X_WR();
    const Eigen::Matrix3d P = f.filter.pose_covariance();
    writer->Add(X_WR.x);
    writer->Add(X_WR.y);
    writer->Add(X_WR.theta);
    writer->Add(P(0, 0));
    writer->Add(P(0, 1));
    writer->Add(P(0, 2));
    writer->Add(P(1, 1));
    writer->Add(P(1, 2));
    writer->Add(P(2, 2));
    writer->Add(f.report.num_features);
    writer->Add(f.report.num_matched);
    writer->Add(f.report.num_updated);
    writer->Add(f.processing_us);
    writer->Add(f.period_steps * dt_s_);
    writer->Add(f.open_loop_s);
    // Empty where P is (nearly) singular: the known start and the steps after.
    const double nees = eval::EvaluatePoseStep(X_WR_true, X_WR, P).nees;
    if (std::isfinite(nees)) {
      writer->Add(nees);
    } else {
      writer->AddEmpty();
    }
  }
}

void SlamPair::WriteMaps(const std::string& dir) const {
  for (const Filter& f : filters_) {
    WriteMapCsv(dir + "/map_" + f.name + ".csv", f.filter.Map());
  }
}

}  // namespace mjslam::app
