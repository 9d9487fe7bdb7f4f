#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "app/engine/control.h"
#include "common/records.h"
#include "common/rng.h"
#include "eval/map_types.h"
#include "rundir/rows.h"
#include "slam/ekf_slam.h"
#include "slam/filter.h"
#include "slam/innovation_check.h"
#include "slam/slam_params.h"

namespace mjslam::app {

/// When each filter runs (`slam.timing`; docs/method.md, "Real-time filter
/// timing").
enum class FilterTiming {
  /// Every filter processes every record, whatever its processing time.
  kEveryScan,
  /// A filter that processed a record at step s is busy until step s + its
  /// command period: the records of the steps in between are not processed
  /// (their scans are skipped); their motion enters the prediction of the
  /// next record it processes.
  kRealtime,
};

/// The FilterTiming of the `slam.timing` text ("every_scan", "realtime");
/// SlamParams::Validate() has checked it. Aborts on any other text.
FilterTiming FilterTimingFromText(const std::string& text);

/// The run's filters on the same records (`slam.filters`, by default the
/// paper's two: the classical sequential EKF and the selective one), each a
/// slam::Filter of a registered kind, built by slam::FilterRegistry.
/// Features are extracted once per scan and given to every filter; each
/// filter's processing time is that extraction plus its own step, measured
/// with a steady clock. Each filter's processing time also gives the command
/// period it would impose (ControlParams). With `slam.timing: realtime` (or
/// the filter's own `timing`) a filter runs on its own timeline
/// (FilterTiming::kRealtime).
class FilterBank {
 public:
  /// The filters of slam::ResolvedFilters(params), in that order. X_WR0:
  /// known initial pose of R; X_RS: the laser mount on R; `dt_s` the control
  /// period without delay (one control step); `run_rng` the run seed's
  /// stream, from which each filter forks its own draws by its name (the
  /// random selection policy). Throws ParamError for a kind that is not
  /// registered or invalid settings.
  FilterBank(const slam::SlamParams& params, const ControlParams& control, double dt_s,
             const Pose2& X_WR0, const Pose2& X_RS, const Rng& run_rng);

  /// Runs every filter on one record, the record of the next control step
  /// (the first call is step 0). In realtime timing, a filter still busy
  /// with an earlier record skips this one (processed(i) is false after the
  /// call): its estimate and map stay those of its last processed record.
  /// A filter that is free predicts over every step since its last processed
  /// record, one prediction per skipped record with that record's own
  /// command, odometry increment and dt, then processes this one.
  void Step(const SensorRecord& record);

  /// Every filter's columns of trajectory.csv after the last step, in the
  /// order of names(); X_WR_true is this step's true pose of R.
  /// A filter that skipped the step reports its last processed estimate,
  /// covariance and map size, 0 matched, updated and microseconds, the period
  /// still running, and processed = false; its NEES compares that estimate
  /// with the true pose of the step it refers to (its last processed one),
  /// not with this step's.
  std::vector<rundir::FilterRow> Rows(const Pose2& X_WR_true);

  /// Number of filters, their names in order, and the index of filter
  /// `name` (-1: none).
  int size() const { return static_cast<int>(filters_.size()); }
  const std::vector<std::string>& names() const { return names_; }
  int IndexOf(const std::string& name) const;
  /// Processing time of filter `i` for the last step, seconds
  /// (ControlParams::processing), and the command period it imposes, in
  /// control steps.
  double processing_s(int i) const { return filters_[i].processing_s; }
  int period_steps(int i) const { return filters_[i].period_steps; }
  /// Totals so far of filter `i`: processing time, and open-loop time on its
  /// own command timeline (a command is issued when the last one's period
  /// has run out and held for the period of that step; all of it but one
  /// control step runs open loop), seconds.
  double total_processing_s(int i) const { return filters_[i].total_processing_s; }
  double open_loop_s(int i) const { return filters_[i].open_loop_s; }
  /// Whether filter `i` processed the last step's record (always in
  /// every_scan timing), and its counts so far of scans processed and of
  /// scans skipped because it was busy.
  bool processed(int i) const { return filters_[i].processed; }
  int scans_processed(int i) const { return filters_[i].scans_processed; }
  int scans_skipped(int i) const { return filters_[i].scans_skipped; }
  /// What the check of filter `i` against its own innovations found so far
  /// (slam.innovation_check; slam::InnovationCheck).
  slam::InnovationCheckResult innovation_check(int i) const {
    return filters_[i].innovation_check.result();
  }
  /// The timing filter `i` runs with.
  FilterTiming timing(int i) const { return filters_[i].timing; }
  /// Filter `i` by index, and its name.
  const slam::Filter& filter(int i) const { return *filters_[i].filter; }
  const std::string& name(int i) const { return names_[i]; }

 private:
  struct Slot {
    Slot(std::unique_ptr<slam::Filter> filter_in, slam::InnovationCheck check_in,
         FilterTiming timing_in)
        : filter(std::move(filter_in)), innovation_check(check_in), timing(timing_in) {}
    std::unique_ptr<slam::Filter> filter;
    slam::InnovationCheck innovation_check;
    FilterTiming timing;
    slam::StepReport report;
    double processing_us = 0.0;
    double processing_s = 0.0;
    int period_steps = 1;
    double total_processing_s = 0.0;
    double open_loop_s = 0.0;
    int steps_to_next_command = 0;
    // Realtime timing: the first step at which the filter is free again,
    // and the records of the steps it skipped since, without their scans.
    int next_free_step = 0;
    std::vector<SensorRecord> skipped_records;
    bool processed = true;
    // The true pose at the last processed step: what the estimate is of.
    Pose2 X_WR_true_processed;
    int scans_processed = 0;
    int scans_skipped = 0;
  };
  // Realtime timing: filter `f` catches up over the records it skipped and
  // processes `record` (the features when it has a scan). Returns the
  // filter's step report.
  slam::StepReport CatchUpAndStep(Slot* f, const SensorRecord& record,
                                  const slam::ScanFeatures* features);

  slam::SlamParams params_;
  ControlParams control_;
  double dt_s_;
  int step_ = 0;  // index of the next record
  std::vector<Slot> filters_;
  std::vector<std::string> names_;  // filters_[i] is named names_[i]
};

/// Writes each filter's map (map_<name>.csv: map_classical.csv,
/// map_selective.csv by default) into the run directory `dir`.
void WriteMaps(const FilterBank& filters, const std::string& dir);

}  // namespace mjslam::app
