// Diagnostic: replays a run directory's recorded scans and odometry through
// one filter (as `mjslam replay` does) and checks every association of a
// line observation against the world's true geometry: the true wall face an
// observed line comes from (found with the true laser pose) against the face
// of the observation that created the map feature it was matched to.
//
//   association_trace RUN_DIR [classical|selective] [T_FROM T_TO [KEY=VALUE ...]]
//
// (KEY=VALUE: config overrides for the filter, e.g. slam.ekf.gate_line_side=false.)
// Prints one line per wrong match (and per new feature created for a face
// that already has one) between T_FROM and T_TO, and a count per 50 s.
// Not part of the test suite: built on request (target association_trace).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "app/evaluate.h"
#include "app/run_config.h"
#include "common/angles.h"
#include "rundir/csv_reader.h"
#include "rundir/recording.h"
#include "slam/ekf_slam.h"
#include "slam/feature_extraction.h"

using namespace mjslam;

namespace {

// The index of the true line (in `truth`) that an observed line in W comes
// from: same direction within 3 deg, rho within 5 cm, its mid-point within
// 0.5 m of the true segment. -1: none.
int TrueFace(const eval::Map& truth, double rho, double alpha, const Eigen::Vector2d& mid) {
  if (rho < 0) {
    rho = -rho;
    alpha = WrapAngle(alpha + kPi);
  }
  int best = -1;
  double best_d = 0.05;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const MapFeature& f = truth[k];
    if (f.type != FeatureType::kLine) continue;
    if (std::abs(WrapAngle(alpha - f.params.y())) > 3.0 * kPi / 180.0) continue;
    const double d = std::abs(rho - f.params.x());
    if (d >= best_d) continue;
    const Eigen::Vector2d ab = f.p_WB - f.p_WA;
    const double s = (mid - f.p_WA).dot(ab) / ab.squaredNorm();
    const double length = ab.norm();
    if (s * length < -0.5 || (s - 1.0) * length > 0.5) continue;
    best = static_cast<int>(k);
    best_d = d;
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: association_trace RUN_DIR [classical|selective] [T_FROM T_TO [KEY=VALUE ...]]\n");
    return 2;
  }
  const std::string dir = argv[1];
  const bool selective = argc > 2 && std::string(argv[2]) == "selective";
  const double t_from = argc > 4 ? std::atof(argv[3]) : 0.0;
  const double t_to = argc > 4 ? std::atof(argv[4]) : 1e9;
  std::vector<std::string> overrides;
  for (int a = 5; a < argc; ++a) overrides.push_back(argv[a]);
  const app::RunConfig config = app::LoadRunConfig(dir + "/config.yaml", overrides);
  const rundir::Recording recording(dir + "/scans.csv", "", config.laser.num_beams);
  const eval::Map truth = app::RunGroundTruth(dir);
  const std::string name = selective ? "selective" : "classical";
  slam::EkfSlam filter(config.slam.ekf,
                       selective ? slam::CorrectionMode::kSelective : slam::CorrectionMode::kClassical,
                       recording.Step(0).X_WR_true, recording.X_RS(),
                       Rng(config.run.seed).Fork("slam." + name + ".selection"));
  const rundir::CsvTable trajectory = rundir::ReadCsv(dir + "/trajectory.csv");
  const int recorded_x = trajectory.ColumnIndex(name + "_x");

  std::vector<int> birth_face;  // per map feature: the true face it was created from
  std::map<int, int> wrong_per_bin, duplicate_per_bin, matched_per_bin, ambiguous_per_bin, new_per_bin;
  std::map<int, double> nis_per_bin;
  Twist2 applied;
  double previous_t = 0.0;
  double max_replay_difference = 0.0;
  for (std::size_t i = 0; i < recording.num_steps(); ++i) {
    const rundir::RecordedStep step = recording.Step(i);
    SensorRecord record;
    record.t_s = step.t_s;
    record.dt_s = i == 0 ? 0.0 : step.t_s - previous_t;
    previous_t = step.t_s;
    record.command = applied;
    applied = step.command;
    record.X_OR = step.X_WR_odometry;
    record.has_scan = step.scan_ranges_m != nullptr;
    slam::ScanFeatures features;
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
      features = slam::ExtractFeatures(scan, config.slam.features);
    }
    const int features_before = filter.num_features();
    const slam::StepReport report = filter.Step(record, record.has_scan ? &features : nullptr);
    max_replay_difference = std::max(
        max_replay_difference, std::abs(filter.X_WR().x - trajectory.rows[i][recorded_x]));
    if (!record.has_scan) continue;
    const Pose2 X_WS = step.X_WR_true * recording.X_RS();
    const Pose2 X_WR = filter.X_WR();
    const double error = std::hypot(X_WR.x - step.X_WR_true.x, X_WR.y - step.X_WR_true.y);
    int added = 0;
    for (int o = 0; o < report.num_observed; ++o) {
      const slam::AssociationOutcome outcome = report.association.outcome[o];
      int face = -1;
      if (o < static_cast<int>(features.lines.size())) {
        const slam::LineObservation& line = features.lines[o];
        const double alpha = WrapAngle(line.alpha_rad + X_WS.theta);
        const double rho = line.rho_m + X_WS.x * std::cos(alpha) + X_WS.y * std::sin(alpha);
        face = TrueFace(truth, rho, alpha, X_WS * (0.5 * (line.p_SA + line.p_SB)));
      }
      const bool shown = step.t_s >= t_from && step.t_s <= t_to;
      const int bin = static_cast<int>(step.t_s / 50.0);
      if (outcome == slam::AssociationOutcome::kMatched) {
        ++matched_per_bin[bin];
        nis_per_bin[bin] += report.nearest_nis[o];
      } else if (outcome == slam::AssociationOutcome::kNew) {
        ++new_per_bin[bin];
      } else {
        ++ambiguous_per_bin[bin];
      }
      if (outcome == slam::AssociationOutcome::kNew) {
        const int k = features_before + added++;
        birth_face.resize(k + 1, -1);
        birth_face[k] = face;
        if (face < 0) continue;
        int same = 0;
        for (int j = 0; j < k; ++j) same += birth_face[j] == face ? 1 : 0;
        if (same > 0) {
          ++duplicate_per_bin[bin];
          if (shown) {
            std::printf("t=%.1f err=%.3f NEW line obs %d of true face %d: already %d feature(s) of it "
                        "(nearest NIS %.1f)\n",
                        step.t_s, error, o, face, same, report.nearest_nis[o]);
          }
        }
      } else if (outcome == slam::AssociationOutcome::kMatched && face >= 0) {
        const int k = report.association.feature[o];
        const int expected = k < static_cast<int>(birth_face.size()) ? birth_face[k] : -1;
        if (expected >= 0 && expected != face) {
          ++wrong_per_bin[bin];
          if (shown) {
            const MapFeature& a = truth[face];
            const MapFeature& b = truth[expected];
            std::printf("t=%.1f err=%.3f WRONG match: line obs %d of true face %d (rho %.3f alpha "
                        "%.1f deg) -> feature %d born of face %d (rho %.3f alpha %.1f deg), NIS %.2f\n",
                        step.t_s, error, o, face, a.params.x(), a.params.y() * 180 / kPi, k,
                        expected, b.params.x(), b.params.y() * 180 / kPi, report.nearest_nis[o]);
          }
        }
      }
    }
  }
  std::printf("replay: largest |x - recorded %s_x| %.3g m\n", name.c_str(), max_replay_difference);
  std::printf("per 50 s: wrong line matches, new line features for faces already mapped; all "
              "observations matched (mean nearest NIS), new, ambiguous\n");
  for (int bin = 0; bin * 50.0 <= previous_t; ++bin) {
    std::printf("  %4d-%4d s: %4d %4d; %5d (%.2f) %4d %4d\n", bin * 50, bin * 50 + 50,
                wrong_per_bin[bin], duplicate_per_bin[bin], matched_per_bin[bin],
                nis_per_bin[bin] / std::max(matched_per_bin[bin], 1), new_per_bin[bin],
                ambiguous_per_bin[bin]);
  }
  return 0;
}
