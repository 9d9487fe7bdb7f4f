#pragma once

// The stages of ExtractFeatures (slam/README.md, "Feature extraction",
// steps 1-8, cited as "step N" below), in pipeline order, with the types
// they pass along. Exposed so
// that each stage is tested on its own (tests/slam/feature_extraction_stages_test.cc);
// the filter and the application use ExtractFeatures only.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/laser_scan.h"
#include "slam/feature_extraction.h"
#include "slam/observations.h"

namespace mjslam::slam::extraction {

/// One returned beam as a point in S, metres; `beam` is its index in the scan.
struct ScanPoint {
  double x = 0.0;
  double y = 0.0;
  double range = 0.0;
  double inverse_range2 = 0.0;  ///< 1 / range^2, 1/m^2
  int beam = 0;
};

/// The beam noise model in the units the fit needs.
struct NoiseModel {
  double range_var = 0.0;              ///< m^2
  double bearing_var = 0.0;            ///< rad^2
  double min_perpendicular_var = 0.0;  ///< floor of a point's perpendicular variance, m^2
};

/// A polar line `x cos(alpha) + y sin(alpha) = rho` fitted to a run of points.
struct LineFit {
  double rho = 0.0;    ///< metres, >= 0
  double alpha = 0.0;  ///< radians, in (-pi, pi]
  double cos_alpha = 1.0;  ///< cos(alpha), kept for the residuals
  double sin_alpha = 0.0;  ///< sin(alpha)
  /// Covariance of (rho, alpha) from the beam noise alone (no floors).
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  /// False when the points define no line (too few, or degenerate).
  bool ok = false;
};

/// A run of points [first, last] (indices into the point array) that becomes
/// a line if it survives the checks.
struct Segment {
  int first = 0;
  int last = 0;  ///< inclusive
  /// Index of the cluster the run belongs to (into the FindClusters result).
  int cluster = 0;
  /// Whether the run is (still) a line candidate; `fit` is its line.
  bool valid = true;
  LineFit fit;
  /// Number of points.
  int Count() const { return last - first + 1; }
};

/// First and last point (inclusive, indices into the point array) of a cluster.
struct ClusterBounds {
  int first = 0;
  int last = 0;
};

/// The beam noise model of `params`: range and bearing variances, and the
/// floor (0.1 sigma_r)^2 of a point's perpendicular variance.
NoiseModel MakeNoiseModel(const FeatureExtractionParams& params);

/// Variance of a point's distance to the line with unit normal (cos_alpha,
/// sin_alpha), m^2 (Pfister et al. 2003, Eq. 7, to first order), floored at
/// `noise.min_perpendicular_var`.
double PerpendicularVariance(const ScanPoint& p, double cos_alpha, double sin_alpha,
                             const NoiseModel& noise);

/// Weighted total-least-squares fit of points [first, last] with its (rho,
/// alpha) covariance (slam/README.md, step 6). With `prior` (the fit of
/// nearly the same points), one reweighted pass from its angle instead of an
/// unweighted fit and two passes. `ok` is false for fewer than 2 points or
/// degenerate ones.
LineFit FitLine(const std::vector<ScanPoint>& points, int first, int last,
                const NoiseModel& noise, const LineFit* prior = nullptr);

/// Points (README step 1): the returned beams of `scan` as points in S, in beam
/// order. No-return beams (also those past the end of `has_return`) and
/// ranges that are not in (1 mm, 10 km) are dropped. Precondition: the
/// increment and `angle_min_rad` are finite (ExtractFeatures checks).
std::vector<ScanPoint> ScanPoints(const LaserScan& scan);

/// Clusters (step 2): consecutive points stay in one cluster while they are
/// within the adaptive breakpoint distance (Borges & Aldon 2004) and at most
/// `max_missing_beams` beams are missing between them; `increment_rad` is the
/// scan's beam increment. Clusters of fewer than `min_points` points are left
/// out; the others are returned in order.
std::vector<ClusterBounds> FindClusters(const std::vector<ScanPoint>& points,
                                        double increment_rad,
                                        const FeatureExtractionParams& params);

/// Split (step 3): each cluster is split recursively at its point farthest
/// from the chord between its ends while that point is farther than
/// `split_distance_m` (iterative end-point fit). Neighbouring runs share their
/// split point. Returns the runs of all clusters in order, `cluster` set to
/// the cluster's index in `clusters`, not yet fitted.
std::vector<Segment> SplitClusters(const std::vector<ScanPoint>& points,
                                   const std::vector<ClusterBounds>& clusters,
                                   double split_distance_m);

/// Merge (step 4): neighbouring runs of one cluster that share their boundary
/// point and whose union's fitted line lies within `split_distance_m` of all
/// its points become one run, the straightest union first.
void MergeRuns(const std::vector<ScanPoint>& points, const NoiseModel& noise,
               double split_distance_m, std::vector<Segment>* runs);

/// Fit test (step 4b): a run whose points do not fit one line, whose sum of
/// squared normalised residuals about its weighted fit (end points left out:
/// a shared split point may lie on the other wall) exceeds the
/// `probability` quantile of chi-square with (those points - 2) dof, is split at
/// the point where two total-least-squares lines over its two parts (sharing
/// that point, as a split does) leave the smallest sum of squared distances;
/// each part is tested again. Catches a step between parallel walls a few
/// centimetres apart that the chord test of the split misses and the merge
/// joins. `probability` 0 leaves the runs as they are.
void SplitInconsistentRuns(const std::vector<ScanPoint>& points, const NoiseModel& noise,
                           double probability, std::vector<Segment>* runs);

/// Vertex points (step 5): a point shared by two neighbouring runs of one
/// cluster (a split point, nearest the vertex) is taken from both. Returns,
/// per point of the `point_count`, 1 for such a vertex point, else 0.
std::vector<char> SeparateVertexPoints(int point_count, std::vector<Segment>* runs);

/// Fit (steps 5-6): every run with at least `min_points` points gets its line
/// fit; `valid` says whether it has one.
void FitRuns(const std::vector<ScanPoint>& points, const NoiseModel& noise, int min_points,
             std::vector<Segment>* runs);

/// Trim (step 5): while the first or last point of a valid run is an outlier
/// of its line (more than `outlier_gate_sigmas` deviations) or within the gate
/// of the neighbouring valid run of its cluster too (ambiguous), it is
/// dropped and the run refitted; a run left with fewer than `min_points`
/// points becomes invalid.
void TrimRuns(const std::vector<ScanPoint>& points, const NoiseModel& noise,
              const FeatureExtractionParams& params, std::vector<Segment>* runs);

/// Grow (step 5): each valid run grows at both ends into the points between
/// it and its valid neighbour (or its cluster's end) that fit its line within
/// the gate and do not fit the neighbour's, never into a vertex point
/// (`is_vertex` from SeparateVertexPoints); refitted after each point.
void GrowRuns(const std::vector<ScanPoint>& points, const NoiseModel& noise,
              const FeatureExtractionParams& params, const std::vector<ClusterBounds>& clusters,
              const std::vector<char>& is_vertex, std::vector<Segment>* runs);

/// Keep lines (step 7): each valid run whose seen segment is at least
/// `min_length_m` long becomes a line (with the model-error floor on its
/// covariance); the others become invalid. `line_of_run` receives, per run,
/// the index of its line or -1.
std::vector<LineObservation> KeepLines(const std::vector<ScanPoint>& points,
                                       const FeatureExtractionParams& params,
                                       std::vector<Segment>* runs, std::vector<int>* line_of_run);

/// The corner where the lines of two consecutive valid runs of one cluster
/// meet (`run_a` before `run_b` in the scan, `line_a`, `line_b` their lines),
/// or nothing when they fail a test of slam/README.md step 8. `increment_rad`
/// is the scan's beam increment (its sign is the scan's turn). The corner's
/// `line_a` and `line_b` indices are left at -1.
std::optional<CornerObservation> CornerBetween(const std::vector<ScanPoint>& points,
                                               const NoiseModel& noise,
                                               const FeatureExtractionParams& params,
                                               double increment_rad, const Segment& run_a,
                                               const Segment& run_b,
                                               const LineObservation& line_a,
                                               const LineObservation& line_b);

/// Corners (step 8): CornerBetween for every two consecutive valid runs of
/// one cluster, in order, with the indices of their lines into `lines`.
std::vector<CornerObservation> FindCorners(const std::vector<ScanPoint>& points,
                                           const NoiseModel& noise,
                                           const FeatureExtractionParams& params,
                                           double increment_rad,
                                           const std::vector<Segment>& runs,
                                           const std::vector<int>& line_of_run,
                                           const std::vector<LineObservation>& lines);

}  // namespace mjslam::slam::extraction
