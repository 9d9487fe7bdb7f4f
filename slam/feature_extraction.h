#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/laser_scan.h"
#include "common/params.h"
#include "slam/observations.h"

namespace mjslam::slam {

/// Parameters of the line and corner extraction (slam/README.md, "Feature
/// extraction"). Serialized under `slam.features.*` in the run config.
struct FeatureExtractionParams {
  /// The filter's model of the beam range noise (one standard deviation),
  /// metres. The line and corner covariances are propagated from it. The
  /// simulated sensor's own noise is a separate key,
  /// `laser.range_noise_std_m` (same default): a model that differs from the
  /// truth is an experiment, and `mjslam run` prints a note when they differ.
  double range_noise_std_m = 0.005;
  /// The filter's model of the beam bearing noise (one standard deviation),
  /// degrees. 0 models a perfect beam direction (the emulated SICK).
  double bearing_noise_std_deg = 0.0;

  /// Consecutive returned beams whose points are farther apart than the
  /// adaptive breakpoint distance of Borges & Aldon (2004) start a new
  /// cluster: `r_near sin(dphi) / sin(lambda - dphi) + k * range_noise_std_m`,
  /// with `lambda` this angle (degrees): the most grazing angle between a beam
  /// and a wall at which the wall's points stay in one cluster.
  double break_min_incidence_deg = 10.0;
  /// `k` in the breakpoint distance above: noise margin in standard deviations.
  double break_noise_sigmas = 3.0;
  /// Consecutive no-return beams that a cluster may bridge (0: every
  /// no-return beam ends a cluster). The breakpoint distance still applies
  /// across the gap, with the gap's angle. Bridging keeps a wall whole when a
  /// few beams lose their echo (laser.dropout_probability in the simulator).
  int max_missing_beams = 2;

  /// Split-and-merge: a run of points is split at its point farthest from the
  /// chord between its ends when that point is farther than this, metres; two
  /// neighbouring runs are merged when every point of their union lies within
  /// this distance of the union's fitted line. At least 3 range noise
  /// deviations (noise alone would split walls); 6 or more is better.
  double split_distance_m = 0.03;
  /// The fit test after split-and-merge: a run whose points fit their line
  /// worse than this quantile of chi-square (points - 2 dof, residuals in
  /// standard deviations of the noise model above) is split where two lines
  /// fit best. A step of a few centimetres between parallel walls passes the
  /// chord test of `split_distance_m` and would become one tilted line with
  /// a covariance far too small. In [0, 1); 0 turns the test off.
  double fit_test_probability = 0.99999;
  /// An end point of a line whose distance to the fitted line exceeds this
  /// many standard deviations of its perpendicular noise is dropped (and the
  /// line refitted); so is an end point next to a neighbouring line that is
  /// within this many standard deviations of that line too (ambiguous).
  double outlier_gate_sigmas = 3.0;
  /// A line needs at least this many points (>= 2).
  int min_points = 6;
  /// A line's seen segment must be at least this long, metres.
  double min_length_m = 0.25;

  /// Model-error floor added to each line's (rho, alpha) variances, one
  /// standard deviation each: walls are not perfectly straight in real life.
  /// In the simulator they are exact planes, so the defaults are small.
  double line_rho_floor_std_m = 0.0001;
  /// See `line_rho_floor_std_m`; degrees.
  double line_alpha_floor_std_deg = 0.0025;

  /// Two neighbouring lines of one cluster meet at a corner only when the
  /// acute angle between them is at least this, degrees (in (0, 90]).
  double corner_min_angle_deg = 30.0;
  /// ... and when each line's seen segment stops short of the intersection
  /// point by at most this distance, metres, plus `corner_endpoint_spacings`
  /// times the spacing of that line's last two points (beams spread with range
  /// and incidence, and the points next to the vertex may have been dropped),
  /// and runs past it by at most this distance (a wall that runs past the
  /// intersection continues behind an occluder: no vertex).
  double corner_max_endpoint_distance_m = 0.05;
  /// See `corner_max_endpoint_distance_m`; a count of point spacings (>= 0).
  double corner_endpoint_spacings = 3.0;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(range_noise_std_m));
    a->Visit(MJSLAM_NVP(bearing_noise_std_deg));
    a->Visit(MJSLAM_NVP(break_min_incidence_deg));
    a->Visit(MJSLAM_NVP(break_noise_sigmas));
    a->Visit(MJSLAM_NVP(max_missing_beams));
    a->Visit(MJSLAM_NVP(split_distance_m));
    a->Visit(MJSLAM_NVP(fit_test_probability));
    a->Visit(MJSLAM_NVP(outlier_gate_sigmas));
    a->Visit(MJSLAM_NVP(min_points));
    a->Visit(MJSLAM_NVP(min_length_m));
    a->Visit(MJSLAM_NVP(line_rho_floor_std_m));
    a->Visit(MJSLAM_NVP(line_alpha_floor_std_deg));
    a->Visit(MJSLAM_NVP(corner_min_angle_deg));
    a->Visit(MJSLAM_NVP(corner_max_endpoint_distance_m));
    a->Visit(MJSLAM_NVP(corner_endpoint_spacings));
  }

  /// Every out-of-range field, with keys relative to this struct.
  std::vector<ParamProblem> Validate() const;
  /// Throws ParamError listing every problem of Validate().
  void ValidateOrThrow() const { ThrowIfProblems(Validate()); }
};

/// Extracts lines and corners from one scan, in the scan's sensor frame S.
///
/// Lines: clusters of returned beams (Borges & Aldon 2004 breakpoints),
/// split-and-merge on each cluster (Nguyen et al. 2005), and a weighted
/// total-least-squares fit in polar form with its (rho, alpha) covariance
/// propagated from the beam noise (Pfister et al. 2003; Arras & Siegwart 1997).
/// Each beam point belongs to at most one line, so lines are independent.
/// Corners: two neighbouring lines of one cluster, at a large enough angle,
/// whose seen segments both end near their intersection, neither running past
/// it, with no point between them behind their lines (so not an occlusion
/// edge); covariance propagated from the two lines. Details and departures
/// from the sources: slam/README.md.
///
/// Lines are ordered by first beam; corners by the lines they join. Pure: no
/// state, no randomness. Never throws because of the scan: an empty scan, an
/// all-no-return scan, ranges that are not finite or outside (1 mm, 10 km)
/// (dropped), a zero or non-finite beam increment, or a `has_return` shorter
/// than `ranges_m` (missing entries are no-return) give fewer or no features.
/// A negative beam increment (a clockwise scan) is fine.
/// Throws ParamError if `params` is invalid.
ScanFeatures ExtractFeatures(const LaserScan& scan,
                             const FeatureExtractionParams& params);

/// Building blocks of ExtractFeatures, exposed for the filter and for tests.

/// The intersection point p_SC of two polar lines `line = (rho, alpha)`
/// (x cos alpha + y sin alpha = rho), metres. If `J` is not null it receives
/// d p_SC / d (rho_a, alpha_a, rho_b, alpha_b). Precondition: the lines are
/// not parallel (|sin(alpha_b - alpha_a)| > 0); checked.
Eigen::Vector2d IntersectLines(const Eigen::Vector2d& line_a,
                               const Eigen::Vector2d& line_b,
                               Eigen::Matrix<double, 2, 4>* J = nullptr);

/// A point p_SC in S as (range, bearing) = (|p|, atan2(y, x)), metres and
/// radians, the bearing in (-pi, pi]. If `J` is not null it receives d(range, bearing)/d(x, y).
/// Precondition: p_SC is not the origin; checked.
Eigen::Vector2d PointToRangeBearing(const Eigen::Vector2d& p_SC,
                                    Eigen::Matrix2d* J = nullptr);

}  // namespace mjslam::slam
