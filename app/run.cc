#include "app/run.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <optional>

#include "app/csv_writer.h"
#include "app/live_video.h"
#include "app/progress.h"
#include "app/run_files.h"
#include "app/slam_pair.h"
#include "app/true_coverage.h"
#include "config/config.h"
#include "explorer/explorer.h"
#include "explorer/waypoint_driver.h"
#include "sim/laser_noise.h"
#include "sim/simulator.h"
#include "sim/wheel_odometry.h"
#include "common/angles.h"

namespace mjslam::app {

std::vector<std::string> TrajectoryColumns() {
  std::vector<std::string> columns = {"t",      "true_x", "true_y", "true_th", "odom_x",
                                      "odom_y", "odom_th", "cmd_v",  "cmd_w",   "explored"};
  for (const std::string& column : SlamPair::Columns()) columns.push_back(column);
  return columns;
}

std::vector<std::string> ScanColumns(int num_beams) {
  std::vector<std::string> columns = {"t", "x", "y", "th"};
  for (int i = 0; i < num_beams; ++i) columns.push_back("r" + std::to_string(i));
  return columns;
}

namespace {

// The manifest as written at the start of the run; the end fills in the rest.
nlohmann::json StartManifest(const RunConfig& config, const RunOptions& options) {
  nlohmann::json manifest;
  manifest["seed"] = config.run.seed;
  manifest["mjslam_version"] = MjslamVersion();
  manifest["git_commit"] = MjslamGitCommit();
  manifest["mujoco_version"] = sim::MujocoVersion();
  manifest["world_file"] = config.run.world;
  manifest["world_hash"] = HashFile(config.run.world);
  manifest["robot_model_file"] = config.run.robot_model;
  manifest["robot_model_hash"] = HashFile(config.run.robot_model);
  manifest["config_file"] = options.config_path;
  manifest["command_line"] = options.command_line;
  manifest["start_time"] = UtcNow();
  manifest["end_time"] = nullptr;
  manifest["status"] = "running";
  manifest["steps"] = 0;
  manifest["sim_time_s"] = 0.0;
  return manifest;
}

// Rows of explorer.csv for the explorer's current frontier points, goal and
// path (t,kind,index,x,y).
void AddExplorerRows(double t, const explorer::Explorer& explorer, CsvWriter* csv) {
  auto add = [&](const char* kind, int index, const Eigen::Vector2d& p) {
    csv->Add(t);
    csv->Add(std::string_view(kind));
    csv->Add(index);
    csv->Add(p.x());
    csv->Add(p.y());
    csv->EndRow();
  };
  const std::vector<Eigen::Vector2d>& frontiers = explorer.frontier_points();
  for (std::size_t i = 0; i < frontiers.size(); ++i) add("frontier", static_cast<int>(i), frontiers[i]);
  if (const std::optional<Eigen::Vector2d> goal = explorer.goal()) add("goal", 0, *goal);
  const explorer::Path& path = explorer.path();
  for (std::size_t i = 0; i < path.size(); ++i) {
    add("path", static_cast<int>(i), path[i].p_W);
  }
}

// Index of the filter that drives the robot, or -1 (odometry, ground truth).
int DrivingFilter(const std::string& pose_source) {
  if (pose_source == "classical") return 0;
  if (pose_source == "selective") return 1;
  return -1;
}

}  // namespace

RunResult RunSimulation(const RunConfig& config, const RunOptions& options) {
  config.ValidateOrThrow();
  MakeRunDirectory(options.out_dir);
  const std::string dir = options.out_dir;
  WriteFileAtomically(dir + "/config.yaml", config::ToYaml(config));
  nlohmann::json manifest = StartManifest(config, options);
  WriteJsonAtomically(dir + "/manifest.json", manifest);

  RunResult result;
  nlohmann::json summary;
  try {
    // The world with the robot at its start pose.
    sim::Simulator simulator(config.run.world, config.run.robot_model, config.sim, config.robot);
    const Pose2 X_WR0 = simulator.X_WR();
    const Pose2 X_RS = simulator.X_RS();
    manifest["laser_mount"] = {{"x", X_RS.x}, {"y", X_RS.y}, {"th", X_RS.theta}};

    // Every random stream forks from the run seed by name.
    const Rng run_rng(config.run.seed);
    sim::LaserNoise laser_noise(config.laser, run_rng);
    sim::WheelOdometry odometry(config.robot, config.odometry, run_rng);

    const double a_m = config.robot.control_point_offset_m;
    const bool explore = config.control.driver == "explorer";
    std::optional<explorer::WaypointDriver> driver;
    std::optional<explorer::Explorer> explorer;
    if (explore) {
      explorer.emplace(config.explorer, a_m);
    } else {
      std::vector<Eigen::Vector2d> waypoints;
      for (const auto& p : config.driver.waypoints) waypoints.emplace_back(p[0], p[1]);
      if (waypoints.empty()) waypoints = simulator.scene().TourWaypoints();
      driver.emplace(config.driver, waypoints, a_m);
    }
    // The tour driver steers from the true pose; the explorer from pose_source.
    const int driving_filter = explore ? DrivingFilter(config.control.pose_source) : -1;

    const double dt = 1.0 / config.run.control_rate_hz;
    SlamPair slam(config.slam, config.control, dt, X_WR0, X_RS);
    TrueCoverage coverage(simulator.scene().Obstacles(), (X_WR0 * Pose2(-a_m, 0.0, 0.0)).translation());
    std::optional<LiveVideo> video;
    if (options.render_video) video.emplace(config, dir);

    CsvWriter trajectory(dir + "/trajectory.csv", TrajectoryColumns());
    CsvWriter scans(dir + "/scans.csv", ScanColumns(config.laser.num_beams));
    std::optional<CsvWriter> explorer_csv;
    if (explore) explorer_csv.emplace(dir + "/explorer.csv", std::vector<std::string>{"t", "kind", "index", "x", "y"});

    const int num_steps = static_cast<int>(std::floor(config.run.duration_s * config.run.control_rate_hz + 1e-9));
    const int steps_per_scan = config.StepsPerScan();
    Progress progress("run", num_steps);
    Twist2 applied;  // the command held during the last period
    double previous_t = 0.0;
    int next_command_step = 0;  // when the controller issues its next command
    int explorer_log_version = -1;
    std::string termination = "time_limit";
    double distance_m = 0.0;
    int collisions = 0;
    int contact_steps = 0;
    bool in_contact = false;
    double t90 = -1.0;
    double t99 = -1.0;
    Pose2 X_WR_previous = X_WR0;
    result.status = "completed";

    for (int step = 0; step <= num_steps; ++step) {
      if (options.stop_requested != nullptr && *options.stop_requested != 0) {
        result.status = "interrupted";
        termination = "interrupted";
        break;
      }
      const double t = step * dt;
      const Pose2 X_WR = simulator.X_WR();
      distance_m += (X_WR.translation() - X_WR_previous.translation()).norm();
      X_WR_previous = X_WR;

      // What the robot reports: odometry, the command it held, maybe a scan.
      SensorRecord record;
      record.t_s = t;
      record.dt_s = step == 0 ? 0.0 : t - previous_t;  // as a replay computes it
      record.command = applied;
      // The odometry pose as written to trajectory.csv (frame O placed at the
      // start pose in W), so that a replay feeds the filters the same bits.
      record.X_OR = X_WR0 * odometry.Update(simulator.WheelAngles());
      record.has_scan = step % steps_per_scan == 0;
      if (record.has_scan) {
        const std::vector<double> jitter = laser_noise.DrawAngleOffsets();
        record.scan = laser_noise.Apply(simulator.CastLaser(config.laser, jitter));
        record.scan.t_s = t;
        const Pose2 X_WS = simulator.X_WS();
        scans.Add(t);
        scans.Add(X_WS.x);
        scans.Add(X_WS.y);
        scans.Add(X_WS.theta);
        for (const double r : record.scan.ranges_m) scans.Add(r);
        scans.EndRow();
        coverage.Observe(X_WS, record.scan);
      }
      const double explored = coverage.ExploredFraction();
      if (t90 < 0.0 && explored >= 0.90) t90 = t;
      if (t99 < 0.0 && explored >= 0.99) t99 = t;

      // Both filters on the same record.
      slam.Step(record);

      // The controller issues a command when the last period has run out;
      // the command is then held for the period the driving filter's
      // processing imposes, and the explorer sees nothing new in between.
      bool finished = false;
      if (step >= next_command_step) {
        const int period_steps = driving_filter >= 0 ? slam.period_steps(driving_filter) : 1;
        next_command_step = step + period_steps;
        Twist2 command;
        if (explore) {
          Pose2 X_WR_used = X_WR;
          if (driving_filter >= 0) {
            X_WR_used = slam.filter(driving_filter).X_WR();
          } else if (config.control.pose_source == "odometry") {
            X_WR_used = record.X_OR;
          }
          const explorer::ExplorerOutput out = explorer->Step(
              X_WR_used, record.has_scan ? &record.scan : nullptr, X_RS, t, period_steps * dt);
          command = out.command;
          if (out.finished) {
            finished = true;
            termination = out.finish_reason;
          }
          if (explorer->log_version() != explorer_log_version) {
            explorer_log_version = explorer->log_version();
            AddExplorerRows(t, *explorer, &*explorer_csv);
          }
        } else {
          command = driver->Command(X_WR, period_steps * dt);
        }
        applied = simulator.SetCommand(command);
      }

      const Pose2& X_WR_odometry = record.X_OR;
      trajectory.Add(t);
      for (const double v : {X_WR.x, X_WR.y, X_WR.theta, X_WR_odometry.x, X_WR_odometry.y,
                             X_WR_odometry.theta, applied.v_mps, applied.w_radps, explored}) {
        trajectory.Add(v);
      }
      slam.AddColumns(X_WR, &trajectory);
      trajectory.EndRow();

      previous_t = t;
      result.steps = step + 1;
      result.sim_time_s = t;
      progress.Update(step);
      if (video) {
        video->Step(t, X_WR, slam, record.has_scan ? &record.scan : nullptr, simulator.X_WS(),
                    explorer ? &*explorer : nullptr);
      }
      if (finished) break;
      if (step < num_steps) {
        simulator.Advance(dt);
        const int contacts = simulator.CountRobotWorldContacts();
        if (contacts > 0) ++contact_steps;
        if (contacts > 0 && !in_contact) ++collisions;
        in_contact = contacts > 0;
      }
    }
    progress.Finish();
    // An interrupted run leaves no video (its writer removes the temporary file).
    if (video && result.status == "completed") {
      result.video_frames = video->Finish();
      result.video_fps = result.video_frames / std::max(video->wall_s(), 1e-9);
    }
    trajectory.Flush();
    scans.Flush();
    if (explorer_csv) explorer_csv->Flush();
    slam.WriteMaps(dir);

    // The run's summary; evaluation adds its own keys later.
    const Pose2 X_WR_end = simulator.X_WR();
    auto time_or_null = [](double t) { return t < 0.0 ? nlohmann::json(nullptr) : nlohmann::json(t); };
    summary["run"] = {{"duration_s", result.sim_time_s},
                      {"distance_m", distance_m},
                      {"collisions", collisions},
                      {"contact_steps", contact_steps},
                      {"termination_reason", termination},
                      {"driver", config.control.driver},
                      {"pose_source", config.control.pose_source},
                      {"explored_fraction", coverage.ExploredFraction()},
                      {"reachable_area_m2", coverage.ReachableArea()},
                      {"t_explored_90_s", time_or_null(t90)},
                      {"t_explored_99_s", time_or_null(t99)}};
    for (int f = 0; f < 2; ++f) {
      const Pose2 X_WR_estimate = slam.filter(f).X_WR();
      summary["filters"][slam.name(f)] = {
          {"final_pose_error",
           {{"x", X_WR_estimate.x - X_WR_end.x},
            {"y", X_WR_estimate.y - X_WR_end.y},
            {"th", WrapAngle(X_WR_estimate.theta - X_WR_end.theta)}}},
          {"num_features", slam.filter(f).num_features()},
          {"processing_s", slam.total_processing_s(f)},
          {"open_loop_s", slam.open_loop_s(f)}};
    }
  } catch (const std::exception& error) {
    manifest["status"] = "failed";
    manifest["error"] = error.what();
    manifest["end_time"] = UtcNow();
    manifest["steps"] = result.steps;
    manifest["sim_time_s"] = result.sim_time_s;
    WriteJsonAtomically(dir + "/manifest.json", manifest);
    throw;
  }
  // A fresh summary for this run (one from a run before is replaced);
  // evaluation merges its own keys into it.
  WriteJsonAtomically(dir + "/summary.json", summary);
  manifest["status"] = result.status;
  manifest["end_time"] = UtcNow();
  manifest["steps"] = result.steps;
  manifest["sim_time_s"] = result.sim_time_s;
  WriteJsonAtomically(dir + "/manifest.json", manifest);
  return result;
}

}  // namespace mjslam::app
