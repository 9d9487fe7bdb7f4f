#include "app/slam_pair.h"

#include <chrono>
#include <cmath>
#include <string>

#include "eval/pose_metrics.h"
#include "rundir/layout.h"
#include "rundir/map_csv.h"
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

std::vector<rundir::FilterRow> SlamPair::Rows(const Pose2& X_WR_true) const {
  std::vector<rundir::FilterRow> rows;
  for (const Filter& f : filters_) {
    rundir::FilterRow row;
    row.X_WR = f.filter.X_WR();
    row.P = f.filter.pose_covariance();
    row.num_features = f.report.num_features;
    row.num_matched = f.report.num_matched;
    row.num_updated = f.report.num_updated;
    row.processing_us = f.processing_us;
    row.period_s = f.period_steps * dt_s_;
    row.open_loop_s = f.open_loop_s;
    // Not finite where P is (nearly) singular: the known start and the steps after.
    row.nees = eval::EvaluatePoseStep(X_WR_true, row.X_WR, row.P).nees;
    rows.push_back(row);
  }
  return rows;
}

void WriteMaps(const SlamPair& slam, const std::string& dir) {
  for (int f = 0; f < 2; ++f) {
    rundir::WriteMapCsv(rundir::PathIn(dir, rundir::MapFile(slam.name(f))),
                        slam.filter(f).Map());
  }
}

}  // namespace mjslam::app
