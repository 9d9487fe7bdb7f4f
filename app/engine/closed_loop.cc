#include "app/engine/closed_loop.h"

#include <cmath>
#include <limits>
#include <vector>

#include "app/engine/true_coverage.h"
#include "common/angles.h"
#include "common/check.h"
#include "common/rng.h"
#include "explorer/waypoint_driver.h"
#include "sim/laser_noise.h"
#include "sim/simulator.h"
#include "sim/wheel_odometry.h"

namespace mjslam::app {
// The simulated world of the loop and what it measures of the run.
struct ClosedLoop::World {
  World(const RunConfig& config, const Rng& run_rng)
      : simulator(config.run.world, config.run.robot_model, config.sim, config.robot),
        laser_noise(config.laser, run_rng),
        odometry(config.robot, config.odometry, run_rng),
        drive_rng(run_rng.Fork("sim.drive_disturbance")) {}

  sim::Simulator simulator;
  sim::LaserNoise laser_noise;
  sim::WheelOdometry odometry;
  // The drive's disturbance, drawn at every control step when it is on.
  Rng drive_rng;
  std::optional<explorer::WaypointDriver> tour;
  std::optional<explorer::Explorer> explorer;
  std::optional<TrueCoverage> coverage;
  // The filter whose pose the explorer navigates with (-1: none).
  int driving_filter = -1;
  int explorer_log_version = -1;
  // What summary.json reports of the run.
  std::string termination = "time_limit";
  double distance_m = 0.0;
  int collisions = 0;
  int contact_steps = 0;
  bool in_contact = false;
  std::optional<double> t90;
  std::optional<double> t99;
  Pose2 X_WR_previous;
};

ClosedLoop::ClosedLoop(const RunConfig& config)
    : config_(config), dt_s_(1.0 / config.run.control_rate_hz) {
  // The world with the robot at its start pose; every random stream forks
  // from the run seed by name.
  world_ = std::make_unique<World>(config_, Rng(config_.run.seed));
  World& w = *world_;
  X_WR0_ = w.simulator.X_WR();
  X_RS_ = w.simulator.X_RS();
  w.X_WR_previous = X_WR0_;

  // The tour driver steers from the true pose; the explorer from pose_source.
  const double a_m = config_.robot.control_point_offset_m;
  if (config_.control.driver == "explorer") {
    w.explorer.emplace(config_.explorer, a_m);
  } else {
    std::vector<Eigen::Vector2d> waypoints;
    for (const auto& p : config_.driver.waypoints) waypoints.emplace_back(p[0], p[1]);
    if (waypoints.empty()) waypoints = w.simulator.scene().TourWaypoints();
    w.tour.emplace(config_.driver, waypoints, a_m);
  }
  filters_.emplace(config_.slam, config_.control, dt_s_, X_WR0_, X_RS_, Rng(config_.run.seed));
  // The filter whose pose the explorer navigates with (-1: odometry, truth).
  if (w.explorer) w.driving_filter = filters_->IndexOf(config_.control.pose_source);
  w.coverage.emplace(w.simulator.scene().Obstacles(), (X_WR0_ * Pose2(-a_m, 0.0, 0.0)).translation());
  last_step_ = static_cast<int>(
      std::floor(config_.run.duration_s * config_.run.control_rate_hz + 1e-9));
}

ClosedLoop::ClosedLoop(const RunConfig& config, const rundir::Recording& recording)
    : config_(config), recording_(&recording), dt_s_(1.0 / config.run.control_rate_hz) {
  // A recording without a true pose (a real log) starts at its odometry pose.
  const rundir::RecordedStep first = recording.Step(0);
  const bool has_truth = std::isfinite(first.X_WR_true.x) && std::isfinite(first.X_WR_true.y) &&
                         std::isfinite(first.X_WR_true.theta);
  const Pose2& X_WR0 = has_truth ? first.X_WR_true : first.X_WR_odometry;
  X_WR0_ = Pose2(X_WR0.x, X_WR0.y, X_WR0.theta);
  X_RS_ = recording.X_RS();
  filters_.emplace(config_.slam, config_.control, dt_s_, X_WR0_, X_RS_, Rng(config_.run.seed));
  last_step_ = static_cast<int>(recording.num_steps()) - 1;
}

ClosedLoop::~ClosedLoop() = default;

bool ClosedLoop::Done() const { return finished_ || step_ > last_step_; }

const explorer::Explorer* ClosedLoop::explorer() const {
  return world_ && world_->explorer ? &*world_->explorer : nullptr;
}

const LoopStep& ClosedLoop::Step() {
  laps_.Start();
  out_ = LoopStep();
  out_.index = step_;
  // What the robot reports: odometry, the command it held, maybe a scan.
  Sense();
  // Every filter on the same record.
  RunFilters();
  // The driver's command, held for the driving filter's command period.
  Drive();
  // The next control step.
  Advance();
  return out_;
}

void ClosedLoop::Sense() {
  if (world_) {
    SenseWorld();
  } else {
    ReadRecording();
    laps_.Start();  // reading a recording is no phase
  }
  previous_t_s_ = out_.record.t_s;
}

void ClosedLoop::SenseWorld() {
  World& w = *world_;
  const double t = step_ * dt_s_;
  const Pose2 X_WR = w.simulator.X_WR();
  w.distance_m += (X_WR.translation() - w.X_WR_previous.translation()).norm();
  w.X_WR_previous = X_WR;

  SensorRecord& record = out_.record;
  record.t_s = t;
  record.dt_s = step_ == 0 ? 0.0 : t - previous_t_s_;  // as a replay computes it
  record.command = applied_;
  // The odometry pose as written to trajectory.csv (frame O placed at the
  // start pose in W), so that a replay feeds the filters the same bits.
  record.X_OR = X_WR0_ * w.odometry.Update(w.simulator.WheelAngles());
  laps_.Charge(&cpu_.odometry_s);
  record.has_scan = step_ % config_.StepsPerScan() == 0;
  out_.X_WS_true = w.simulator.X_WS();
  if (record.has_scan) {
    const std::vector<double> jitter = w.laser_noise.DrawAngleOffsets();
    if (config_.laser.HasMixedPixels() || config_.laser.HasGrazingDropouts()) {
      sim::LaserFootprint footprint;
      const LaserScan exact = w.simulator.CastLaser(config_.laser, jitter, &footprint);
      record.scan = w.laser_noise.Apply(exact, &footprint);
    } else {
      record.scan = w.laser_noise.Apply(w.simulator.CastLaser(config_.laser, jitter));
    }
    record.scan.t_s = t;
    laps_.Charge(&cpu_.laser_s);
  }
  if (record.has_scan) w.coverage->Observe(out_.X_WS_true, record.scan);
  const double explored = w.coverage->ExploredFraction();
  if (!w.t90 && explored >= 0.90) w.t90 = t;
  if (!w.t99 && explored >= 0.99) w.t99 = t;
  laps_.Charge(&cpu_.coverage_s);

  out_.row.t_s = t;
  out_.row.X_WR_true = X_WR;
  out_.row.X_WR_odometry = record.X_OR;
  out_.row.explored = explored;
}

void ClosedLoop::ReadRecording() {
  const rundir::RecordedStep recorded = recording_->Step(static_cast<std::size_t>(step_));
  SensorRecord& record = out_.record;
  record.t_s = recorded.t_s;
  record.dt_s = step_ == 0 ? 0.0 : record.t_s - previous_t_s_;
  record.command = applied_;
  const Pose2& X_OR = recorded.X_WR_odometry;
  record.X_OR = Pose2(X_OR.x, X_OR.y, X_OR.theta);
  record.has_scan = recorded.scan_ranges_m != nullptr;
  if (record.has_scan) {
    LaserScan& scan = record.scan;
    const int num_beams = config_.laser.num_beams;
    scan.t_s = record.t_s;
    scan.angle_min_rad = config_.laser.AngleMinRad();
    scan.angle_increment_rad = config_.laser.AngleIncrementRad();
    scan.max_range_m = config_.laser.max_range_m;
    scan.ranges_m = *recorded.scan_ranges_m;
    scan.has_return.resize(num_beams);
    for (int b = 0; b < num_beams; ++b) {
      scan.has_return[b] = scan.ranges_m[b] < scan.max_range_m ? 1 : 0;
    }
  }
  // The row keeps the recorded values as they were written.
  out_.row.t_s = recorded.t_s;
  out_.row.X_WR_true = recorded.X_WR_true;
  out_.row.X_WR_odometry = recorded.X_WR_odometry;
  out_.row.command = recorded.command;
  out_.row.explored = recorded.explored;
}

void ClosedLoop::RunFilters() {
  filters_->Step(out_.record);
  const Pose2& X_WR = out_.row.X_WR_true;
  out_.row.filters = filters_->Rows(Pose2(X_WR.x, X_WR.y, X_WR.theta));
  laps_.Charge(&cpu_.filters_s);
}

void ClosedLoop::Drive() {
  if (world_) {
    DriveInWorld();
  } else {
    applied_ = out_.row.command;  // a recording brings its own commands
  }
  out_.row.command = applied_;
  laps_.Charge(&cpu_.explorer_s);
}

// The controller issues a command when the last period has run out; the
// command is then held for the period the driving filter's processing
// imposes, and the explorer sees nothing new in between.
void ClosedLoop::DriveInWorld() {
  if (step_ < next_command_step_) return;
  World& w = *world_;
  const int period_steps = w.driving_filter >= 0 ? filters_->period_steps(w.driving_filter) : 1;
  next_command_step_ = step_ + period_steps;
  const double t = out_.record.t_s;
  const Pose2& X_WR = out_.row.X_WR_true;
  Twist2 command;
  if (w.explorer) {
    Pose2 X_WR_used = X_WR;
    if (w.driving_filter >= 0) {
      X_WR_used = filters_->filter(w.driving_filter).X_WR();
    } else if (config_.control.pose_source == "odometry") {
      X_WR_used = out_.record.X_OR;
    }
    const SensorRecord& record = out_.record;
    const explorer::ExplorerOutput explored = w.explorer->Step(
        X_WR_used, record.has_scan ? &record.scan : nullptr, X_RS_, t, period_steps * dt_s_);
    command = explored.command;
    if (explored.finished) {
      out_.finished = true;
      w.termination = explored.finish_reason;
    }
    if (w.explorer->log_version() != w.explorer_log_version) {
      w.explorer_log_version = w.explorer->log_version();
      out_.explorer_changed = true;
    }
  } else {
    command = w.tour->Command(X_WR, period_steps * dt_s_);
  }
  applied_ = w.simulator.SetCommand(command);
}

void ClosedLoop::Advance() {
  finished_ = out_.finished;
  if (world_ && !finished_ && step_ < last_step_) {
    World& w = *world_;
    const double disturbance = config_.sim.drive_disturbance_std_fraction;
    if (disturbance > 0.0) {
      // Two draws a step: (e_v, e_w) of the twist or (e_left, e_right).
      const double e_1 = w.drive_rng.Gaussian(0.0, disturbance);
      const double e_2 = w.drive_rng.Gaussian(0.0, disturbance);
      if (config_.sim.drive_disturbance == "wheels") {
        w.simulator.SetWheelFactors(1.0 + e_1, 1.0 + e_2);
      } else {
        w.simulator.SetDriveFactors(1.0 + e_1, 1.0 + e_2);
      }
    }
    w.simulator.Advance(dt_s_);
    const int contacts = w.simulator.CountRobotWorldContacts();
    if (contacts > 0) ++w.contact_steps;
    if (contacts > 0 && !w.in_contact) ++w.collisions;
    w.in_contact = contacts > 0;
    laps_.Charge(&cpu_.physics_s);
  }
  ++step_;
}

rundir::RunSummary ClosedLoop::Summary(bool interrupted) const {
  MJSLAM_CHECK(world_ != nullptr);
  const World& w = *world_;
  rundir::RunSummary summary;
  summary.duration_s = previous_t_s_;
  summary.distance_m = w.distance_m;
  summary.collisions = w.collisions;
  summary.contact_steps = w.contact_steps;
  summary.termination_reason = interrupted ? "interrupted" : w.termination;
  summary.driver = config_.control.driver;
  summary.pose_source = config_.control.pose_source;
  summary.explored_fraction = w.coverage->ExploredFraction();
  summary.reachable_area_m2 = w.coverage->ReachableArea();
  summary.t_explored_90_s = w.t90;
  summary.t_explored_99_s = w.t99;
  const Pose2 X_WR_end = w.simulator.X_WR();
  for (int f = 0; f < filters_->size(); ++f) {
    const Pose2 X_WR_estimate = filters_->filter(f).X_WR();
    rundir::RunSummary::Filter filter;
    filter.name = filters_->name(f);
    filter.error_x = X_WR_estimate.x - X_WR_end.x;
    filter.error_y = X_WR_estimate.y - X_WR_end.y;
    filter.error_th = WrapAngle(X_WR_estimate.theta - X_WR_end.theta);
    filter.num_features = filters_->filter(f).num_features();
    filter.processing_s = filters_->total_processing_s(f);
    filter.open_loop_s = filters_->open_loop_s(f);
    filter.scans_processed = filters_->scans_processed(f);
    filter.scans_skipped = filters_->scans_skipped(f);
    filter.submap_starts_s = filters_->filter(f).SubmapStartTimes();
    const slam::InnovationCheckResult check = filters_->innovation_check(f);
    filter.innovation_windows = check.windows;
    filter.innovation_failed_windows = check.failed_windows;
    filter.innovation_longest_failed_streak = check.longest_failed_streak;
    filter.innovation_mean_nis = check.mean_nis;
    filter.innovation_inconsistent_since_s = check.inconsistent_since_s;
    filter.near_miss_windows = check.near_miss_windows;
    filter.near_miss_failed_windows = check.near_miss_failed_windows;
    filter.near_miss_fraction = check.near_miss_fraction;
    filter.near_miss_since_s = check.near_miss_since_s;
    filter.copies = check.copies;
    filter.copied_scans = check.copied_scans;
    filter.map_copied_at_s = check.map_copied_at_s;
    summary.filters.push_back(filter);
  }
  return summary;
}

}  // namespace mjslam::app
