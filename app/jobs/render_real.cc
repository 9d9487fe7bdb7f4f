#include "app/jobs/render_real.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <stdexcept>

#include "app/jobs/evaluate_real.h"
#include "app/engine/run_config.h"
#include "common/interrupt.h"
#include "renders/filter_colors.h"
#include "renders/plan_canvas.h"
#include "renders/video_writer.h"
#include "rundir/csv_reader.h"
#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/map_csv.h"
#include "rundir/rows.h"

namespace mjslam::app {
namespace {

using renders::PlanCanvas;
using renders::Rgb;

// Most frames a real log's video gets (30 s at 30 frames/s).
constexpr int kMaxVideoFrames = 900;

const Rgb kReference = {0, 0, 0};
const Rgb kMapLine = {20, 20, 20};
const Rgb kCorner = {200, 0, 160};
const Rgb kRobot = {220, 0, 0};

// One trajectory of the run: which (0 odometry, 1 + f filter f in the order
// of trajectory.csv's filters), its colours and map file.
struct Track {
  int index;
  Rgb path;
  Rgb points;
  std::string map_name;  // empty: no map (odometry)
};

// The odometry's track, then one per filter of `names`, coloured as the
// renders of simulated runs colour it (renders::FilterColors), its scan
// points that colour faded 60 % towards white.
std::vector<Track> Tracks(const std::vector<std::string>& names) {
  std::vector<Track> tracks = {{0, {200, 40, 40}, {235, 160, 160}, ""}};
  const std::vector<std::array<float, 3>> colors = renders::FilterColors(names);
  for (std::size_t f = 0; f < names.size(); ++f) {
    Rgb path, points;
    for (int c = 0; c < 3; ++c) {
      const double v = 255.0 * colors[f][c];
      path[c] = static_cast<std::uint8_t>(std::lround(v));
      points[c] = static_cast<std::uint8_t>(std::lround(v + 0.6 * (255.0 - v)));
    }
    tracks.push_back({static_cast<int>(f) + 1, path, points, names[f]});
  }
  return tracks;
}

// The files of the run, read once.
struct RealRun {
  RunConfig config;
  // The filters, from trajectory.csv's header, and the tracks drawn.
  std::vector<std::string> names;
  std::vector<Track> tracks;
  Pose2 X_RS;
  std::vector<rundir::TrajectoryRow> trajectory;
  std::string scans_path;
  std::vector<rundir::ScanRow> scans;
  std::vector<Pose2> reference;
  std::map<double, std::size_t> row_at;  // trajectory row of each time
};

RealRun ReadRealRun(const std::string& dir) {
  RealRun run;
  run.config = LoadRunConfig(rundir::PathIn(dir, rundir::kConfigFile), {});
  const std::optional<Pose2> mount =
      rundir::ReadLaserMount(rundir::PathIn(dir, rundir::kManifestFile));
  if (!mount) throw std::runtime_error(rundir::PathIn(dir, rundir::kManifestFile) + ": no laser_mount");
  run.X_RS = *mount;
  const std::string trajectory_path = rundir::PathIn(dir, rundir::kTrajectoryFile);
  run.names = rundir::TrajectoryFilterNames(rundir::ReadCsvHeader(trajectory_path));
  if (run.names.empty()) {
    throw std::runtime_error(trajectory_path + ": no filter columns (<name>_x, ...) to render "
                             "(a trajectory written by the import, before its replay?)");
  }
  run.trajectory = rundir::ReadTrajectoryRows(trajectory_path);
  run.tracks = Tracks(run.names);
  run.scans_path = ImportedScansPath(dir);
  run.scans = rundir::ReadScanRows(run.scans_path);
  for (std::size_t i = 0; i < run.trajectory.size(); ++i) run.row_at[run.trajectory[i].t_s] = i;
  const nlohmann::json manifest = rundir::ReadManifest(dir);
  if (manifest.value("reference", std::string("none")) != "none") {
    for (const rundir::ReferenceRow& row :
         rundir::ReadReferenceRows(rundir::PathIn(dir, rundir::kReferenceFile))) {
      run.reference.push_back(row.X_WR);
    }
  }
  return run;
}

// The pose of `track` in trajectory row `i`.
const Pose2& PoseAt(const RealRun& run, const Track& track, std::size_t i) {
  const rundir::TrajectoryRow& row = run.trajectory[i];
  return track.index == 0 ? row.X_WR_odometry : row.filters[track.index - 1].X_WR;
}

// The hit points of scan `k` placed with the pose of `track` at its time.
std::vector<Eigen::Vector2d> ScanPoints(const RealRun& run, const Track& track, std::size_t k) {
  const rundir::ScanRow& scan = run.scans[k];
  const auto it = run.row_at.find(scan.t_s);
  if (it == run.row_at.end()) {
    throw std::runtime_error(run.scans_path + ": scan at t = " + std::to_string(scan.t_s) +
                             " has no trajectory row");
  }
  const Pose2 X_WS = PoseAt(run, track, it->second) * run.X_RS;
  const sim::LaserParams& laser = run.config.laser;
  std::vector<Eigen::Vector2d> points;
  for (int b = 0; b < laser.num_beams; ++b) {
    const double r = scan.ranges_m[b];
    if (!(r < laser.max_range_m)) continue;
    const double angle = laser.AngleMinRad() + b * laser.AngleIncrementRad();
    points.push_back(X_WS * Eigen::Vector2d(r * std::cos(angle), r * std::sin(angle)));
  }
  return points;
}

// The window: the 0.5 and 99.5 percentiles of the selective filter's points
// (without one, the last filter's), so that a few stray long beams do not
// shrink the building.
std::pair<Eigen::Vector2d, Eigen::Vector2d> Window(const RealRun& run) {
  const auto selective = std::find(run.names.begin(), run.names.end(), "selective");
  const std::size_t framing =
      selective != run.names.end() ? selective - run.names.begin() : run.names.size() - 1;
  std::vector<double> xs, ys;
  for (std::size_t k = 0; k < run.scans.size(); ++k) {
    for (const Eigen::Vector2d& p : ScanPoints(run, run.tracks[framing + 1], k)) {
      xs.push_back(p.x());
      ys.push_back(p.y());
    }
  }
  if (xs.empty()) throw std::runtime_error(run.scans_path + ": no laser returns to draw");
  auto quantile = [](std::vector<double>* v, double q) {
    const std::size_t i = static_cast<std::size_t>(q * (v->size() - 1));
    std::nth_element(v->begin(), v->begin() + i, v->end());
    return (*v)[i];
  };
  return {{quantile(&xs, 0.005), quantile(&ys, 0.005)}, {quantile(&xs, 0.995), quantile(&ys, 0.995)}};
}

void DrawMap(const std::string& dir, const std::string& name, PlanCanvas* canvas) {
  for (const MapFeature& f : rundir::ReadMapCsv(rundir::PathIn(dir, rundir::MapFile(name)))) {
    if (f.type == FeatureType::kLine && f.has_segment) {
      canvas->Segment(f.p_WA, f.p_WB, kMapLine, 1);
    } else if (f.type == FeatureType::kCorner) {
      canvas->Dot(f.params, kCorner, 2);
    }
  }
}

// Adds scans [from, to) of `track` to its panel: points, then its path to
// the last of them.
void AddScans(const RealRun& run, const Track& track, std::size_t from, std::size_t to,
              PlanCanvas* canvas) {
  for (std::size_t k = from; k < to; ++k) {
    if (k % 256 == 0) ThrowIfInterrupted("render");
    for (const Eigen::Vector2d& p : ScanPoints(run, track, k)) canvas->Dot(p, track.points);
  }
  const std::size_t first_row = from == 0 ? 0 : run.row_at.at(run.scans[from - 1].t_s);
  const std::size_t last_row = run.row_at.at(run.scans[to - 1].t_s);
  for (std::size_t i = first_row; i + 1 <= last_row; ++i) {
    canvas->Segment(PoseAt(run, track, i).translation(),
                    PoseAt(run, track, i + 1).translation(), track.path);
  }
}

void DrawReference(const RealRun& run, PlanCanvas* canvas) {
  for (std::size_t i = 0; i + 1 < run.reference.size(); ++i) {
    canvas->Segment(run.reference[i].translation(), run.reference[i + 1].translation(),
                    kReference);
  }
}

// Pastes `panels` side by side into one image.
renders::Image SideBySide(const std::vector<const renders::Image*>& panels) {
  renders::Image out;
  out.height = panels.front()->height;
  for (const renders::Image* p : panels) out.width += p->width;
  out.rgb.resize(static_cast<std::size_t>(out.width) * out.height * 3);
  int x0 = 0;
  for (const renders::Image* p : panels) {
    for (int y = 0; y < out.height; ++y) {
      std::copy_n(&p->rgb[static_cast<std::size_t>(y) * p->width * 3], p->width * 3,
                  &out.rgb[(static_cast<std::size_t>(y) * out.width + x0) * 3]);
    }
    x0 += p->width;
  }
  return out;
}

}  // namespace

int RenderImportedRun(const std::string& run_dir, const renders::RenderParams& params) {
  const RealRun run = ReadRealRun(run_dir);
  const std::size_t num_scans = run.scans.size();
  const auto [min, max] = Window(run);
  const int side = params.height - params.height % 2;
  std::vector<PlanCanvas> panels;
  for (const Track& track : run.tracks) {
    ThrowIfInterrupted("render");
    panels.emplace_back(side, side, min, max);
    DrawReference(run, &panels.back());
    AddScans(run, track, 0, num_scans, &panels.back());
    if (!track.map_name.empty()) DrawMap(run_dir, track.map_name, &panels.back());
  }
  std::vector<const renders::Image*> images;
  for (const PlanCanvas& panel : panels) images.push_back(&panel.image());
  renders::WritePng(rundir::PathIn(run_dir, rundir::kFinalImageFile), SideBySide(images));
  if (!params.video) return 0;

  // The video: the filters' panels growing scan by scan.
  const std::size_t num_filters = run.names.size();
  std::vector<PlanCanvas> growing;
  for (std::size_t f = 0; f < num_filters; ++f) {
    growing.emplace_back(side, side, min, max);
    DrawReference(run, &growing.back());
  }
  renders::VideoWriter video(rundir::PathIn(run_dir, rundir::kVideoFile),
                             static_cast<int>(num_filters) * side, side, params.fps, params.crf);
  const std::size_t stride = (num_scans + kMaxVideoFrames - 1) / kMaxVideoFrames;
  for (std::size_t from = 0; from < num_scans; from += stride) {
    // A stop leaves no video (the writer removes its temporary file).
    ThrowIfInterrupted("render");
    const std::size_t to = std::min(num_scans, from + stride);
    std::vector<PlanCanvas> frame;
    for (std::size_t f = 0; f < num_filters; ++f) {
      const Track& track = run.tracks[f + 1];
      AddScans(run, track, from, to, &growing[f]);
      frame.push_back(growing[f]);
      const std::size_t row = run.row_at.at(run.scans[to - 1].t_s);
      frame.back().Dot(PoseAt(run, track, row).translation(), kRobot, 3);
    }
    std::vector<const renders::Image*> frame_images;
    for (const PlanCanvas& panel : frame) frame_images.push_back(&panel.image());
    video.AddFrame(SideBySide(frame_images));
  }
  video.Finish();
  return video.frames();
}

}  // namespace mjslam::app
