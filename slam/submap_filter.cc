#include "slam/submap_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <utility>

#include <Eigen/Cholesky>

#include "common/check.h"
#include "slam/data_association.h"
#include "slam/ekf_filter.h"
#include "slam/observation_models.h"

namespace mjslam::slam {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The variance of the identity constraint f_submap - f_global = 0 that fuses
// a matched pair (metres^2, radians^2): far below any feature's, it only
// keeps the batch's S positive definite when constraints are redundant (a
// corner made from two lines that match too).
constexpr double kConstraintVariance = 1e-10;

// The quantities a join carries to W, y = [x_B', c, f_1, ..., f_L] of the
// submap (c: its nc self-calibration entries as they are now), with their
// Jacobians by the old base x_B and by the submap's entries
// [x_BR, c, f_1, ..., f_L].
struct Transformed {
  Eigen::VectorXd y;
  Eigen::MatrixXd J_base;    // ny x 3
  Eigen::MatrixXd J_submap;  // ny x ny
};

Transformed ToWorld(const SlamState& s, int nc, const Eigen::Vector3d& base) {
  const int L = s.num_features();
  const int ny = 3 + nc + 2 * L;
  Transformed t{Eigen::VectorXd(ny), Eigen::MatrixXd::Zero(ny, 3),
                Eigen::MatrixXd::Zero(ny, ny)};
  const double c = std::cos(base(2));
  const double sn = std::sin(base(2));
  Eigen::Matrix2d R;
  R << c, -sn, sn, c;
  // A point p of B: x_B + R p.
  const auto point = [&](const Eigen::Vector2d& p, int row) {
    t.y.segment<2>(row) = base.head<2>() + R * p;
    t.J_base.block<2, 2>(row, 0).setIdentity();
    t.J_base(row, 2) = -sn * p.x() - c * p.y();
    t.J_base(row + 1, 2) = c * p.x() - sn * p.y();
    t.J_submap.block<2, 2>(row, row) = R;
  };
  // The new base: the submap's robot pose, carried to W.
  const Eigen::Vector3d pose = s.pose();
  point(pose.head<2>(), 0);
  t.y(2) = WrapAngle(base(2) + pose(2));
  t.J_base(2, 2) = 1.0;
  t.J_submap(2, 2) = 1.0;
  // The self-calibration as it is now.
  for (int i = 0; i < nc; ++i) {
    t.y(3 + i) = s.mean()(3 + i);
    t.J_submap(3 + i, 3 + i) = 1.0;
  }
  for (int k = 0; k < L; ++k) {
    const int row = 3 + nc + 2 * k;
    const Eigen::Vector2d f = s.feature(k);
    if (s.feature_type(k) == FeatureType::kCorner) {
      point(f, row);
      continue;
    }
    // Line (r, al) of B: al_W = al + th_B, r_W = r + x_B cos al_W + y_B sin al_W.
    const double al = f.y() + base(2);
    const double ca = std::cos(al);
    const double sa = std::sin(al);
    const double dr_dal = -base(0) * sa + base(1) * ca;
    Eigen::Matrix<double, 2, 3> Jb;
    Jb << ca, sa, dr_dal, 0.0, 0.0, 1.0;
    Eigen::Matrix2d Jf;
    Jf << 1.0, dr_dal, 0.0, 1.0;
    Eigen::Matrix2d C;
    t.y.segment<2>(row) = CanonicalLine(Eigen::Vector2d(f.x() + base(0) * ca + base(1) * sa, al), &C);
    t.J_base.block<2, 3>(row, 0) = C * Jb;
    t.J_submap.block<2, 2>(row, row) = C * Jf;
  }
  return t;
}

// The direction of line (r, al)'s normal towards the side it was seen from
// (`seen_side`, the sign of r - p_S . n), rotated by `rotation`.
double Facing(const Eigen::Vector2d& line, int seen_side, double rotation) {
  if (seen_side == 0) return std::numeric_limits<double>::quiet_NaN();
  return WrapAngle(line.y() + (seen_side > 0 ? kPi : 0.0) + rotation);
}

// The difference d = A f_a - f_b of two features of one type in W (a line's
// f_a in f_b's polar form: A = diag(-1, 1) and al + pi when their normals
// are opposite), and A.
Eigen::Vector2d Difference(FeatureType type, const Eigen::Vector2d& f_a,
                           const Eigen::Vector2d& f_b, Eigen::Matrix2d* A) {
  A->setIdentity();
  if (type == FeatureType::kCorner) return f_a - f_b;
  double dal = WrapAngle(f_a.y() - f_b.y());
  double r_a = f_a.x();
  if (std::abs(dal) > kPi / 2) {
    (*A)(0, 0) = -1.0;
    r_a = -r_a;
    dal = WrapAngle(dal + kPi);
  }
  return {r_a - f_b.x(), dal};
}

// Whether the seen segments of lines a and b (in W) are within `max_gap`
// of each other along line b.
bool SegmentsMeet(const Eigen::Vector2d& line_a, const LineSegment& seg_a,
                  const Eigen::Vector2d& line_b, const LineSegment& seg_b, double max_gap) {
  if (max_gap <= 0.0) return true;
  const LineSegment a_on_b = SegmentFromPoints(line_b, PointOnLine(line_a, seg_a.s_min),
                                               PointOnLine(line_a, seg_a.s_max));
  return std::max(a_on_b.s_min - seg_b.s_max, seg_b.s_min - a_on_b.s_max) <= max_gap;
}

}  // namespace

namespace {

// The shared part of a submap and the global map: the self-calibration's
// estimated entries (`entries`, of 0..4) at the submap's start, c0. With
// P_cc and c the global map's covariance and estimate of them, and P0' and
// c0' the submap's: M = P_cc^-1 P_(c, global), D = P_cc - P0',
// delta = c0' - c.
struct SharedPart {
  std::vector<int> entries;
  Eigen::MatrixXd M;
  Eigen::MatrixXd D;
  Eigen::VectorXd delta;
};

SharedPart SharedPartOf(const EkfSlam& submap, const JoinedMap& map) {
  SharedPart shared;
  const SlamState& s = submap.slam_state();
  const int nc = map.calibration_size;
  if (nc == 0) return shared;
  MJSLAM_CHECK(s.SharedIndex() >= 0);
  // The estimated entries: those with a prior variance.
  for (int i = 0; i < nc; ++i) {
    if (map.covariance(3 + i, 3 + i) > 0.0) shared.entries.push_back(i);
  }
  const int na = static_cast<int>(shared.entries.size());
  const int ng = static_cast<int>(map.mean.size());
  const auto P_sub = s.covariance();
  Eigen::MatrixXd P_cc(na, na);
  Eigen::MatrixXd P_cg(na, ng);
  Eigen::MatrixXd P0_new(na, na);
  shared.delta.resize(na);
  for (int i = 0; i < na; ++i) {
    const int gi = 3 + shared.entries[i];
    const int si = s.SharedIndex() + shared.entries[i];
    shared.delta(i) = s.mean()(si) - map.mean(gi);
    P_cg.row(i) = map.covariance.row(gi);
    for (int j = 0; j < na; ++j) {
      P_cc(i, j) = map.covariance(gi, 3 + shared.entries[j]);
      P0_new(i, j) = P_sub(si, s.SharedIndex() + shared.entries[j]);
    }
  }
  shared.M = P_cc.ldlt().solve(P_cg);
  shared.D = P_cc - P0_new;
  return shared;
}

}  // namespace

JoinReport JoinSubmap(const EkfSlam& submap, double gate, double max_segment_gap_m,
                      JoinedMap* map, int* next_id) {
  const SlamState& s = submap.slam_state();
  const int nc = map->calibration_size;
  const int L = s.num_features();
  const int Lg = map->num_features();
  const int ng = 3 + nc + 2 * Lg;
  const Eigen::Vector3d base = map->mean.head<3>();

  // 1. The shared calibration: the submap's estimate of the entries' value
  // at its start, c0, updates the global map through their correlations (the
  // global map is independent of the submap given c0): x += M^T delta,
  // P -= M^T D M, and Cov(submap entry, global) = P_(entry, c0) M.
  const SharedPart shared = SharedPartOf(submap, *map);
  Eigen::VectorXd xg = map->mean;
  Eigen::MatrixXd Pg = map->covariance;
  if (!shared.entries.empty()) {
    xg.noalias() += shared.M.transpose() * shared.delta;
    const Eigen::MatrixXd DM = shared.D * shared.M;
    Pg.noalias() -= shared.M.transpose() * DM;
    Pg = 0.5 * (Pg + Pg.transpose()).eval();
  }

  // 2. The submap's entries [x_BR, c, f_1, ..., f_L] (c: the current
  // self-calibration, if any), their covariance, and their covariance with
  // c0 (the estimated entries).
  std::vector<int> entries = {0, 1, 2};
  for (int i = 0; i < nc; ++i) entries.push_back(3 + i);
  for (int k = 0; k < L; ++k) {
    entries.push_back(s.FeatureIndex(k));
    entries.push_back(s.FeatureIndex(k) + 1);
  }
  const int ns = static_cast<int>(entries.size());
  const int na = static_cast<int>(shared.entries.size());
  const auto P_sub_full = s.covariance();
  Eigen::MatrixXd P_ss(ns, ns);
  Eigen::MatrixXd P_s0(ns, na);
  for (int i = 0; i < ns; ++i) {
    for (int j = 0; j < ns; ++j) P_ss(i, j) = P_sub_full(entries[i], entries[j]);
    for (int j = 0; j < na; ++j) {
      P_s0(i, j) = P_sub_full(entries[i], s.SharedIndex() + shared.entries[j]);
    }
  }

  // 3. Carried to W: y = [x_B', c, f_W] from x_B and the submap's entries.
  const Transformed t = ToWorld(s, nc, base);
  const Eigen::MatrixXd JsP_s0 = t.J_submap * P_s0;  // ny x na
  // Cov(y, global) and Cov(y, y); the old base and c0 are then left out.
  Eigen::MatrixXd P_yg = t.J_base * Pg.topRows<3>();
  if (na > 0) P_yg.noalias() += JsP_s0 * shared.M;
  Eigen::MatrixXd P_yy = t.J_base * Pg.topLeftCorner<3, 3>() * t.J_base.transpose() +
                         t.J_submap * P_ss * t.J_submap.transpose();
  if (na > 0) {
    const Eigen::MatrixXd cross = t.J_base * shared.M.leftCols<3>().transpose() *
                                  JsP_s0.transpose();  // J_b Cov(x_B, s) J_s^T
    P_yy += cross + cross.transpose();
  }
  P_yy = 0.5 * (P_yy + P_yy.transpose()).eval();

  // The joined state [x_B', c, old features, submap features].
  const int nv = 3 + nc;  // y's head: x_B' and c
  const int n = ng + 2 * L;
  const int nF = 2 * Lg;
  Eigen::VectorXd x(n);
  x.head(nv) = t.y.head(nv);
  x.segment(nv, nF) = xg.tail(nF);
  x.tail(2 * L) = t.y.tail(2 * L);
  Eigen::MatrixXd P(n, n);
  P.topLeftCorner(nv, nv) = P_yy.topLeftCorner(nv, nv);
  P.block(0, nv, nv, nF) = P_yg.block(0, nv, nv, nF);
  P.block(0, ng, nv, 2 * L) = P_yy.topRightCorner(nv, 2 * L);
  P.block(nv, nv, nF, nF) = Pg.bottomRightCorner(nF, nF);
  P.block(ng, nv, 2 * L, nF) = P_yg.block(nv, nv, 2 * L, nF);
  P.bottomRightCorner(2 * L, 2 * L) = P_yy.bottomRightCorner(2 * L, 2 * L);
  P.block(nv, 0, nF, nv) = P.block(0, nv, nv, nF).transpose();
  P.block(ng, 0, 2 * L, nv) = P.block(0, ng, nv, 2 * L).transpose();
  P.block(nv, ng, nF, 2 * L) = P.block(ng, nv, 2 * L, nF).transpose();

  // The submap's features as the global map keeps them.
  const Pose2 X_WB(base(0), base(1), base(2));
  for (int k = 0; k < L; ++k) {
    const FeatureType type = s.feature_type(k);
    map->types.push_back(type);
    map->ids.push_back(-1);  // given below if the feature stays
    if (type == FeatureType::kLine) {
      const Eigen::Vector2d line_B = s.feature(k);
      const Eigen::Vector2d line_W = x.segment<2>(ng + 2 * k);
      map->segments.push_back(
          SegmentFromPoints(line_W, X_WB * PointOnLine(line_B, submap.segment(k).s_min),
                            X_WB * PointOnLine(line_B, submap.segment(k).s_max)));
      map->facing.push_back(Facing(line_B, submap.seen_side(k), base(2)));
    } else {
      map->segments.push_back({});
      map->facing.push_back(std::numeric_limits<double>::quiet_NaN());
    }
  }
  const auto index = [&](int k) { return nv + 2 * k; };

  // 4. Candidate pairs (submap feature a, global feature b) inside the gate,
  // matched closest first.
  std::vector<std::tuple<double, int, int>> pairs;
  for (int a = Lg; a < Lg + L; ++a) {
    const int ia = index(a);
    const Eigen::Vector2d f_a = x.segment<2>(ia);
    const Eigen::Matrix2d P_aa = P.block<2, 2>(ia, ia);
    for (int b = 0; b < Lg; ++b) {
      if (map->types[b] != map->types[a]) continue;
      const int ib = index(b);
      const Eigen::Vector2d f_b = x.segment<2>(ib);
      if (map->types[a] == FeatureType::kLine) {
        const double fa = map->facing[a];
        const double fb = map->facing[b];
        if (!std::isnan(fa) && !std::isnan(fb) && std::cos(fa - fb) <= 0.0) continue;
        if (!SegmentsMeet(f_a, map->segments[a], f_b, map->segments[b], max_segment_gap_m)) {
          continue;
        }
      }
      Eigen::Matrix2d A;
      const Eigen::Vector2d d = Difference(map->types[a], f_a, f_b, &A);
      const Eigen::Matrix2d P_ab = P.block<2, 2>(ia, ib);
      const Eigen::Matrix2d S = A * P_aa * A.transpose() + P.block<2, 2>(ib, ib) -
                                A * P_ab - P_ab.transpose() * A.transpose();
      const double d2 = d.dot(S.ldlt().solve(d));
      if (d2 < gate) pairs.emplace_back(d2, a, b);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> match(Lg + L, -1);
  std::vector<bool> taken(Lg, false);
  std::vector<std::pair<int, int>> matches;
  for (const auto& [d2, a, b] : pairs) {
    if (match[a] >= 0 || taken[b]) continue;
    match[a] = b;
    taken[b] = true;
    matches.emplace_back(a, b);
  }

  // 5. Fuse the matches: one batch update with the constraints A f_a - f_b = 0.
  JoinReport report;
  report.num_matched = static_cast<int>(matches.size());
  report.num_new = L - report.num_matched;
  report.state_size = n;
  const int m = static_cast<int>(matches.size());
  if (m > 0) {
    Eigen::MatrixXd PHt(n, 2 * m);
    Eigen::VectorXd nu(2 * m);
    std::vector<Eigen::Matrix2d> As(m);
    for (int i = 0; i < m; ++i) {
      const auto [a, b] = matches[i];
      nu.segment<2>(2 * i) =
          -Difference(map->types[a], x.segment<2>(index(a)), x.segment<2>(index(b)), &As[i]);
      PHt.middleCols<2>(2 * i) =
          P.middleCols<2>(index(a)) * As[i].transpose() - P.middleCols<2>(index(b));
    }
    // H P H^T: the rows of P H^T at each constraint's entries.
    Eigen::MatrixXd S(2 * m, 2 * m);
    for (int i = 0; i < m; ++i) {
      const auto [a, b] = matches[i];
      S.middleRows<2>(2 * i) =
          As[i] * PHt.middleRows<2>(index(a)) - PHt.middleRows<2>(index(b));
    }
    S = 0.5 * (S + S.transpose()).eval();
    // A hard constraint, kept positive definite where constraints are
    // redundant (a corner made from two lines that match too).
    S.diagonal().array() += kConstraintVariance;
    const Eigen::LLT<Eigen::MatrixXd> llt(S);
    MJSLAM_CHECK(llt.info() == Eigen::Success);
    const Eigen::MatrixXd W =
        llt.matrixU().solve(Eigen::MatrixXd::Identity(2 * m, 2 * m));  // S^-1 = W W^T
    // K nu = V W^T nu and P <- P - V V^T, with V = P H^T W.
    const Eigen::MatrixXd V = PHt * W;
    x.noalias() += V * (W.transpose() * nu);
    P.selfadjointView<Eigen::Lower>().rankUpdate(V, -1.0);
    P.triangularView<Eigen::StrictlyUpper>() = P.transpose().eval();
    x(2) = WrapAngle(x(2));
  }

  // 6. Keep the global features and the submap's unmatched ones; a matched
  // line's segment grows by its submap copy's.
  std::vector<int> keep;  // state entries
  for (int i = 0; i < nv; ++i) keep.push_back(i);
  JoinedMap joined;
  joined.calibration_size = nc;
  for (int k = 0; k < Lg + L; ++k) {
    const int ik = index(k);
    if (map->types[k] == FeatureType::kLine) {
      // The canonical form; a flipped line's direction, and so its
      // segment's positions, reverse.
      Eigen::Matrix2d C;
      x.segment<2>(ik) = CanonicalLine(x.segment<2>(ik), &C);
      if (C(0, 0) < 0.0) {
        const LineSegment seg = map->segments[k];
        map->segments[k] = {-seg.s_max, -seg.s_min};
      }
    }
    if (k >= Lg && match[k] >= 0) continue;
    keep.push_back(ik);
    keep.push_back(ik + 1);
    joined.types.push_back(map->types[k]);
    joined.ids.push_back(k < Lg ? map->ids[k] : (*next_id)++);
    joined.segments.push_back(map->segments[k]);
    joined.facing.push_back(map->facing[k]);
  }
  for (const auto& [a, b] : matches) {
    if (map->types[a] != FeatureType::kLine) continue;
    const Eigen::Vector2d line_a = x.segment<2>(index(a));
    const Eigen::Vector2d line_b = x.segment<2>(index(b));
    // b is global: its index in `joined` is b (global features come first).
    joined.segments[b] = ExtendSegment(joined.segments[b], line_b,
                                       PointOnLine(line_a, map->segments[a].s_min),
                                       PointOnLine(line_a, map->segments[a].s_max));
  }
  const int kept = static_cast<int>(keep.size());
  joined.mean.resize(kept);
  joined.covariance.resize(kept, kept);
  for (int j = 0; j < kept; ++j) {
    joined.mean(j) = x(keep[j]);
    for (int i = 0; i < kept; ++i) joined.covariance(i, j) = P(keep[i], keep[j]);
  }
  *map = std::move(joined);
  return report;
}

SubmapFilter::SubmapFilter(const FilterSettings& settings, const Pose2& X_WR0, const Pose2& X_RS,
                           Rng rng)
    : params_(settings.slam.ekf),
      mode_(CorrectionModeFromName(settings.filter.update)),
      X_RS_(X_RS),
      rng_(std::move(rng)),
      odometry_(PredictsFromOdometry(settings.slam.ekf.process_model)),
      max_features_(settings.filter.submap_max_features),
      gate_(ChiSquare2Quantile(settings.slam.ekf.gate_probability)) {
  if (max_features_ < 1) {
    throw ParamError("submap_max_features: expected a value >= 1 (got " +
                     std::to_string(max_features_) + ")");
  }
  // The global map: the base at the initial pose, and the self-calibration's
  // prior, which the first submap starts from.
  StartSubmap(nullptr);
  const SlamState& s = submap_->slam_state();
  const int nc = s.calibrated() ? SlamState::kCalibrationSize : 0;
  global_.calibration_size = nc;
  global_.mean = Eigen::VectorXd::Zero(3 + nc);
  global_.mean.head<3>() = Eigen::Vector3d(X_WR0.x, X_WR0.y, X_WR0.theta);
  global_.covariance = Eigen::MatrixXd::Zero(3 + nc, 3 + nc);
  const double sp = params_.initial_position_std_m;
  const double sh = params_.initial_heading_std_rad;
  global_.covariance.topLeftCorner<3, 3>() =
      Eigen::Vector3d(sp * sp, sp * sp, sh * sh).asDiagonal();
  if (nc > 0) {
    global_.mean.tail(nc) = s.calibration();
    global_.covariance.bottomRightCorner(nc, nc) = s.covariance().block(3, 3, nc, nc);
    submap_->StartCalibrationFrom(global_.mean.tail(nc),
                                  global_.covariance.bottomRightCorner(nc, nc));
  }
}

void SubmapFilter::StartSubmap(const SensorRecord* record) {
  EkfParams params = params_;
  params.initial_position_std_m = 0.0;
  params.initial_heading_std_rad = 0.0;
  submap_ = std::make_unique<EkfSlam>(params, mode_, Pose2(), X_RS_,
                                      rng_.Fork("submap." + std::to_string(num_joins_)));
  const int nc = global_.calibration_size;
  if (record != nullptr && nc > 0) {
    // The self-calibration goes on from the global map's estimate, shared.
    submap_->StartCalibrationFrom(global_.mean.segment(3, nc),
                                  global_.covariance.block(3, 3, nc, nc));
  }
  if (record != nullptr) {
    // The reference of the next increment, with no motion of its own.
    SensorRecord reference = *record;
    reference.dt_s = 0.0;
    submap_->Step(reference, nullptr);
  }
}

StepReport SubmapFilter::Step(const SensorRecord& record, const ScanFeatures* features) {
  StepReport report;
  double cost_n2 = 0.0;
  if (features != nullptr && submap_->num_features() >= max_features_) {
    // The full submap moves to this record and is joined; the new one
    // starts here and takes the scan, so that it sees its features from
    // its origin and each scan enters one submap only.
    submap_->Step(record, nullptr);
    const JoinReport join =
        JoinSubmap(*submap_, gate_, params_.line_match_max_gap_m, &global_, &next_id_);
    const double size = join.state_size;
    cost_n2 += join.num_matched * size * size;
    ++num_joins_;
    StartSubmap(&record);
    SensorRecord here = record;
    here.dt_s = 0.0;
    report = submap_->Step(here, features);
  } else {
    report = submap_->Step(record, features);
  }
  const double n = submap_->slam_state().dimension();
  report.correction_cost_n2 = cost_n2 + report.num_updated * n * n;
  report.num_features = num_features();
  return report;
}

void SubmapFilter::Base(Eigen::Vector3d* x_B, Eigen::Matrix3d* P_B,
                        Eigen::Matrix3d* C_BR) const {
  // The base given the submap's estimate of the shared calibration (as
  // JoinSubmap's step 1 would update it), and its covariance with x_BR.
  *x_B = global_.mean.head<3>();
  *P_B = global_.covariance.topLeftCorner<3, 3>();
  C_BR->setZero();
  const SharedPart shared = SharedPartOf(*submap_, global_);
  if (shared.entries.empty()) return;
  const SlamState& s = submap_->slam_state();
  const Eigen::MatrixXd M_B = shared.M.leftCols<3>();
  *x_B += M_B.transpose() * shared.delta;
  *P_B -= M_B.transpose() * shared.D * M_B;
  Eigen::MatrixXd P_0R(shared.entries.size(), 3);
  for (std::size_t i = 0; i < shared.entries.size(); ++i) {
    P_0R.row(i) = s.covariance().block(s.SharedIndex() + shared.entries[i], 0, 1, 3);
  }
  *C_BR = M_B.transpose() * P_0R;
}

Pose2 SubmapFilter::X_WR() const {
  Eigen::Vector3d x_B;
  Eigen::Matrix3d P_B;
  Eigen::Matrix3d C_BR;
  Base(&x_B, &P_B, &C_BR);
  return Pose2(x_B(0), x_B(1), x_B(2)) * submap_->X_WR();
}

Eigen::Matrix3d SubmapFilter::pose_covariance() const {
  Eigen::Vector3d x_B;
  Eigen::Matrix3d P_B;
  Eigen::Matrix3d C_BR;
  Base(&x_B, &P_B, &C_BR);
  const Pose2 X_BR = submap_->X_WR();
  const double c = std::cos(x_B(2));
  const double sn = std::sin(x_B(2));
  Eigen::Matrix3d J_base = Eigen::Matrix3d::Identity();
  J_base(0, 2) = -sn * X_BR.x - c * X_BR.y;
  J_base(1, 2) = c * X_BR.x - sn * X_BR.y;
  Eigen::Matrix3d J_pose = Eigen::Matrix3d::Identity();
  J_pose.topLeftCorner<2, 2>() << c, -sn, sn, c;
  const Eigen::Matrix3d cross = J_base * C_BR * J_pose.transpose();
  const Eigen::Matrix3d P = J_base * P_B * J_base.transpose() +
                            J_pose * submap_->pose_covariance() * J_pose.transpose() + cross +
                            cross.transpose();
  return 0.5 * (P + P.transpose());
}

std::vector<MapFeature> SubmapFilter::Map() const {
  JoinedMap joined = global_;
  int next_id = next_id_;
  JoinSubmap(*submap_, gate_, params_.line_match_max_gap_m, &joined, &next_id);
  std::vector<MapFeature> map;
  map.reserve(joined.num_features());
  for (int k = 0; k < joined.num_features(); ++k) {
    MapFeature feature;
    feature.id = joined.ids[k];
    feature.type = joined.types[k];
    const int i = 3 + joined.calibration_size + 2 * k;
    const Eigen::Vector2d params = joined.mean.segment<2>(i);
    const Eigen::Matrix2d covariance = joined.covariance.block<2, 2>(i, i);
    if (feature.type == FeatureType::kLine) {
      Eigen::Matrix2d J;
      feature.params = CanonicalLine(params, &J);
      feature.covariance = J * covariance * J.transpose();
      feature.has_segment = true;
      feature.p_WA = PointOnLine(params, joined.segments[k].s_min);
      feature.p_WB = PointOnLine(params, joined.segments[k].s_max);
    } else {
      feature.params = params;
      feature.covariance = covariance;
    }
    map.push_back(feature);
  }
  return map;
}

int SubmapFilter::num_features() const {
  return global_.num_features() + submap_->num_features();
}

}  // namespace mjslam::slam
