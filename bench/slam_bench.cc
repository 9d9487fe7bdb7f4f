// Benchmarks of the EKF-SLAM kernels (slam/README.md, "Cost"): for maps of
// 25 to 400 features, one sparse correction, the selection criterion of 20
// candidates, a whole classical and a whole selective step with 15 matched
// observations, a dense (I - K H) P reference, and one pass over P (its sum
// and a copy) to compare against; plus feature extraction on one scan; and
// the classical step against (number of corrections) x (one pass over P),
// measured side by side at 600 features (BM_ClassicalStepOverPasses).
//
//   build-ekf/bench/mjslam_bench --benchmark_min_time=0.2

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>
#include <benchmark/benchmark.h>

#include "common/angles.h"
#include "common/cpu_time.h"
#include "common/laser_scan.h"
#include "common/pose2.h"
#include "common/records.h"
#include "common/rng.h"
#include "slam/corrections.h"
#include "slam/ekf_slam.h"
#include "slam/feature_extraction.h"
#include "slam/observations.h"
#include "slam/slam_params.h"
#include "slam/submap_filter.h"

namespace mjslam::slam {
namespace {

constexpr int kMatchedPerStep = 15;
constexpr int kCandidates = 20;

// Observations of map features k = 0, 1, ... as predicted by the filter, with
// a little noise: they all pass the gate. Lines get a 2 m seen segment.
ScanFeatures ObservationsOf(const EkfSlam& filter, int count, Rng* rng) {
  ScanFeatures features;
  const SlamState& state = filter.slam_state();
  for (int k = 0; k < count && k < state.num_features(); ++k) {
    const Eigen::Vector2d h = state.Measure(k).h;
    if (state.feature_type(k) == FeatureType::kLine) {
      LineObservation line;
      line.rho_m = h.x() + rng->Gaussian(0.0, 0.005);
      line.alpha_rad = h.y() + rng->Gaussian(0.0, 0.002);
      line.covariance = Eigen::Vector2d(0.01 * 0.01, 0.004 * 0.004).asDiagonal();
      const Eigen::Vector2d normal(std::cos(line.alpha_rad), std::sin(line.alpha_rad));
      const Eigen::Vector2d along(-normal.y(), normal.x());
      line.p_SA = line.rho_m * normal - along;
      line.p_SB = line.rho_m * normal + along;
      features.lines.push_back(line);
    } else {
      CornerObservation corner;
      corner.range_m = h.x() + rng->Gaussian(0.0, 0.01);
      corner.bearing_rad = h.y() + rng->Gaussian(0.0, 0.003);
      corner.covariance = Eigen::Vector2d(0.02 * 0.02, 0.006 * 0.006).asDiagonal();
      corner.p_SC = corner.range_m *
                    Eigen::Vector2d(std::cos(corner.bearing_rad), std::sin(corner.bearing_rad));
      features.corners.push_back(corner);
    }
  }
  return features;
}

// A filter with `num_features` features (alternating lines and corners, all
// distinct), made dense and correlated by an uncertain start and a few steps
// that re-observe some of them.
EkfSlam MakeFilter(int num_features, CorrectionMode mode) {
  EkfParams params;
  params.initial_position_std_m = 0.05;
  params.initial_heading_std_rad = 0.02;
  EkfSlam filter(params, mode, Pose2(0.0, 0.0, 0.0), Pose2(0.1, 0.0, 0.0));

  // Every feature seen once from the start pose: lines at distinct (rho,
  // alpha), corners on a spiral; all far apart in Mahalanobis distance.
  ScanFeatures first;
  for (int k = 0; k < num_features; ++k) {
    const double angle = WrapAngle(0.7 * k);
    const double distance = 2.0 + 0.05 * k;
    if (k % 2 == 0) {
      LineObservation line;
      line.rho_m = distance;
      line.alpha_rad = angle;
      line.covariance = Eigen::Vector2d(0.01 * 0.01, 0.004 * 0.004).asDiagonal();
      const Eigen::Vector2d normal(std::cos(angle), std::sin(angle));
      const Eigen::Vector2d along(-normal.y(), normal.x());
      line.p_SA = distance * normal - along;
      line.p_SB = distance * normal + along;
      first.lines.push_back(line);
    } else {
      CornerObservation corner;
      corner.range_m = distance;
      corner.bearing_rad = angle;
      corner.covariance = Eigen::Vector2d(0.02 * 0.02, 0.006 * 0.006).asDiagonal();
      corner.p_SC = distance * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      first.corners.push_back(corner);
    }
  }
  SensorRecord record;
  filter.Step(record, &first);

  // A few noisy re-observations spread the correlations through P.
  Rng rng(7);
  record.dt_s = 0.1;
  for (int step = 0; step < 3; ++step) {
    const ScanFeatures again = ObservationsOf(filter, num_features, &rng);
    filter.Step(record, &again);
  }
  return filter;
}

void MapSizes(benchmark::internal::Benchmark* b) {
  for (const int size : {25, 50, 100, 200, 400}) b->Arg(size);
}

void ReportSize(benchmark::State& state, const SlamState& slam) {
  state.counters["features"] = slam.num_features();
  state.counters["n"] = slam.dimension();
}

// Reference: one read pass over P (the sum of its n x n entries).
void BM_PassOverP_Sum(benchmark::State& state) {
  const EkfSlam filter = MakeFilter(static_cast<int>(state.range(0)), CorrectionMode::kClassical);
  const SlamState& slam = filter.slam_state();
  for (auto _ : state) {
    benchmark::DoNotOptimize(slam.covariance().sum());
  }
  ReportSize(state, slam);
}
BENCHMARK(BM_PassOverP_Sum)->Apply(MapSizes)->Unit(benchmark::kMicrosecond);

// Reference: one read + write pass over P (a copy into a preallocated matrix).
void BM_PassOverP_Copy(benchmark::State& state) {
  const EkfSlam filter = MakeFilter(static_cast<int>(state.range(0)), CorrectionMode::kClassical);
  const SlamState& slam = filter.slam_state();
  Eigen::MatrixXd copy(slam.dimension(), slam.dimension());
  for (auto _ : state) {
    copy = slam.covariance();
    benchmark::DoNotOptimize(copy.data());
    benchmark::ClobberMemory();
  }
  ReportSize(state, slam);
}
BENCHMARK(BM_PassOverP_Copy)->Apply(MapSizes)->Unit(benchmark::kMicrosecond);

// One sparse sequential correction (SlamState::Update): 5 columns of P and a
// symmetric rank-2 downdate.
void BM_Correction(benchmark::State& state) {
  const EkfSlam filter = MakeFilter(static_cast<int>(state.range(0)), CorrectionMode::kClassical);
  SlamState slam = filter.slam_state();
  const int k = slam.num_features() / 2;
  const Eigen::Vector2d z = slam.Measure(k).h + Eigen::Vector2d(0.005, 0.002);
  const Eigen::Matrix2d R = Eigen::Vector2d(1e-4, 1e-5).asDiagonal();
  for (auto _ : state) {
    slam.Update(k, z, R);
    benchmark::ClobberMemory();
  }
  ReportSize(state, slam);
}
BENCHMARK(BM_Correction)->Apply(MapSizes)->Unit(benchmark::kMicrosecond);

// The dense textbook correction, for comparison: K from P H^T and
// P <- (I - K H) P as an n x n product (O(n^3)).
void BM_DenseCorrectionReference(benchmark::State& state) {
  const EkfSlam filter = MakeFilter(static_cast<int>(state.range(0)), CorrectionMode::kClassical);
  const SlamState& slam = filter.slam_state();
  const int n = slam.dimension();
  const int k = slam.num_features() / 2;
  const SlamState::Measurement m = slam.Measure(k);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2, n);
  H.leftCols<3>() = m.H_pose;
  H.middleCols<2>(slam.FeatureIndex(k)) = m.H_feature;
  const Eigen::Matrix2d R = Eigen::Vector2d(1e-4, 1e-5).asDiagonal();
  const Eigen::MatrixXd P = slam.covariance();
  Eigen::MatrixXd P_new(n, n);
  Eigen::MatrixXd I_KH(n, n);
  for (auto _ : state) {
    const Eigen::MatrixXd PHt = P * H.transpose();
    const Eigen::Matrix2d S = H * PHt + R;
    const Eigen::MatrixXd K = PHt * S.inverse();
    I_KH.setIdentity();
    I_KH.noalias() -= K * H;
    P_new.noalias() = I_KH * P;
    benchmark::DoNotOptimize(P_new.data());
    benchmark::ClobberMemory();
  }
  ReportSize(state, slam);
}
BENCHMARK(BM_DenseCorrectionReference)->Apply(MapSizes)->Unit(benchmark::kMicrosecond);

// The selection criterion of Algorithm 2 for 20 candidates (one round).
void BM_SelectionCriterion20(benchmark::State& state) {
  const EkfSlam filter = MakeFilter(static_cast<int>(state.range(0)), CorrectionMode::kSelective);
  const SlamState& slam = filter.slam_state();
  std::vector<MatchedObservation> candidates;
  for (int k = 0; k < kCandidates; ++k) {
    const Eigen::Vector2d z = slam.Measure(k).h;
    candidates.push_back({k, z, Eigen::Vector2d(1e-4, 1e-5).asDiagonal()});
  }
  for (auto _ : state) {
    double best = 1e300;
    for (const MatchedObservation& candidate : candidates) {
      best = std::min(best, SelectionCriterion(slam, candidate));
    }
    benchmark::DoNotOptimize(best);
  }
  ReportSize(state, slam);
}
BENCHMARK(BM_SelectionCriterion20)->Apply(MapSizes)->Unit(benchmark::kMicrosecond);

// A whole EkfSlam::Step: prediction, association of 15 observations against
// the whole map, correction, secondary map. The robot stands still, so the
// same observations match every time.
void StepBenchmark(benchmark::State& state, CorrectionMode mode) {
  EkfSlam filter = MakeFilter(static_cast<int>(state.range(0)), mode);
  Rng rng(11);
  const ScanFeatures features = ObservationsOf(filter, kMatchedPerStep, &rng);
  SensorRecord record;
  record.dt_s = 0.1;
  StepReport report;
  for (auto _ : state) {
    report = filter.Step(record, &features);
    benchmark::ClobberMemory();
  }
  ReportSize(state, filter.slam_state());
  state.counters["matched"] = report.num_matched;
  state.counters["updated"] = report.num_updated;
}

void BM_ClassicalStep(benchmark::State& state) { StepBenchmark(state, CorrectionMode::kClassical); }
BENCHMARK(BM_ClassicalStep)->Apply(MapSizes)->Unit(benchmark::kMicrosecond);

void BM_SelectiveStep(benchmark::State& state) { StepBenchmark(state, CorrectionMode::kSelective); }
BENCHMARK(BM_SelectiveStep)->Apply(MapSizes)->Unit(benchmark::kMicrosecond);

// The classical step against its floor: each iteration times one classical
// step (15 matched observations, each a sequential correction) and one read
// pass over P (its sum), alternately, so both see the same machine state,
// in thread CPU time (other jobs on the machine do not count).
// Counters: the mean of each, the corrections per step, and
// ratio = step / (corrections x pass); the target is ratio <= 2.
void BM_ClassicalStepOverPasses(benchmark::State& state) {
  EkfSlam filter = MakeFilter(static_cast<int>(state.range(0)), CorrectionMode::kClassical);
  Rng rng(11);
  const ScanFeatures features = ObservationsOf(filter, kMatchedPerStep, &rng);
  SensorRecord record;
  record.dt_s = 0.1;
  StepReport report;
  double step_s = 0.0;
  double pass_s = 0.0;
  for (auto _ : state) {
    const double t0 = ThreadCpuSeconds();
    report = filter.Step(record, &features);
    benchmark::ClobberMemory();
    const double t1 = ThreadCpuSeconds();
    benchmark::DoNotOptimize(filter.slam_state().covariance().sum());
    const double t2 = ThreadCpuSeconds();
    step_s += t1 - t0;
    pass_s += t2 - t1;
  }
  const double n = static_cast<double>(state.iterations());
  ReportSize(state, filter.slam_state());
  state.counters["step_us"] = 1e6 * step_s / n;
  state.counters["pass_us"] = 1e6 * pass_s / n;
  state.counters["corrections"] = report.num_updated;
  state.counters["ratio"] = step_s / (report.num_updated * pass_s);
}
BENCHMARK(BM_ClassicalStepOverPasses)->Arg(400)->Arg(600)->Unit(benchmark::kMicrosecond);

// A SICK-like scan (181 beams over 180 degrees, 1 degree apart, 30 m) from
// inside a 10 x 8 m room with a 2 x 2 m pillar, range noise 5 mm.
LaserScan RoomScan() {
  const std::vector<std::array<Eigen::Vector2d, 2>> walls = {
      {Eigen::Vector2d(0, 0), Eigen::Vector2d(10, 0)}, {Eigen::Vector2d(10, 0), Eigen::Vector2d(10, 8)},
      {Eigen::Vector2d(10, 8), Eigen::Vector2d(0, 8)}, {Eigen::Vector2d(0, 8), Eigen::Vector2d(0, 0)},
      {Eigen::Vector2d(4, 3), Eigen::Vector2d(6, 3)},  {Eigen::Vector2d(6, 3), Eigen::Vector2d(6, 5)},
      {Eigen::Vector2d(6, 5), Eigen::Vector2d(4, 5)},  {Eigen::Vector2d(4, 5), Eigen::Vector2d(4, 3)}};
  const Pose2 X_WS(1.5, 2.0, 0.5);
  Rng rng(3);
  LaserScan scan;
  scan.angle_min_rad = -kPi / 2.0;
  scan.angle_increment_rad = kPi / 180.0;
  scan.max_range_m = 30.0;
  for (int i = 0; i < 181; ++i) {
    const double angle = X_WS.theta + scan.BeamAngle(i);
    const Eigen::Vector2d origin = X_WS.translation();
    const Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
    double range = scan.max_range_m;
    for (const auto& wall : walls) {
      // Ray-segment intersection: origin + t d = a + s (b - a).
      const Eigen::Vector2d edge = wall[1] - wall[0];
      Eigen::Matrix2d M;
      M << direction, -edge;
      if (std::abs(M.determinant()) < 1e-12) continue;
      const Eigen::Vector2d ts = M.inverse() * (wall[0] - origin);
      if (ts.x() > 0.0 && ts.y() >= 0.0 && ts.y() <= 1.0) range = std::min(range, ts.x());
    }
    const bool hit = range < scan.max_range_m;
    scan.ranges_m.push_back(hit ? range + rng.Gaussian(0.0, 0.005) : scan.max_range_m);
    scan.has_return.push_back(hit ? 1 : 0);
  }
  return scan;
}

// Kind submaps in a long corridor of posts (corners 1 m apart on both
// sides, seen within 6 m): `SubmapCorridor(n)` drives until the global map
// holds n features and a submap has just started.
constexpr double kPostSpacing = 1.0;

ScanFeatures PostsSeenFrom(double x, Rng* rng) {
  ScanFeatures features;
  for (int i = static_cast<int>(std::floor((x - 6.0) / kPostSpacing));
       i <= static_cast<int>(std::ceil((x + 6.0) / kPostSpacing)); ++i) {
    for (const double y : {-2.0, 2.0}) {
      const Eigen::Vector2d p(i * kPostSpacing - x, y);
      if (i < 0 || p.norm() > 6.0) continue;
      CornerObservation corner;
      corner.range_m = p.norm() + rng->Gaussian(0.0, 0.01);
      corner.bearing_rad = std::atan2(p.y(), p.x()) + rng->Gaussian(0.0, 0.003);
      corner.covariance = Eigen::Vector2d(0.01 * 0.01, 0.003 * 0.003).asDiagonal();
      corner.p_SC = corner.range_m *
                    Eigen::Vector2d(std::cos(corner.bearing_rad), std::sin(corner.bearing_rad));
      features.corners.push_back(corner);
    }
  }
  return features;
}

FilterSettings SubmapSettings(CorrectionMode mode) {
  FilterSettings settings;
  settings.slam.ekf.process_model = CommandProcessModel{};
  settings.filter.name = "submaps";
  settings.filter.kind = "submaps";
  settings.filter.update = mode == CorrectionMode::kClassical ? "classical" : "selective";
  settings.filter.submap_max_features = 40;
  return settings;
}

struct Corridor {
  std::unique_ptr<SubmapFilter> filter;
  double x = 0.0;
};

Corridor SubmapCorridor(int num_features, CorrectionMode mode) {
  Corridor c{std::make_unique<SubmapFilter>(SubmapSettings(mode), Pose2(), Pose2(), Rng(1)), 0.0};
  Rng rng(5);
  SensorRecord record;
  record.dt_s = 0.5;
  record.command = {1.0, 0.0};
  int joins = 0;
  while (c.filter->global_map().num_features() < num_features || c.filter->num_joins() == joins) {
    joins = c.filter->num_joins();
    c.x += 0.5;
    const ScanFeatures seen = PostsSeenFrom(c.x, &rng);
    c.filter->Step(record, &seen);
  }
  return c;
}

void SubmapSizes(benchmark::internal::Benchmark* b) {
  for (const int size : {100, 300, 1000}) b->Arg(size);
}

// One step of kind submaps standing still (its scan matches its submap, no
// join): flat in the size of the global map.
void SubmapStepBenchmark(benchmark::State& state, CorrectionMode mode) {
  Corridor c = SubmapCorridor(static_cast<int>(state.range(0)), mode);
  Rng rng(11);
  const ScanFeatures seen = PostsSeenFrom(c.x, &rng);
  SensorRecord still;
  for (auto _ : state) {
    c.filter->Step(still, &seen);
    benchmark::ClobberMemory();
  }
  state.counters["global_features"] = c.filter->global_map().num_features();
  state.counters["submap_features"] = c.filter->submap().num_features();
  state.counters["joins"] = c.filter->num_joins();
}
void BM_SubmapClassicalStep(benchmark::State& state) {
  SubmapStepBenchmark(state, CorrectionMode::kClassical);
}
BENCHMARK(BM_SubmapClassicalStep)->Apply(SubmapSizes)->Unit(benchmark::kMicrosecond);
void BM_SubmapSelectiveStep(benchmark::State& state) {
  SubmapStepBenchmark(state, CorrectionMode::kSelective);
}
BENCHMARK(BM_SubmapSelectiveStep)->Apply(SubmapSizes)->Unit(benchmark::kMicrosecond);

// One join of the current submap into (a copy of) the global map: O(n^2)
// in the global map's size per fused pair.
void BM_SubmapJoin(benchmark::State& state) {
  Corridor c = SubmapCorridor(static_cast<int>(state.range(0)), CorrectionMode::kSelective);
  Rng rng(11);
  SensorRecord record;
  record.dt_s = 0.5;
  record.command = {1.0, 0.0};
  for (int i = 0; i < 10; ++i) {
    c.x += 0.5;
    const ScanFeatures seen = PostsSeenFrom(c.x, &rng);
    c.filter->Step(record, &seen);
  }
  JoinReport report;
  for (auto _ : state) {
    JoinedMap map = c.filter->global_map();
    int next_id = 0;
    report = JoinSubmap(c.filter->submap(), c.filter->link(), EkfParams(),
                        &map, &next_id);
    benchmark::ClobberMemory();
  }
  state.counters["global_features"] = c.filter->global_map().num_features();
  state.counters["fused"] = report.num_matched;
}
BENCHMARK(BM_SubmapJoin)->Apply(SubmapSizes)->Unit(benchmark::kMillisecond);


void BM_FeatureExtraction(benchmark::State& state) {
  const LaserScan scan = RoomScan();
  const FeatureExtractionParams params;
  ScanFeatures features;
  for (auto _ : state) {
    features = ExtractFeatures(scan, params);
    benchmark::DoNotOptimize(features.lines.data());
  }
  state.counters["lines"] = static_cast<double>(features.lines.size());
  state.counters["corners"] = static_cast<double>(features.corners.size());
}
BENCHMARK(BM_FeatureExtraction)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mjslam::slam
