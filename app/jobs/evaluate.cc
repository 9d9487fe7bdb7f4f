#include "app/jobs/evaluate.h"

#include <algorithm>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <utility>

#include "app/engine/cpu_profile.h"  // CpuLaps
#include "app/engine/run_config.h"
#include "common/interrupt.h"
#include "common/rng.h"
#include "rundir/csv_reader.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/map_csv.h"
#include "rundir/rows.h"
#include "rundir/run_files.h"
#include "rundir/summary.h"
#include "sim/obstacles.h"
#include "sim/scene.h"

namespace mjslam::app {
namespace {

using rundir::CsvTable;

nlohmann::json Xyz(const Eigen::Vector3d& v) {
  return {{"x", v(0)}, {"y", v(1)}, {"th", v(2)}};
}

// NaN as JSON null (nlohmann writes NaN as null anyway; explicit for clarity).
nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

// Why the map divergence cannot be computed for a run with filters `names`
// (it compares the filters classical and selective), or "" when it can.
std::string NoDivergencePair(const std::vector<std::string>& names, const std::string& run_dir) {
  const std::vector<std::string>& pair = rundir::DefaultFilterNames();
  if (std::find(names.begin(), names.end(), pair[0]) != names.end() &&
      std::find(names.begin(), names.end(), pair[1]) != names.end()) {
    return "";
  }
  std::string got;
  for (const std::string& name : names) got += (got.empty() ? "" : ", ") + name;
  return rundir::PathIn(run_dir, rundir::kTrajectoryFile) +
         ": the map divergence compares the filters " + pair[0] + " and " + pair[1] + " (got " +
         (got.empty() ? "none" : got) + ")";
}

// The indices of the classical and selective filters among `names`, the
// pair the map divergence compares; NoDivergencePair must be "".
std::pair<std::size_t, std::size_t> DivergencePair(const std::vector<std::string>& names) {
  const std::vector<std::string>& pair = rundir::DefaultFilterNames();
  return {static_cast<std::size_t>(std::find(names.begin(), names.end(), pair[0]) - names.begin()),
          static_cast<std::size_t>(std::find(names.begin(), names.end(), pair[1]) - names.begin())};
}

// eval::DivergenceStudy of a run's classical and selective maps; its errors
// (a map with nothing to compare) name the run's map files and its world.
std::vector<eval::DivergenceStatistics> StudyRunMaps(const std::string& run_dir,
                                                     const eval::Map& classical,
                                                     const eval::Map& selective,
                                                     const eval::Map& truth,
                                                     const std::vector<int>& num_points,
                                                     int realisations, const Rng& rng,
                                                     const eval::DivergenceParams& params) {
  const std::vector<std::string>& names = rundir::DefaultFilterNames();
  try {
    return eval::DivergenceStudy(classical, selective, truth, num_points, realisations, rng,
                                 params);
  } catch (const std::invalid_argument& error) {
    throw std::runtime_error(rundir::PathIn(run_dir, rundir::MapFile(names[0])) + ", " +
                             rundir::MapFile(names[1]) + " and the ground truth of " +
                             rundir::kConfigFile + "'s world: " + error.what());
  }
}

}  // namespace

eval::Map WorldGroundTruth(const std::string& world, const std::string& robot_model,
                           const eval::GroundTruthParams& params, double max_world_extent_m) {
  const sim::Scene scene(world, robot_model);
  sim::CheckWorldExtent(scene, max_world_extent_m);
  std::vector<eval::WallRectangle> walls;
  for (const sim::ObstacleFootprint& obstacle : scene.Obstacles()) {
    if (obstacle.shape != sim::ObstacleFootprint::Shape::kRectangle) continue;
    const std::array<Eigen::Vector2d, 4> corners = sim::RectangleCorners(obstacle);
    walls.push_back({corners});
  }
  try {
    // Only what faces the free space the robot starts in.
    return eval::ReachableFeatures(eval::BuildGroundTruthMap(walls, params), walls,
                                   scene.StartPose().translation());
  } catch (const std::invalid_argument& error) {
    throw std::runtime_error(world + ": " + error.what());
  }
}

eval::Map RunGroundTruth(const std::string& run_dir, const eval::GroundTruthParams& params) {
  const std::string config_path = rundir::PathIn(run_dir, rundir::kConfigFile);
  if (!std::filesystem::is_regular_file(config_path)) {
    throw std::runtime_error(config_path + ": missing (is '" + run_dir + "' a run directory?)");
  }
  const RunConfig config = LoadRunConfig(config_path, {});
  return WorldGroundTruth(config.run.world, config.run.robot_model, params,
                          config.sim.max_world_extent_m);
}

std::vector<eval::PoseStepMetrics> PoseSteps(const CsvTable& trajectory, const std::string& name) {
  const int truth = trajectory.ColumnIndex("true_x");
  const int estimate = trajectory.ColumnIndex(name + "_x");
  const int pxx = trajectory.ColumnIndex(name + "_pxx");
  // Realtime timing: a row whose scan the filter skipped holds the estimate
  // of its last processed row, compared with that row's truth.
  const auto& columns = trajectory.columns;
  const bool has_processed =
      std::find(columns.begin(), columns.end(), name + "_processed") != columns.end();
  const int processed = has_processed ? trajectory.ColumnIndex(name + "_processed") : -1;
  std::vector<eval::PoseStepMetrics> steps;
  Pose2 X_WR_true;
  for (const std::vector<double>& row : trajectory.rows) {
    if (processed < 0 || row[processed] != 0.0 || steps.empty()) {
      X_WR_true = Pose2(row[truth], row[truth + 1], row[truth + 2]);
    }
    Eigen::Matrix3d P;
    P << row[pxx], row[pxx + 1], row[pxx + 2], row[pxx + 1], row[pxx + 3], row[pxx + 4],
        row[pxx + 2], row[pxx + 4], row[pxx + 5];
    steps.push_back(eval::EvaluatePoseStep(
        X_WR_true, Pose2(row[estimate], row[estimate + 1], row[estimate + 2]), P));
  }
  return steps;
}

std::vector<double> PoseNees(const CsvTable& trajectory, const std::string& name) {
  std::vector<double> nees;
  for (std::size_t c = 0; c < trajectory.columns.size(); ++c) {
    if (trajectory.columns[c] != name + "_nees") continue;
    for (const std::vector<double>& row : trajectory.rows) nees.push_back(row[c]);
    return nees;
  }
  for (const eval::PoseStepMetrics& m : PoseSteps(trajectory, name)) nees.push_back(m.nees);
  return nees;
}

RunEvaluation EvaluateRunDirectory(const std::string& run_dir, const EvaluateOptions& options) {
  const double start_s = ThreadCpuSeconds();
  RunEvaluation result;
  options.ground_truth.ValidateOrThrow();
  options.match.ValidateOrThrow();
  options.divergence.ValidateOrThrow();
  const nlohmann::json manifest = rundir::ReadManifest(run_dir);
  // Not while a run (or another evaluation) writes there.
  const rundir::RunDirectoryLock lock(run_dir);
  CpuLaps laps;
  laps.Start();
  const CsvTable trajectory =
      rundir::ReadTrajectoryCsv(rundir::PathIn(run_dir, rundir::kTrajectoryFile));
  laps.Charge(&result.cpu.trajectory_s);
  // A recording without truth (a real log) has no world to compare with.
  if (std::isnan(trajectory.rows[0][1])) {
    throw std::runtime_error(trajectory.path + ": true_x is nan: no true pose to evaluate against "
                             "(a real log: evaluate the directory mjslam import wrote)");
  }
  result.truth = RunGroundTruth(run_dir, options.ground_truth);
  rundir::WriteMapCsv(rundir::PathIn(run_dir, rundir::kGroundTruthMapFile), result.truth);
  laps.Charge(&result.cpu.ground_truth_s);
  result.observations = CheckLineObservations(
      rundir::PathIn(run_dir, rundir::kScansFile),
      LoadRunConfig(rundir::PathIn(run_dir, rundir::kConfigFile), {}), result.truth);
  laps.Charge(&result.cpu.observations_s);

  // Poses and maps of every filter of the trajectory.
  result.names = rundir::TrajectoryFilterNames(trajectory.columns);
  if (result.names.empty()) {
    throw std::runtime_error(trajectory.path + ": no filter columns (<name>_x, ...)");
  }
  std::vector<eval::Map> maps;
  for (const std::string& name : result.names) {
    ThrowIfInterrupted("evaluation");
    std::vector<eval::PoseStepMetrics> steps = PoseSteps(trajectory, name);
    const std::vector<double> nees = PoseNees(trajectory, name);
    for (std::size_t k = 0; k < steps.size(); ++k) steps[k].nees = nees[k];
    result.pose.push_back(eval::SummarisePoseSteps(steps));
    laps.Charge(&result.cpu.poses_s);
    maps.push_back(rundir::ReadMapCsv(rundir::PathIn(run_dir, rundir::MapFile(name))));
    result.map.push_back(eval::MatchMaps(maps.back(), result.truth, options.match));
    laps.Charge(&result.cpu.maps_s);
  }
  result.no_divergence = options.divergence_points > 0 ? NoDivergencePair(result.names, run_dir) : "";
  if (options.divergence_points > 0 && result.no_divergence.empty()) {
    const std::uint64_t seed = manifest.value("seed", std::uint64_t{0});
    const auto [classical, selective] = DivergencePair(result.names);
    const std::vector<eval::DivergenceStatistics> rows = StudyRunMaps(
        run_dir, maps[classical], maps[selective], result.truth, {options.divergence_points},
        options.divergence_realisations, Rng(seed).Fork("evaluate"), options.divergence);
    result.has_divergence = true;
    result.divergence = {rows[0].mean, rows[1].mean, rows[2].mean, rows[3].mean};
    laps.Charge(&result.cpu.divergence_s);
  }

  // Merge into summary.json.
  nlohmann::json summary = rundir::ReadSummary(run_dir);
  for (std::size_t i = 0; i < result.names.size(); ++i) {
    nlohmann::json& f = summary["filters"][result.names[i]];
    const eval::PoseSummary& pose = result.pose[i];
    const eval::MapMatchReport& map = result.map[i];
    f["inside_2sigma"] = Xyz(pose.inside_2sigma);
    f["rmse"] = Xyz(pose.rmse);
    f["mean_nees"] = Number(pose.mean_nees);
    f["final_pose_error"] = Xyz(pose.final_error);
    f["num_features"] = static_cast<int>(maps[i].size());
    f["map"] = {{"num_estimates", map.num_estimates},
                {"num_truth", map.num_truth},
                {"matched_estimates", map.num_matched_estimates},
                {"matched_truth", map.num_matched_truth},
                {"matched_fraction", map.matched_fraction},
                {"duplicates", map.num_duplicates},
                {"unmatched_estimates", map.num_unmatched_estimates},
                {"inconsistent", map.num_inconsistent},
                {"mean_feature_nees", Number(map.mean_nees)},
                {"line_rho_rmse_m", Number(map.line_rho_rmse_m)},
                {"line_alpha_rmse_rad", Number(map.line_alpha_rmse_rad)},
                {"corner_rmse_m", Number(map.corner_rmse_m)}};
  }
  const ObservationCheck& o = result.observations;
  summary["observations"] = {{"lines", o.lines},
                             {"matched", o.matched},
                             {"range_bias_m", o.range_bias_m},
                             {"mean_nis", Number(o.mean_nis)},
                             {"fraction_above_gate", Number(o.fraction_above_gate)},
                             {"max_nis", Number(o.max_nis)}};
  if (result.has_divergence) {
    summary["divergence"] = {{"num_points", options.divergence_points},
                             {"realisations", options.divergence_realisations},
                             {"classical_selective", result.divergence.classical_selective},
                             {"selective_classical", result.divergence.selective_classical},
                             {"classical_truth", result.divergence.classical_truth},
                             {"selective_truth", result.divergence.selective_truth}};
  }
  rundir::WriteSummary(run_dir, summary);
  laps.Charge(&result.cpu.summary_s);
  result.cpu.total_s = ThreadCpuSeconds() - start_s;
  return result;
}

std::vector<eval::DivergenceStatistics> WriteDivergenceStudy(
    const std::string& run_dir, const std::vector<int>& num_points, int realisations,
    const std::string& out_path, const EvaluateOptions& options) {
  const nlohmann::json manifest = rundir::ReadManifest(run_dir);
  // The classical and selective filters of the run (its trajectory's header).
  const std::string trajectory_path = rundir::PathIn(run_dir, rundir::kTrajectoryFile);
  std::vector<std::string> names;
  if (std::filesystem::exists(trajectory_path)) {
    names = rundir::TrajectoryFilterNames(rundir::ReadCsvHeader(trajectory_path));
  } else {
    names = rundir::DefaultFilterNames();  // maps alone: the default filters'
  }
  const std::string no_pair = NoDivergencePair(names, run_dir);
  if (!no_pair.empty()) throw std::runtime_error(no_pair);
  const eval::Map truth = RunGroundTruth(run_dir, options.ground_truth);
  const std::vector<std::string>& pair = rundir::DefaultFilterNames();
  const eval::Map classical = rundir::ReadMapCsv(rundir::PathIn(run_dir, rundir::MapFile(pair[0])));
  const eval::Map selective = rundir::ReadMapCsv(rundir::PathIn(run_dir, rundir::MapFile(pair[1])));
  const std::uint64_t seed = manifest.value("seed", std::uint64_t{0});
  const std::vector<eval::DivergenceStatistics> rows =
      StudyRunMaps(run_dir, classical, selective, truth, num_points, realisations,
                   Rng(seed).Fork("divergence"), options.divergence);
  std::string text = rundir::HeaderLine(rundir::DivergenceColumns());
  for (const eval::DivergenceStatistics& row : rows) {
    text += std::to_string(row.num_points) + "," + row.pair + "," + rundir::FormatDouble(row.mean) +
            "," + rundir::FormatDouble(row.variance) + "\n";
  }
  rundir::WriteFileAtomically(out_path, text);
  return rows;
}

}  // namespace mjslam::app
