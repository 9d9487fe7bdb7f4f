// Diagnostic: the extractor's lines and corners against the world's true
// walls and corners seen from the true laser pose, normalised by the
// extractor's covariance R (plus the filter's extra noise,
// slam.ekf.extra_*). For every scan of the run directories given it extracts
// the features (as the filter does), finds each line's true wall face
// (tests/tools/association_audit.h, TrueFace) and each corner's true corner
// (the nearest within 0.1 m), and prints, pooled over the runs:
//   - per kind, and per bin of range, incidence and number of points: the
//     count and the mean of e' R^-1 e (2 when R is right) and of each
//     component's (e / sigma)^2 (1 when right);
//   - per kind and component: the correlation of (e / sigma) of one true
//     feature between scans k apart while it is seen (k = 1 .. 50), and the
//     variance of the sum of L consecutive scans' (e / sigma) over L times
//     the variance of one (1 for independent errors; the factor by which L
//     scans' information is overcounted).
//
//   feature_errors [KEY=VALUE ...] RUN_DIR [RUN_DIR ...]
//
// KEY=VALUE: config overrides, e.g. slam.ekf.extra_line_alpha_std_rad=0.002.
// Not part of the test suite: built on request (target feature_errors).
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "tests/tools/association_audit.h"

namespace {

using namespace mjslam;

// Sums of one bin: count, sum of e'R^-1 e, of each component's (e/sigma)^2.
struct Bin {
  long count = 0;
  double nees = 0.0;
  std::array<double, 2> z2 = {0.0, 0.0};
  void Add(double nees_value, const Eigen::Vector2d& z) {
    ++count;
    nees += nees_value;
    z2[0] += z[0] * z[0];
    z2[1] += z[1] * z[1];
  }
};

// One kind's figures (lines or corners).
struct KindStats {
  Bin all;
  std::map<std::string, Bin> bins;
  long unmatched = 0;
  // Per (run, true feature): scan index -> (e / sigma) per component.
  std::map<std::pair<int, int>, std::map<int, Eigen::Vector2d>> tracks;
};

constexpr int kMaxLag = 50;

void PrintBin(const std::string& name, const Bin& bin) {
  if (bin.count == 0) return;
  std::printf("  %-26s %7ld  %7.3f  %7.3f  %7.3f\n", name.c_str(), bin.count,
              bin.nees / bin.count, bin.z2[0] / bin.count, bin.z2[1] / bin.count);
}

void PrintCorrelation(const char* kind, const char* names[2], const KindStats& stats) {
  const int lags[] = {1, 2, 5, 10, 20, 50};
  const int lengths[] = {1, 5, 10, 20, 50};
  for (int c = 0; c < 2; ++c) {
    // Mean of z over all tracked scans (the correlation is of z - mean).
    double sum = 0.0, sum2 = 0.0;
    long n = 0;
    for (const auto& [key, track] : stats.tracks) {
      for (const auto& [scan, z] : track) {
        sum += z[c];
        sum2 += z[c] * z[c];
        ++n;
      }
    }
    if (n == 0) continue;
    const double mean = sum / n;
    const double var = sum2 / n - mean * mean;
    std::printf("%s %s: mean e/sigma %+.3f, variance %.3f; correlation at lag", kind, names[c],
                mean, var);
    for (int lag : lags) {
      double cov = 0.0;
      long pairs = 0;
      for (const auto& [key, track] : stats.tracks) {
        for (const auto& [scan, z] : track) {
          const auto later = track.find(scan + lag);
          if (later == track.end()) continue;
          cov += (z[c] - mean) * (later->second[c] - mean);
          ++pairs;
        }
      }
      std::printf("  %d: %.2f (%ld)", lag, pairs > 0 ? cov / pairs / var : 0.0, pairs);
    }
    std::printf("\n%s %s: var(sum of L scans) / (L var) for L", kind, names[c]);
    for (int length : lengths) {
      // Non-overlapping windows of L consecutive scans of one track.
      double total = 0.0;
      long windows = 0;
      for (const auto& [key, track] : stats.tracks) {
        auto it = track.begin();
        while (it != track.end()) {
          double window_sum = 0.0;
          int taken = 0;
          int expected = it->first;
          auto cursor = it;
          while (cursor != track.end() && cursor->first == expected && taken < length) {
            window_sum += cursor->second[c] - mean;
            ++taken;
            ++expected;
            ++cursor;
          }
          if (taken == length) {
            total += window_sum * window_sum / length;
            ++windows;
            it = cursor;
          } else {
            it = cursor == it ? std::next(it) : cursor;
          }
        }
      }
      std::printf("  %d: %.2f (%ld)", length, windows > 0 ? total / windows / var : 0.0, windows);
    }
    std::printf("\n");
  }
}

std::string RangeBin(double range) {
  static const double edges[] = {1.0, 2.0, 4.0, 8.0};
  static const char* names[] = {"range < 1 m", "range 1-2 m", "range 2-4 m", "range 4-8 m",
                                "range >= 8 m"};
  int i = 0;
  while (i < 4 && range >= edges[i]) ++i;
  return names[i];
}

std::string IncidenceBin(double incidence_deg) {
  if (incidence_deg < 30.0) return "incidence < 30 deg";
  if (incidence_deg < 60.0) return "incidence 30-60 deg";
  return "incidence >= 60 deg";
}

std::string PointsBin(int points) {
  if (points < 20) return "points < 20";
  if (points < 50) return "points 20-49";
  if (points < 150) return "points 50-149";
  return "points >= 150";
}

// Adds run `run` (directory `dir`) to the line and corner statistics.
void AddRun(int run, const std::string& dir, const std::vector<std::string>& overrides,
            KindStats* lines, KindStats* corners) {
  const app::RunConfig config = app::LoadRunConfig(dir + "/config.yaml", overrides);
  const rundir::Recording recording(dir + "/scans.csv", "", config.laser.num_beams);
  const FeatureMap truth = app::RunGroundTruth(dir);
  const slam::EkfParams& ekf = config.slam.ekf;
  const Eigen::Matrix2d extra_line =
      Eigen::Vector2d(ekf.extra_line_rho_std_m * ekf.extra_line_rho_std_m,
                      ekf.extra_line_alpha_std_rad * ekf.extra_line_alpha_std_rad)
          .asDiagonal();
  const Eigen::Matrix2d extra_corner =
      Eigen::Vector2d(ekf.extra_corner_range_std_m * ekf.extra_corner_range_std_m,
                      ekf.extra_corner_bearing_std_rad * ekf.extra_corner_bearing_std_rad)
          .asDiagonal();
  Twist2 applied;
  double previous_t = 0.0;
  int scan_index = 0;
  for (std::size_t i = 0; i < recording.num_steps(); ++i) {
    const rundir::RecordedStep step = recording.Step(i);
    const SensorRecord record = testing::audit_detail::RecordOf(step, config, i, previous_t, applied);
    previous_t = step.t_s;
    applied = step.command;
    if (!record.has_scan) continue;
    ++scan_index;
    const slam::ScanFeatures features = slam::ExtractFeatures(record.scan, config.slam.features);
    const Pose2 X_WS = step.X_WR_true * recording.X_RS();
    for (const slam::LineObservation& observed : features.lines) {
      const Eigen::Vector2d mid_S = 0.5 * (observed.p_SA + observed.p_SB);
      const int face = testing::audit_detail::TrueFace(truth, WrapAngle(observed.alpha_rad + X_WS.theta),
                                              X_WS * mid_S);
      if (face < 0) {
        ++lines->unmatched;
        continue;
      }
      // The true line in S, canonical (rho >= 0).
      const MapFeature& f = truth[face];
      const double alpha_W = f.params.y();
      double rho = f.params.x() - (X_WS.x * std::cos(alpha_W) + X_WS.y * std::sin(alpha_W));
      double alpha = alpha_W - X_WS.theta;
      if (rho < 0.0) {
        rho = -rho;
        alpha += kPi;
      }
      const Eigen::Vector2d e(observed.rho_m - rho, WrapAngle(observed.alpha_rad - alpha));
      const Eigen::Matrix2d R = observed.covariance + extra_line;
      const double nees = e.dot(R.ldlt().solve(e));
      const Eigen::Vector2d z(e[0] / std::sqrt(R(0, 0)), e[1] / std::sqrt(R(1, 1)));
      const double incidence =
          std::abs(WrapAngle(std::atan2(mid_S.y(), mid_S.x()) - observed.alpha_rad)) * 180.0 / kPi;
      lines->all.Add(nees, z);
      lines->bins[RangeBin(mid_S.norm())].Add(nees, z);
      lines->bins[IncidenceBin(incidence)].Add(nees, z);
      lines->bins[PointsBin(observed.last_beam - observed.first_beam + 1)].Add(nees, z);
      lines->tracks[{run, face}][scan_index] = z;
    }
    for (const slam::CornerObservation& observed : features.corners) {
      const Eigen::Vector2d p_W = X_WS * observed.p_SC;
      int best = -1;
      double best_d = 0.1;
      for (std::size_t k = 0; k < truth.size(); ++k) {
        if (truth[k].type != FeatureType::kCorner) continue;
        const double d = (truth[k].params - p_W).norm();
        if (d < best_d) {
          best_d = d;
          best = static_cast<int>(k);
        }
      }
      if (best < 0) {
        ++corners->unmatched;
        continue;
      }
      const Eigen::Vector2d p_S = X_WS.Inverse() * Eigen::Vector2d(truth[best].params);
      const Eigen::Vector2d e(observed.range_m - p_S.norm(),
                              WrapAngle(observed.bearing_rad - std::atan2(p_S.y(), p_S.x())));
      const Eigen::Matrix2d R = observed.covariance + extra_corner;
      const double nees = e.dot(R.ldlt().solve(e));
      const Eigen::Vector2d z(e[0] / std::sqrt(R(0, 0)), e[1] / std::sqrt(R(1, 1)));
      corners->all.Add(nees, z);
      corners->bins[RangeBin(p_S.norm())].Add(nees, z);
      corners->bins[observed.kind == slam::CornerKind::kConvex ? "convex" : "concave"].Add(nees,
                                                                                          z);
      corners->tracks[{run, best}][scan_index] = z;
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> overrides;
  std::vector<std::string> dirs;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    (arg.find('=') != std::string::npos ? overrides : dirs).push_back(arg);
  }
  if (dirs.empty()) {
    std::fprintf(stderr, "usage: feature_errors [KEY=VALUE ...] RUN_DIR [RUN_DIR ...]\n");
    return 2;
  }
  KindStats lines, corners;
  try {
    for (std::size_t r = 0; r < dirs.size(); ++r) {
      AddRun(static_cast<int>(r), dirs[r], overrides, &lines, &corners);
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "feature_errors: %s\n", error.what());
    return 1;
  }
  std::printf("%zu runs. Per bin: count, mean e'R^-1 e (2 dof), mean (e/sigma)^2 of each "
              "component (1)\n",
              dirs.size());
  const char* line_names[2] = {"rho", "alpha"};
  const char* corner_names[2] = {"range", "bearing"};
  std::printf("lines (rho, alpha), %ld without a true face:\n", lines.unmatched);
  PrintBin("all", lines.all);
  for (const auto& [name, bin] : lines.bins) PrintBin(name, bin);
  std::printf("corners (range, bearing), %ld without a true corner:\n", corners.unmatched);
  PrintBin("all", corners.all);
  for (const auto& [name, bin] : corners.bins) PrintBin(name, bin);
  PrintCorrelation("line", line_names, lines);
  PrintCorrelation("corner", corner_names, corners);
  return 0;
}
