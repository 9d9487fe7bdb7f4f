#include "app/jobs/evaluate_real.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "app/engine/run_config.h"
#include "rundir/csv_reader.h"
#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/map_csv.h"
#include "rundir/rows.h"
#include "rundir/run_files.h"

namespace mjslam::app {
namespace {

using realdata::Relation;
using realdata::RelationErrors;
using realdata::TimedPose;

// The filters of an imported run's trajectory.csv (its header's): the
// filters' estimates are what it is scored on. Throws std::runtime_error
// naming the file when it has none (a trajectory written by the import,
// before its replay).
std::vector<std::string> FilterNames(const std::string& path) {
  std::vector<std::string> names = rundir::TrajectoryFilterNames(rundir::ReadCsvHeader(path));
  if (names.empty()) {
    throw std::runtime_error(path + ": no filter columns (<name>_x, ...) for the evaluation of "
                             "an imported log to score");
  }
  return names;
}

// The poses of the robot centre B of the trajectory `track` (0 odometry, 1 +
// f filter f) at `times` (all rows when empty).
std::vector<TimedPose> PosesOf(const std::vector<rundir::TrajectoryRow>& trajectory, int track,
                               const std::set<double>& times, const Pose2& X_RB) {
  std::vector<TimedPose> poses;
  for (const rundir::TrajectoryRow& row : trajectory) {
    if (!times.empty() && times.count(row.t_s) == 0) continue;
    const Pose2& X_WR = track == 0 ? row.X_WR_odometry : row.filters[track - 1].X_WR;
    poses.push_back({row.t_s, X_WR * X_RB});
  }
  return poses;
}

// The poses of B of the reference.
std::vector<TimedPose> PosesOf(const std::vector<rundir::ReferenceRow>& reference,
                               const Pose2& X_RB) {
  std::vector<TimedPose> poses;
  for (const rundir::ReferenceRow& row : reference) poses.push_back({row.t_s, row.X_WR * X_RB});
  return poses;
}

nlohmann::json ToJson(const std::vector<ScoredTrajectory>& scored) {
  nlohmann::json out = nlohmann::json::object();
  for (const ScoredTrajectory& s : scored) {
    const RelationErrors& e = s.errors;
    out[s.name] = {{"num_relations", e.num_relations},
                   {"num_matched", e.num_matched},
                   {"translation_mean_m", e.translation_mean_m},
                   {"translation_std_m", e.translation_std_m},
                   {"rotation_mean_deg", e.rotation_mean_deg},
                   {"rotation_std_deg", e.rotation_std_deg},
                   {"translation_sq_mean_m2", e.translation_sq_mean_m2},
                   {"translation_sq_std_m2", e.translation_sq_std_m2},
                   {"rotation_sq_mean_deg2", e.rotation_sq_mean_deg2},
                   {"rotation_sq_std_deg2", e.rotation_sq_std_deg2}};
  }
  return out;
}

// Counts the rows whose pose covariance of filter `filter` (in the order of
// trajectory.csv's filters) is not positive semi-definite, and those where it is
// singular (the file holds the upper triangle: symmetric by construction).
std::pair<int, int> CovarianceDefects(const std::vector<rundir::TrajectoryRow>& trajectory,
                                      std::size_t filter) {
  int not_psd = 0, singular = 0;
  for (const rundir::TrajectoryRow& row : trajectory) {
    const Eigen::Matrix3d& P = row.filters[filter].P;
    const Eigen::Vector3d eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(P,
        Eigen::EigenvaluesOnly).eigenvalues();
    const double scale = std::max(eigenvalues.cwiseAbs().maxCoeff(), 1e-300);
    if (!P.allFinite() || eigenvalues.minCoeff() < -1e-9 * scale) ++not_psd;
    else if (eigenvalues.minCoeff() <= 1e-9 * scale) ++singular;
  }
  return {not_psd, singular};
}

}  // namespace

bool IsImportedRun(const std::string& run_dir) {
  const nlohmann::json manifest =
      rundir::ReadJsonFile(rundir::PathIn(run_dir, rundir::kManifestFile), nlohmann::json::object());
  const std::string mode = manifest.value("mode", std::string());
  if (mode == "import") return true;
  if (mode != "replay") return false;
  // A replay of an imported run.
  const std::string scans = manifest.value("scans_file", std::string());
  const std::string source_dir = std::filesystem::path(scans).parent_path().string();
  const nlohmann::json source = rundir::ReadJsonFile(
      rundir::PathIn(source_dir.empty() ? "." : source_dir, rundir::kManifestFile),
      nlohmann::json::object());
  return source.value("mode", std::string()) == "import";
}

std::string ImportedScansPath(const std::string& run_dir) {
  const nlohmann::json manifest = rundir::ReadManifest(run_dir);
  if (manifest.value("mode", std::string()) == "replay") {
    return manifest.value("scans_file", std::string());
  }
  return rundir::PathIn(run_dir, rundir::kScansFile);
}

// Reads the files, scores each trajectory on each set of relations and
// writes summary.json: a list of the same few steps per set.
// vs_reference_lags as {"1": [...], "10": [...], "100": [...]}.
nlohmann::json ReferenceLagsJson(const RealEvaluation& result) {
  nlohmann::json lags = nlohmann::json::object();
  for (std::size_t i = 0; i < result.vs_reference_lags.size(); ++i) {
    lags[std::to_string(RealEvaluation::kReferenceLags[i])] = ToJson(result.vs_reference_lags[i]);
  }
  return lags;
}

RealEvaluation EvaluateImportedRun(const std::string& run_dir) {
  const nlohmann::json manifest = rundir::ReadManifest(run_dir);
  const RunConfig config = LoadRunConfig(rundir::PathIn(run_dir, rundir::kConfigFile), {});
  const Pose2 X_RB(-config.slam.ekf.control_point_offset_m, 0.0, 0.0);
  const std::string trajectory_path = rundir::PathIn(run_dir, rundir::kTrajectoryFile);
  const std::vector<std::string> filters = FilterNames(trajectory_path);
  const std::vector<rundir::TrajectoryRow> trajectory = rundir::ReadTrajectoryRows(trajectory_path);
  std::set<double> scan_times;
  for (const rundir::ScanRow& scan : rundir::ReadScanRows(ImportedScansPath(run_dir))) {
    scan_times.insert(scan.t_s);
  }

  RealEvaluation result;
  result.filter_names = filters;
  // The trajectories scored, by their track in PosesOf: the filters, then
  // the odometry.
  std::vector<std::string> names = filters;
  names.push_back("odometry");
  std::vector<int> tracks;
  for (std::size_t f = 0; f < filters.size(); ++f) tracks.push_back(static_cast<int>(f) + 1);
  tracks.push_back(0);
  const std::string reference_path = rundir::PathIn(run_dir, rundir::kReferenceFile);
  const bool has_reference =
      manifest.value("reference", std::string("none")) != "none";
  std::vector<rundir::ReferenceRow> reference;
  if (has_reference) reference = rundir::ReadReferenceRows(reference_path);

  const std::string relations_path = manifest.value("relations_file", std::string());
  if (!relations_path.empty()) {
    const std::vector<Relation> relations = realdata::ReadRelations(relations_path);
    realdata::RelationMatching matching;
    matching.time_offset_s = manifest.value("relations_time_offset_s", 0.0);
    matching.tolerance_s = manifest.value("relations_tolerance_s", 0.006);
    result.time_offset_s = matching.time_offset_s;
    result.tolerance_s = matching.tolerance_s;
    for (std::size_t i = 0; i < names.size(); ++i) {
      result.at_scans.push_back({names[i], realdata::ScoreRelations(
          relations, PosesOf(trajectory, tracks[i], scan_times, X_RB), matching)});
      result.at_records.push_back({names[i], realdata::ScoreRelations(
          relations, PosesOf(trajectory, tracks[i], {}, X_RB), matching)});
    }
    const std::vector<TimedPose> at_scans = PosesOf(trajectory, 0, scan_times, X_RB);
    if (has_reference) {
      result.at_scans.push_back({"reference", realdata::ScoreRelations(
          relations, PosesOf(reference, X_RB), matching)});
    }
    std::set<double> times;
    for (const Relation& r : relations) times.insert({r.t1_s, r.t2_s});
    result.relation_times = static_cast<int>(times.size());
    for (double t : times) {
      const bool hit = realdata::NearestPose(at_scans, t - matching.time_offset_s,
                                             matching.tolerance_s) >= 0;
      result.relation_times_at_scans += hit ? 1 : 0;
    }
  }
  if (has_reference) {
    // Relations between scans of the reference `lag` apart, matched exactly.
    const std::vector<TimedPose> ref = PosesOf(reference, X_RB);
    const realdata::RelationMatching exact{0.0, 0.0};
    for (const int lag : RealEvaluation::kReferenceLags) {
      const std::size_t step = static_cast<std::size_t>(lag);
      std::vector<Relation> apart;
      for (std::size_t i = 0; i + step < ref.size(); ++i) {
        apart.push_back({ref[i].t_s, ref[i + step].t_s,
                         ref[i].pose.Inverse() * ref[i + step].pose, static_cast<int>(i + 2)});
      }
      std::vector<ScoredTrajectory> scored;
      for (std::size_t i = 0; i < names.size(); ++i) {
        scored.push_back({names[i], realdata::ScoreRelations(
            apart, PosesOf(trajectory, tracks[i], scan_times, X_RB), exact)});
      }
      result.vs_reference_lags.push_back(scored);
    }
  }
  for (std::size_t f = 0; f < filters.size(); ++f) {
    const auto [not_psd, singular] = CovarianceDefects(trajectory, f);
    result.not_positive_semidefinite.push_back(not_psd);
    result.singular.push_back(singular);
    result.num_features.push_back(static_cast<int>(
        rundir::ReadMapCsv(rundir::PathIn(run_dir, rundir::MapFile(filters[f]))).size()));
  }

  const std::string summary_path = rundir::PathIn(run_dir, rundir::kSummaryFile);
  nlohmann::json summary = rundir::ReadJsonFile(summary_path, nlohmann::json::object());
  summary["real"] = {{"relations_file", relations_path},
                     {"time_offset_s", result.time_offset_s},
                     {"tolerance_s", result.tolerance_s},
                     {"relation_times", result.relation_times},
                     {"relation_times_at_scans", result.relation_times_at_scans},
                     {"relations_at_scans", ToJson(result.at_scans)},
                     {"relations_at_records", ToJson(result.at_records)},
                     {"vs_reference_scans_apart", ReferenceLagsJson(result)},
                     {"pose_covariance_not_psd_rows", result.not_positive_semidefinite},
                     {"pose_covariance_singular_rows", result.singular},
                     {"num_features", result.num_features}};
  rundir::WriteJsonAtomically(summary_path, summary);
  return result;
}

}  // namespace mjslam::app
