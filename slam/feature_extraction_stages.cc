#include "slam/feature_extraction_stages.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "common/angles.h"
#include "common/chi_square.h"

namespace mjslam::slam::extraction {
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
// Returned ranges outside (kMinRangeM, kMaxRangeM) are dropped as corrupt
// (no laser reports them; they would only overflow the sums).
constexpr double kMinRangeM = 1e-3;
constexpr double kMaxRangeM = 1e4;
// Merge cost of two runs that must not merge.
constexpr double kNoMerge = std::numeric_limits<double>::infinity();

// Weighted moments of points [first, last] about the first point (for
// numerical stability): the sums of w, w dx, w dy, w dx^2, w dy^2, w dx dy.
struct Moments {
  double x0 = 0.0;
  double y0 = 0.0;
  double sw = 0.0;
  double sx = 0.0;
  double sy = 0.0;
  double sxx = 0.0;
  double syy = 0.0;
  double sxy = 0.0;
};

// The moments with unit weights (`weighted` false) or with
// w_i = 1 / PerpendicularVariance at the normal angle `prior_alpha`.
Moments Accumulate(const std::vector<ScanPoint>& points, int first, int last, bool weighted,
                   double prior_alpha, const NoiseModel& noise) {
  const double cos_prior = std::cos(prior_alpha);
  const double sin_prior = std::sin(prior_alpha);
  Moments m;
  m.x0 = points[first].x;
  m.y0 = points[first].y;
  for (int i = first; i <= last; ++i) {
    const ScanPoint& p = points[i];
    const double w =
        weighted ? 1.0 / PerpendicularVariance(p, cos_prior, sin_prior, noise) : 1.0;
    const double dx = p.x - m.x0;
    const double dy = p.y - m.y0;
    m.sw += w;
    m.sx += w * dx;
    m.sy += w * dy;
    m.sxx += w * dx * dx;
    m.syy += w * dy * dy;
    m.sxy += w * dx * dy;
  }
  return m;
}

// Weighted total least squares in polar form from the moments (Arras &
// Siegwart 1997, Eqs. 4-5, with weights): minimises
// sum w_i (x_i cos alpha + y_i sin alpha - rho)^2, in canonical form (rho >= 0,
// alpha in (-pi, pi]). Returns false if the points define no direction.
bool SolveLine(const Moments& m, double* rho, double* alpha) {
  const double mx = m.sx / m.sw;
  const double my = m.sy / m.sw;
  const double cxx = m.sxx - m.sw * mx * mx;
  const double cyy = m.syy - m.sw * my * my;
  const double cxy = m.sxy - m.sw * mx * my;
  if (!(std::abs(cxx) + std::abs(cyy) > 0.0)) return false;
  // The normal direction minimises the weighted scatter across the line.
  double a = 0.5 * std::atan2(-2.0 * cxy, cyy - cxx);
  double r = (m.x0 + mx) * std::cos(a) + (m.y0 + my) * std::sin(a);
  if (r < 0.0) {
    r = -r;
    a += kPi;
  }
  *rho = r;
  *alpha = WrapAngle(a);
  return std::isfinite(*rho) && std::isfinite(*alpha);
}

}  // namespace

// Variance of a point's distance to the line with normal angle `alpha`, from
// range noise along the beam and bearing noise across it (Pfister et al. 2003,
// Eq. 7, to first order): sigma_r^2 cos^2(phi - alpha) + r^2 sigma_phi^2
// sin^2(phi - alpha). Departure: floored so that grazing points do not get
// unbounded weight.
double PerpendicularVariance(const ScanPoint& p, double cos_alpha, double sin_alpha,
                             const NoiseModel& noise) {
  const double along_normal = p.x * cos_alpha + p.y * sin_alpha;     // r cos(phi - alpha)
  const double along_line = -p.x * sin_alpha + p.y * cos_alpha;      // r sin(phi - alpha)
  const double cos2 = along_normal * along_normal * p.inverse_range2;
  const double variance =
      noise.range_var * cos2 + noise.bearing_var * along_line * along_line;
  return std::max(variance, noise.min_perpendicular_var);
}

// Fits points [first, last] and propagates the beam noise to (rho, alpha).
// The estimate is the fixed point of the reweighted fit (Pfister et al. 2003):
// an unweighted fit, then kReweightPasses weighted ones (one from `prior`, the
// fit of nearly the same points, when given). Its covariance is the inverse
// Fisher information of the perpendicular residuals
// d_i = r_i cos(phi_i - alpha) - rho, whose gradient in (rho, alpha) is
// (-1, t_i) with t_i = r_i sin(phi_i - alpha) the point's coordinate along the
// line: to first order the same as propagating the beam covariances through
// the closed form (Arras & Siegwart 1997), and exact in rho because d_i is
// linear in the ranges. The information uses the weights of the last pass
// (taken at the previous angle estimate, a second-order difference).
LineFit FitLine(const std::vector<ScanPoint>& points, int first, int last,
                const NoiseModel& noise, const LineFit* prior) {
  LineFit fit;
  if (last - first + 1 < 2) return fit;
  double rho = 0.0;
  double alpha = 0.0;
  int passes = 1;
  if (prior != nullptr && prior->ok) {
    alpha = prior->alpha;
  } else {
    const Moments unweighted = Accumulate(points, first, last, false, 0.0, noise);
    if (!SolveLine(unweighted, &rho, &alpha)) return fit;
    passes = kReweightPasses;
  }
  Moments m;
  for (int pass = 0; pass < passes; ++pass) {
    m = Accumulate(points, first, last, true, alpha, noise);
    if (!SolveLine(m, &rho, &alpha)) return fit;
  }
  // Fisher information sum w_i [1, -t_i; -t_i, t_i^2] from the moments, with
  // t_i = t_0 + u_i and u_i = -dx_i sin(alpha) + dy_i cos(alpha).
  const double c = std::cos(alpha);
  const double s = std::sin(alpha);
  const double t0 = -m.x0 * s + m.y0 * c;
  const double sum_u = -s * m.sx + c * m.sy;
  const double sum_uu = s * s * m.sxx - 2.0 * s * c * m.sxy + c * c * m.syy;
  const double info_rr = m.sw;
  const double info_ra = -(m.sw * t0 + sum_u);
  const double info_aa = m.sw * t0 * t0 + 2.0 * t0 * sum_u + sum_uu;
  // The determinant is translation invariant: sw sum_uu - sum_u^2.
  const double det = m.sw * sum_uu - sum_u * sum_u;
  if (!(det > 1e-12 * info_rr * info_aa) || !std::isfinite(det)) return fit;
  fit.rho = rho;
  fit.alpha = alpha;
  fit.cos_alpha = c;
  fit.sin_alpha = s;
  fit.covariance << info_aa / det, -info_ra / det, -info_ra / det, info_rr / det;
  fit.ok = true;
  return fit;
}

namespace {

// Signed distance of a point from a fitted line, metres (positive on the far
// side from the sensor).
double SignedDistance(const LineFit& fit, double x, double y) {
  return x * fit.cos_alpha + y * fit.sin_alpha - fit.rho;
}

// Distance of a point from a fitted line in standard deviations of the
// point's perpendicular noise.
double NormalizedResidual(const LineFit& fit, const ScanPoint& p, const NoiseModel& noise) {
  const double d = SignedDistance(fit, p.x, p.y);
  return std::abs(d) /
         std::sqrt(PerpendicularVariance(p, fit.cos_alpha, fit.sin_alpha, noise));
}

// Projection of a point onto a fitted line, in S.
Eigen::Vector2d ProjectOntoLine(const LineFit& fit, const ScanPoint& p) {
  const double c = fit.cos_alpha;
  const double s = fit.sin_alpha;
  const double t = -p.x * s + p.y * c;
  return {fit.rho * c - t * s, fit.rho * s + t * c};
}

// The split step of split-and-merge, splitting at the point farthest from the
// chord (iterative end-point fit; Nguyen et al. 2005, Algorithm 1, with the
// chord in place of the fitted line). Neighbouring runs share their split
// point. Appends the runs of [first, last] in order.
void SplitRun(const std::vector<ScanPoint>& points, int first, int last,
              double split_distance_m, int cluster, std::vector<Segment>* runs) {
  // Unit chord direction (any direction if the ends coincide: then the
  // distance is measured across it from the first point).
  const ScanPoint& a = points[first];
  double ux = points[last].x - a.x;
  double uy = points[last].y - a.y;
  const double length = std::sqrt(ux * ux + uy * uy);
  if (length > 1e-12) {
    ux /= length;
    uy /= length;
  } else {
    ux = 1.0;
    uy = 0.0;
  }
  int farthest = -1;
  double farthest_distance = split_distance_m;
  for (int i = first + 1; i < last; ++i) {
    const double d = std::abs(ux * (points[i].y - a.y) - uy * (points[i].x - a.x));
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

// Whether point `p` does not belong to the line `fit`: it is an outlier of
// that line, or it lies within the gate of the neighbouring line too
// (ambiguous, near a vertex). `neighbour` may be null.
bool RejectsPoint(const LineFit& fit, const ScanPoint& p, const Segment* neighbour,
                  const NoiseModel& noise, double gate) {
  if (NormalizedResidual(fit, p, noise) > gate) return true;
  return neighbour != nullptr && neighbour->fit.ok &&
         NormalizedResidual(neighbour->fit, p, noise) <= gate;
}

// Whether the end of `segment` next to `neighbour` (the first point if
// `at_first`, else the last) must go; see RejectsPoint.
bool ShouldTrim(const std::vector<ScanPoint>& points, const Segment& segment,
                bool at_first, const Segment* neighbour, const NoiseModel& noise,
                double gate) {
  return RejectsPoint(segment.fit, points[at_first ? segment.first : segment.last],
                      neighbour, noise, gate);
}

// The line observation of a final segment, with the model-error floor.
// d (rho, alpha) / d b of the fit of `segment` when every range is off by b.
// A point's residual d_i = r_i cos(phi_i - alpha) - rho grows by b c_i,
// c_i = cos(phi_i - alpha); the weighted fit absorbs it through the gradient
// (-1, t_i) of d_i in (rho, alpha) (FitLine), so to first order
//   d (rho, alpha) / d b = Cov sum w_i c_i (1, -t_i),
// Cov the fit's covariance (the inverse of sum w_i (-1, t_i)^T (-1, t_i)),
// w_i its weights at the fitted angle.
Eigen::Vector2d RangeBiasGradient(const std::vector<ScanPoint>& points, const Segment& segment,
                                  const NoiseModel& noise) {
  const LineFit& fit = segment.fit;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int i = segment.first; i <= segment.last; ++i) {
    const ScanPoint& p = points[i];
    const double w = 1.0 / PerpendicularVariance(p, fit.cos_alpha, fit.sin_alpha, noise);
    const double along_normal = p.x * fit.cos_alpha + p.y * fit.sin_alpha;
    const double along_line = -p.x * fit.sin_alpha + p.y * fit.cos_alpha;
    const double c = along_normal / p.range;
    sum += w * c * Eigen::Vector2d(1.0, -along_line);
  }
  return fit.covariance * sum;
}

LineObservation MakeLine(const std::vector<ScanPoint>& points, const Segment& segment,
                         const Eigen::Matrix2d& floor, const NoiseModel& noise) {
  LineObservation line;
  line.rho_m = segment.fit.rho;
  line.alpha_rad = segment.fit.alpha;
  line.range_bias_gradient = RangeBiasGradient(points, segment, noise);
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

// The nearest valid run before (after) run i in its cluster, or null.
const Segment* ValidBefore(const std::vector<Segment>& runs, std::size_t i) {
  for (std::size_t j = i; j-- > 0;) {
    if (runs[j].cluster != runs[i].cluster) return nullptr;
    if (runs[j].valid) return &runs[j];
  }
  return nullptr;
}

const Segment* ValidAfter(const std::vector<Segment>& runs, std::size_t i) {
  for (std::size_t j = i + 1; j < runs.size(); ++j) {
    if (runs[j].cluster != runs[i].cluster) return nullptr;
    if (runs[j].valid) return &runs[j];
  }
  return nullptr;
}

// Calls visit(run, before, after) for each valid run in order, with its
// nearest valid neighbours in its cluster when it comes up (null: none).
template <typename Visit>
void ForEachValidRun(std::vector<Segment>* runs, Visit visit) {
  for (std::size_t i = 0; i < runs->size(); ++i) {
    Segment& run = (*runs)[i];
    if (!run.valid) continue;
    visit(run, ValidBefore(*runs, i), ValidAfter(*runs, i));
  }
}

// Refits a run whose points changed by one, from its previous fit; it stays
// valid with at least `min_points` points and a fit.
void Refit(const std::vector<ScanPoint>& points, const NoiseModel& noise, int min_points,
           Segment* run) {
  run->valid = run->Count() >= min_points;
  if (run->valid) {
    run->fit = FitLine(points, run->first, run->last, noise, &run->fit);
    run->valid = run->fit.ok;
  }
}

}  // namespace

NoiseModel MakeNoiseModel(const FeatureExtractionParams& params) {
  NoiseModel noise;
  noise.range_var = params.range_noise_std_m * params.range_noise_std_m;
  const double bearing_std = DegToRad(params.bearing_noise_std_deg);
  noise.bearing_var = bearing_std * bearing_std;
  noise.min_perpendicular_var = kMinPerpendicularNoiseFraction *
                                kMinPerpendicularNoiseFraction * noise.range_var;
  return noise;
}

std::vector<ScanPoint> ScanPoints(const LaserScan& scan) {
  const double increment = scan.angle_increment_rad;
  const int beam_count = scan.size();
  const int flagged = std::min(beam_count, static_cast<int>(scan.has_return.size()));
  std::vector<ScanPoint> points;
  points.reserve(static_cast<std::size_t>(flagged));
  // Beam directions by rotating the previous one by the increment, anchored
  // with an exact sincos every kAnchorBeams beams (rounding stays ~1e-15).
  constexpr int kAnchorBeams = 16;
  const double cos_increment = std::cos(increment);
  const double sin_increment = std::sin(increment);
  double cos_bearing = 1.0;
  double sin_bearing = 0.0;
  for (int i = 0; i < flagged; ++i) {
    if (i % kAnchorBeams == 0) {
      cos_bearing = std::cos(scan.BeamAngle(i));
      sin_bearing = std::sin(scan.BeamAngle(i));
    } else {
      const double rotated_cos = cos_bearing * cos_increment - sin_bearing * sin_increment;
      sin_bearing = sin_bearing * cos_increment + cos_bearing * sin_increment;
      cos_bearing = rotated_cos;
    }
    const double range = scan.ranges_m[i];
    if (scan.has_return[i] == 0 || !(range > kMinRangeM && range < kMaxRangeM)) continue;
    points.push_back({range * cos_bearing, range * sin_bearing, range, 1.0 / (range * range), i});
  }
  return points;
}

std::vector<ClusterBounds> FindClusters(const std::vector<ScanPoint>& points,
                                        double increment_rad,
                                        const FeatureExtractionParams& params) {
  // Break at gaps of no-return beams and at range discontinuities (adaptive
  // breakpoint detector, Borges & Aldon 2004, Eq. 4, with the nearer of the
  // two ranges so that the test does not depend on the scan direction).
  const int point_count = static_cast<int>(points.size());
  const double lambda = DegToRad(params.break_min_incidence_deg);
  const double noise_margin = params.break_noise_sigmas * params.range_noise_std_m;
  const double adjacent_dphi = std::abs(increment_rad);
  const double adjacent_factor = std::sin(adjacent_dphi) / std::sin(lambda - adjacent_dphi);
  std::vector<ClusterBounds> clusters;
  clusters.reserve(16);
  int cluster_first = 0;
  for (int i = 1; i <= point_count; ++i) {
    bool breaks = (i == point_count);
    if (!breaks) {
      const ScanPoint& a = points[i - 1];
      const ScanPoint& b = points[i];
      const int beam_gap = b.beam - a.beam;
      const double dphi = std::abs(increment_rad) * beam_gap;
      if (beam_gap - 1 > params.max_missing_beams || dphi >= lambda) {
        breaks = true;
      } else {
        const double factor = beam_gap == 1
                                  ? adjacent_factor
                                  : std::sin(dphi) / std::sin(lambda - dphi);
        const double max_distance = std::min(a.range, b.range) * factor + noise_margin;
        const double dx = b.x - a.x;
        const double dy = b.y - a.y;
        breaks = dx * dx + dy * dy > max_distance * max_distance;
      }
    }
    if (!breaks) continue;
    // The finished cluster [cluster_first, i - 1], if it can hold a line.
    if (i - cluster_first >= params.min_points) clusters.push_back({cluster_first, i - 1});
    cluster_first = i;
  }
  return clusters;
}

std::vector<Segment> SplitClusters(const std::vector<ScanPoint>& points,
                                   const std::vector<ClusterBounds>& clusters,
                                   double split_distance_m) {
  std::vector<Segment> runs;
  runs.reserve(32);
  for (std::size_t cluster = 0; cluster < clusters.size(); ++cluster) {
    SplitRun(points, clusters[cluster].first, clusters[cluster].last, split_distance_m,
             static_cast<int>(cluster), &runs);
  }
  return runs;
}

void MergeRuns(const std::vector<ScanPoint>& points, const NoiseModel& noise,
               double split_distance_m, std::vector<Segment>* runs_in) {
  // The straightest union merges first, so that a run split off by a noisy
  // chord rejoins its own wall rather than the wall across a vertex.
  std::vector<Segment>& runs = *runs_in;
  std::vector<double> union_cost(runs.size(), 0.0);
  const auto merge_cost = [&](std::size_t i) {
    const Segment& a = runs[i];
    const Segment& b = runs[i + 1];
    if (a.cluster != b.cluster || a.last != b.first) return kNoMerge;
    const LineFit fit = FitLine(points, a.first, b.last, noise);
    if (!fit.ok) return kNoMerge;
    const double distance = MaxDistance(points, a.first, b.last, fit);
    return distance <= split_distance_m ? distance : kNoMerge;
  };
  for (std::size_t i = 0; i + 1 < runs.size(); ++i) union_cost[i] = merge_cost(i);
  while (runs.size() > 1) {
    const auto best = std::min_element(union_cost.begin(), union_cost.end() - 1);
    if (*best == kNoMerge) break;
    const std::size_t i = static_cast<std::size_t>(best - union_cost.begin());
    runs[i].last = runs[i + 1].last;
    runs.erase(runs.begin() + static_cast<std::ptrdiff_t>(i) + 1);
    union_cost.erase(union_cost.begin() + static_cast<std::ptrdiff_t>(i) + 1);
    if (i + 1 < runs.size()) union_cost[i] = merge_cost(i);
    if (i > 0) union_cost[i - 1] = merge_cost(i - 1);
  }
}

namespace {

// Sum of squared normalised residuals of points [first, last] about `fit`.
double FitChiSquare(const std::vector<ScanPoint>& points, int first, int last, const LineFit& fit,
                    const NoiseModel& noise) {
  double sum = 0.0;
  for (int i = first; i <= last; ++i) {
    const double r = NormalizedResidual(fit, points[i], noise);
    sum += r * r;
  }
  return sum;
}

// The chi-square quantile of `probability` for `dof` degrees of freedom,
// remembered per dof (the probability is one per configuration).
double CachedChiSquareQuantile(double probability, int dof) {
  thread_local double cached_probability = -1.0;
  thread_local std::vector<double> quantiles;
  if (probability != cached_probability) {
    cached_probability = probability;
    quantiles.clear();
  }
  if (static_cast<int>(quantiles.size()) <= dof) {
    quantiles.resize(static_cast<std::size_t>(dof) + 1, -1.0);
  }
  double& q = quantiles[static_cast<std::size_t>(dof)];
  if (q < 0.0) q = ChiSquareQuantile(probability, dof);
  return q;
}

// Sum of squared distances of n points to their total-least-squares line,
// from their sums: the smaller eigenvalue of the centred scatter matrix.
double TotalLeastSquaresResidual(double n, double sx, double sy, double sxx, double syy,
                                 double sxy) {
  const double cxx = sxx - sx * sx / n;
  const double cyy = syy - sy * sy / n;
  const double cxy = sxy - sx * sy / n;
  const double half_trace = 0.5 * (cxx + cyy);
  const double half_difference = 0.5 * (cxx - cyy);
  return std::max(0.0, half_trace - std::sqrt(half_difference * half_difference + cxy * cxy));
}

// The point k in (first, last) where lines over [first, k] and [k, last] (at
// least 2 points each side besides k) fit best, by prefix sums: O(points).
// -1 when the run has fewer than 5 points.
int BestSplitPoint(const std::vector<ScanPoint>& points, int first, int last) {
  const int n = last - first + 1;
  if (n < 5) return -1;
  // Prefix sums about the first point (well conditioned).
  const double x0 = points[first].x;
  const double y0 = points[first].y;
  std::vector<double> sx(n + 1, 0.0), sy(n + 1, 0.0), sxx(n + 1, 0.0), syy(n + 1, 0.0),
      sxy(n + 1, 0.0);
  for (int j = 0; j < n; ++j) {
    const double x = points[first + j].x - x0;
    const double y = points[first + j].y - y0;
    sx[j + 1] = sx[j] + x;
    sy[j + 1] = sy[j] + y;
    sxx[j + 1] = sxx[j] + x * x;
    syy[j + 1] = syy[j] + y * y;
    sxy[j + 1] = sxy[j] + x * y;
  }
  // Sums over points [a, b] (offsets from first, inclusive).
  const auto residual = [&](int a, int b) {
    return TotalLeastSquaresResidual(b - a + 1, sx[b + 1] - sx[a], sy[b + 1] - sy[a],
                                     sxx[b + 1] - sxx[a], syy[b + 1] - syy[a],
                                     sxy[b + 1] - sxy[a]);
  };
  int best = -1;
  double best_residual = std::numeric_limits<double>::infinity();
  for (int k = 2; k <= n - 3; ++k) {
    const double total = residual(0, k) + residual(k, n - 1);
    if (total < best_residual) {
      best_residual = total;
      best = first + k;
    }
  }
  return best;
}

// The test leaves out the run's end points: a split point shared with the
// neighbouring run may lie on the other wall, and steps 5 take it (and
// outlying ends) from the line anyway.
void SplitIfInconsistent(const std::vector<ScanPoint>& points, const NoiseModel& noise,
                         double probability, const Segment& run, std::vector<Segment>* out) {
  const int first = run.first + 1;
  const int last = run.last - 1;
  const int dof = last - first + 1 - 2;
  const int k = dof >= 3 ? BestSplitPoint(points, run.first, run.last) : -1;
  if (k >= 0) {
    const LineFit fit = FitLine(points, first, last, noise);
    if (fit.ok && FitChiSquare(points, first, last, fit, noise) >
                      CachedChiSquareQuantile(probability, dof)) {
      Segment left = run;
      left.last = k;
      Segment right = run;
      right.first = k;
      SplitIfInconsistent(points, noise, probability, left, out);
      SplitIfInconsistent(points, noise, probability, right, out);
      return;
    }
  }
  out->push_back(run);
}

}  // namespace

void SplitInconsistentRuns(const std::vector<ScanPoint>& points, const NoiseModel& noise,
                           double probability, std::vector<Segment>* runs) {
  if (probability <= 0.0) return;
  std::vector<Segment> split;
  split.reserve(runs->size());
  for (const Segment& run : *runs) SplitIfInconsistent(points, noise, probability, run, &split);
  *runs = std::move(split);
}

std::vector<char> SeparateVertexPoints(int point_count, std::vector<Segment>* runs_in) {
  // Each point belongs to at most one line: a split point shared by two runs
  // (the point nearest the vertex) goes to neither, so the lines' errors are
  // independent, and no line ever takes it back: it may lie on either wall,
  // and on the other wall a few millimetres from the vertex it passes every
  // residual test of this one while tilting its fit (a beam grazing the end
  // face of a wall, next to a convex corner).
  std::vector<Segment>& runs = *runs_in;
  std::vector<char> is_vertex(static_cast<std::size_t>(point_count), 0);
  for (std::size_t i = 0; i + 1 < runs.size(); ++i) {
    if (runs[i].cluster == runs[i + 1].cluster && runs[i].last == runs[i + 1].first) {
      is_vertex[runs[i].last] = 1;
      --runs[i].last;
      ++runs[i + 1].first;
    }
  }
  return is_vertex;
}

void FitRuns(const std::vector<ScanPoint>& points, const NoiseModel& noise, int min_points,
             std::vector<Segment>* runs) {
  for (Segment& run : *runs) {
    run.valid = run.Count() >= min_points;
    if (run.valid) {
      run.fit = FitLine(points, run.first, run.last, noise);
      run.valid = run.fit.ok;
    }
  }
}

void TrimRuns(const std::vector<ScanPoint>& points, const NoiseModel& noise,
              const FeatureExtractionParams& params, std::vector<Segment>* runs) {
  // Outliers of their own line, and points near a vertex that fit the
  // neighbouring line of the same cluster too; refit after each.
  const double gate = params.outlier_gate_sigmas;
  ForEachValidRun(runs, [&](Segment& run, const Segment* before, const Segment* after) {
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
      if (changed) Refit(points, noise, params.min_points, &run);
    }
  });
}

void GrowRuns(const std::vector<ScanPoint>& points, const NoiseModel& noise,
              const FeatureExtractionParams& params, const std::vector<ClusterBounds>& clusters,
              const std::vector<char>& is_vertex, std::vector<Segment>* runs) {
  // Into points that no line holds (points trimmed before, runs too short to
  // be lines; never a vertex point): a point joins when it fits the line
  // within the gate and does not fit the neighbouring line (not ambiguous).
  const double gate = params.outlier_gate_sigmas;
  ForEachValidRun(runs, [&](Segment& run, const Segment* before, const Segment* after) {
    const int lowest = before != nullptr ? before->last + 1 : clusters[run.cluster].first;
    const int highest = after != nullptr ? after->first - 1 : clusters[run.cluster].last;
    while (run.valid && run.first > lowest && is_vertex[run.first - 1] == 0 &&
           !RejectsPoint(run.fit, points[run.first - 1], before, noise, gate)) {
      --run.first;
      Refit(points, noise, params.min_points, &run);
    }
    while (run.valid && run.last < highest && is_vertex[run.last + 1] == 0 &&
           !RejectsPoint(run.fit, points[run.last + 1], after, noise, gate)) {
      ++run.last;
      Refit(points, noise, params.min_points, &run);
    }
  });
}

std::vector<LineObservation> KeepLines(const std::vector<ScanPoint>& points,
                                       const FeatureExtractionParams& params,
                                       std::vector<Segment>* runs_in,
                                       std::vector<int>* line_of_run) {
  // Enough points (valid) and a long enough seen segment.
  std::vector<Segment>& runs = *runs_in;
  const double rho_floor = params.line_rho_floor_std_m;
  const double alpha_floor = DegToRad(params.line_alpha_floor_std_deg);
  Eigen::Matrix2d floor = Eigen::Matrix2d::Zero();
  floor(0, 0) = rho_floor * rho_floor + kCovarianceFloor;
  floor(1, 1) = alpha_floor * alpha_floor + kCovarianceFloor;
  const NoiseModel noise = MakeNoiseModel(params);
  line_of_run->assign(runs.size(), -1);
  std::vector<LineObservation> lines;
  lines.reserve(runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (!runs[i].valid) continue;
    LineObservation line = MakeLine(points, runs[i], floor, noise);
    if ((line.p_SB - line.p_SA).norm() < params.min_length_m) {
      runs[i].valid = false;
      continue;
    }
    (*line_of_run)[i] = static_cast<int>(lines.size());
    lines.push_back(line);
  }
  return lines;
}

std::optional<CornerObservation> CornerBetween(const std::vector<ScanPoint>& points,
                                               const NoiseModel& noise,
                                               const FeatureExtractionParams& params,
                                               double increment_rad, const Segment& run_a,
                                               const Segment& run_b,
                                               const LineObservation& line_a,
                                               const LineObservation& line_b) {
  // A large enough angle between the lines.
  const double min_sin_angle = std::sin(DegToRad(params.corner_min_angle_deg));
  const double sin_angle = std::abs(std::sin(line_b.alpha_rad - line_a.alpha_rad));
  if (sin_angle < min_sin_angle || sin_angle == 0.0) return std::nullopt;

  // The vertex, and how far short of it each seen segment ends (negative:
  // the segment runs past it). A segment may stop short by the endpoint
  // distance plus a few point spacings, but run past by the endpoint
  // distance only: a wall that runs past is one that continues behind an
  // occluder, where the occluder's face line happens to meet it.
  const Eigen::Vector2d params_a(line_a.rho_m, line_a.alpha_rad);
  const Eigen::Vector2d params_b(line_b.rho_m, line_b.alpha_rad);
  Eigen::Matrix<double, 2, 4> J_vertex;
  const Eigen::Vector2d p_SC = IntersectLines(params_a, params_b, &J_vertex);
  const double short_of_a = (p_SC - line_a.p_SB).dot((line_a.p_SB - line_a.p_SA).normalized());
  const double short_of_b = (p_SC - line_b.p_SA).dot((line_b.p_SA - line_b.p_SB).normalized());
  const double tolerance_a = params.corner_max_endpoint_distance_m +
                             params.corner_endpoint_spacings * EndSpacing(points, run_a, false);
  const double tolerance_b = params.corner_max_endpoint_distance_m +
                             params.corner_endpoint_spacings * EndSpacing(points, run_b, true);
  const double overshoot = params.corner_max_endpoint_distance_m;
  if (short_of_a > tolerance_a || short_of_a < -overshoot || short_of_b > tolerance_b ||
      short_of_b < -overshoot) {
    return std::nullopt;
  }

  // No point between the two seen segments (points dropped near the vertex)
  // may lie far behind the line on its side of the vertex. Where an
  // occluder's face ends in front of a wall, the beams between the face's
  // end and the intersection hit the wall behind the face's line; at a real
  // vertex they hit the line itself. One-sided, at twice the gate, so that
  // noise outliers (which is why most of these points were dropped) pass.
  const double gate = params.outlier_gate_sigmas;
  const double scan_turn = increment_rad > 0.0 ? 1.0 : -1.0;
  bool behind = false;
  for (int j = run_a.last + 1; j < run_b.first && !behind; ++j) {
    const ScanPoint& p = points[j];
    const bool before_vertex = scan_turn * (p.x * p_SC.y() - p.y * p_SC.x()) > 0.0;
    const LineFit& own = before_vertex ? run_a.fit : run_b.fit;
    const double sigma = std::sqrt(PerpendicularVariance(p, own.cos_alpha, own.sin_alpha, noise));
    behind = SignedDistance(own, p.x, p.y) > 2.0 * gate * sigma;
  }
  if (behind) return std::nullopt;

  // Kind: at a convex corner each wall's far end lies beyond the other
  // wall's line (away from the sensor); at a concave one on the sensor side.
  const double beyond_a = SignedDistance(run_a.fit, line_b.p_SB.x(), line_b.p_SB.y());
  const double beyond_b = SignedDistance(run_b.fit, line_a.p_SA.x(), line_a.p_SA.y());
  if ((beyond_a > 0.0) != (beyond_b > 0.0) || p_SC.squaredNorm() == 0.0) return std::nullopt;

  // Covariance: the two lines are independent (disjoint points).
  Eigen::Matrix4d lines_covariance = Eigen::Matrix4d::Zero();
  lines_covariance.topLeftCorner<2, 2>() = line_a.covariance;
  lines_covariance.bottomRightCorner<2, 2>() = line_b.covariance;
  const Eigen::Matrix2d point_covariance = J_vertex * lines_covariance * J_vertex.transpose();
  Eigen::Matrix2d J_polar;
  const Eigen::Vector2d range_bearing = PointToRangeBearing(p_SC, &J_polar);
  const Eigen::Matrix2d propagated = J_polar * point_covariance * J_polar.transpose();
  // Symmetrised from a separate matrix (in place, Eigen's transpose aliases).
  Eigen::Matrix2d covariance = 0.5 * (propagated + propagated.transpose());
  covariance(0, 0) += kCovarianceFloor;
  covariance(1, 1) += kCovarianceFloor;

  CornerObservation corner;
  corner.range_m = range_bearing.x();
  corner.bearing_rad = range_bearing.y();
  corner.covariance = covariance;
  Eigen::Vector4d lines_bias_gradient;
  lines_bias_gradient << line_a.range_bias_gradient, line_b.range_bias_gradient;
  corner.range_bias_gradient = J_polar * (J_vertex * lines_bias_gradient);
  corner.p_SC = p_SC;
  corner.kind = beyond_a > 0.0 ? CornerKind::kConvex : CornerKind::kConcave;
  return corner;
}

std::vector<CornerObservation> FindCorners(const std::vector<ScanPoint>& points,
                                           const NoiseModel& noise,
                                           const FeatureExtractionParams& params,
                                           double increment_rad,
                                           const std::vector<Segment>& runs,
                                           const std::vector<int>& line_of_run,
                                           const std::vector<LineObservation>& lines) {
  // Consecutive lines of one cluster (no range jump between them).
  std::vector<CornerObservation> corners;
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
    std::optional<CornerObservation> corner = CornerBetween(
        points, noise, params, increment_rad, run_a, run_b, lines[index_a], lines[index_b]);
    if (!corner) continue;
    corner->line_a = index_a;
    corner->line_b = index_b;
    corners.push_back(*corner);
  }
  return corners;
}

}  // namespace mjslam::slam::extraction
