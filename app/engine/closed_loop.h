#pragma once

#include <memory>
#include <optional>
#include <string>

#include "app/engine/cpu_profile.h"
#include "app/engine/run_config.h"
#include "app/engine/filter_bank.h"
#include "common/records.h"
#include "explorer/explorer.h"
#include "rundir/recording.h"
#include "rundir/rows.h"
#include "rundir/summary.h"

namespace mjslam::app {

/// What one step of the closed loop produced. The filters and the explorer
/// after the step are ClosedLoop::slam() and ClosedLoop::explorer().
struct LoopStep {
  /// Index of the control step, from 0.
  int index = 0;
  /// The record every filter ran on (time, odometry, held command, scan).
  SensorRecord record;
  /// True pose of the laser S in W at the step (simulated loop only).
  Pose2 X_WS_true;
  /// The step's row of trajectory.csv: truth, odometry, the command applied
  /// from now on, the explored fraction and every filter's columns.
  rundir::TrajectoryRow row;
  /// The explorer's sets changed in this step (explorer.csv gets rows).
  bool explorer_changed = false;
  /// The driver has finished (no frontier left, goal unreachable): the loop
  /// is done after this step.
  bool finished = false;
};

/// The closed loop of `mjslam run` and `mjslam replay`: a source of records
/// (the simulator, or a recording of an earlier run), the run's filters
/// (FilterBank), the driver (the frontier explorer or the tour; a recording
/// brings its own commands) and the clock (control steps, the command held
/// for the driving filter's command period). One Step() reads like the data
/// flow: sense, filter, drive, advance. Writes no files: its callers hand
/// each LoopStep to the rundir writers.
///
/// Composed as Cartographer's LocalTrajectoryBuilder2D: small parts, private
/// steps as named methods.
class ClosedLoop {
 public:
  /// The simulated loop: the world and robot of `config.run`, the laser and
  /// odometry noise seeded from run.seed, the driver of control.driver,
  /// run.duration_s of steps. Throws what the simulator throws (sim::SimError)
  /// for a bad world or robot; `config` must be valid.
  explicit ClosedLoop(const RunConfig& config);
  /// The recorded loop: the filters on the records rebuilt from
  /// `recording` (true start pose, or the first odometry pose of a recording
  /// without truth such as an imported log; odometry, held commands, scans laid out
  /// as config.laser says; ranges at the maximum are no-return). `recording`
  /// must outlive the loop.
  ClosedLoop(const RunConfig& config, const rundir::Recording& recording);
  ~ClosedLoop();
  ClosedLoop(const ClosedLoop&) = delete;
  ClosedLoop& operator=(const ClosedLoop&) = delete;

  /// True once every step has run or the driver has finished.
  bool Done() const;
  /// Runs one control step; requires !Done(). The result stays valid until
  /// the next call.
  const LoopStep& Step();

  /// Number of steps the loop will run at most.
  int num_steps() const { return last_step_ + 1; }
  /// The laser mount X_RS on R.
  const Pose2& X_RS() const { return X_RS_; }
  /// The run's filters.
  const FilterBank& filters() const { return *filters_; }
  /// The explorer when it drives, else null.
  const explorer::Explorer* explorer() const;
  /// The simulated run so far (simulated loop only): distance, contacts,
  /// exploration, termination (`interrupted` when `interrupted`), and each
  /// filter's end state against the current true pose.
  rundir::RunSummary Summary(bool interrupted) const;
  /// CPU seconds spent so far in each phase of the steps (the physics, the
  /// laser, odometry, coverage, the filters, the driver); the files, video
  /// and total are the caller's to fill in.
  const PhaseCpu& cpu() const { return cpu_; }

 private:
  struct World;  // the simulated world: simulator, noise, odometry, driver, coverage

  // The steps of Step(), in order.
  void Sense();
  void SenseWorld();
  void ReadRecording();
  void RunFilters();
  void Drive();
  void DriveInWorld();
  void Advance();

  const RunConfig config_;
  std::unique_ptr<World> world_;                     // simulated loop
  const rundir::Recording* recording_ = nullptr;     // recorded loop
  std::optional<FilterBank> filters_;
  Pose2 X_WR0_;
  Pose2 X_RS_;

  // The clock: control steps of dt_s_, the command held until
  // next_command_step_.
  double dt_s_ = 0.0;
  int step_ = 0;
  int last_step_ = 0;
  int next_command_step_ = 0;
  double previous_t_s_ = 0.0;
  Twist2 applied_;
  bool finished_ = false;
  LoopStep out_;
  PhaseCpu cpu_;
  // The clock of cpu_: each phase of a step is charged when it ends.
  CpuLaps laps_;
};

}  // namespace mjslam::app
