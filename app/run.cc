#include "app/run.h"

#include <cmath>
#include <exception>

#include "app/csv_writer.h"
#include "app/progress.h"
#include "app/run_files.h"
#include "app/slam_pair.h"
#include "config/config.h"
#include "explorer/waypoint_driver.h"
#include "sim/laser_noise.h"
#include "sim/simulator.h"
#include "sim/wheel_odometry.h"

namespace mjslam::app {

std::vector<std::string> TrajectoryColumns() {
  std::vector<std::string> columns = {"t",      "true_x", "true_y", "true_th", "odom_x",
                                      "odom_y", "odom_th", "cmd_v",  "cmd_w"};
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

}  // namespace

RunResult RunSimulation(const RunConfig& config, const RunOptions& options) {
  config.ValidateOrThrow();
  MakeRunDirectory(options.out_dir);
  const std::string dir = options.out_dir;
  WriteFileAtomically(dir + "/config.yaml", config::ToYaml(config));
  nlohmann::json manifest = StartManifest(config, options);
  WriteJsonAtomically(dir + "/manifest.json", manifest);

  RunResult result;
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

    std::vector<Eigen::Vector2d> waypoints;
    for (const auto& p : config.driver.waypoints) waypoints.emplace_back(p[0], p[1]);
    if (waypoints.empty()) waypoints = simulator.TourWaypoints();
    explorer::WaypointDriver driver(config.driver, waypoints,
                                    config.robot.control_point_offset_m);

    SlamPair slam(config.slam, X_WR0, X_RS);

    CsvWriter trajectory(dir + "/trajectory.csv", TrajectoryColumns());
    CsvWriter scans(dir + "/scans.csv", ScanColumns(config.laser.num_beams));

    const double dt = 1.0 / config.run.control_rate_hz;
    const int num_steps = static_cast<int>(std::floor(config.run.duration_s * config.run.control_rate_hz + 1e-9));
    const int steps_per_scan = config.StepsPerScan();
    Progress progress("run", num_steps);
    Twist2 applied;  // the command held during the last period
    double previous_t = 0.0;
    result.status = "completed";

    for (int step = 0; step <= num_steps; ++step) {
      if (options.stop_requested != nullptr && *options.stop_requested != 0) {
        result.status = "interrupted";
        break;
      }
      const double t = step * dt;
      const Pose2 X_WR = simulator.X_WR();

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
      }

      // Both filters on the same record.
      slam.Step(record);

      // The driver steers from the true pose until the explorer exists.
      applied = simulator.SetCommand(driver.Command(X_WR, dt));

      const Pose2& X_WR_odometry = record.X_OR;
      trajectory.Add(t);
      for (const double v : {X_WR.x, X_WR.y, X_WR.theta, X_WR_odometry.x, X_WR_odometry.y,
                             X_WR_odometry.theta, applied.v_mps, applied.w_radps}) {
        trajectory.Add(v);
      }
      slam.AddColumns(&trajectory);
      trajectory.EndRow();

      previous_t = t;
      result.steps = step + 1;
      result.sim_time_s = t;
      progress.Update(step);
      if (step < num_steps) simulator.Advance(dt);
    }
    progress.Finish();
    trajectory.Flush();
    scans.Flush();
    slam.WriteMaps(dir);
  } catch (const std::exception& error) {
    manifest["status"] = "failed";
    manifest["error"] = error.what();
    manifest["end_time"] = UtcNow();
    manifest["steps"] = result.steps;
    manifest["sim_time_s"] = result.sim_time_s;
    WriteJsonAtomically(dir + "/manifest.json", manifest);
    throw;
  }
  manifest["status"] = result.status;
  manifest["end_time"] = UtcNow();
  manifest["steps"] = result.steps;
  manifest["sim_time_s"] = result.sim_time_s;
  WriteJsonAtomically(dir + "/manifest.json", manifest);
  return result;
}

}  // namespace mjslam::app
