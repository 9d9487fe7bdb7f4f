#include "app/jobs/render_run.h"

#include <sys/wait.h>
#include <unistd.h>

#include <spawn.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <vector>

#include "app/jobs/progress.h"
#include "app/engine/run_config.h"
#include "app/jobs/scene_frame.h"
#include "common/interrupt.h"
#include "renders/scene_renderer.h"
#include "rundir/layout.h"
#include "rundir/map_csv.h"
#include "rundir/rows.h"
#include "rundir/summary.h"
#include "renders/video_writer.h"
#include "sim/scene.h"

extern char** environ;

namespace mjslam::app {

namespace {

namespace fs = std::filesystem;

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

// The value at `path` in `json` (null: none).
const nlohmann::json* FindPath(const nlohmann::json& json,
                               std::initializer_list<std::string> path) {
  const nlohmann::json* node = &json;
  for (const std::string& key : path) {
    if (!node->is_object() || !node->contains(key)) return nullptr;
    node = &(*node)[key];
  }
  return node;
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
  // Wait, polling for a stop request: the script is asked to stop (SIGTERM:
  // it removes its temporary file) and the render ends as interrupted.
  int status = 0;
  bool stopping = false;
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid || (done < 0 && errno != EINTR)) break;
    if (InterruptRequested() && !stopping) {
      ::kill(pid, SIGTERM);
      stopping = true;
    }
    ::usleep(20000);
  }
  ThrowIfInterrupted("plots");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error("renders/report.py failed for '" + arguments.back() + "'");
  }
}

}  // namespace

bool IsSweepDirectory(const std::string& dir) {
  const fs::path runs = fs::path(dir) / rundir::kSweepRunsFolder;
  if (!fs::is_directory(runs) || fs::exists(fs::path(dir) / rundir::kTrajectoryFile)) return false;
  // At least one run folder of a sweep: an empty runs/ is no sweep.
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(runs, error)) {
    if (entry.is_directory()) return true;
  }
  return false;
}

void RenderSweep(const std::string& sweep_dir) { RunReportScript({"sweep", sweep_dir}); }

namespace {

// A run's recorded files played back as frames: the trajectory, scans and
// explorer sets up to a time T become the paths, poses, current scan and
// explorer layers of `frame()`. Time only moves forward.
class RunPlayback {
 public:
  RunPlayback(const fs::path& dir, const RunConfig& config, double min_step_m)
      : dir_(dir),
        config_(config),
        min_step_m_(min_step_m),
        trajectory_path_((dir / rundir::kTrajectoryFile).string()),
        trajectory_(rundir::ReadTrajectoryRows(trajectory_path_)),
        scans_(rundir::ReadScanRows((dir / rundir::kScansFile).string())),
        explorer_(ReadExplorer((dir / rundir::kExplorerFile).string())) {
    // One layer per filter of the trajectory, in its order.
    std::vector<std::string> names;
    for (const rundir::FilterRow& f : trajectory_.front().filters) names.push_back(f.name);
    if (names.empty()) {
      throw std::runtime_error(trajectory_path_ + ": no filter columns (<name>_x, ...)");
    }
    frame_.filters = FilterLayers(names);
    for (std::size_t i = 0; i < names.size(); ++i) filter_of_layer_.push_back(i);
    // Filters of submaps: when each submap began (summary.json).
    const nlohmann::json summary = rundir::ReadSummary(dir.string());
    submap_starts_.resize(names.size());
    next_submap_.assign(names.size(), 0);
    for (std::size_t i = 0; i < names.size(); ++i) {
      const nlohmann::json* f = FindPath(summary, {"filters", names[i], "submaps", "started_at_s"});
      if (f != nullptr && f->is_array()) submap_starts_[i] = f->get<std::vector<double>>();
    }
  }

  /// Time of the last row, seconds.
  double end_t() const { return trajectory_.back().t_s; }
  renders::SceneFrame& frame() { return frame_; }

  /// Advances the frame to time T: paths, poses, current scan and explorer sets.
  void AdvanceTo(double T) {
    AddRowsUpTo(T);
    SetScanAt(T);
    frame_.explorer.reset();
    const auto snapshot = std::upper_bound(explorer_.begin(), explorer_.end(), T + 1e-9,
                                           [](double value, const ExplorerSnapshot& s) { return value < s.t_s; });
    if (snapshot != explorer_.begin()) frame_.explorer = (snapshot - 1)->layer;
  }

  /// Puts every filter's final map (map_*.csv) into the frame.
  void ShowFinalMaps() {
    for (renders::FilterLayer& layer : frame_.filters) {
      ReadMap((dir_ / rundir::MapFile(layer.name)).string(), &layer);
    }
  }

 private:
  // The trajectory rows up to T: the paths grow, the poses move.
  void AddRowsUpTo(double T) {
    while (next_row_ < trajectory_.size() && trajectory_[next_row_].t_s <= T + 1e-9) {
      const rundir::TrajectoryRow& row = trajectory_[next_row_];
      const bool last = next_row_ + 1 == trajectory_.size();
      frame_.t_s = row.t_s;
      frame_.X_WR_true = row.X_WR_true;
      AppendPathPoint(&frame_.true_path, {row.X_WR_true.x, row.X_WR_true.y}, min_step_m_, last);
      for (std::size_t i = 0; i < filter_of_layer_.size(); ++i) {
        const rundir::FilterRow& f = row.filters[filter_of_layer_[i]];
        renders::FilterLayer& layer = frame_.filters[i];
        AppendPathPoint(&layer.path, {f.X_WR.x, f.X_WR.y}, min_step_m_, last);
        layer.X_WR = f.X_WR;
        layer.P_xy = f.P.topLeftCorner<2, 2>();
        const std::vector<double>& starts = submap_starts_[i];
        while (next_submap_[i] < starts.size() && starts[next_submap_[i]] <= row.t_s + 1e-9) {
          layer.submap_starts.push_back(f.X_WR);
          ++next_submap_[i];
        }
      }
      ++next_row_;
    }
  }

  // The hits of the latest scan at or before T (none before the first).
  void SetScanAt(double T) {
    const auto scan = std::upper_bound(scans_.begin(), scans_.end(), T + 1e-9,
                                       [](double value, const rundir::ScanRow& row) { return value < row.t_s; });
    if (scan == scans_.begin()) {
      frame_.laser_hits.clear();
      return;
    }
    const rundir::ScanRow& row = *(scan - 1);
    frame_.laser_hits = LaserHits(row.X_WS, row.ranges_m, config_.laser.max_range_m,
                                  config_.laser.AngleMinRad(), config_.laser.AngleIncrementRad());
  }

  fs::path dir_;
  const RunConfig& config_;
  double min_step_m_;
  std::string trajectory_path_;
  std::vector<rundir::TrajectoryRow> trajectory_;
  std::vector<rundir::ScanRow> scans_;
  std::vector<ExplorerSnapshot> explorer_;
  renders::SceneFrame frame_;
  // The filter (in the trajectory's order) of each of frame_.filters.
  std::vector<std::size_t> filter_of_layer_;
  std::size_t next_row_ = 0;
  // Per layer: the times its submaps began, and the next not yet drawn.
  std::vector<std::vector<double>> submap_starts_;
  std::vector<std::size_t> next_submap_;
};

// video.mp4: one frame per params.speedup / params.fps simulated seconds,
// the final maps in the last frame. Fills the video fields of `result`.
void RenderVideo(const fs::path& dir, const renders::RenderParams& params,
                 const RenderOptions& options, renders::SceneRenderer* renderer,
                 RunPlayback* playback, RenderResult* result) {
  const auto start = std::chrono::steady_clock::now();
  const double end_t = playback->end_t();
  const double frame_dt = params.speedup / params.fps;
  const int num_frames = params.NumVideoFrames(end_t);
  renders::VideoWriter video((dir / rundir::kVideoFile).string(), params.width, params.height, params.fps, params.crf);
  Progress progress("render", num_frames);
  for (int k = 0; k < num_frames; ++k) {
    if (options.stop_requested != nullptr && *options.stop_requested != 0) {
      throw std::runtime_error("render of '" + dir.string() + "' interrupted; no video written");
    }
    const bool last = k + 1 == num_frames;
    playback->AdvanceTo(last ? end_t : k * frame_dt);
    if (last) playback->ShowFinalMaps();
    video.AddFrame(renderer->Render(playback->frame()));
    if (options.show_progress) progress.Update(k + 1);
  }
  video.Finish();
  if (options.show_progress) progress.Finish();
  result->video_frames = num_frames;
  result->video_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result->video_fps = num_frames / std::max(result->video_wall_s, 1e-9);
}

}  // namespace

RenderResult RenderRun(const std::string& run_dir, const renders::RenderParams& params,
                       const RenderOptions& options) {
  params.ValidateOrThrow();
  const fs::path dir(run_dir);
  if (!fs::is_directory(dir)) throw std::runtime_error("run directory not found: '" + run_dir + "'");
  const RunConfig config = LoadRunConfig((dir / rundir::kConfigFile).string(), {});

  const sim::Scene scene(config.run.world, config.run.robot_model);
  sim::CheckWorldExtent(scene, config.sim.max_world_extent_m);
  renders::SceneRenderer renderer(scene, config.sim, config.robot, params.width, params.height);
  RunPlayback playback(dir, config, PixelSizeM(renderer));
  playback.frame().ellipse_scale = params.ellipse_scale;

  RenderResult result;
  if (params.video) RenderVideo(dir, params, options, &renderer, &playback, &result);

  // The final image: the whole run with both final maps.
  playback.AdvanceTo(playback.end_t());
  playback.ShowFinalMaps();
  renders::WritePng((dir / rundir::kFinalImageFile).string(), renderer.Render(playback.frame()));

  if (params.plots) RunReportScript({"run", dir.string()});
  return result;
}

}  // namespace mjslam::app
