#pragma once

// The layout of a run directory: its file names and the columns of its CSV
// files. The one source of both for the program, the tests and
// docs/run_directory.md (tests/rundir/layout_test.cc checks the documented
// tables against these lists).
#include <string>
#include <vector>

namespace mjslam::rundir {

/// Files of a run directory (docs/run_directory.md).
inline constexpr char kConfigFile[] = "config.yaml";
inline constexpr char kManifestFile[] = "manifest.json";
inline constexpr char kSummaryFile[] = "summary.json";
inline constexpr char kTrajectoryFile[] = "trajectory.csv";
inline constexpr char kScansFile[] = "scans.csv";
inline constexpr char kExplorerFile[] = "explorer.csv";
inline constexpr char kGroundTruthMapFile[] = "ground_truth_map.csv";
inline constexpr char kDivergenceFile[] = "divergence.csv";
inline constexpr char kVideoFile[] = "video.mp4";
inline constexpr char kFinalImageFile[] = "final.png";
/// An imported log's reference trajectory (`mjslam import`): the poses the
/// log itself carries, a SLAM estimate, not ground truth.
inline constexpr char kReferenceFile[] = "reference.csv";
/// Files of a sweep directory besides config.yaml, summary.json and
/// divergence.csv: the runs' folder and the average NEES per step.
inline constexpr char kSweepRunsFolder[] = "runs";
inline constexpr char kNeesFile[] = "nees.csv";

/// The names of the default filters (slam.filters absent), classical then
/// selective, as in file names (MapFile) and column prefixes
/// (FilterColumns). A run's own are in its trajectory.csv's header
/// (TrajectoryFilterNames) or config (slam::FilterNamesOf).
const std::vector<std::string>& DefaultFilterNames();

/// The filters of a trajectory.csv with `columns`: the name of each column
/// `<name>_x` other than true_x and odom_x, in order (empty: a recording).
std::vector<std::string> TrajectoryFilterNames(const std::vector<std::string>& columns);

/// The map file of filter `name`: "map_<name>.csv".
std::string MapFile(const std::string& filter_name);

/// `dir` + "/" + `file`.
std::string PathIn(const std::string& dir, const std::string& file);

/// trajectory.csv: t, the true pose, the odometry pose, the command, the
/// explored fraction, then FilterColumns() of each filter of
/// `filter_names`, in order.
std::vector<std::string> TrajectoryColumns(
    const std::vector<std::string>& filter_names = DefaultFilterNames());
/// The recorded columns of trajectory.csv that come first, t .. cmd_w (what
/// a replay reads).
std::vector<std::string> RecordedTrajectoryColumns();
/// The per-filter column suffixes of trajectory.csv (x, y, th, pxx, ...,
/// nees), and one filter's columns "<name>_<suffix>".
const std::vector<std::string>& FilterColumnSuffixes();
std::vector<std::string> FilterColumns(const std::string& filter_name);

/// scans.csv for `num_beams` beams: t, x, y, th, r0 .. r<num_beams - 1>.
std::vector<std::string> ScanColumns(int num_beams);
/// Columns of scans.csv before the ranges.
inline constexpr int kScanRangesStart = 4;

/// explorer.csv: t, kind, index, x, y (kind is text).
std::vector<std::string> ExplorerColumns();
/// Map CSVs (map_<filter>.csv, ground_truth_map.csv): id, type, p0, p1,
/// c00, c01, c11, ax, ay, bx, by (type is text).
std::vector<std::string> MapColumns();
/// nees.csv of a sweep: t, <name>_anees of each filter (classical_anees,
/// selective_anees by default), lower, upper, n_runs.
std::vector<std::string> NeesColumns(
    const std::vector<std::string>& filter_names = DefaultFilterNames());
/// reference.csv: t, x, y, th (the pose of R at each scan of an imported log
/// that carries one).
std::vector<std::string> ReferenceColumns();
/// divergence.csv: num_points, pair, mean, variance (pair is text).
std::vector<std::string> DivergenceColumns();

/// The header row of a CSV file with `columns`: the names joined by commas,
/// and a line end.
std::string HeaderLine(const std::vector<std::string>& columns);

}  // namespace mjslam::rundir
