#pragma once

// Replays a run directory's recorded scans and odometry through one filter
// (as `mjslam replay` does) and checks every association of a line
// observation against the world's true geometry: the true wall face an
// observed line comes from (found with the true laser pose) against the line
// of the face whose observation created the map feature it was matched to.
// Used by tests/tools/association_trace.cc.
// Links mjslam::app.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "app/jobs/evaluate.h"
#include "app/engine/run_config.h"
#include "common/angles.h"
#include "rundir/csv_reader.h"
#include "rundir/recording.h"
#include "slam/ekf_slam.h"
#include "slam/data_association.h"
#include "slam/feature_extraction.h"
#include "slam/innovation_check.h"

namespace mjslam::testing {

/// What AuditAssociations found; the counts are per 50 s of simulated time.
struct AssociationAudit {
  /// Line observations matched to a feature made from another true line
  /// (none in the maze runs of docs/results.md, "The maze map loss").
  std::map<int, int> wrong_matches;
  /// New line features for a true line that already has one.
  std::map<int, int> duplicates;
  /// Every observation: matched (with the sum of its nearest NIS), new,
  /// ambiguous.
  std::map<int, int> matched, added, ambiguous;
  std::map<int, double> matched_nis;
  /// One line per wrong match or duplicate between the times asked for.
  std::vector<std::string> events;
  /// One line per scan with a copy or a near miss between the times asked
  /// for: "scan t observed matched new unanchored copies near_misses
  /// position_error_m pose_nees".
  std::vector<std::string> scan_lines;
  /// Largest position error of the replayed filter (metres), per 50 s.
  std::map<int, double> max_error_m;
  /// Largest |x - recorded x| of the replayed filter (0: bit-identical).
  double max_replay_difference = 0.0;
  /// Time of the last recorded step.
  double end_t_s = 0.0;
  /// The run's innovation check (slam.innovation_check) on the replayed
  /// filter, as `mjslam run` reports it in summary.json.
  slam::InnovationCheckResult innovation;
  /// Totals over the run.
  int total_wrong_matches() const { return Total(wrong_matches); }
  int total_duplicates() const { return Total(duplicates); }

 private:
  static int Total(const std::map<int, int>& bins) {
    int total = 0;
    for (const auto& [bin, count] : bins) total += count;
    return total;
  }
};

namespace audit_detail {

// Whether the true lines a and b are one line (collinear wall pieces are one
// line feature to the filter).
inline bool SameLine(const MapFeature& a, const MapFeature& b) {
  return std::abs(a.params.x() - b.params.x()) < 0.02 &&
         std::abs(WrapAngle(a.params.y() - b.params.y())) < 0.01;
}

// The index of the true line that an observed line comes from: direction
// (alpha, in W) within 3 deg, the mid-point `mid` of its seen segment (in W)
// within 5 cm of the true line and within 0.5 m of the true segment's ends;
// the nearest such. -1: none. The distance is measured at the mid-point, not
// as a difference of rho: a short line tilted by its fit error by d alpha
// has its rho moved by about d alpha times its distance along the line from
// the foot of the origin's perpendicular (0.11 m for 1.3 deg at 5 m), which
// would pass it for the wall's other face 0.15 m away.
inline int TrueFace(const FeatureMap& truth, double alpha, const Eigen::Vector2d& mid) {
  int best = -1;
  double best_d = 0.05;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const MapFeature& f = truth[k];
    if (f.type != FeatureType::kLine) continue;
    const double turn = WrapAngle(alpha - f.params.y());
    if (std::abs(turn) > 3.0 * kPi / 180.0 && std::abs(WrapAngle(turn + kPi)) > 3.0 * kPi / 180.0) {
      continue;
    }
    const Eigen::Vector2d normal(std::cos(f.params.y()), std::sin(f.params.y()));
    const double d = std::abs(normal.dot(mid) - f.params.x());
    if (d >= best_d) continue;
    const Eigen::Vector2d ab = f.p_WB - f.p_WA;
    const double length = ab.norm();
    const double s = (mid - f.p_WA).dot(ab) / (length * length);
    if (s * length < -0.5 || (s - 1.0) * length > 0.5) continue;
    best = static_cast<int>(k);
    best_d = d;
  }
  return best;
}

// The record of recorded step i as the closed loop builds it in a replay
// (app/engine/closed_loop.cc, ReadRecording); `applied` is the command of step i-1.
inline SensorRecord RecordOf(const rundir::RecordedStep& step, const app::RunConfig& config,
                             std::size_t i, double previous_t, const Twist2& applied) {
  SensorRecord record;
  record.t_s = step.t_s;
  record.dt_s = i == 0 ? 0.0 : step.t_s - previous_t;
  record.command = applied;
  record.X_OR = step.X_WR_odometry;
  record.has_scan = step.scan_ranges_m != nullptr;
  if (record.has_scan) {
    LaserScan& scan = record.scan;
    scan.t_s = record.t_s;
    scan.angle_min_rad = config.laser.AngleMinRad();
    scan.angle_increment_rad = config.laser.AngleIncrementRad();
    scan.max_range_m = config.laser.max_range_m;
    scan.ranges_m = *step.scan_ranges_m;
    scan.has_return.resize(config.laser.num_beams);
    for (int b = 0; b < config.laser.num_beams; ++b) {
      scan.has_return[b] = scan.ranges_m[b] < scan.max_range_m ? 1 : 0;
    }
  }
  return record;
}

// The beams of observed line `observed`, grouped into runs by the true wall
// face each hits (the nearest true segment), one event line per run.
inline void DescribePoints(const FeatureMap& truth, const LaserScan& scan, const Pose2& X_WS,
                           const slam::LineObservation& observed, std::vector<std::string>* out) {
  int run_face = -2, run_first = 0, run_count = 0;
  double run_max_d = 0.0;
  char text[300];
  auto flush = [&](int last) {
    if (run_count == 0) return;
    if (run_face >= 0) {
      const MapFeature& f = truth[run_face];
      std::snprintf(text, sizeof(text),
                    "    beams %d-%d (%d points): true face %d (rho %.3f, alpha %.1f deg, "
                    "(%.3f, %.3f)-(%.3f, %.3f)), largest distance %.4f m",
                    run_first, last, run_count, run_face, f.params.x(), f.params.y() * 180.0 / kPi,
                    f.p_WA.x(), f.p_WA.y(), f.p_WB.x(), f.p_WB.y(), run_max_d);
    } else {
      std::snprintf(text, sizeof(text), "    beams %d-%d: no return", run_first, last);
    }
    out->emplace_back(text);
  };
  for (int b = observed.first_beam; b <= observed.last_beam; ++b) {
    int face = -1;
    double best = 1e9;
    if (scan.has_return[b]) {
      const double phi = scan.angle_min_rad + b * scan.angle_increment_rad;
      const Eigen::Vector2d p =
          X_WS * Eigen::Vector2d(scan.ranges_m[b] * std::cos(phi), scan.ranges_m[b] * std::sin(phi));
      for (std::size_t k = 0; k < truth.size(); ++k) {
        const MapFeature& f = truth[k];
        if (f.type != FeatureType::kLine) continue;
        const Eigen::Vector2d ab = f.p_WB - f.p_WA;
        const double s = std::clamp((p - f.p_WA).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
        const double d = (p - f.p_WA - s * ab).norm();
        if (d < best) {
          best = d;
          face = static_cast<int>(k);
        }
      }
    }
    if (face != run_face) {
      flush(b - 1);
      run_face = face;
      run_first = b;
      run_count = 0;
      run_max_d = 0.0;
    }
    ++run_count;
    run_max_d = std::max(run_max_d, best);
  }
  flush(observed.last_beam);
  const Eigen::Vector2d a = X_WS * observed.p_SA, b = X_WS * observed.p_SB;
  std::snprintf(text, sizeof(text), "    seen segment (%.3f, %.3f)-(%.3f, %.3f)", a.x(), a.y(),
                b.x(), b.y());
  out->emplace_back(text);
}

}  // namespace audit_detail

/// Audits filter `name` ("classical" or "selective") on run directory `dir`
/// (its config with `overrides`), listing events between t_from and t_to.
inline AssociationAudit AuditAssociations(const std::string& dir, const std::string& name,
                                          const std::vector<std::string>& overrides,
                                          double t_from = 0.0, double t_to = -1.0) {
  using audit_detail::SameLine;
  const app::RunConfig config = app::LoadRunConfig(dir + "/config.yaml", overrides);
  const rundir::Recording recording(dir + "/scans.csv", "", config.laser.num_beams);
  const FeatureMap truth = app::RunGroundTruth(dir);
  slam::EkfSlam filter(
      config.slam.ekf,
      name == "selective" ? slam::CorrectionMode::kSelective : slam::CorrectionMode::kClassical,
      recording.Step(0).X_WR_true, recording.X_RS(),
      Rng(config.run.seed).Fork("slam." + name + ".selection"));
  const rundir::CsvTable trajectory = rundir::ReadCsv(dir + "/trajectory.csv");
  const int recorded_x = trajectory.ColumnIndex(name + "_x");

  AssociationAudit audit;
  slam::InnovationCheck check(config.slam.innovation_check,
                              slam::ChiSquare2Quantile(config.slam.ekf.gate_probability));
  std::vector<int> birth_face;  // per map feature: the true line it was made from, -1 none
  std::vector<Eigen::Vector2d> birth_sensor;  // per map feature: the true sensor position then
  Twist2 applied;
  double previous_t = 0.0;
  char line[400];
  for (std::size_t i = 0; i < recording.num_steps(); ++i) {
    const rundir::RecordedStep step = recording.Step(i);
    const SensorRecord record = audit_detail::RecordOf(step, config, i, previous_t, applied);
    previous_t = step.t_s;
    applied = step.command;
    audit.end_t_s = step.t_s;
    slam::ScanFeatures features;
    if (record.has_scan) features = slam::ExtractFeatures(record.scan, config.slam.features);
    const int features_before = filter.num_features();
    const slam::StepReport report = filter.Step(record, record.has_scan ? &features : nullptr);
    check.Add(record.t_s, report.nis_sum, report.num_matched, report.num_observed,
              check.NearMisses(report.nearest_nis),
              check.Copies(report.association, report.nearest_nis));
    audit.innovation = check.result();
    audit.max_replay_difference = std::max(
        audit.max_replay_difference, std::abs(filter.X_WR().x - trajectory.rows[i][recorded_x]));
    if (!record.has_scan) continue;
    const Pose2 X_WS = step.X_WR_true * recording.X_RS();
    const Pose2 X_WR = filter.X_WR();
    const double error = std::hypot(X_WR.x - step.X_WR_true.x, X_WR.y - step.X_WR_true.y);
    const bool shown = step.t_s >= t_from && (t_to < 0.0 || step.t_s <= t_to);
    const int bin = static_cast<int>(step.t_s / 50.0);
    audit.max_error_m[bin] = std::max(audit.max_error_m[bin], error);
    {
      int copies = 0;
      int near = 0;
      for (int o = 0; o < report.num_observed; ++o) {
        const double nis = report.nearest_nis[o];
        const bool close = nis < config.slam.innovation_check.near_miss_max_nis;
        const slam::AssociationOutcome outcome = report.association.outcome[o];
        if (outcome == slam::AssociationOutcome::kNew && close) ++copies;
        if (outcome != slam::AssociationOutcome::kMatched && close &&
            nis >= slam::ChiSquare2Quantile(config.slam.ekf.gate_probability)) {
          ++near;
        }
      }
      if (shown && (copies > 0 || near > 0)) {
        const Eigen::Vector3d e(X_WR.x - step.X_WR_true.x, X_WR.y - step.X_WR_true.y,
                                WrapAngle(X_WR.theta - step.X_WR_true.theta));
        const double nees = e.dot(filter.pose_covariance().ldlt().solve(e));
        std::snprintf(line, sizeof(line), "scan %.1f %d %d %d %d %d %d %.4f %.1f", step.t_s,
                      report.num_observed, report.num_matched, report.num_new,
                      report.num_unanchored, copies, near, error, nees);
        audit.scan_lines.emplace_back(line);
      }
    }
    int added = 0;
    for (int o = 0; o < report.num_observed; ++o) {
      const slam::AssociationOutcome outcome = report.association.outcome[o];
      if (outcome == slam::AssociationOutcome::kMatched) {
        ++audit.matched[bin];
        audit.matched_nis[bin] += report.nearest_nis[o];
      } else if (outcome == slam::AssociationOutcome::kNew) {
        ++audit.added[bin];
      } else {
        ++audit.ambiguous[bin];
      }
      int face = -1;
      if (o < static_cast<int>(features.lines.size())) {
        const slam::LineObservation& observed = features.lines[o];
        face = audit_detail::TrueFace(truth, WrapAngle(observed.alpha_rad + X_WS.theta),
                                      X_WS * (0.5 * (observed.p_SA + observed.p_SB)));
      }
      if (outcome == slam::AssociationOutcome::kNew) {
        const int k = features_before + added++;
        birth_face.resize(k + 1, -1);
        birth_face[k] = face;
        birth_sensor.resize(k + 1, Eigen::Vector2d::Zero());
        birth_sensor[k] = Eigen::Vector2d(X_WS.x, X_WS.y);
        if (face < 0) continue;
        int same = 0;
        for (int j = 0; j < k; ++j) same += birth_face[j] >= 0 && SameLine(truth[birth_face[j]], truth[face]);
        if (same == 0) continue;
        ++audit.duplicates[bin];
        if (shown) {
          std::snprintf(line, sizeof(line),
                        "t=%.1f err=%.3f NEW line of true line %d: already %d feature(s) of it "
                        "(nearest NIS %.1f)",
                        step.t_s, error, face, same, report.nearest_nis[o]);
          audit.events.emplace_back(line);
        }
      } else if (outcome == slam::AssociationOutcome::kMatched && face >= 0) {
        const int k = report.association.feature[o];
        const int expected = k < static_cast<int>(birth_face.size()) ? birth_face[k] : -1;
        if (expected < 0 || SameLine(truth[expected], truth[face])) continue;
        ++audit.wrong_matches[bin];
        if (shown) {
          // The sensor's side of the feature's true line, then and now.
          const MapFeature& made = truth[expected];
          const Eigen::Vector2d n(std::cos(made.params.y()), std::sin(made.params.y()));
          const double side_then = made.params.x() - n.dot(birth_sensor[k]);
          const double side_now = made.params.x() - n.dot(Eigen::Vector2d(X_WS.x, X_WS.y));
          std::snprintf(line, sizeof(line),
                        "t=%.1f err=%.3f WRONG match: line of true face (rho %.3f, alpha %.1f deg) "
                        "-> feature %d made from (rho %.3f, alpha %.1f deg), NIS %.2f; sensor %.2f "
                        "from that line when it was made, %.2f now",
                        step.t_s, error, truth[face].params.x(),
                        truth[face].params.y() * 180.0 / kPi, k, made.params.x(),
                        made.params.y() * 180.0 / kPi, report.nearest_nis[o], side_then, side_now);
          audit.events.emplace_back(line);
          audit_detail::DescribePoints(truth, record.scan, X_WS, features.lines[o], &audit.events);
        }
      }
    }
  }
  return audit;
}

}  // namespace mjslam::testing
