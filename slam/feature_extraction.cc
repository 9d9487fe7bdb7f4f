#include "slam/feature_extraction.h"

#include <cmath>
#include <string_view>
#include <vector>

#include "common/angles.h"
#include "common/check.h"
#include "slam/feature_extraction_stages.h"

namespace mjslam::slam {

std::vector<ParamProblem> FeatureExtractionParams::Validate() const {
  ParamChecker check;
  const auto finite_positive = [&check](std::string_view key, double value) {
    check.Require(std::isfinite(value) && value > 0.0, key, value, "a finite value > 0");
  };
  const auto finite_non_negative = [&check](std::string_view key, double value) {
    check.Require(std::isfinite(value) && value >= 0.0, key, value, "a finite value >= 0");
  };
  finite_positive("range_noise_std_m", range_noise_std_m);
  finite_non_negative("bearing_noise_std_deg", bearing_noise_std_deg);
  check.Require(break_min_incidence_deg > 0.0 && break_min_incidence_deg <= 90.0,
                "break_min_incidence_deg", break_min_incidence_deg, "a value in (0, 90]");
  finite_non_negative("break_noise_sigmas", break_noise_sigmas);
  check.NonNegative("max_missing_beams", max_missing_beams);
  finite_positive("split_distance_m", split_distance_m);
  // Below a few noise deviations, noise alone splits walls into short pieces.
  check.Require(!(split_distance_m < 3.0 * range_noise_std_m), "split_distance_m",
                split_distance_m, "a value >= 3 * range_noise_std_m");
  check.Require(fit_test_probability >= 0.0 && fit_test_probability < 1.0, "fit_test_probability",
                fit_test_probability, "a value in [0, 1)");
  finite_positive("outlier_gate_sigmas", outlier_gate_sigmas);
  check.Require(min_points >= 2, "min_points", min_points, "a value >= 2");
  finite_non_negative("min_length_m", min_length_m);
  finite_non_negative("line_rho_floor_std_m", line_rho_floor_std_m);
  finite_non_negative("line_alpha_floor_std_deg", line_alpha_floor_std_deg);
  check.Require(corner_min_angle_deg > 0.0 && corner_min_angle_deg <= 90.0,
                "corner_min_angle_deg", corner_min_angle_deg, "a value in (0, 90]");
  finite_non_negative("corner_max_endpoint_distance_m", corner_max_endpoint_distance_m);
  finite_non_negative("corner_endpoint_spacings", corner_endpoint_spacings);
  return check.problems();
}

Eigen::Vector2d IntersectLines(const Eigen::Vector2d& line_a, const Eigen::Vector2d& line_b,
                               Eigen::Matrix<double, 2, 4>* J) {
  // Solve N p = rho with the unit normals as the rows of N.
  const double ca = std::cos(line_a.y());
  const double sa = std::sin(line_a.y());
  const double cb = std::cos(line_b.y());
  const double sb = std::sin(line_b.y());
  const double det = ca * sb - sa * cb;  // sin(alpha_b - alpha_a)
  MJSLAM_CHECK(std::abs(det) > 0.0);
  Eigen::Matrix2d N_inverse;
  N_inverse << sb / det, -sa / det, -cb / det, ca / det;
  const Eigen::Vector2d p = N_inverse * Eigen::Vector2d(line_a.x(), line_b.x());
  if (J != nullptr) {
    // n_k . dp = d rho_k - t_k d alpha_k, with t_k = p . (-sin alpha_k, cos alpha_k).
    const double ta = -p.x() * sa + p.y() * ca;
    const double tb = -p.x() * sb + p.y() * cb;
    Eigen::Matrix<double, 2, 4> D;
    D << 1.0, -ta, 0.0, 0.0, 0.0, 0.0, 1.0, -tb;
    *J = N_inverse * D;
  }
  return p;
}

Eigen::Vector2d PointToRangeBearing(const Eigen::Vector2d& p_SC, Eigen::Matrix2d* J) {
  const double range2 = p_SC.squaredNorm();
  MJSLAM_CHECK(range2 > 0.0);
  const double range = std::sqrt(range2);
  if (J != nullptr) {
    *J << p_SC.x() / range, p_SC.y() / range, -p_SC.y() / range2, p_SC.x() / range2;
  }
  return {range, WrapAngle(std::atan2(p_SC.y(), p_SC.x()))};  // atan2 may give -pi
}

ScanFeatures ExtractFeatures(const LaserScan& scan, const FeatureExtractionParams& params) {
  using namespace extraction;  // the stages, slam/feature_extraction_stages.h
  params.ValidateOrThrow();
  ScanFeatures features;
  const double increment = scan.angle_increment_rad;
  if (scan.ranges_m.empty() || !std::isfinite(increment) || increment == 0.0 ||
      !std::isfinite(scan.angle_min_rad)) {
    return features;
  }
  const NoiseModel noise = MakeNoiseModel(params);

  // Returned beams as points in S, their clusters, and the clusters' runs
  // after split-and-merge.
  const std::vector<ScanPoint> points = ScanPoints(scan);
  const int point_count = static_cast<int>(points.size());
  if (point_count < params.min_points) return features;
  const std::vector<ClusterBounds> clusters = FindClusters(points, increment, params);
  std::vector<Segment> runs = SplitClusters(points, clusters, params.split_distance_m);
  MergeRuns(points, noise, params.split_distance_m, &runs);
  SplitInconsistentRuns(points, noise, params.fit_test_probability, &runs);

  // Points to lines: vertex points to none, a first fit, then trimmed and
  // grown ends.
  const std::vector<char> is_vertex = SeparateVertexPoints(point_count, &runs);
  FitRuns(points, noise, params.min_points, &runs);
  TrimRuns(points, noise, params, &runs);
  GrowRuns(points, noise, params, clusters, is_vertex, &runs);

  // The lines that are long enough, and the corners between them.
  std::vector<int> line_of_run;
  features.lines = KeepLines(points, params, &runs, &line_of_run);
  features.corners =
      FindCorners(points, noise, params, increment, runs, line_of_run, features.lines);
  return features;
}

}  // namespace mjslam::slam
