#include "app/render_run.h"

#include <sys/wait.h>

#include <spawn.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <vector>

#include "app/progress.h"
#include "app/run_config.h"
#include "app/scene_frame.h"
#include "renders/scene_renderer.h"
#include "rundir/csv_reader.h"
#include "rundir/layout.h"
#include "rundir/map_csv.h"
#include "rundir/rows.h"
#include "renders/video_writer.h"
#include "sim/scene.h"

extern char** environ;

namespace mjslam::app {

namespace {

namespace fs = std::filesystem;

// One filter's columns of trajectory.csv.
struct FilterColumns {
  int x, y, th, pxx, pxy, pyy;
};

using rundir::CsvTable;
using rundir::ReadCsv;

// The explorer's sets over time (explorer.csv) as the layers a frame draws.
struct ExplorerSnapshot {
  double t_s;
  renders::ExplorerLayer layer;
};

std::vector<ExplorerSnapshot> ReadExplorer(const std::string& path) {
  std::vector<ExplorerSnapshot> snapshots;
  for (const rundir::ExplorerSnapshot& read : rundir::ReadExplorerCsv(path)) {
    renders::ExplorerLayer layer;
    layer.frontier = read.frontier;
    layer.goal = read.goal;
    layer.path = read.path;
    snapshots.push_back({read.t_s, layer});
  }
  return snapshots;
}

// The map of a map CSV file into `layer` (none when the file is missing).
void ReadMap(const std::string& path, renders::FilterLayer* layer) {
  if (fs::exists(path)) SetMapLayer(rundir::ReadMapCsv(path), layer);
}

constexpr char kPython[] = "/usr/bin/python3";

// Runs renders/report.py with `arguments`; throws when it fails.
void RunReportScript(const std::vector<std::string>& arguments) {
  // Debian's interpreter, which finds Debian's matplotlib (a python3 earlier
  // on PATH, e.g. from pyenv, may not).
  std::vector<std::string> all = {kPython, std::string(MJSLAM_SOURCE_DIR) + "/renders/report.py"};
  all.insert(all.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int spawned = ::posix_spawn(&pid, kPython, nullptr, nullptr, argv.data(), environ);
  if (spawned != 0) {
    throw std::runtime_error(std::string("cannot start ") + kPython + " for the plots: " + std::strerror(spawned));
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error("renders/report.py failed for '" + arguments.back() + "'");
  }
}

}  // namespace

bool IsSweepDirectory(const std::string& dir) {
  return fs::is_directory(fs::path(dir) / rundir::kSweepRunsFolder) &&
         !fs::exists(fs::path(dir) / rundir::kTrajectoryFile);
}

void RenderSweep(const std::string& sweep_dir) { RunReportScript({"sweep", sweep_dir}); }

// Over 80 lines: one frame loop whose state (the frame, the next row) the
// video and the final image share through two lambdas; to be cut into named
// steps with the scene split (issue 11, item 2), which rewrites its start.
RenderResult RenderRun(const std::string& run_dir, const renders::RenderParams& params,
                       const RenderOptions& options) {
  params.ValidateOrThrow();
  const fs::path dir(run_dir);
  if (!fs::is_directory(dir)) throw std::runtime_error("run directory not found: '" + run_dir + "'");
  const RunConfig config = LoadRunConfig((dir / rundir::kConfigFile).string(), {});

  // The run's files.
  const CsvTable trajectory = ReadCsv((dir / rundir::kTrajectoryFile).string());
  if (trajectory.rows.empty()) throw std::runtime_error(trajectory.path + ": no rows to render");
  const CsvTable scans = ReadCsv((dir / rundir::kScansFile).string());
  const std::vector<ExplorerSnapshot> explorer = ReadExplorer((dir / rundir::kExplorerFile).string());
  const int t_col = trajectory.ColumnIndex("t");
  const int true_x = trajectory.ColumnIndex("true_x"), true_y = trajectory.ColumnIndex("true_y");
  const int true_th = trajectory.ColumnIndex("true_th");
  renders::SceneFrame frame;
  frame.filters = FilterLayers();
  std::vector<FilterColumns> filters;
  for (const renders::FilterLayer& layer : frame.filters) {
    const std::string& name = layer.name;
    filters.push_back({trajectory.ColumnIndex(name + "_x"), trajectory.ColumnIndex(name + "_y"),
                       trajectory.ColumnIndex(name + "_th"), trajectory.ColumnIndex(name + "_pxx"),
                       trajectory.ColumnIndex(name + "_pxy"), trajectory.ColumnIndex(name + "_pyy")});
  }
  const int scan_t = scans.ColumnIndex("t"), scan_x = scans.ColumnIndex("x");
  const int scan_y = scans.ColumnIndex("y"), scan_th = scans.ColumnIndex("th");
  const int scan_r0 = scans.ColumnIndex("r0");

  renders::SceneRenderer renderer(sim::Scene(config.run.world, config.run.robot_model), config.sim,
                                  config.robot, params.width, params.height);
  const double min_step_m = PixelSizeM(renderer);
  frame.ellipse_scale = params.ellipse_scale;
  std::size_t next_row = 0;
  auto append = [&](std::vector<Eigen::Vector2d>* path, const Eigen::Vector2d& p, bool last) {
    AppendPathPoint(path, p, min_step_m, last);
  };
  // Advances the frame to time T: paths, poses, current scan and explorer sets.
  auto advance_to = [&](double T) {
    while (next_row < trajectory.rows.size() && trajectory.rows[next_row][t_col] <= T + 1e-9) {
      const std::vector<double>& row = trajectory.rows[next_row];
      const bool last = next_row + 1 == trajectory.rows.size();
      frame.t_s = row[t_col];
      frame.X_WR_true = Pose2(row[true_x], row[true_y], row[true_th]);
      append(&frame.true_path, {row[true_x], row[true_y]}, last);
      for (std::size_t i = 0; i < filters.size(); ++i) {
        const FilterColumns& f = filters[i];
        renders::FilterLayer& layer = frame.filters[i];
        append(&layer.path, {row[f.x], row[f.y]}, last);
        layer.X_WR = Pose2(row[f.x], row[f.y], row[f.th]);
        layer.P_xy << row[f.pxx], row[f.pxy], row[f.pxy], row[f.pyy];
      }
      ++next_row;
    }
    const auto scan = std::upper_bound(scans.rows.begin(), scans.rows.end(), T + 1e-9,
                                       [&](double value, const std::vector<double>& row) { return value < row[scan_t]; });
    if (scan != scans.rows.begin()) {
      const std::vector<double>& row = *(scan - 1);
      frame.laser_hits = LaserHits(Pose2(row[scan_x], row[scan_y], row[scan_th]),
                                   std::vector<double>(row.begin() + scan_r0, row.end()),
                                   config.laser.max_range_m, config.laser.AngleMinRad(),
                                   config.laser.AngleIncrementRad());
    } else {
      frame.laser_hits.clear();
    }
    frame.explorer.reset();
    const auto snapshot = std::upper_bound(explorer.begin(), explorer.end(), T + 1e-9,
                                           [](double value, const ExplorerSnapshot& s) { return value < s.t_s; });
    if (snapshot != explorer.begin()) frame.explorer = (snapshot - 1)->layer;
  };
  auto stopped = [&]() { return options.stop_requested != nullptr && *options.stop_requested != 0; };

  RenderResult result;
  const double end_t = trajectory.rows.back()[t_col];
  if (params.video) {
    const auto start = std::chrono::steady_clock::now();
    const double frame_dt = params.speedup / params.fps;
    const int num_frames = static_cast<int>(std::floor(end_t / frame_dt + 1e-9)) + 1;
    renders::VideoWriter video((dir / rundir::kVideoFile).string(), params.width, params.height, params.fps, params.crf);
    Progress progress("render", num_frames);
    for (int k = 0; k < num_frames; ++k) {
      if (stopped()) throw std::runtime_error("render of '" + run_dir + "' interrupted; no video written");
      const bool last = k + 1 == num_frames;
      advance_to(last ? end_t : k * frame_dt);
      if (last) {
        for (std::size_t i = 0; i < filters.size(); ++i) {
          ReadMap((dir / rundir::MapFile(frame.filters[i].name)).string(), &frame.filters[i]);
        }
      }
      video.AddFrame(renderer.Render(frame));
      if (options.show_progress) progress.Update(k + 1);
    }
    video.Finish();
    if (options.show_progress) progress.Finish();
    result.video_frames = num_frames;
    result.video_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.video_fps = num_frames / std::max(result.video_wall_s, 1e-9);
  }

  // The final image: the whole run with both final maps.
  advance_to(end_t);
  for (renders::FilterLayer& layer : frame.filters) {
    ReadMap((dir / rundir::MapFile(layer.name)).string(), &layer);
  }
  renders::WritePng((dir / rundir::kFinalImageFile).string(), renderer.Render(frame));

  if (params.plots) RunReportScript({"run", dir.string()});
  return result;
}

}  // namespace mjslam::app
