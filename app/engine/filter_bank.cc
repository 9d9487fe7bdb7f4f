#include "app/engine/filter_bank.h"

#include <chrono>
#include <cmath>
#include <string>

#include "common/check.h"
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

FilterTiming FilterTimingFromText(const std::string& text) {
  if (text == "realtime") return FilterTiming::kRealtime;
  MJSLAM_CHECK(text == "every_scan");
  return FilterTiming::kEveryScan;
}

FilterBank::FilterBank(const slam::SlamParams& params, const ControlParams& control, double dt_s,
                       const Pose2& X_WR0, const Pose2& X_RS, const Rng& run_rng)
    : params_(params), control_(control), dt_s_(dt_s) {
  const slam::InnovationCheck check(params.innovation_check,
                                    slam::ChiSquare2Quantile(params.ekf.gate_probability));
  // Each filter's draws (the selection policy random) are a stream of their
  // own, forked from the run seed by the filter's name.
  for (const slam::FilterParams& entry : slam::ResolvedFilters(params)) {
    const slam::FilterSettings settings = slam::SettingsOf(params, entry);
    filters_.emplace_back(slam::FilterRegistry::Global().Make(settings, X_WR0, X_RS, run_rng),
                          check, FilterTimingFromText(settings.slam.timing));
    names_.push_back(entry.name);
  }
}

int FilterBank::IndexOf(const std::string& name) const {
  for (int i = 0; i < size(); ++i) {
    if (names_[i] == name) return i;
  }
  return -1;
}

void FilterBank::Step(const SensorRecord& record) {
  const int step = step_++;
  // Who processes this record: every filter, or in realtime timing those
  // whose last period has run out.
  bool any_processes = false;
  for (Slot& f : filters_) {
    f.processed = f.timing == FilterTiming::kEveryScan || step >= f.next_free_step;
    any_processes = any_processes || f.processed;
  }
  slam::ScanFeatures features;
  double extraction_us = 0.0;
  if (record.has_scan && any_processes) {
    const Clock::time_point start = Clock::now();
    features = slam::ExtractFeatures(record.scan, params_.features);
    extraction_us = MicrosecondsSince(start);
  }
  for (Slot& f : filters_) {
    if (f.processed) {
      const Clock::time_point start = Clock::now();
      const slam::ScanFeatures* given = record.has_scan ? &features : nullptr;
      f.report = f.timing == FilterTiming::kEveryScan ? f.filter->Step(record, given)
                                                      : CatchUpAndStep(&f, record, given);
      // A submap's join runs beside the filter: not in its processing time.
      f.processing_us = extraction_us + MicrosecondsSince(start) - f.report.beside_us;
      f.processing_s = ProcessingSeconds(control_, f.report, record.has_scan, f.processing_us);
      f.period_steps = CommandPeriodSteps(f.processing_s, dt_s_);
      f.total_processing_s += f.processing_s;
      f.next_free_step = step + f.period_steps;
      if (record.has_scan) ++f.scans_processed;
      f.innovation_check.Add(record.t_s, f.report.nis_sum, f.report.num_matched,
                             f.report.num_observed,
                             f.innovation_check.NearMisses(f.report.nearest_nis),
                             f.innovation_check.Copies(f.report.association, f.report.nearest_nis));
    } else {
      // Busy: the scan is lost; the record's motion (its command, its
      // odometry pose) waits for the next prediction.
      SensorRecord motion;
      motion.t_s = record.t_s;
      motion.dt_s = record.dt_s;
      motion.command = record.command;
      motion.X_OR = record.X_OR;
      f.skipped_records.push_back(motion);
      slam::StepReport held;
      held.num_features = f.report.num_features;
      f.report = held;
      f.processing_us = 0.0;
      f.processing_s = 0.0;
      if (record.has_scan) ++f.scans_skipped;
    }
    // The filter's command timeline: a period starts at each processed
    // record (in realtime timing exactly when the last one has run out).
    if (f.steps_to_next_command <= 0) {
      f.open_loop_s += (f.period_steps - 1) * dt_s_;
      f.steps_to_next_command = f.period_steps;
    }
    --f.steps_to_next_command;
  }
}

slam::StepReport FilterBank::CatchUpAndStep(Slot* f, const SensorRecord& record,
                                          const slam::ScanFeatures* features) {
  // One prediction per skipped record, each with its own command, odometry
  // increment and dt, as if the filter had run them: one prediction over
  // the whole period would take its noise and its self-calibration
  // Jacobians from the net increment and the last command, which a turn in
  // place followed by a drive does not resemble.
  for (const SensorRecord& skipped : f->skipped_records) f->filter->Step(skipped, nullptr);
  f->skipped_records.clear();
  return f->filter->Step(record, features);
}

std::vector<rundir::FilterRow> FilterBank::Rows(const Pose2& X_WR_true) {
  std::vector<rundir::FilterRow> rows;
  for (Slot& f : filters_) {
    if (f.processed) f.X_WR_true_processed = X_WR_true;
    rundir::FilterRow row;
    row.X_WR = f.filter->X_WR();
    row.P = f.filter->pose_covariance();
    row.num_features = f.report.num_features;
    row.num_matched = f.report.num_matched;
    row.num_updated = f.report.num_updated;
    row.processing_us = f.processing_us;
    row.period_s = f.period_steps * dt_s_;
    row.open_loop_s = f.open_loop_s;
    row.processed = f.processed;
    // Not finite where P is (nearly) singular: the known start and the steps after.
    row.nees = eval::EvaluatePoseStep(f.X_WR_true_processed, row.X_WR, row.P).nees;
    rows.push_back(row);
  }
  return rows;
}

void WriteMaps(const FilterBank& filters, const std::string& dir) {
  for (int f = 0; f < filters.size(); ++f) {
    rundir::WriteMapCsv(rundir::PathIn(dir, rundir::MapFile(filters.name(f))),
                        filters.filter(f).Map());
  }
}

}  // namespace mjslam::app
