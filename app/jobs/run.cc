#include "app/jobs/run.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <optional>
#include <utility>

#include "app/engine/closed_loop.h"
#include "app/jobs/live_video.h"
#include "app/jobs/progress.h"
#include "app/engine/filter_bank.h"
#include "app/jobs/version.h"
#include "common/interrupt.h"
#include "common/params.h"
#include "config/config.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/rows.h"
#include "rundir/run_files.h"
#include "rundir/summary.h"
#include "sim/simulator.h"

namespace mjslam::app {
namespace {

// The manifest as written at the start of the run; the end fills in the rest.
nlohmann::json StartManifest(const RunConfig& config, const RunOptions& options) {
  nlohmann::json manifest;
  manifest["seed"] = config.run.seed;
  manifest["mjslam_version"] = MjslamVersion();
  manifest["git_commit"] = MjslamGitCommit();
  manifest["mujoco_version"] = sim::MujocoVersion();
  manifest["world_file"] = config.run.world;
  manifest["world_hash"] = rundir::HashFile(config.run.world);
  manifest["robot_model_file"] = config.run.robot_model;
  manifest["robot_model_hash"] = rundir::HashFile(config.run.robot_model);
  manifest["config_file"] = options.config_path;
  manifest["command_line"] = options.command_line;
  manifest["end_time"] = nullptr;
  manifest["steps"] = 0;
  manifest["sim_time_s"] = 0.0;
  return manifest;
}

// The files a simulated run writes step by step, through rundir's writers:
// trajectory.csv, scans.csv and (when the explorer drives) explorer.csv.
class StepFiles {
 public:
  StepFiles(const std::string& dir, const RunConfig& config,
            const std::vector<std::string>& filter_names)
      : trajectory_(rundir::PathIn(dir, rundir::kTrajectoryFile),
                    rundir::TrajectoryColumns(filter_names)),
        scans_(rundir::PathIn(dir, rundir::kScansFile), rundir::ScanColumns(config.laser.num_beams)) {
    if (config.control.driver == "explorer") {
      explorer_.emplace(rundir::PathIn(dir, rundir::kExplorerFile), rundir::ExplorerColumns());
    }
  }

  void Add(const LoopStep& step, const explorer::Explorer* explorer) {
    if (step.record.has_scan) {
      rundir::AddScanRow(step.record.t_s, step.X_WS_true, step.record.scan.ranges_m, &scans_);
    }
    if (step.explorer_changed && explorer != nullptr && explorer_) {
      rundir::ExplorerSnapshot snapshot;
      snapshot.t_s = step.record.t_s;
      snapshot.frontier = explorer->frontier_points();
      snapshot.goal = explorer->goal();
      for (const explorer::PathPoint& point : explorer->path()) snapshot.path.push_back(point.p_W);
      rundir::AddExplorerRows(snapshot, &*explorer_);
    }
    rundir::AddTrajectoryRow(step.row, &trajectory_);
  }

  void Flush() {
    trajectory_.Flush();
    scans_.Flush();
    if (explorer_) explorer_->Flush();
  }

 private:
  rundir::CsvWriter trajectory_;
  rundir::CsvWriter scans_;
  std::optional<rundir::CsvWriter> explorer_;
};

bool StopRequested(const RunOptions& options) {
  return options.stop_requested != nullptr && *options.stop_requested != 0;
}

}  // namespace

std::optional<std::string> RangeNoiseNote(const RunConfig& config) {
  const double simulated = config.laser.range_noise_std_m;
  const double assumed = config.slam.features.range_noise_std_m;
  if (assumed == simulated) return std::nullopt;
  return "note: the filters assume a range noise of " + ValueText(assumed) +
         " m (slam.features.range_noise_std_m), the simulated laser has " + ValueText(simulated) +
         " m (laser.range_noise_std_m)";
}

RunResult RunSimulation(const RunConfig& config, const RunOptions& options) {
  const double start_cpu_s = ThreadCpuSeconds();
  config.ValidateOrThrow();
  const std::string& dir = options.out_dir;
  // The manifest reads (hashes) the world and robot files: a missing one is
  // an error before anything is written.
  nlohmann::json start_manifest = StartManifest(config, options);
  // A video of too many frames is refused before the run, not hours into it.
  if (options.render_video) config.render.NumVideoFrames(config.run.duration_s);
  const rundir::RunDirectoryLock lock(dir);
  rundir::WriteFileAtomically(rundir::PathIn(dir, rundir::kConfigFile), config::ToYaml(config));
  rundir::ManifestWriter manifest(dir, std::move(start_manifest));
  RunResult result;
  result.status = "completed";
  auto record_progress = [&]() {
    manifest.fields()["steps"] = result.steps;
    manifest.fields()["sim_time_s"] = result.sim_time_s;
  };
  try {
    ClosedLoop loop(config);
    manifest.SetLaserMount(loop.X_RS());
    std::optional<LiveVideo> video;
    if (options.render_video) video.emplace(config, dir);
    StepFiles files(dir, config, loop.filters().names());
    Progress progress("run", loop.num_steps() - 1);
    while (!loop.Done()) {
      if (StopRequested(options)) {
        result.status = "interrupted";
        break;
      }
      const LoopStep& step = loop.Step();
      {
        const ScopedCpuTimer timer(&result.cpu.files_s);
        files.Add(step, loop.explorer());
      }
      result.steps = step.index + 1;
      result.sim_time_s = step.record.t_s;
      progress.Update(step.index);
      if (video) {
        const ScopedCpuTimer timer(&result.cpu.video_s);
        video->Step(step.record.t_s, step.row.X_WR_true, loop.filters(),
                    step.record.has_scan ? &step.record.scan : nullptr, step.X_WS_true, loop.explorer());
      }
    }
    progress.Finish();
    // An interrupted run leaves no video (its writer removes the temporary file).
    if (video && result.status == "completed") {
      result.video_frames = video->Finish();
      result.video_fps = result.video_frames / std::max(video->wall_s(), 1e-9);
    }
    files.Flush();
    WriteMaps(loop.filters(), dir);
    // A fresh summary for this run (one from a run before is replaced);
    // evaluation merges its own keys into it.
    const rundir::RunSummary summary = loop.Summary(result.status == "interrupted");
    rundir::WriteSummary(dir, rundir::ToJson(summary));
    result.warnings = InnovationWarnings(summary);
    const PhaseCpu& loop_cpu = loop.cpu();
    result.cpu.physics_s = loop_cpu.physics_s;
    result.cpu.laser_s = loop_cpu.laser_s;
    result.cpu.odometry_s = loop_cpu.odometry_s;
    result.cpu.coverage_s = loop_cpu.coverage_s;
    result.cpu.filters_s = loop_cpu.filters_s;
    result.cpu.explorer_s = loop_cpu.explorer_s;
  } catch (const Interrupted&) {
    // Stopped before the loop (a large world's setup): nothing to resume from.
    record_progress();
    manifest.Finish("interrupted");
    throw;
  } catch (const std::exception& error) {
    record_progress();
    manifest.Fail(error.what());
    throw;
  }
  record_progress();
  manifest.Finish(result.status);
  result.cpu.run_total_s = ThreadCpuSeconds() - start_cpu_s;
  return result;
}

std::vector<std::string> InnovationWarnings(const rundir::RunSummary& summary) {
  std::vector<std::string> lines;
  for (const rundir::RunSummary::Filter& f : summary.filters) {
    if (!f.innovation_inconsistent_since_s) continue;
    char copied[160] = "";
    if (f.map_copied_at_s) {
      std::snprintf(copied, sizeof(copied),
                    "; %d scans made new features of mapped structure, the first at t = %.1f s",
                    f.copied_scans, *f.map_copied_at_s);
    }
    char line[560];
    std::snprintf(line, sizeof(line),
                  "warning: the %s filter is inconsistent with its own innovations from t = %.1f s "
                  "(%d of %d windows failed, mean NIS %.2f; %d of %d windows with too many near "
                  "misses, %.1f %% of the observations%s; summary.json "
                  "filters.%s.innovation_check): its map and pose may be wrong",
                  f.name.c_str(), *f.innovation_inconsistent_since_s, f.innovation_failed_windows,
                  f.innovation_windows, f.innovation_mean_nis, f.near_miss_failed_windows,
                  f.near_miss_windows, 100.0 * f.near_miss_fraction, copied, f.name.c_str());
    lines.emplace_back(line);
  }
  return lines;
}

}  // namespace mjslam::app
