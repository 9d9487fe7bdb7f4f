#pragma once

#include <string>
#include <utility>
#include <vector>

#include "app/control.h"
#include "common/records.h"
#include "eval/map_types.h"
#include "rundir/rows.h"
#include "slam/ekf_slam.h"
#include "slam/slam_params.h"

namespace mjslam::app {

/// The two filters of the paper on the same records: the classical sequential
/// EKF and the selective one. Features are extracted once per scan and given
/// to both; each filter's processing time is that extraction plus its own
/// step, measured with a steady clock. Each filter's processing time also
/// gives the command period it would impose (ControlParams).
class SlamPair {
 public:
  /// X_WR0: known initial pose of R; X_RS: the laser mount on R; `dt_s` the
  /// control period without delay (one control step).
  SlamPair(const slam::SlamParams& params, const ControlParams& control, double dt_s,
           const Pose2& X_WR0, const Pose2& X_RS);

  /// Runs both filters on one record.
  void Step(const SensorRecord& record);

  /// Both filters' columns of trajectory.csv after the last step, in the
  /// order of rundir::FilterNames(); X_WR_true is the true pose of R for
  /// the NEES.
  std::vector<rundir::FilterRow> Rows(const Pose2& X_WR_true) const;

  /// Processing time of filter `i` (0 classical, 1 selective) for the last
  /// step, seconds (ControlParams::processing), and the command period it
  /// imposes, in control steps.
  double processing_s(int i) const { return filters_[i].processing_s; }
  int period_steps(int i) const { return filters_[i].period_steps; }
  /// Totals so far of filter `i`: processing time, and open-loop time on its
  /// own command timeline (a command is issued when the last one's period
  /// has run out and held for the period of that step; all of it but one
  /// control step runs open loop), seconds.
  double total_processing_s(int i) const { return filters_[i].total_processing_s; }
  double open_loop_s(int i) const { return filters_[i].open_loop_s; }
  /// Filter `i` by index, and its name.
  const slam::EkfSlam& filter(int i) const { return filters_[i].filter; }
  const std::string& name(int i) const { return filters_[i].name; }

  const slam::EkfSlam& classical() const { return filters_[0].filter; }
  const slam::EkfSlam& selective() const { return filters_[1].filter; }

 private:
  struct Filter {
    Filter(std::string name_in, slam::EkfSlam filter_in)
        : name(std::move(name_in)), filter(std::move(filter_in)) {}
    std::string name;
    slam::EkfSlam filter;
    slam::StepReport report;
    double processing_us = 0.0;
    double processing_s = 0.0;
    int period_steps = 1;
    double total_processing_s = 0.0;
    double open_loop_s = 0.0;
    int steps_to_next_command = 0;
  };
  slam::SlamParams params_;
  ControlParams control_;
  double dt_s_;
  std::vector<Filter> filters_;
};

/// Writes each filter's map (map_classical.csv, map_selective.csv) into the
/// run directory `dir`.
void WriteMaps(const SlamPair& slam, const std::string& dir);

}  // namespace mjslam::app
