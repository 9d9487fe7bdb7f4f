#include "slam/submap_join.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <utility>

#include <Eigen/Eigenvalues>

#include "common/angles.h"
#include "common/check.h"
#include "slam/data_association.h"
#include "slam/observation_models.h"

namespace mjslam::slam {
namespace {

// The smallest eigenvalue of the shared part's prior covariance, scaled to a
// unit diagonal, that its update uses: a smaller one is a function of the
// other entries.
constexpr double kMinSharedEigenvalue = 1e-9;

// The variance a join adds to the first-order S of a pair's difference, in
// its gate and in its fusion: 1 mm (and 0.1 mrad), the order of a feature's
// error when seen once. The first-order S misses the linearisation's residue,
// which matters where the two copies are nearly one function of the same
// entries (a corner of two shared lines, a wall the submap saw only through
// its shared part): there S is near 0, and a hard constraint would turn a
// residue of micrometres into a correction of many standard deviations.
const Eigen::Vector2d kLineResidue(1e-6, 1e-8);
const Eigen::Vector2d kCornerResidue(1e-6, 1e-6);

const Eigen::Vector2d& Residue(FeatureType type) {
  return type == FeatureType::kLine ? kLineResidue : kCornerResidue;
}

// Calls pair(i, j) for every i > j < n, tile by tile: the global map's
// covariance is too large for the cache, and reading it transposed by whole
// columns missed it.
template <typename Pair>
void ForLowerPairsByTiles(int n, Pair pair) {
  constexpr int kTile = 64;
  for (int j0 = 0; j0 < n; j0 += kTile) {
    for (int i0 = j0; i0 < n; i0 += kTile) {
      for (int j = j0; j < std::min(j0 + kTile, n); ++j) {
        for (int i = std::max(i0, j + 1); i < std::min(i0 + kTile, n); ++i) pair(i, j);
      }
    }
  }
}

// P <- (P + P^T) / 2: the same values as the expression on the whole
// matrix (each pair's sum is formed once; the diagonal stays).
void Symmetrize(Eigen::MatrixXd* P) {
  ForLowerPairsByTiles(static_cast<int>(P->rows()), [P](int i, int j) {
    const double mean = 0.5 * ((*P)(i, j) + (*P)(j, i));
    (*P)(i, j) = mean;
    (*P)(j, i) = mean;
  });
}

// The strictly upper triangle of P <- that of P^T.
void MirrorLower(Eigen::MatrixXd* P) {
  ForLowerPairsByTiles(static_cast<int>(P->rows()), [P](int i, int j) { (*P)(j, i) = (*P)(i, j); });
}

// The quantities a join carries to W, y = [x_B', c, f_k...] of the submap
// (c: its nc self-calibration entries as they are now; f_k its features
// listed), with their Jacobians by the old base x_B and by the submap's
// entries [x_BR, c, f_k...].
struct Transformed {
  Eigen::VectorXd y;
  Eigen::MatrixXd J_base;    // ny x 3
  Eigen::MatrixXd J_submap;  // ny x ny
};

Transformed ToWorld(const SlamState& s, int nc, const std::vector<int>& features,
                    const Eigen::Vector3d& base) {
  const int L = static_cast<int>(features.size());
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
  for (int i = 0; i < L; ++i) {
    const int k = features[i];
    const int row = 3 + nc + 2 * i;
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
    const Eigen::Vector2d line_W(f.x() + base(0) * ca + base(1) * sa, al);
    t.y.segment<2>(row) = CanonicalLine(line_W, &C);
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
  Eigen::Vector2d aligned = f_a;
  if (AlignLineToObservation(f_b, &aligned)) (*A)(0, 0) = -1.0;
  return -Innovation(f_b, aligned);
}

// Whether the seen segments of lines a and b (in W) are within `max_gap`
// of each other along line b.
bool SegmentsMeet(const Eigen::Vector2d& line_a, const LineSegment& seg_a,
                  const Eigen::Vector2d& line_b, const LineSegment& seg_b, double max_gap) {
  if (max_gap <= 0.0) return true;
  const LineSegment a_on_b = SegmentFromPoints(line_b, PointOnLine(line_a, seg_a.s_min),
                                               PointOnLine(line_a, seg_a.s_max));
  return SegmentGap(a_on_b, seg_b) <= max_gap;
}

}  // namespace

SubmapLink LinkOf(const JoinedMap& map, const std::vector<int>& global_features) {
  const int nc = map.calibration_size;
  const int ng = static_cast<int>(map.mean.size());
  const int nC = nc + 2 * static_cast<int>(global_features.size());
  SubmapLink link;
  link.global_features = global_features;
  link.value.resize(nC);
  link.G.assign(nC, {});
  for (int i = 0; i < nc; ++i) {
    link.value(i) = map.mean(3 + i);
    link.G[i] = {{3 + i, 1.0}};
  }
  const Eigen::Vector3d base = map.mean.head<3>();
  const double c = std::cos(base(2));
  const double sn = std::sin(base(2));
  for (std::size_t j = 0; j < global_features.size(); ++j) {
    const int g = global_features[j];
    const int col = 3 + nc + 2 * g;
    const int row = nc + 2 * static_cast<int>(j);
    const Eigen::Vector2d f = map.mean.segment<2>(col);
    if (map.types[g] == FeatureType::kCorner) {
      // p_B = R^T (p_W - t).
      const Eigen::Vector2d d = f - base.head<2>();
      link.value.segment<2>(row) << c * d.x() + sn * d.y(), -sn * d.x() + c * d.y();
      link.G[row] = {{col, c}, {col + 1, sn}, {0, -c}, {1, -sn}, {2, -sn * d.x() + c * d.y()}};
      link.G[row + 1] = {
          {col, -sn}, {col + 1, c}, {0, sn}, {1, -c}, {2, -c * d.x() - sn * d.y()}};
      continue;
    }
    // Line: al_B = al_W - th_B, r_B = r_W - t . n(al_W), then canonical.
    const double ca = std::cos(f.y());
    const double sa = std::sin(f.y());
    Eigen::Matrix2d C;
    link.value.segment<2>(row) =
        CanonicalLine(Eigen::Vector2d(f.x() - base(0) * ca - base(1) * sa, f.y() - base(2)), &C);
    const double k = C(0, 0);  // -1 where the form flipped
    link.G[row] = {{col, k}, {col + 1, k * (base(0) * sa - base(1) * ca)}, {0, -k * ca},
                   {1, -k * sa}};
    link.G[row + 1] = {{col + 1, 1.0}, {2, -1.0}};
  }
  // G P and G P G^T.
  link.GP = Eigen::MatrixXd::Zero(nC, ng);
  for (int r = 0; r < nC; ++r) {
    for (const auto& [col, v] : link.G[r]) link.GP.row(r) += v * map.covariance.row(col);
  }
  link.P_CC = Eigen::MatrixXd::Zero(nC, nC);
  for (int r = 0; r < nC; ++r) {
    for (const auto& [col, v] : link.G[r]) link.P_CC.col(r) += v * link.GP.col(col);
  }
  link.P_CC = 0.5 * (link.P_CC + link.P_CC.transpose()).eval();
  return link;
}

namespace {

// The shared part C as the submap now knows it, against the link: the
// rows of C that are estimated (a prior variance > 0, and the feature still
// in the submap), their state indices in the submap, delta = C' - C and
// D = P_CC - P'_CC over them.
struct SharedPart {
  std::vector<int> rows;
  std::vector<int> submap_indices;
  Eigen::VectorXd delta;
  // +1, or -1 on the r row of a line whose form flipped in the submap.
  Eigen::VectorXd sign;
  Eigen::MatrixXd D;
  // M = P_CC^-1 G P over the rows: all of the global map, or its first
  // three columns (the base).
  Eigen::MatrixXd M;
};

// P_CC^+ over `rows` of the link's P_CC: P_CC is singular where C holds a
// function of its other entries (a corner of two shared lines); neither the
// prior nor the submap can move that direction, so the pseudo-inverse leaves
// it out. Scaled to a unit diagonal, so that the cut does not depend on units.
Eigen::MatrixXd SharedPseudoInverse(const SubmapLink& link, const std::vector<int>& rows) {
  const int na = static_cast<int>(rows.size());
  Eigen::MatrixXd P_CC(na, na);
  for (int i = 0; i < na; ++i) {
    for (int j = 0; j < na; ++j) P_CC(i, j) = link.P_CC(rows[i], rows[j]);
  }
  const Eigen::VectorXd scale = P_CC.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scale.asDiagonal() * P_CC *
                                                               scale.asDiagonal());
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(na);
  for (int i = 0; i < na; ++i) {
    if (eigen.eigenvalues()(i) > kMinSharedEigenvalue) inverse(i) = 1.0 / eigen.eigenvalues()(i);
  }
  const Eigen::MatrixXd Q = scale.asDiagonal() * eigen.eigenvectors();
  return Q * inverse.asDiagonal() * Q.transpose();
}

SharedPart SharedPartOf(const EkfSlam& submap, const SubmapLink& link, bool base_only) {
  SharedPart shared;
  const SlamState& s = submap.slam_state();
  const int nC = static_cast<int>(link.value.size());
  const int nc = nC - 2 * static_cast<int>(link.global_features.size());
  std::vector<int> index(nC, -1);
  for (int i = 0; i < nc; ++i) index[i] = s.SharedIndex() + i;
  for (std::size_t j = 0; j < link.submap_ids.size(); ++j) {
    const int k = submap.IndexOfId(link.submap_ids[j]);
    if (k < 0) continue;
    index[nc + 2 * j] = s.FeatureIndex(k);
    index[nc + 2 * j + 1] = s.FeatureIndex(k) + 1;
  }
  for (int r = 0; r < nC; ++r) {
    if (index[r] >= 0 && link.P_CC(r, r) > 0.0) {
      shared.rows.push_back(r);
      shared.submap_indices.push_back(index[r]);
    }
  }
  const int na = static_cast<int>(shared.rows.size());
  if (na == 0) return shared;
  const auto P_sub = s.covariance();
  Eigen::MatrixXd P_CC(na, na);
  Eigen::MatrixXd P_new(na, na);
  Eigen::MatrixXd GP(na, base_only ? 3 : link.GP.cols());
  shared.delta.resize(na);
  shared.sign = Eigen::VectorXd::Ones(na);
  for (int i = 0; i < na; ++i) {
    const int r = shared.rows[i];
    const double value = s.mean()(shared.submap_indices[i]);
    shared.delta(i) = value - link.value(r);
    if (r >= nc && (r - nc) % 2 == 1) {
      // A line's angle: wrapped; a line whose form flipped in the submap
      // ((r, al) became (-r, al + pi), r crossing 0) is compared in the
      // link's form, its r row negated.
      shared.delta(i) = WrapAngle(shared.delta(i));
      if (std::abs(shared.delta(i)) > kPi / 2) {
        shared.delta(i) = WrapAngle(shared.delta(i) + kPi);
        shared.sign(i - 1) = -1.0;
        shared.delta(i - 1) = -s.mean()(shared.submap_indices[i - 1]) - link.value(r - 1);
      }
    }
    GP.row(i) = link.GP.row(r).head(GP.cols());
  }
  for (int i = 0; i < na; ++i) {
    for (int j = 0; j < na; ++j) {
      P_CC(i, j) = link.P_CC(shared.rows[i], shared.rows[j]);
      P_new(i, j) = shared.sign(i) * shared.sign(j) *
                    P_sub(shared.submap_indices[i], shared.submap_indices[j]);
    }
  }
  shared.D = P_CC - P_new;
  // M = P_CC^+ G P, P_CC^+ computed once per set of rows.
  if (link.pseudo_inverse_rows != shared.rows) {
    link.pseudo_inverse = SharedPseudoInverse(link, shared.rows);
    link.pseudo_inverse_rows = shared.rows;
  }
  shared.M = link.pseudo_inverse * GP;
  return shared;
}

}  // namespace

JoinReport JoinSubmap(const EkfSlam& submap, const SubmapLink& link, const EkfParams& params,
                      JoinedMap* map, int* next_id) {
  const double gate = ChiSquare2Quantile(params.gate_probability);
  const SlamState& s = submap.slam_state();
  const int nc = map->calibration_size;
  const int Lg = map->num_features();
  const int ng = 3 + nc + 2 * Lg;

  // 1. The shared part C (the self-calibration at the submap's start, c0,
  // and the features the submap started with) updates the global map
  // through its correlations with C: the map is independent of the submap
  // given C, so x += M^T delta, P -= M^T D M, and Cov(submap entry, map) =
  // P_(entry, C) M.
  const SharedPart shared = SharedPartOf(submap, link, false);
  const int na = static_cast<int>(shared.rows.size());
  Eigen::VectorXd xg = map->mean;
  Eigen::MatrixXd Pg = map->covariance;
  if (na > 0) {
    xg.noalias() += shared.M.transpose() * shared.delta;
    const Eigen::MatrixXd DM = shared.D * shared.M;
    Pg.noalias() -= shared.M.transpose() * DM;
    Symmetrize(&Pg);
  }
  const Eigen::Vector3d base = xg.head<3>();

  // 2. The submap's entries [x_BR, c, f_k...] (c: the current
  // self-calibration, if any; f_k the features it added), their covariance,
  // and their covariance with C.
  std::vector<int> own;  // the submap's features that are not shared
  std::vector<int> global_of_shared(s.num_features(), -1);
  for (std::size_t j = 0; j < link.submap_ids.size(); ++j) {
    const int k = submap.IndexOfId(link.submap_ids[j]);
    if (k >= 0) global_of_shared[k] = link.global_features[j];
  }
  for (int k = 0; k < s.num_features(); ++k) {
    if (global_of_shared[k] < 0) own.push_back(k);
  }
  const int L = static_cast<int>(own.size());
  std::vector<int> entries = {0, 1, 2};
  for (int i = 0; i < nc; ++i) entries.push_back(3 + i);
  for (const int k : own) {
    entries.push_back(s.FeatureIndex(k));
    entries.push_back(s.FeatureIndex(k) + 1);
  }
  const int ns = static_cast<int>(entries.size());
  const auto P_sub_full = s.covariance();
  Eigen::MatrixXd P_ss(ns, ns);
  Eigen::MatrixXd P_sC(ns, na);
  for (int i = 0; i < ns; ++i) {
    for (int j = 0; j < ns; ++j) P_ss(i, j) = P_sub_full(entries[i], entries[j]);
    for (int j = 0; j < na; ++j) {
      P_sC(i, j) = shared.sign(j) * P_sub_full(entries[i], shared.submap_indices[j]);
    }
  }

  // 3. Carried to W: y = [x_B', c, f_W...] from x_B and the submap's entries.
  const Transformed t = ToWorld(s, nc, own, base);
  const Eigen::MatrixXd JsP_sC = t.J_submap * P_sC;  // ny x na
  Eigen::MatrixXd P_yg = t.J_base * Pg.topRows<3>();
  if (na > 0) P_yg.noalias() += JsP_sC * shared.M;
  Eigen::MatrixXd P_yy = t.J_base * Pg.topLeftCorner<3, 3>() * t.J_base.transpose() +
                         t.J_submap * P_ss * t.J_submap.transpose();
  if (na > 0) {
    const Eigen::MatrixXd cross = t.J_base * shared.M.leftCols<3>().transpose() *
                                  JsP_sC.transpose();  // J_b Cov(x_B, s) J_s^T
    P_yy += cross + cross.transpose();
  }
  P_yy = 0.5 * (P_yy + P_yy.transpose()).eval();

  // The joined state [x_B', c, old features, the submap's own features];
  // the old base and C are left out.
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

  // The submap's own features as the global map keeps them.
  const Pose2 X_WB(base(0), base(1), base(2));
  for (int i = 0; i < L; ++i) {
    const int k = own[i];
    const FeatureType type = s.feature_type(k);
    map->types.push_back(type);
    map->ids.push_back(-1);  // given below if the feature stays
    if (type == FeatureType::kLine) {
      const Eigen::Vector2d line_B = s.feature(k);
      const Eigen::Vector2d line_W = x.segment<2>(ng + 2 * i);
      map->segments.push_back(
          SegmentFromPoints(line_W, X_WB * PointOnLine(line_B, submap.segment(k).s_min),
                            X_WB * PointOnLine(line_B, submap.segment(k).s_max)));
      map->facing.push_back(Facing(line_B, submap.seen_side(k), base(2)));
    } else {
      map->segments.push_back({});
      map->facing.push_back(std::numeric_limits<double>::quiet_NaN());
    }
  }
  // The shared lines' segments grow by what the submap saw of them.
  for (int k = 0; k < s.num_features(); ++k) {
    const int g = global_of_shared[k];
    if (g < 0 || s.feature_type(k) != FeatureType::kLine) continue;
    const Eigen::Vector2d line_B = s.feature(k);
    map->segments[g] = ExtendSegment(map->segments[g], xg.segment<2>(nv + 2 * g),
                                     X_WB * PointOnLine(line_B, submap.segment(k).s_min),
                                     X_WB * PointOnLine(line_B, submap.segment(k).s_max));
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
        if (!SegmentsMeet(f_a, map->segments[a], f_b, map->segments[b],
                          params.line_match_max_gap_m)) {
          continue;
        }
      }
      Eigen::Matrix2d A;
      const Eigen::Vector2d d = Difference(map->types[a], f_a, f_b, &A);
      const Eigen::Matrix2d P_ab = P.block<2, 2>(ia, ib);
      Eigen::Matrix2d S = A * P_aa * A.transpose() + P.block<2, 2>(ib, ib) - A * P_ab -
                          P_ab.transpose() * A.transpose();
      S += Residue(map->types[a]).asDiagonal();
      const double d2 = d.dot(S.ldlt().solve(d));
      if (d2 < gate) pairs.emplace_back(d2, a, b);
    }
  }
  // Each submap feature takes its nearest; a global feature may take
  // several (a wall the submap mapped twice, in pieces that its own
  // duplicate test had not yet joined).
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> match(Lg + L, -1);
  std::vector<std::pair<int, int>> matches;
  for (const auto& [d2, a, b] : pairs) {
    if (match[a] >= 0) continue;
    match[a] = b;
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
    // Each constraint with the gate's residue: S = W^-T W^-1, its eigenvalues
    // kept at or above the smallest residue (round-off can leave one below
    // where constraints are redundant: a corner made from two lines that
    // match too).
    for (int i = 0; i < m; ++i) {
      S.block<2, 2>(2 * i, 2 * i) += Residue(map->types[matches[i].first]).asDiagonal();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(S);
    const Eigen::VectorXd inverse_sqrt =
        eigen.eigenvalues().cwiseMax(kLineResidue.minCoeff()).array().rsqrt();
    const Eigen::MatrixXd W = eigen.eigenvectors() * inverse_sqrt.asDiagonal();  // S^-1 = W W^T
    // K nu = V W^T nu and P <- P - V V^T, with V = P H^T W.
    const Eigen::MatrixXd V = PHt * W;
    x.noalias() += V * (W.transpose() * nu);
    P.selfadjointView<Eigen::Lower>().rankUpdate(V, -1.0);
    MirrorLower(&P);
    x(2) = WrapAngle(x(2));
  }

  // 6. Keep the global features and the submap's unmatched ones; a matched
  // line's segment grows by its submap copy's.
  std::vector<int> keep;  // state entries
  for (int i = 0; i < nv; ++i) keep.push_back(i);
  std::vector<int> own_index(L, -1);  // each own feature's index in the joined map
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
    if (k >= Lg) {
      own_index[k - Lg] = match[k] >= 0 ? match[k] : joined.num_features();
      if (match[k] >= 0) continue;
    }
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
  report.global_index = global_of_shared;
  for (int i = 0; i < L; ++i) report.global_index[own[i]] = own_index[i];
  return report;
}

BaseEstimate BaseGivenSubmap(const EkfSlam& submap, const SubmapLink& link, const JoinedMap& map) {
  BaseEstimate base;
  base.x_B = map.mean.head<3>();
  base.P_B = map.covariance.topLeftCorner<3, 3>();
  base.C_BR.setZero();
  const SharedPart shared = SharedPartOf(submap, link, true);
  if (shared.rows.empty()) return base;
  const SlamState& s = submap.slam_state();
  base.x_B += shared.M.transpose() * shared.delta;
  base.P_B -= shared.M.transpose() * shared.D * shared.M;
  Eigen::MatrixXd P_CR(shared.rows.size(), 3);
  for (std::size_t i = 0; i < shared.rows.size(); ++i) {
    P_CR.row(i) = shared.sign(i) * s.covariance().block(shared.submap_indices[i], 0, 1, 3);
  }
  base.C_BR = shared.M.transpose() * P_CR;
  return base;
}

}  // namespace mjslam::slam
