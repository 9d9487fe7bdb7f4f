#include "app/jobs/observation_check.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/LU>

#include "common/angles.h"
#include "common/laser_scan.h"
#include "common/pose2.h"
#include "rundir/rows.h"
#include "slam/data_association.h"
#include "slam/feature_extraction.h"

namespace mjslam::app {
namespace {

// A matched observation's residual against its true line.
struct Residual {
  Eigen::Vector2d nu;
  Eigen::Matrix2d R_inverse;
  Eigen::Vector2d g;
};

// The true line of `truth` that the seen segment A-B lies on: both ends
// within max_distance_m of it and overlapping its true segment (0.1 m of
// slack for the seen ends' spacing); the nearest. Null when none is.
const MapFeature* TrueLineOf(const eval::Map& truth, const Eigen::Vector2d& A,
                             const Eigen::Vector2d& B, double max_distance_m) {
  const MapFeature* best = nullptr;
  double best_distance = max_distance_m;
  for (const MapFeature& f : truth) {
    if (f.type != FeatureType::kLine || !f.has_segment) continue;
    const Eigen::Vector2d n(std::cos(f.params.y()), std::sin(f.params.y()));
    const double distance =
        std::max(std::abs(A.dot(n) - f.params.x()), std::abs(B.dot(n) - f.params.x()));
    if (distance > best_distance) continue;
    const Eigen::Vector2d along = f.p_WB - f.p_WA;
    const double length = along.norm();
    if (length <= 0.0) continue;
    const Eigen::Vector2d u = along / length;
    const double sa = (A - f.p_WA).dot(u);
    const double sb = (B - f.p_WA).dot(u);
    const double gap = std::max(std::min(sa, sb) - length, -std::max(sa, sb));
    if (gap > 0.1) continue;
    best = &f;
    best_distance = distance;
  }
  return best;
}

}  // namespace

ObservationCheck CheckLineObservations(const std::string& scans_path, const RunConfig& config,
                                       const eval::Map& truth, double max_distance_m,
                                       double max_corner_distance_m) {
  const std::vector<rundir::ScanRow> scans = rundir::ReadScanRows(scans_path);
  const int num_beams = config.laser.num_beams;
  ObservationCheck check;
  check.seen.assign(truth.size(), 0);
  std::vector<int> true_corners;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    if (truth[k].type == FeatureType::kCorner) true_corners.push_back(static_cast<int>(k));
  }
  std::vector<Residual> residuals;
  LaserScan scan;
  scan.angle_min_rad = config.laser.AngleMinRad();
  scan.angle_increment_rad = config.laser.AngleIncrementRad();
  scan.max_range_m = config.laser.max_range_m;
  scan.has_return.resize(num_beams);
  for (const rundir::ScanRow& row : scans) {
    if (static_cast<int>(row.ranges_m.size()) != num_beams) {
      throw std::runtime_error(scans_path + ": " + std::to_string(row.ranges_m.size()) +
                               " ranges per row, the run's laser.num_beams is " +
                               std::to_string(num_beams));
    }
    if (std::isnan(row.X_WS.x)) {
      throw std::runtime_error(scans_path + ": no true laser pose (a real log has no true walls)");
    }
    scan.t_s = row.t_s;
    scan.ranges_m = row.ranges_m;
    for (int b = 0; b < num_beams; ++b) {
      scan.has_return[b] = scan.ranges_m[b] < scan.max_range_m ? 1 : 0;
    }
    const Pose2& X_WS = row.X_WS;
    const slam::ScanFeatures features = slam::ExtractFeatures(scan, config.slam.features);
    for (const slam::LineObservation& line : features.lines) {
      ++check.lines;
      const MapFeature* wall =
          TrueLineOf(truth, X_WS * line.p_SA, X_WS * line.p_SB, max_distance_m);
      if (wall == nullptr) continue;
      ++check.matched;
      check.seen[wall - truth.data()] = 1;
      // The true line seen from X_WS, in the observation's polar form.
      const double r = wall->params.x();
      const double alpha = wall->params.y();
      double rho = r - X_WS.x * std::cos(alpha) - X_WS.y * std::sin(alpha);
      double phi = alpha - X_WS.theta;
      if (rho < 0.0) {
        rho = -rho;
        phi += kPi;
      }
      Residual residual;
      residual.nu = Eigen::Vector2d(line.rho_m - rho, WrapAngle(line.alpha_rad - phi));
      residual.R_inverse = line.covariance.inverse();
      residual.g = line.range_bias_gradient;
      residuals.push_back(residual);
    }
    for (const slam::CornerObservation& corner : features.corners) {
      const Eigen::Vector2d p = X_WS * corner.p_SC;
      double best = max_corner_distance_m;
      int nearest = -1;
      for (const int k : true_corners) {
        const double distance = (truth[k].params - p).norm();
        if (distance <= best) {
          best = distance;
          nearest = k;
        }
      }
      if (nearest >= 0) check.seen[nearest] = 1;
    }
  }
  if (residuals.empty()) return check;
  double numerator = 0.0;
  double denominator = 0.0;
  for (const Residual& e : residuals) {
    numerator += e.g.dot(e.R_inverse * e.nu);
    denominator += e.g.dot(e.R_inverse * e.g);
  }
  check.range_bias_m = denominator > 0.0 ? numerator / denominator : 0.0;
  const double gate = slam::ChiSquare2Quantile(0.99);
  double sum = 0.0;
  int above = 0;
  check.max_nis = 0.0;
  for (const Residual& e : residuals) {
    const Eigen::Vector2d nu = e.nu - e.g * check.range_bias_m;
    const double nis = nu.dot(e.R_inverse * nu);
    sum += nis;
    if (nis > gate) ++above;
    check.max_nis = std::max(check.max_nis, nis);
  }
  check.mean_nis = sum / static_cast<double>(residuals.size());
  check.fraction_above_gate = static_cast<double>(above) / static_cast<double>(residuals.size());
  return check;
}

}  // namespace mjslam::app
