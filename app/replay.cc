#include "app/replay.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

#include "app/csv_reader.h"
#include "app/csv_writer.h"
#include "app/progress.h"
#include "app/run.h"
#include "app/run_files.h"
#include "app/slam_pair.h"
#include "common/angles.h"
#include "config/config.h"

namespace mjslam::app {
namespace {

// The laser mount recorded by the run, if its manifest is beside the scans.
bool ReadLaserMount(const std::string& manifest_path, Pose2* X_RS) {
  std::ifstream in(manifest_path);
  if (!in) return false;
  nlohmann::json manifest;
  try {
    manifest = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& error) {
    throw std::runtime_error(manifest_path + ": not valid JSON: " + error.what());
  }
  if (!manifest.contains("laser_mount")) return false;
  const nlohmann::json& mount = manifest["laser_mount"];
  *X_RS = Pose2(mount.at("x").get<double>(), mount.at("y").get<double>(),
                mount.at("th").get<double>());
  return true;
}

}  // namespace

void Replay(const RunConfig& config, const ReplayOptions& options) {
  config.ValidateOrThrow();
  const std::filesystem::path scans_dir =
      std::filesystem::path(options.scans_path).parent_path();
  const std::string trajectory_path = options.trajectory_path.empty()
                                          ? (scans_dir / "trajectory.csv").string()
                                          : options.trajectory_path;
  const CsvTable scans = ReadCsv(options.scans_path);
  const CsvTable input = ReadCsv(trajectory_path);
  if (input.rows.empty()) throw std::runtime_error(trajectory_path + ": no rows");

  // Columns of the inputs.
  const int num_beams = config.laser.num_beams;
  if (static_cast<int>(scans.columns.size()) != 4 + num_beams) {
    throw std::runtime_error(options.scans_path + ": expected " + std::to_string(4 + num_beams) +
                             " columns for laser.num_beams = " + std::to_string(num_beams) +
                             " (got " + std::to_string(scans.columns.size()) + ")");
  }
  const int t_col = input.ColumnIndex("t");
  const int true_col = input.ColumnIndex("true_x");
  const int odom_col = input.ColumnIndex("odom_x");
  const int cmd_col = input.ColumnIndex("cmd_v");
  // The recorded columns t..cmd_w come first, in the order of a run.
  const std::vector<std::string> expected = TrajectoryColumns();
  for (int c = 0; c <= cmd_col + 1; ++c) {
    if (c >= static_cast<int>(input.columns.size()) || input.columns[c] != expected[c]) {
      throw std::runtime_error(trajectory_path + ": expected column " + std::to_string(c + 1) +
                               " to be " + expected[c]);
    }
  }
  auto pose_at = [](const std::vector<double>& row, int col) {
    return Pose2(row[col], row[col + 1], row[col + 2]);
  };
  std::map<double, const std::vector<double>*> scan_at;
  for (const std::vector<double>& row : scans.rows) scan_at[row[0]] = &row;

  const Pose2 X_WR0 = pose_at(input.rows.front(), true_col);
  Pose2 X_RS;
  if (!ReadLaserMount((scans_dir / "manifest.json").string(), &X_RS)) {
    // The mount from the true poses of R and of the laser at the first scan.
    bool found = false;
    for (const std::vector<double>& row : input.rows) {
      auto it = scan_at.find(row[t_col]);
      if (it == scan_at.end()) continue;
      X_RS = pose_at(row, true_col).Inverse() * pose_at(*it->second, 1);
      found = true;
      break;
    }
    if (!found) throw std::runtime_error(options.scans_path + ": no scan at a trajectory time");
  }

  MakeRunDirectory(options.out_dir);
  const std::string dir = options.out_dir;
  WriteFileAtomically(dir + "/config.yaml", config::ToYaml(config));
  nlohmann::json manifest;
  manifest["mode"] = "replay";
  manifest["scans_file"] = options.scans_path;
  manifest["trajectory_file"] = trajectory_path;
  manifest["mjslam_version"] = MjslamVersion();
  manifest["git_commit"] = MjslamGitCommit();
  manifest["config_file"] = options.config_path;
  manifest["command_line"] = options.command_line;
  manifest["start_time"] = UtcNow();
  manifest["status"] = "running";
  WriteJsonAtomically(dir + "/manifest.json", manifest);

  try {
    SlamPair slam(config.slam, config.control, 1.0 / config.run.control_rate_hz, X_WR0, X_RS);
    // The explored fraction is the run's (it needs the world), when it has one.
    int explored_col = -1;
    for (std::size_t c = 0; c < input.columns.size(); ++c) {
      if (input.columns[c] == "explored") explored_col = static_cast<int>(c);
    }
    CsvWriter trajectory(dir + "/trajectory.csv", TrajectoryColumns());
    Progress progress("replay", static_cast<double>(input.rows.size()));
    Twist2 held;
    double previous_t = input.rows.front()[t_col];
    for (std::size_t i = 0; i < input.rows.size(); ++i) {
      const std::vector<double>& row = input.rows[i];
      SensorRecord record;
      record.t_s = row[t_col];
      record.dt_s = i == 0 ? 0.0 : record.t_s - previous_t;
      record.command = held;
      record.X_OR = pose_at(row, odom_col);
      auto it = scan_at.find(record.t_s);
      record.has_scan = it != scan_at.end();
      if (record.has_scan) {
        LaserScan& scan = record.scan;
        scan.t_s = record.t_s;
        scan.angle_min_rad = config.laser.AngleMinRad();
        scan.angle_increment_rad = config.laser.AngleIncrementRad();
        scan.max_range_m = config.laser.max_range_m;
        scan.ranges_m.assign(it->second->begin() + 4, it->second->end());
        scan.has_return.resize(num_beams);
        for (int b = 0; b < num_beams; ++b) {
          scan.has_return[b] = scan.ranges_m[b] < scan.max_range_m ? 1 : 0;
        }
      }
      slam.Step(record);
      held = {row[cmd_col], row[cmd_col + 1]};
      previous_t = record.t_s;

      for (int c = 0; c <= cmd_col + 1; ++c) trajectory.Add(row[c]);
      if (explored_col >= 0) {
        trajectory.Add(row[explored_col]);
      } else {
        trajectory.AddEmpty();
      }
      slam.AddColumns(pose_at(row, true_col), &trajectory);
      trajectory.EndRow();
      progress.Update(static_cast<double>(i));
    }
    progress.Finish();
    trajectory.Flush();
    slam.WriteMaps(dir);
  } catch (const std::exception& error) {
    manifest["status"] = "failed";
    manifest["error"] = error.what();
    manifest["end_time"] = UtcNow();
    WriteJsonAtomically(dir + "/manifest.json", manifest);
    throw;
  }
  manifest["status"] = "completed";
  manifest["end_time"] = UtcNow();
  WriteJsonAtomically(dir + "/manifest.json", manifest);
}

}  // namespace mjslam::app
