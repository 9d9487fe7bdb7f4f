#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rundir/rows.h"
#include "eval/ground_truth.h"
#include "eval/map_divergence.h"
#include "eval/map_matching.h"
#include "eval/map_types.h"
#include "eval/pose_metrics.h"
#include "app/jobs/observation_check.h"
#include "sim/sim_params.h"

namespace mjslam::app {

/// How `mjslam evaluate` evaluates a run directory.
struct EvaluateOptions {
  eval::GroundTruthParams ground_truth;
  eval::MatchParams match;
  eval::DivergenceParams divergence;
  /// Monte Carlo points of the map divergence (0: no divergence).
  int divergence_points = 20000;
  /// Realisations of the divergence (their mean is reported).
  int divergence_realisations = 1;
  /// The two filters the divergence compares (`--pair A B`); empty: the
  /// choice of ChooseDivergencePair.
  std::vector<std::string> divergence_pair;
};

/// CPU seconds (of the calling thread) EvaluateRunDirectory spent in each
/// stage, as `mjslam evaluate --profile` prints them.
struct EvaluationCpu {
  /// Reading trajectory.csv.
  double trajectory_s = 0.0;
  /// The world's ground truth map (RunGroundTruth) and ground_truth_map.csv.
  double ground_truth_s = 0.0;
  /// Both filters' pose metrics (PoseSteps, PoseNees, SummarisePoseSteps).
  double poses_s = 0.0;
  /// Reading both map files and matching them with the truth.
  double maps_s = 0.0;
  /// Re-extracting the scans' lines against the truth (CheckLineObservations).
  double observations_s = 0.0;
  /// The map divergence (eval::DivergenceStudy).
  double divergence_s = 0.0;
  /// Merging into summary.json.
  double summary_s = 0.0;
  /// The whole evaluation.
  double total_s = 0.0;
};

/// What EvaluateRunDirectory found, per filter in the order of `names`.
struct RunEvaluation {
  /// The run's filters, from its trajectory.csv's header.
  std::vector<std::string> names;
  eval::Map truth;
  std::vector<eval::PoseSummary> pose;
  std::vector<eval::MapMatchReport> map;
  /// The scans' line observations against the true walls.
  ObservationCheck observations;
  /// Set when divergence_points > 0 and the run has a pair of filters to
  /// compare (ChooseDivergencePair), `divergence_pair`; else, with
  /// divergence_points > 0, `no_divergence` says why there is none.
  bool has_divergence = false;
  std::string no_divergence;
  eval::DivergencePair divergence_pair;
  eval::MapDivergences divergence;
  /// Where the evaluation's CPU time went.
  EvaluationCpu cpu;
};

/// The true map of a world file: the wall (box) footprints of
/// sim::Scene::Obstacles() (no physics is run), through
/// eval::BuildGroundTruthMap, restricted to the features that face the free
/// space reachable from the world's start site (eval::ReachableFeatures);
/// pillars (round or other non-box geoms) are left out. Throws naming the
/// world when it cannot be loaded, spans more than `max_world_extent_m`
/// (sim::CheckWorldExtent) or a wall is not a rectangle.
eval::Map WorldGroundTruth(const std::string& world, const std::string& robot_model,
                           const eval::GroundTruthParams& params = {},
                           double max_world_extent_m = sim::SimParams{}.max_world_extent_m);

/// WorldGroundTruth of the world in the run's config.yaml. Throws naming the
/// file when the run directory's config or world cannot be loaded.
eval::Map RunGroundTruth(const std::string& run_dir, const eval::GroundTruthParams& params = {});

/// The two filters of a run the map divergence compares. `names`: the run's
/// filters in trajectory.csv's order; `has_mass(i)`: whether filter i's map
/// has something to compare (eval::HasDivergenceMass). `requested` (two
/// names, `--pair`) when given: both must be filters of the run and differ,
/// else throws std::runtime_error naming `where` and the run's filters.
/// Without it: classical and selective when the run has both, else the first
/// two filters whose maps have something to compare; when fewer than two
/// have, std::nullopt, and `why_not` (when given) says why, naming `where`.
std::optional<eval::DivergencePair> ChooseDivergencePair(
    const std::vector<std::string>& names, const std::function<bool(std::size_t)>& has_mass,
    const std::vector<std::string>& requested, const std::string& where,
    std::string* why_not = nullptr);

/// The pose metrics (error, NEES, inside 2 sigma) of the trajectory's
/// filter `filter` (its index in TrajectoryRow::filters) at every row. A row
/// whose scan the filter skipped (realtime timing, processed false) holds the
/// estimate of its last processed row and is compared with that row's true
/// pose.
std::vector<eval::PoseStepMetrics> PoseSteps(const std::vector<rundir::TrajectoryRow>& trajectory,
                                             std::size_t filter);

/// The pose NEES (3 dof) of the trajectory's filter `filter` at every row:
/// its `<name>_nees` column, or, in a run from before that column (all
/// NaN), computed from the estimate, the truth and the covariance (NaN
/// where the covariance is not positive definite, e.g. the known start).
std::vector<double> PoseNees(const std::vector<rundir::TrajectoryRow>& trajectory,
                             std::size_t filter);

/// Evaluates a finished run directory: builds the ground truth
/// (RunGroundTruth) and writes it to ground_truth_map.csv, compares both
/// filters' poses (trajectory.csv) and maps (map_<filter>.csv) with the
/// truth and, when asked, computes the map divergence of two of them
/// (ChooseDivergencePair; seeded from the run's seed). Merges the results into summary.json (created if missing; other
/// writers' keys are kept): for each filter `filters.<f>.inside_2sigma`,
/// `rmse` ({x, y, th}), `mean_nees`, `final_pose_error` ({x, y, th}),
/// `num_features`, `map` {...}, `observations` {...} (CheckLineObservations
/// over scans.csv) and `divergence` {...}, keyed by eval::DivergenceLabels
/// (docs/run_directory.md). Files are written atomically. Throws std::runtime_error naming
/// the file for a missing or malformed input.
RunEvaluation EvaluateRunDirectory(const std::string& run_dir, const EvaluateOptions& options = {});

/// `mjslam divergence`: the paper's Figs. 6 and 7 for one run directory.
/// For each entry of `num_points`, `realisations` realisations of the four
/// divergences of the pair of filters ChooseDivergencePair gives
/// (`options.divergence_pair` or its choice; eval::DivergenceStudy, seeded
/// from the run's seed), written to `out_path` as divergence.csv
/// (num_points,pair,mean,variance), atomically. Returns the rows. Throws
/// std::runtime_error when the run has no pair to compare.
std::vector<eval::DivergenceStatistics> WriteDivergenceStudy(
    const std::string& run_dir, const std::vector<int>& num_points, int realisations,
    const std::string& out_path, const EvaluateOptions& options = {});

}  // namespace mjslam::app
