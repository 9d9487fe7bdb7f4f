#include "slam/feature_extraction.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string_view>

#include "common/angles.h"
#include "common/check.h"

namespace mjslam::slam {
namespace {

// Added to the diagonal of every output covariance (m^2, rad^2) so that it
// stays positive definite even with zero floors: 1e-6 m or rad std, far below
// any fitted uncertainty.
constexpr double kCovarianceFloor = 1e-12;
// The perpendicular noise of a point never drops below this fraction of the
// range noise (a beam at more than ~84 deg incidence gets no more weight than
// one at 84 deg); see PerpendicularVariance.
constexpr double kMinPerpendicularNoiseFraction = 0.1;
// Reweighting passes of the weighted fit after the unweighted one.
constexpr int kReweightPasses = 2;

// One returned beam as a point in S.
struct ScanPoint {
  double x = 0.0;
  double y = 0.0;
  double range = 0.0;
  int beam = 0;
};

// The beam noise model in the units the fit needs.
struct NoiseModel {
  double range_var = 0.0;    // m^2
  double bearing_var = 0.0;  // rad^2
  double min_perpendicular_var = 0.0;  // m^2
};

// A polar line fitted to points [first, last] of the point array.
struct LineFit {
  double rho = 0.0;
  double alpha = 0.0;
  // Covariance of (rho, alpha) from the beam noise alone (no floors).
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  bool ok = false;
};

// A run of points that will become a line if it survives the checks.
struct Segment {
  int first = 0;  // index into the point array
  int last = 0;   // inclusive
  int cluster = 0;
  bool valid = true;
  LineFit fit;
  int Count() const { return last - first + 1; }
};

// Variance of a point's distance to the line with normal angle `alpha`, from
// range noise along the beam and bearing noise across it (Pfister et al. 2003,
// Eq. 7, to first order): sigma_r^2 cos^2(phi - alpha) + r^2 sigma_phi^2
// sin^2(phi - alpha). Departure: floored so that grazing points do not get
// unbounded weight.
double PerpendicularVariance(const ScanPoint& p, double cos_alpha, double sin_alpha,
                             const NoiseModel& noise) {
  const double along_normal = p.x * cos_alpha + p.y * sin_alpha;     // r cos(phi - alpha)
  const double along_line = -p.x * sin_alpha + p.y * cos_alpha;      // r sin(phi - alpha)
  const double cos2 = along_normal * along_normal / (p.range * p.range);
  const double variance =
      noise.range_var * cos2 + noise.bearing_var * along_line * along_line;
  return std::max(variance, noise.min_perpendicular_var);
}

// Weighted total least squares of points [first, last] in polar form
// (Arras & Siegwart 1997, Eqs. 4-5, with weights): minimises
// sum w_i (x_i cos alpha + y_i sin alpha - rho)^2. With `weighted` false all
// weights are one; otherwise w_i = 1 / PerpendicularVariance at `prior_alpha`.
// Returns false if the points do not define a direction.
bool FitOnce(const std::vector<ScanPoint>& points, int first, int last, bool weighted,
             double prior_alpha, const NoiseModel& noise, double* rho, double* alpha) {
  const double cos_prior = std::cos(prior_alpha);
  const double sin_prior = std::sin(prior_alpha);
  // Moments about the first point, for numerical stability.
  const double x0 = points[first].x;
  const double y0 = points[first].y;
  double sw = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0;
  for (int i = first; i <= last; ++i) {
    const ScanPoint& p = points[i];
    const double w =
        weighted ? 1.0 / PerpendicularVariance(p, cos_prior, sin_prior, noise) : 1.0;
    const double dx = p.x - x0;
    const double dy = p.y - y0;
    sw += w;
    sx += w * dx;
    sy += w * dy;
    sxx += w * dx * dx;
    syy += w * dy * dy;
    sxy += w * dx * dy;
  }
  const double mx = sx / sw;
  const double my = sy / sw;
  const double cxx = sxx - sw * mx * mx;
  const double cyy = syy - sw * my * my;
  const double cxy = sxy - sw * mx * my;
  if (!(std::abs(cxx) + std::abs(cyy) > 0.0)) return false;
  // The normal direction minimises the weighted scatter across the line.
  double a = 0.5 * std::atan2(-2.0 * cxy, cyy - cxx);
  double r = (x0 + mx) * std::cos(a) + (y0 + my) * std::sin(a);
  // Canonical form: rho >= 0, alpha in (-pi, pi].
  if (r < 0.0) {
    r = -r;
    a += kPi;
  }
  *rho = r;
  *alpha = WrapAngle(a);
  return std::isfinite(*rho) && std::isfinite(*alpha);
}

// Fits points [first, last] and propagates the beam noise to (rho, alpha).
// The estimate is the fixed point of the reweighted fit (Pfister et al. 2003);
// its covariance is the inverse Fisher information of the perpendicular
// residuals d_i = r_i cos(phi_i - alpha) - rho, with gradient
// (-1, r_i sin(phi_i - alpha)) in (rho, alpha): to first order the same as
// propagating the beam covariances through the closed form (Arras & Siegwart
// 1997), and exact in rho because d_i is linear in the ranges.
LineFit FitLine(const std::vector<ScanPoint>& points, int first, int last,
                const NoiseModel& noise) {
  LineFit fit;
  if (last - first + 1 < 2) return fit;
  double rho = 0.0;
  double alpha = 0.0;
  if (!FitOnce(points, first, last, false, 0.0, noise, &rho, &alpha)) return fit;
  for (int pass = 0; pass < kReweightPasses; ++pass) {
    if (!FitOnce(points, first, last, true, alpha, noise, &rho, &alpha)) return fit;
  }
  // Fisher information of (rho, alpha) at the final estimate.
  const double c = std::cos(alpha);
  const double s = std::sin(alpha);
  double info_rr = 0.0, info_ra = 0.0, info_aa = 0.0;
  for (int i = first; i <= last; ++i) {
    const ScanPoint& p = points[i];
    const double w = 1.0 / PerpendicularVariance(p, c, s, noise);
    const double t = -p.x * s + p.y * c;  // r sin(phi - alpha)
    info_rr += w;
    info_ra -= w * t;
    info_aa += w * t * t;
  }
  const double det = info_rr * info_aa - info_ra * info_ra;
  if (!(det > 1e-12 * info_rr * info_aa) || !std::isfinite(det)) return fit;
  fit.rho = rho;
  fit.alpha = alpha;
  fit.covariance << info_aa / det, -info_ra / det, -info_ra / det, info_rr / det;
  fit.ok = true;
  return fit;
}

// Signed distance of a point from a fitted line, metres (positive on the far
// side from the sensor), and the same in standard deviations of the point's
// perpendicular noise.
double SignedDistance(const LineFit& fit, double x, double y) {
  return x * std::cos(fit.alpha) + y * std::sin(fit.alpha) - fit.rho;
}
double NormalizedResidual(const LineFit& fit, const ScanPoint& p, const NoiseModel& noise) {
  const double c = std::cos(fit.alpha);
  const double s = std::sin(fit.alpha);
  const double d = p.x * c + p.y * s - fit.rho;
  return std::abs(d) / std::sqrt(PerpendicularVariance(p, c, s, noise));
}

// Projection of a point onto a fitted line, in S.
Eigen::Vector2d ProjectOntoLine(const LineFit& fit, const ScanPoint& p) {
  const double c = std::cos(fit.alpha);
  const double s = std::sin(fit.alpha);
  const double t = -p.x * s + p.y * c;
  return {fit.rho * c - t * s, fit.rho * s + t * c};
}

// Distance of a point from the chord through two others (or from the first
// one if they coincide).
double ChordDistance(const ScanPoint& a, const ScanPoint& b, const ScanPoint& p) {
  const double ux = b.x - a.x;
  const double uy = b.y - a.y;
  const double length = std::hypot(ux, uy);
  const double px = p.x - a.x;
  const double py = p.y - a.y;
  if (length < 1e-12) return std::hypot(px, py);
  return std::abs(ux * py - uy * px) / length;
}

// The split step of split-and-merge, splitting at the point farthest from the
// chord (iterative end-point fit; Nguyen et al. 2005, Algorithm 1, with the
// chord in place of the fitted line). Neighbouring runs share their split
// point. Appends the runs of [first, last] in order.
void SplitRun(const std::vector<ScanPoint>& points, int first, int last,
              double split_distance_m, int cluster, std::vector<Segment>* runs) {
  int farthest = -1;
  double farthest_distance = split_distance_m;
  for (int i = first + 1; i < last; ++i) {
    const double d = ChordDistance(points[first], points[last], points[i]);
    if (d > farthest_distance) {
      farthest_distance = d;
      farthest = i;
    }
  }
  if (farthest < 0) {
    Segment run;
    run.first = first;
    run.last = last;
    run.cluster = cluster;
    runs->push_back(run);
    return;
  }
  SplitRun(points, first, farthest, split_distance_m, cluster, runs);
  SplitRun(points, farthest, last, split_distance_m, cluster, runs);
}

// Largest distance of points [first, last] from a fitted line, metres.
double MaxDistance(const std::vector<ScanPoint>& points, int first, int last,
                   const LineFit& fit) {
  double max_distance = 0.0;
  for (int i = first; i <= last; ++i) {
    max_distance = std::max(max_distance, std::abs(SignedDistance(fit, points[i].x, points[i].y)));
  }
  return max_distance;
}

// Whether the end of `segment` next to a neighbouring line (the first point
// if `at_first`, else the last) must go: an outlier of its own line, or
// within the gate of the neighbouring line too (ambiguous near a vertex).
bool ShouldTrim(const std::vector<ScanPoint>& points, const Segment& segment,
                bool at_first, const Segment* neighbour, const NoiseModel& noise,
                double gate) {
  const ScanPoint& p = points[at_first ? segment.first : segment.last];
  if (NormalizedResidual(segment.fit, p, noise) > gate) return true;
  return neighbour != nullptr && neighbour->fit.ok &&
         NormalizedResidual(neighbour->fit, p, noise) <= gate;
}

// The line observation of a final segment, with the model-error floor.
LineObservation MakeLine(const std::vector<ScanPoint>& points, const Segment& segment,
                         const Eigen::Matrix2d& floor) {
  LineObservation line;
  line.rho_m = segment.fit.rho;
  line.alpha_rad = segment.fit.alpha;
  const Eigen::Matrix2d covariance = segment.fit.covariance + floor;
  line.covariance = 0.5 * (covariance + covariance.transpose());
  line.p_SA = ProjectOntoLine(segment.fit, points[segment.first]);
  line.p_SB = ProjectOntoLine(segment.fit, points[segment.last]);
  line.first_beam = points[segment.first].beam;
  line.last_beam = points[segment.last].beam;
  return line;
}

// Spacing of the last two points of a segment at its end next to a vertex,
// measured along the fitted line, metres.
double EndSpacing(const std::vector<ScanPoint>& points, const Segment& segment,
                  bool at_first) {
  const int end = at_first ? segment.first : segment.last;
  const int next = at_first ? segment.first + 1 : segment.last - 1;
  const Eigen::Vector2d a = ProjectOntoLine(segment.fit, points[end]);
  const Eigen::Vector2d b = ProjectOntoLine(segment.fit, points[next]);
  return (a - b).norm();
}

}  // namespace

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
  return {range, std::atan2(p_SC.y(), p_SC.x())};
}

ScanFeatures ExtractFeatures(const LaserScan& scan, const FeatureExtractionParams& params) {
  params.ValidateOrThrow();
  ScanFeatures features;
  const double increment = scan.angle_increment_rad;
  if (scan.ranges_m.empty() || !std::isfinite(increment) || increment == 0.0 ||
      !std::isfinite(scan.angle_min_rad)) {
    return features;
  }

  NoiseModel noise;
  noise.range_var = params.range_noise_std_m * params.range_noise_std_m;
  const double bearing_std = DegToRad(params.bearing_noise_std_deg);
  noise.bearing_var = bearing_std * bearing_std;
  noise.min_perpendicular_var = kMinPerpendicularNoiseFraction *
                                kMinPerpendicularNoiseFraction * noise.range_var;

  // Returned beams as points in S; no-return and invalid beams are dropped.
  const int beam_count = scan.size();
  const int flagged = std::min(beam_count, static_cast<int>(scan.has_return.size()));
  std::vector<ScanPoint> points;
  points.reserve(static_cast<std::size_t>(flagged));
  for (int i = 0; i < flagged; ++i) {
    const double range = scan.ranges_m[i];
    if (scan.has_return[i] == 0 || !std::isfinite(range) || range <= 0.0) continue;
    const double bearing = scan.BeamAngle(i);
    points.push_back({range * std::cos(bearing), range * std::sin(bearing), range, i});
  }
  const int point_count = static_cast<int>(points.size());
  if (point_count < params.min_points) return features;

  // Clusters: break at gaps of no-return beams and at range discontinuities
  // (adaptive breakpoint detector, Borges & Aldon 2004, Eq. 4, with the nearer
  // of the two ranges so that the test does not depend on the scan direction).
  const double lambda = DegToRad(params.break_min_incidence_deg);
  const double noise_margin = params.break_noise_sigmas * params.range_noise_std_m;
  std::vector<Segment> runs;
  runs.reserve(32);
  int cluster_first = 0;
  int cluster = 0;
  const double split_distance = params.split_distance_m;
  for (int i = 1; i <= point_count; ++i) {
    bool breaks = (i == point_count);
    if (!breaks) {
      const ScanPoint& a = points[i - 1];
      const ScanPoint& b = points[i];
      const int beam_gap = b.beam - a.beam;
      const double dphi = std::abs(increment) * beam_gap;
      if (beam_gap - 1 > params.max_missing_beams || dphi >= lambda) {
        breaks = true;
      } else {
        const double r_near = std::min(a.range, b.range);
        const double max_distance =
            r_near * std::sin(dphi) / std::sin(lambda - dphi) + noise_margin;
        breaks = std::hypot(b.x - a.x, b.y - a.y) > max_distance;
      }
    }
    if (!breaks) continue;
    // Split the finished cluster [cluster_first, i - 1].
    if (i - cluster_first >= params.min_points) {
      SplitRun(points, cluster_first, i - 1, split_distance, cluster, &runs);
      ++cluster;
    }
    cluster_first = i;
  }

  // Merge: neighbouring runs of one cluster whose union is straight within
  // the split distance become one run (they share their boundary point).
  std::size_t kept = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (kept > 0) {
      Segment& previous = runs[kept - 1];
      if (previous.cluster == runs[i].cluster && previous.last == runs[i].first) {
        const LineFit union_fit = FitLine(points, previous.first, runs[i].last, noise);
        if (union_fit.ok &&
            MaxDistance(points, previous.first, runs[i].last, union_fit) <= split_distance) {
          previous.last = runs[i].last;
          continue;
        }
      }
    }
    runs[kept++] = runs[i];
  }
  runs.resize(kept);

  // Each point belongs to at most one line: a split point shared by two runs
  // (the point nearest the vertex) goes to neither, so the lines' errors are
  // independent.
  for (std::size_t i = 0; i + 1 < runs.size(); ++i) {
    if (runs[i].cluster == runs[i + 1].cluster && runs[i].last == runs[i + 1].first) {
      --runs[i].last;
      ++runs[i + 1].first;
    }
  }
  for (Segment& run : runs) {
    run.valid = run.Count() >= params.min_points;
    if (run.valid) {
      run.fit = FitLine(points, run.first, run.last, noise);
      run.valid = run.fit.ok;
    }
  }

  // Trim the ends: outliers of their own line, and points near a vertex that
  // fit the neighbouring line of the same cluster too; refit after each.
  const double gate = params.outlier_gate_sigmas;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    Segment& run = runs[i];
    if (!run.valid) continue;
    const Segment* before = nullptr;
    const Segment* after = nullptr;
    for (std::size_t j = i; j-- > 0;) {
      if (runs[j].cluster != run.cluster) break;
      if (runs[j].valid) {
        before = &runs[j];
        break;
      }
    }
    for (std::size_t j = i + 1; j < runs.size(); ++j) {
      if (runs[j].cluster != run.cluster) break;
      if (runs[j].valid) {
        after = &runs[j];
        break;
      }
    }
    bool changed = true;
    while (changed && run.valid) {
      changed = false;
      if (ShouldTrim(points, run, true, before, noise, gate)) {
        ++run.first;
        changed = true;
      }
      if (run.Count() >= 2 && ShouldTrim(points, run, false, after, noise, gate)) {
        --run.last;
        changed = true;
      }
      if (changed) {
        run.valid = run.Count() >= params.min_points;
        if (run.valid) {
          run.fit = FitLine(points, run.first, run.last, noise);
          run.valid = run.fit.ok;
        }
      }
    }
  }

  // Lines: enough points and a long enough seen segment.
  const double rho_floor = params.line_rho_floor_std_m;
  const double alpha_floor = DegToRad(params.line_alpha_floor_std_deg);
  Eigen::Matrix2d floor = Eigen::Matrix2d::Zero();
  floor(0, 0) = rho_floor * rho_floor + kCovarianceFloor;
  floor(1, 1) = alpha_floor * alpha_floor + kCovarianceFloor;
  std::vector<int> line_of_run(runs.size(), -1);
  features.lines.reserve(runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (!runs[i].valid) continue;
    LineObservation line = MakeLine(points, runs[i], floor);
    if ((line.p_SB - line.p_SA).norm() < params.min_length_m) {
      runs[i].valid = false;
      continue;
    }
    line_of_run[i] = static_cast<int>(features.lines.size());
    features.lines.push_back(line);
  }

  // Corners: consecutive lines of one cluster (seen without a range jump in
  // between, so never at an occlusion edge) meeting at a large enough angle,
  // with both seen segments ending near the intersection.
  const double min_sin_angle = std::sin(DegToRad(params.corner_min_angle_deg));
  int previous = -1;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (!runs[i].valid) continue;
    const int current = static_cast<int>(i);
    if (previous < 0 || runs[previous].cluster != runs[current].cluster) {
      previous = current;
      continue;
    }
    const int index_a = line_of_run[previous];
    const int index_b = line_of_run[current];
    const Segment& run_a = runs[previous];
    const Segment& run_b = runs[current];
    previous = current;
    const LineObservation& line_a = features.lines[index_a];
    const LineObservation& line_b = features.lines[index_b];
    const double sin_angle = std::abs(std::sin(line_b.alpha_rad - line_a.alpha_rad));
    if (sin_angle < min_sin_angle || sin_angle == 0.0) continue;

    // The vertex, and how far each seen segment ends from it.
    const Eigen::Vector2d params_a(line_a.rho_m, line_a.alpha_rad);
    const Eigen::Vector2d params_b(line_b.rho_m, line_b.alpha_rad);
    Eigen::Matrix<double, 2, 4> J_vertex;
    const Eigen::Vector2d p_SC = IntersectLines(params_a, params_b, &J_vertex);
    const double tolerance_a = params.corner_max_endpoint_distance_m +
                               params.corner_endpoint_spacings * EndSpacing(points, run_a, false);
    const double tolerance_b = params.corner_max_endpoint_distance_m +
                               params.corner_endpoint_spacings * EndSpacing(points, run_b, true);
    if ((line_a.p_SB - p_SC).norm() > tolerance_a || (line_b.p_SA - p_SC).norm() > tolerance_b) {
      continue;
    }

    // Kind: at a convex corner each wall's far end lies beyond the other
    // wall's line (away from the sensor); at a concave one on the sensor side.
    const double beyond_a = SignedDistance(run_a.fit, line_b.p_SB.x(), line_b.p_SB.y());
    const double beyond_b = SignedDistance(run_b.fit, line_a.p_SA.x(), line_a.p_SA.y());
    if ((beyond_a > 0.0) != (beyond_b > 0.0) || p_SC.squaredNorm() == 0.0) continue;

    // Covariance: the two lines are independent (disjoint points).
    Eigen::Matrix4d lines_covariance = Eigen::Matrix4d::Zero();
    lines_covariance.topLeftCorner<2, 2>() = line_a.covariance;
    lines_covariance.bottomRightCorner<2, 2>() = line_b.covariance;
    const Eigen::Matrix2d point_covariance = J_vertex * lines_covariance * J_vertex.transpose();
    Eigen::Matrix2d J_polar;
    const Eigen::Vector2d range_bearing = PointToRangeBearing(p_SC, &J_polar);
    Eigen::Matrix2d covariance = J_polar * point_covariance * J_polar.transpose();
    covariance = 0.5 * (covariance + covariance.transpose());
    covariance(0, 0) += kCovarianceFloor;
    covariance(1, 1) += kCovarianceFloor;

    CornerObservation corner;
    corner.range_m = range_bearing.x();
    corner.bearing_rad = range_bearing.y();
    corner.covariance = covariance;
    corner.p_SC = p_SC;
    corner.kind = beyond_a > 0.0 ? CornerKind::kConvex : CornerKind::kConcave;
    corner.line_a = index_a;
    corner.line_b = index_b;
    features.corners.push_back(corner);
  }
  return features;
}

}  // namespace mjslam::slam
