#include "app/jobs/evaluate.h"

#include <algorithm>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
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


nlohmann::json Xyz(const Eigen::Vector3d& v) {
  return {{"x", v(0)}, {"y", v(1)}, {"th", v(2)}};
}

// NaN as JSON null (nlohmann writes NaN as null anyway; explicit for clarity).
nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

// The names joined by ", " ("none" when empty).
std::string Joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text.empty() ? std::string("none") : text;
}

std::size_t IndexOf(const std::vector<std::string>& names, const std::string& name) {
  return static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
}

// eval::DivergenceStudy of two of a run's maps; its errors (a map with
// nothing to compare) name the run's map files and its world.
std::vector<eval::DivergenceStatistics> StudyRunMaps(const std::string& run_dir,
                                                     const eval::DivergencePair& pair,
                                                     const eval::Map& first,
                                                     const eval::Map& second,
                                                     const eval::Map& truth,
                                                     const std::vector<int>& num_points,
                                                     int realisations, const Rng& rng,
                                                     const eval::DivergenceParams& params) {
  try {
    return eval::DivergenceStudy(first, second, truth, pair, num_points, realisations, rng,
                                 params);
  } catch (const std::invalid_argument& error) {
    throw std::runtime_error(rundir::PathIn(run_dir, rundir::MapFile(pair.first)) + ", " +
                             rundir::MapFile(pair.second) + " and the ground truth of " +
                             rundir::kConfigFile + "'s world: " + error.what());
  }
}

}  // namespace

std::optional<eval::DivergencePair> ChooseDivergencePair(
    const std::vector<std::string>& names, const std::function<bool(std::size_t)>& has_mass,
    const std::vector<std::string>& requested, const std::string& where, std::string* why_not) {
  if (!requested.empty()) {
    if (requested.size() != 2) {
      throw std::runtime_error(where + ": --pair takes two filters (got " +
                               Joined(requested) + ")");
    }
    for (const std::string& name : requested) {
      if (IndexOf(names, name) == names.size()) {
        throw std::runtime_error(where + ": --pair: no filter " + name + " in the run (its filters: " +
                                 Joined(names) + ")");
      }
    }
    if (requested[0] == requested[1]) {
      throw std::runtime_error(where + ": --pair needs two different filters (got " +
                               requested[0] + " twice)");
    }
    return eval::DivergencePair{requested[0], requested[1]};
  }
  const eval::DivergencePair paper;  // classical and selective
  if (IndexOf(names, paper.first) < names.size() && IndexOf(names, paper.second) < names.size()) {
    return paper;
  }
  std::vector<std::string> with_mass;
  std::vector<std::string> described;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const bool mass = has_mass(i);
    if (mass) with_mass.push_back(names[i]);
    described.push_back(names[i] + (mass ? "" : " (nothing to compare)"));
  }
  if (with_mass.size() >= 2) return eval::DivergencePair{with_mass[0], with_mass[1]};
  if (why_not != nullptr) {
    *why_not = where + ": the map divergence needs two filters whose maps have a corner or a "
               "seen line (got " + Joined(described) + ")";
  }
  return std::nullopt;
}

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

std::vector<eval::PoseStepMetrics> PoseSteps(const std::vector<rundir::TrajectoryRow>& trajectory,
                                             std::size_t filter) {
  // Realtime timing: a row whose scan the filter skipped holds the estimate
  // of its last processed row, compared with that row's truth.
  std::vector<eval::PoseStepMetrics> steps;
  Pose2 X_WR_true;
  for (const rundir::TrajectoryRow& row : trajectory) {
    const rundir::FilterRow& f = row.filters.at(filter);
    if (f.processed || steps.empty()) X_WR_true = row.X_WR_true;
    steps.push_back(eval::EvaluatePoseStep(X_WR_true, f.X_WR, f.P));
  }
  return steps;
}

std::vector<double> PoseNees(const std::vector<rundir::TrajectoryRow>& trajectory,
                             std::size_t filter) {
  std::vector<double> nees;
  bool written = false;  // a run from before the column has none
  for (const rundir::TrajectoryRow& row : trajectory) {
    nees.push_back(row.filters.at(filter).nees);
    written = written || !std::isnan(nees.back());
  }
  if (written) return nees;
  nees.clear();
  for (const eval::PoseStepMetrics& m : PoseSteps(trajectory, filter)) nees.push_back(m.nees);
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
  const std::string trajectory_path = rundir::PathIn(run_dir, rundir::kTrajectoryFile);
  const std::vector<rundir::TrajectoryRow> trajectory =
      rundir::ReadTrajectoryRows(trajectory_path);
  laps.Charge(&result.cpu.trajectory_s);
  // A recording without truth (a real log) has no world to compare with.
  if (std::isnan(trajectory.at(0).X_WR_true.x)) {
    throw std::runtime_error(trajectory_path + ": true_x is nan: no true pose to evaluate against "
                             "(a real log: evaluate the directory mjslam import wrote)");
  }
  for (const rundir::FilterRow& f : trajectory[0].filters) result.names.push_back(f.name);
  // A --pair the run has not: an error before anything is written.
  if (!options.divergence_pair.empty()) {
    ChooseDivergencePair(result.names, [](std::size_t) { return true; }, options.divergence_pair,
                         trajectory_path);
  }
  result.truth = RunGroundTruth(run_dir, options.ground_truth);
  rundir::WriteMapCsv(rundir::PathIn(run_dir, rundir::kGroundTruthMapFile), result.truth);
  laps.Charge(&result.cpu.ground_truth_s);
  result.observations = CheckLineObservations(
      rundir::PathIn(run_dir, rundir::kScansFile),
      LoadRunConfig(rundir::PathIn(run_dir, rundir::kConfigFile), {}), result.truth);
  laps.Charge(&result.cpu.observations_s);

  // Poses and maps of every filter of the trajectory.
  if (result.names.empty()) {
    throw std::runtime_error(trajectory_path + ": no filter columns (<name>_x, ...)");
  }
  std::vector<eval::Map> maps;
  for (std::size_t i = 0; i < result.names.size(); ++i) {
    const std::string& name = result.names[i];
    ThrowIfInterrupted("evaluation");
    std::vector<eval::PoseStepMetrics> steps = PoseSteps(trajectory, i);
    const std::vector<double> nees = PoseNees(trajectory, i);
    for (std::size_t k = 0; k < steps.size(); ++k) steps[k].nees = nees[k];
    result.pose.push_back(eval::SummarisePoseSteps(steps));
    laps.Charge(&result.cpu.poses_s);
    maps.push_back(rundir::ReadMapCsv(rundir::PathIn(run_dir, rundir::MapFile(name))));
    result.map.push_back(eval::MatchMaps(maps.back(), result.truth, options.match));
    laps.Charge(&result.cpu.maps_s);
  }
  if (options.divergence_points > 0) {
    const std::optional<eval::DivergencePair> pair = ChooseDivergencePair(
        result.names, [&maps](std::size_t i) { return eval::HasDivergenceMass(maps[i]); },
        options.divergence_pair, trajectory_path, &result.no_divergence);
    if (pair) {
      const std::uint64_t seed = manifest.value("seed", std::uint64_t{0});
      const std::vector<eval::DivergenceStatistics> rows = StudyRunMaps(
          run_dir, *pair, maps[IndexOf(result.names, pair->first)],
          maps[IndexOf(result.names, pair->second)], result.truth, {options.divergence_points},
          options.divergence_realisations, Rng(seed).Fork("evaluate"), options.divergence);
      result.has_divergence = true;
      result.divergence_pair = *pair;
      result.divergence = {rows[0].mean, rows[1].mean, rows[2].mean, rows[3].mean};
      laps.Charge(&result.cpu.divergence_s);
    }
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
    const eval::SeenMatch seen = eval::MatchedSeen(map, result.observations.seen);
    f["map"] = {{"num_estimates", map.num_estimates},
                {"num_truth", map.num_truth},
                {"matched_estimates", map.num_matched_estimates},
                {"matched_truth", map.num_matched_truth},
                {"matched_fraction", map.matched_fraction},
                {"seen_truth", seen.seen},
                {"matched_seen_fraction", Number(seen.matched_fraction)},
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
    const std::vector<std::string> labels = eval::DivergenceLabels(result.divergence_pair);
    const eval::MapDivergences& d = result.divergence;
    summary["divergence"] = {{"num_points", options.divergence_points},
                             {"realisations", options.divergence_realisations},
                             {labels[0], d.first_second},
                             {labels[1], d.second_first},
                             {labels[2], d.first_truth},
                             {labels[3], d.second_truth}};
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
  // The run's filters (its trajectory's header), the pair among them.
  const std::string trajectory_path = rundir::PathIn(run_dir, rundir::kTrajectoryFile);
  std::vector<std::string> names;
  if (std::filesystem::exists(trajectory_path)) {
    names = rundir::TrajectoryFilterNames(rundir::ReadCsvHeader(trajectory_path));
  } else {
    names = rundir::DefaultFilterNames();  // maps alone: the default filters'
  }
  auto read_map = [&run_dir](const std::string& name) {
    return rundir::ReadMapCsv(rundir::PathIn(run_dir, rundir::MapFile(name)));
  };
  std::string why_not;
  const std::optional<eval::DivergencePair> pair = ChooseDivergencePair(
      names, [&](std::size_t i) { return eval::HasDivergenceMass(read_map(names[i])); },
      options.divergence_pair, trajectory_path, &why_not);
  if (!pair) throw std::runtime_error(why_not);
  const eval::Map truth = RunGroundTruth(run_dir, options.ground_truth);
  const eval::Map first = read_map(pair->first);
  const eval::Map second = read_map(pair->second);
  const std::uint64_t seed = manifest.value("seed", std::uint64_t{0});
  const std::vector<eval::DivergenceStatistics> rows =
      StudyRunMaps(run_dir, *pair, first, second, truth, num_points, realisations,
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
