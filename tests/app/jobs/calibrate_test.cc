// mjslam calibrate's fit (app/jobs/calibrate.h) on synthetic runs whose odometry
// errors are drawn from a known model: it must give back that model's
// noise, skid and per-run systematic errors.
#include "app/jobs/calibrate.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "app/engine/run_config.h"
#include "common/rng.h"
#include "slam/motion_model.h"

namespace mjslam::app {
namespace {

constexpr double kA = 0.2;      // control point offset, m
constexpr double kB = 0.33;     // axle track, m
constexpr double kDt = 0.1;     // record period, s
constexpr double kSkid = 0.01;  // process_model.lateral.skid_s

struct TrueModel {
  double distance_per_sqrt_m = 0.008;
  double distance_per_sqrt_rad = 0.003;
  double heading_per_sqrt_m = 0.045;
  double heading_per_sqrt_rad = 0.02;
  double lateral_per_sqrt_m = 0.0005;
};

Pose2 Apply(const Pose2& X, double d, double dth, double skid_s, double lateral_m) {
  const Eigen::Vector3d next = slam::PredictPose(Eigen::Vector3d(X.x, X.y, X.theta),
                                                 Eigen::Vector2d(d, dth), kA, nullptr, nullptr,
                                                 skid_s / kDt);
  const double phi = X.theta + 0.5 * dth;
  return Pose2(next.x() - lateral_m * std::sin(phi), next.y() + lateral_m * std::cos(phi), next.z());
}

// A run of `records` records: stretches of driving straight, on arcs and
// turning on the spot; odometry from the drawn increments, the truth from
// them with the run's systematic errors, random errors, skid and lateral slip.
RunMotion SyntheticRun(int index, int records, const TrueModel& m, RunSystematics* systematic) {
  Rng rng(1000 + index);
  systematic->distance_scale = rng.Gaussian(0.0, 0.01);
  systematic->heading_scale = rng.Gaussian(0.0, 0.02);
  systematic->heading_per_m_rad = rng.Gaussian(0.0, 0.03);
  RunMotion run;
  run.name = "synthetic_" + std::to_string(index);
  Pose2 truth(0.0, 0.0, 0.0);
  Pose2 odometry(0.0, 0.0, 0.0);
  double v = 0.0;
  double w = 0.0;
  for (int i = 0; i < records; ++i) {
    if (i % 30 == 0) {
      const double kind = rng.Uniform();
      v = kind < 0.2 ? 0.0 : 0.1 + 0.3 * rng.Uniform();
      w = kind < 0.5 ? rng.Gaussian(0.0, 0.6) : 0.0;
    }
    run.t_s.push_back(i * kDt);
    run.X_WR_true.push_back(truth);
    run.X_OR.push_back(odometry);
    const double d = v * kDt;
    const double dth = w * kDt;
    const double sd = std::sqrt(m.distance_per_sqrt_m * m.distance_per_sqrt_m * std::abs(d) +
                                m.distance_per_sqrt_rad * m.distance_per_sqrt_rad * std::abs(dth));
    const double sth = std::sqrt(m.heading_per_sqrt_m * m.heading_per_sqrt_m * std::abs(d) +
                                 m.heading_per_sqrt_rad * m.heading_per_sqrt_rad * std::abs(dth));
    const double true_d = d + systematic->distance_scale * d +
                          systematic->heading_per_m_rad * kB * kB / 4.0 * dth + rng.Gaussian(0.0, sd);
    const double true_dth = dth + systematic->heading_scale * dth +
                            systematic->heading_per_m_rad * d + rng.Gaussian(0.0, sth);
    const double lateral = rng.Gaussian(0.0, m.lateral_per_sqrt_m * std::sqrt(std::abs(d)));
    truth = Apply(truth, true_d, true_dth, kSkid, lateral);
    odometry = Apply(odometry, d, dth, 0.0, 0.0);
  }
  return run;
}

slam::EkfParams Model() {
  slam::EkfParams model;
  model.control_point_offset_m = kA;
  model.axle_track_m = kB;
  return model;
}

TEST(CalibrateTest, RecoversTheNoiseTheSkidAndEachRunsSystematicErrors) {
  const TrueModel m;
  std::vector<RunMotion> runs;
  std::vector<RunSystematics> drawn(20);
  for (int r = 0; r < 20; ++r) runs.push_back(SyntheticRun(r, 1500, m, &drawn[r]));
  const Calibration c = Calibrate(runs, Model(), 10);
  const slam::OdometryProcessModel& fitted =
      std::get<slam::OdometryProcessModel>(c.fitted.process_model);
  const slam::OdometryNoiseParams& n = fitted.noise;
  // 3000 windows: the standard deviations within 10 %, the floors and the
  // per-radian lateral term (none drawn) small.
  EXPECT_NEAR(n.distance_std_m_per_sqrt_m, m.distance_per_sqrt_m, 0.1 * m.distance_per_sqrt_m);
  EXPECT_NEAR(n.distance_std_m_per_sqrt_rad, m.distance_per_sqrt_rad,
              0.1 * m.distance_per_sqrt_rad);
  EXPECT_NEAR(n.heading_std_rad_per_sqrt_m, m.heading_per_sqrt_m, 0.1 * m.heading_per_sqrt_m);
  EXPECT_NEAR(n.heading_std_rad_per_sqrt_rad, m.heading_per_sqrt_rad,
              0.1 * m.heading_per_sqrt_rad);
  EXPECT_NEAR(fitted.lateral.slip_std_m_per_sqrt_m, m.lateral_per_sqrt_m,
              0.1 * m.lateral_per_sqrt_m);
  EXPECT_LT(n.distance_std_m, 2e-4);
  EXPECT_LT(n.heading_std_rad, 1e-3);
  EXPECT_LT(fitted.lateral.slip_std_m_per_rad, 2e-4);
  EXPECT_NEAR(fitted.lateral.skid_s, kSkid, 0.05 * kSkid);
  // Each run's systematic errors, least squares over its records: their
  // errors are those of a 150 s run, so the test bounds the RMS over the
  // runs at a third of the drawn spread (0.01, 0.02 and 0.03).
  ASSERT_EQ(c.runs.size(), drawn.size());
  std::array<double, 3> squared{0.0, 0.0, 0.0};
  for (std::size_t r = 0; r < drawn.size(); ++r) {
    squared[0] += std::pow(c.runs[r].distance_scale - drawn[r].distance_scale, 2);
    squared[1] += std::pow(c.runs[r].heading_scale - drawn[r].heading_scale, 2);
    squared[2] += std::pow(c.runs[r].heading_per_m_rad - drawn[r].heading_per_m_rad, 2);
  }
  const double runs_n = static_cast<double>(drawn.size());
  std::printf("RMS error of the runs' q_d %.4f, q_th %.4f, k %.4f rad/m\n", std::sqrt(squared[0] / runs_n),
              std::sqrt(squared[1] / runs_n), std::sqrt(squared[2] / runs_n));
  EXPECT_LT(std::sqrt(squared[0] / runs_n), 0.01 / 3.0);
  EXPECT_LT(std::sqrt(squared[1] / runs_n), 0.02 / 3.0);
  EXPECT_LT(std::sqrt(squared[2] / runs_n), 0.03 / 3.0);
  // The fitted model passes its own check at the fit's window.
  ASSERT_EQ(c.fitted_checks.size(), 3u);
  EXPECT_NEAR(c.fitted_checks[1].distance, 1.0, 0.1);
  EXPECT_NEAR(c.fitted_checks[1].heading, 1.0, 0.1);
  EXPECT_NEAR(c.fitted_checks[1].lateral, 1.0, 0.1);
}

TEST(CalibrateTest, TheWrittenConfigHoldsTheFittedKeysOnItsBase) {
  const TrueModel m;
  std::vector<RunMotion> runs;
  RunSystematics drawn;
  for (int r = 0; r < 5; ++r) runs.push_back(SyntheticRun(r, 400, m, &drawn));
  const Calibration c = Calibrate(runs, Model(), 10);
  const std::string yaml = CalibrationYaml(c, "../configs/default.yaml", "line one\nline two");
  EXPECT_EQ(yaml.rfind("# line one\n# line two\nbase: ../configs/default.yaml\nslam:\n  ekf:\n", 0), 0u)
      << yaml;
  // Loaded as a config on the default, it gives the fitted keys.
  const std::string path = ::testing::TempDir() + "/calibrated.yaml";
  std::ofstream(path) << CalibrationYaml(c, std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml",
                                         "test");
  const RunConfig loaded = LoadRunConfig(path, {});
  const slam::OdometryProcessModel& fitted =
      std::get<slam::OdometryProcessModel>(c.fitted.process_model);
  const auto* read = std::get_if<slam::OdometryProcessModel>(&loaded.slam.ekf.process_model);
  ASSERT_NE(read, nullptr);
  EXPECT_EQ(read->noise.heading_std_rad_per_sqrt_m, fitted.noise.heading_std_rad_per_sqrt_m);
  EXPECT_EQ(read->lateral.slip_std_m_per_sqrt_m, fitted.lateral.slip_std_m_per_sqrt_m);
  EXPECT_EQ(read->lateral.skid_s, fitted.lateral.skid_s);
  EXPECT_EQ(read->integration, "exact");

  // On a base of kind command (paper.yaml: euler), the given model's
  // integration is kept and the process model becomes of kind odometry.
  slam::EkfParams given = Model();
  std::get<slam::CommandProcessModel>(given.process_model).integration = "euler";
  const Calibration euler = Calibrate(runs, given, 10);
  std::ofstream(path) << CalibrationYaml(euler, std::string(MJSLAM_SOURCE_DIR) + "/configs/paper.yaml",
                                         "test");
  const RunConfig on_paper = LoadRunConfig(path, {});
  const auto* switched = std::get_if<slam::OdometryProcessModel>(&on_paper.slam.ekf.process_model);
  ASSERT_NE(switched, nullptr);
  EXPECT_EQ(switched->integration, "euler");
  EXPECT_EQ(switched->lateral.skid_s,
            std::get<slam::OdometryProcessModel>(euler.fitted.process_model).lateral.skid_s);
}

TEST(CalibrateTest, RefusesTooFewWindowsAndRecordsThatAreNotFinite) {
  const TrueModel m;
  RunSystematics drawn;
  std::vector<RunMotion> runs{SyntheticRun(0, 100, m, &drawn)};
  EXPECT_THROW(Calibrate(runs, Model(), 10), std::invalid_argument);
  runs = {SyntheticRun(0, 1000, m, &drawn)};
  runs[0].X_OR[500].x = std::nan("");
  try {
    Calibrate(runs, Model(), 10);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("synthetic_0: record 501: the odometry pose"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace mjslam::app
