// FilterBank on synthetic records: any number of named filters of
// registered kinds, each on its own timing; and the realtime timing: a filter busy for k
// control steps skips exactly the scans of those steps, and it predicts
// over each skipped step in turn.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/engine/control.h"
#include "app/engine/filter_bank.h"
#include "app/engine/run_config.h"
#include "config/config.h"
#include "common/records.h"
#include "eval/pose_metrics.h"
#include "slam/filter.h"
#include "slam/slam_params.h"

namespace mjslam::app {
namespace {

constexpr double kDt = 0.1;  // control step, seconds

// A scan with no return on any beam: no features, so the cost model charges
// only model_base_s for it.
LaserScan EmptyScan(double t_s) {
  LaserScan scan;
  scan.t_s = t_s;
  scan.angle_min_rad = -M_PI / 2;
  scan.angle_increment_rad = M_PI / 180.0;
  scan.max_range_m = 8.0;
  scan.ranges_m.assign(181, scan.max_range_m);
  scan.has_return.assign(181, 0);
  return scan;
}

// Records of a robot driving straight along x from the origin: step k has
// the command `v_mps[k]` applied over the step before it, the odometry pose
// integrated from those commands, and a scan.
std::vector<SensorRecord> StraightRecords(const std::vector<double>& v_mps) {
  std::vector<SensorRecord> records;
  double x = 0.0;
  for (std::size_t k = 0; k < v_mps.size(); ++k) {
    SensorRecord record;
    record.t_s = k * kDt;
    record.dt_s = k == 0 ? 0.0 : record.t_s - records.back().t_s;
    record.command.v_mps = k == 0 ? 0.0 : v_mps[k];
    x += record.command.v_mps * record.dt_s;
    record.X_OR = Pose2(x, 0.0, 0.0);
    record.has_scan = true;
    record.scan = EmptyScan(record.t_s);
    records.push_back(record);
  }
  return records;
}

// The cost model only: each scan costs `base_s`.
ControlParams ModelCost(double base_s) {
  ControlParams control;
  control.processing = "model";
  control.model_base_s = base_s;
  control.model_s_per_update_per_n2 = 0.0;
  return control;
}

slam::SlamParams Timing(const std::string& timing, const std::string& input) {
  slam::SlamParams params;
  params.timing = timing;
  if (input == "odometry") params.ekf.process_model = slam::OdometryProcessModel{};
  return params;
}

TEST(FilterBankTest, TimingTextBecomesTheEnum) {
  EXPECT_EQ(FilterTimingFromText("every_scan"), FilterTiming::kEveryScan);
  EXPECT_EQ(FilterTimingFromText("realtime"), FilterTiming::kRealtime);
  slam::SlamParams params;
  EXPECT_EQ(params.timing, "every_scan");
  EXPECT_TRUE(params.Validate().empty());
  params.timing = "sometimes";
  ASSERT_EQ(params.Validate().size(), 1u);
  EXPECT_EQ(params.Validate()[0].key, "timing");
}

// A period of k steps (cost 0.1 (k - 1) + 0.05 s): the filter processes
// steps 0, k, 2k, ... and skips the scans of every step in between.
TEST(FilterBankTest, RealtimeFilterBusyForKStepsSkipsExactlyThoseScans) {
  const std::vector<SensorRecord> records = StraightRecords(std::vector<double>(20, 0.3));
  for (const int k : {1, 2, 3, 5}) {
    FilterBank pair(Timing("realtime", "command"), ModelCost(kDt * (k - 1) + 0.05), kDt,
                  Pose2(), Pose2(), Rng(1));
    int processed = 0;
    for (int s = 0; s < static_cast<int>(records.size()); ++s) {
      pair.Step(records[s]);
      for (int f = 0; f < 2; ++f) {
        EXPECT_EQ(pair.processed(f), s % k == 0) << "k " << k << " step " << s << " filter " << f;
        EXPECT_EQ(pair.period_steps(f), k) << "k " << k << " step " << s;
      }
      processed += s % k == 0 ? 1 : 0;
    }
    for (int f = 0; f < 2; ++f) {
      EXPECT_EQ(pair.scans_processed(f), processed) << "k " << k;
      EXPECT_EQ(pair.scans_skipped(f), 20 - processed) << "k " << k;
    }
  }
}

// The same records in every_scan timing: every scan processed, whatever the
// period.
TEST(FilterBankTest, EveryScanTimingProcessesEveryScan) {
  const std::vector<SensorRecord> records = StraightRecords(std::vector<double>(10, 0.3));
  FilterBank pair(Timing("every_scan", "command"), ModelCost(0.25), kDt, Pose2(), Pose2(), Rng(1));
  for (const SensorRecord& record : records) {
    pair.Step(record);
    EXPECT_TRUE(pair.processed(0));
    EXPECT_TRUE(pair.processed(1));
    EXPECT_EQ(pair.period_steps(0), 3);
  }
  EXPECT_EQ(pair.scans_processed(0), 10);
  EXPECT_EQ(pair.scans_skipped(0), 0);
}

// A skipped step's row holds the last processed estimate and says so.
TEST(FilterBankTest, SkippedStepReportsTheLastProcessedEstimate) {
  const std::vector<SensorRecord> records = StraightRecords(std::vector<double>(4, 0.5));
  FilterBank pair(Timing("realtime", "command"), ModelCost(0.25), kDt, Pose2(), Pose2(), Rng(1));
  pair.Step(records[0]);
  const std::vector<rundir::FilterRow> first = pair.Rows(Pose2());
  pair.Step(records[1]);
  const std::vector<rundir::FilterRow> skipped = pair.Rows(Pose2(0.05, 0.0, 0.0));
  for (int f = 0; f < 2; ++f) {
    EXPECT_TRUE(first[f].processed);
    EXPECT_FALSE(skipped[f].processed);
    EXPECT_EQ(skipped[f].X_WR.x, first[f].X_WR.x);
    EXPECT_EQ(skipped[f].P, first[f].P);
    EXPECT_EQ(skipped[f].processing_us, 0.0);
    EXPECT_DOUBLE_EQ(skipped[f].period_s, 0.30000000000000004);
  }
}

// A skipped step's NEES compares the estimate it holds (of its last processed
// step) with the truth of that step, not with the truth of the step skipped:
// the row repeats the processed row's NEES, which the current truth would
// change.
TEST(FilterBankTest, SkippedStepNeesIsThatOfTheStepItsEstimateIsOf) {
  const std::vector<SensorRecord> records = StraightRecords(std::vector<double>(12, 0.5));
  FilterBank pair(Timing("realtime", "command"), ModelCost(0.25), kDt, Pose2(), Pose2(), Rng(1));
  std::vector<double> processed_nees(2, std::nan(""));
  int finite_skipped = 0;
  for (std::size_t k = 0; k < records.size(); ++k) {
    pair.Step(records[k]);
    // A truth a little off the commanded path, so that the NEES changes.
    const Pose2 truth(records[k].X_OR.x + 0.004 * k, 0.002 * k, 0.001 * k);
    const std::vector<rundir::FilterRow> rows = pair.Rows(truth);
    for (int f = 0; f < 2; ++f) {
      if (rows[f].processed) {
        processed_nees[f] = rows[f].nees;
        continue;
      }
      if (!std::isfinite(processed_nees[f])) continue;
      ++finite_skipped;
      EXPECT_EQ(rows[f].nees, processed_nees[f]) << "step " << k << " filter " << f;
      EXPECT_NE(rows[f].nees, eval::EvaluatePoseStep(truth, rows[f].X_WR, rows[f].P).nees);
    }
  }
  EXPECT_GT(finite_skipped, 4);
}

// Driving straight with a different command on each step, a filter busy for
// 3 steps is, at its next processed step, where the commands of all 3 steps
// take it (not 3 times the last one), exactly as a filter that ran every
// step; in between it holds its last estimate.
TEST(FilterBankTest, RealtimePredictionIntegratesEveryCommandOfTheSkippedSteps) {
  const std::vector<double> v = {0.0, 0.1, 0.2, 0.4, 0.3, 0.5, 0.1, 0.2, 0.3, 0.6, 0.2};
  const std::vector<SensorRecord> records = StraightRecords(v);
  FilterBank realtime(Timing("realtime", "command"), ModelCost(0.25), kDt, Pose2(), Pose2(), Rng(1));
  FilterBank every_scan(Timing("every_scan", "command"), ModelCost(0.25), kDt, Pose2(), Pose2(), Rng(1));
  double x = 0.0;
  double x_processed = 0.0;
  for (int s = 0; s < static_cast<int>(records.size()); ++s) {
    realtime.Step(records[s]);
    every_scan.Step(records[s]);
    x += v[s] * kDt * (s > 0 ? 1 : 0);
    for (int f = 0; f < 2; ++f) {
      if (s % 3 == 0) {
        ASSERT_TRUE(realtime.processed(f)) << "step " << s;
        EXPECT_NEAR(realtime.filter(f).X_WR().x, x, 1e-12) << "step " << s;
        EXPECT_EQ(realtime.filter(f).X_WR().x, every_scan.filter(f).X_WR().x) << "step " << s;
        EXPECT_EQ(realtime.filter(f).pose_covariance(), every_scan.filter(f).pose_covariance())
            << "step " << s;
      } else {
        ASSERT_FALSE(realtime.processed(f)) << "step " << s;
        EXPECT_EQ(realtime.filter(f).X_WR().x, x_processed) << "step " << s;
      }
    }
    if (s % 3 == 0) x_processed = realtime.filter(0).X_WR().x;
  }
  // The robot moved: a prediction that dropped the skipped steps would be off.
  EXPECT_GT(x, 0.2);
}

// With odometry input the prediction of the next processed step takes the
// odometry increment over all the skipped steps at once.
TEST(FilterBankTest, RealtimePredictionTakesTheOdometryOfTheSkippedSteps) {
  const std::vector<double> v(13, 0.5);
  const std::vector<SensorRecord> records = StraightRecords(v);
  FilterBank realtime(Timing("realtime", "odometry"), ModelCost(0.35), kDt, Pose2(), Pose2(), Rng(1));
  for (int s = 0; s < static_cast<int>(records.size()); ++s) {
    realtime.Step(records[s]);
    const double expected = s % 4 == 0 ? s * kDt * 0.5 : (s / 4) * 4 * kDt * 0.5;
    for (int f = 0; f < 2; ++f) {
      EXPECT_EQ(realtime.processed(f), s % 4 == 0) << "step " << s;
      EXPECT_NEAR(realtime.filter(f).X_WR().x, expected, 1e-12) << "step " << s;
      EXPECT_NEAR(realtime.filter(f).X_WR().y, 0.0, 1e-12) << "step " << s;
    }
  }
  EXPECT_EQ(realtime.scans_processed(0), 4);
  EXPECT_EQ(realtime.scans_skipped(0), 9);
}

// A turn in place, then a drive: the odometry prediction over skipped steps
// runs one prediction per skipped record, as the filter given every record
// would (the same estimate and covariance, bit for bit). One prediction over
// the net increment would take its noise and its self-calibration
// Jacobians from a motion the robot did not make (an arc with the last
// record's command): a different covariance.
TEST(FilterBankTest, RealtimeOdometryPredictsOverEachSkippedRecord) {
  std::vector<SensorRecord> records = StraightRecords(std::vector<double>(5, 0.0));
  double th = 0.0;
  double x = 0.0;
  for (std::size_t k = 1; k < records.size(); ++k) {
    records[k].command = k <= 2 ? Twist2{0.0, 4.0} : Twist2{0.5, 0.0};  // 0.4 rad, then 0.1 m
    th += records[k].command.w_radps * kDt;
    x += records[k].command.v_mps * kDt;
    records[k].X_OR = Pose2(x * std::cos(th), x * std::sin(th), th);
  }
  const slam::SlamParams params = Timing("realtime", "odometry");
  FilterBank realtime(params, ModelCost(0.35), kDt, Pose2(), Pose2(), Rng(1));
  for (const SensorRecord& record : records) realtime.Step(record);
  ASSERT_TRUE(realtime.processed(0));
  ASSERT_EQ(realtime.scans_skipped(0), 3);

  const slam::ScanFeatures none;
  slam::EkfSlam every_record(params.ekf, slam::CorrectionMode::kClassical, Pose2(), Pose2());
  for (const SensorRecord& record : records) every_record.Step(record, &none);
  EXPECT_EQ(realtime.filter(0).X_WR().x, every_record.X_WR().x);
  EXPECT_EQ(realtime.filter(0).X_WR().y, every_record.X_WR().y);
  EXPECT_EQ(realtime.filter(0).X_WR().theta, every_record.X_WR().theta);
  EXPECT_EQ(realtime.filter(0).pose_covariance(), every_record.pose_covariance());

  slam::EkfSlam net_increment(params.ekf, slam::CorrectionMode::kClassical, Pose2(), Pose2());
  net_increment.Step(records[0], &none);
  SensorRecord last = records[4];
  last.dt_s = 4 * kDt;
  net_increment.Step(last, &none);
  EXPECT_GT((net_increment.pose_covariance() - every_record.pose_covariance()).norm(),
            0.03 * every_record.pose_covariance().norm());
}

slam::FilterParams Entry(const std::string& name, const std::string& update) {
  slam::FilterParams entry;
  entry.name = name;
  entry.update = update;
  return entry;
}

TEST(FilterBankTest, DefaultsAreThePapersTwoFilters) {
  const FilterBank bank(slam::SlamParams{}, ModelCost(0.05), kDt, Pose2(), Pose2(), Rng(1));
  ASSERT_EQ(bank.size(), 2);
  EXPECT_EQ(bank.names(), (std::vector<std::string>{"classical", "selective"}));
  EXPECT_EQ(bank.IndexOf("selective"), 1);
  EXPECT_EQ(bank.IndexOf("odometry"), -1);
}

// Three named filters on the same records, one of them realtime: each runs
// on its own timeline; the every_scan ones stay bit-identical to the
// default bank's filters of the same update rule.
TEST(FilterBankTest, NamedFiltersEachRunWithTheirOwnTiming) {
  slam::SlamParams params;
  params.filters = {Entry("a", "classical"), Entry("b", "selective"), Entry("c", "selective")};
  params.filters[2].timing = "realtime";
  params.filters[1].max_updates = 1;
  ASSERT_TRUE(params.Validate().empty());
  FilterBank bank(params, ModelCost(0.25), kDt, Pose2(), Pose2(), Rng(1));
  FilterBank defaults(slam::SlamParams{}, ModelCost(0.25), kDt, Pose2(), Pose2(), Rng(1));
  ASSERT_EQ(bank.names(), (std::vector<std::string>{"a", "b", "c"}));
  const std::vector<SensorRecord> records = StraightRecords(std::vector<double>(9, 0.3));
  for (int s = 0; s < static_cast<int>(records.size()); ++s) {
    bank.Step(records[s]);
    defaults.Step(records[s]);
    EXPECT_TRUE(bank.processed(0));
    EXPECT_TRUE(bank.processed(1));
    EXPECT_EQ(bank.processed(2), s % 3 == 0) << "step " << s;
    EXPECT_EQ(bank.Rows(Pose2()).size(), 3u);
    EXPECT_EQ(bank.filter(0).X_WR().x, defaults.filter(0).X_WR().x);
    EXPECT_EQ(bank.filter(0).pose_covariance(), defaults.filter(0).pose_covariance());
  }
  EXPECT_EQ(bank.timing(2), FilterTiming::kRealtime);
  EXPECT_EQ(bank.scans_skipped(2), 6);
  EXPECT_EQ(bank.scans_skipped(0), 0);
}

TEST(FilterBankTest, BadEntriesAreNamedByIndexAndKey) {
  slam::SlamParams params;
  params.filters = {Entry("a", "classical"), Entry("a", "sometimes"), Entry("Bad name", "selective"),
                    Entry("odometry", "selective")};
  params.filters[3].kind = "particle";
  params.filters[0].selection_policy = "best";
  std::vector<std::string> keys;
  for (const ParamProblem& p : params.Validate()) keys.push_back(p.key);
  EXPECT_EQ(keys, (std::vector<std::string>{"filters[0].selection_policy", "filters[1].update",
                                            "filters[1].name", "filters[2].name",
                                            "filters[3].name", "filters[3].kind"}));
}

// `slam.filters` in a config file: each problem names the file's line, the
// key and the value; control.pose_source must name a filter; without the key
// the resolved config has none (run directories as before).
TEST(FilterBankTest, ConfigErrorsNameLineKeyAndValue) {
  const std::string text =
      "slam:\n"
      "  filters:\n"
      "    - {name: a, kind: ekf, update: classical}\n"
      "    - {name: b, kind: ekf, update: sometimes}\n"
      "    - {name: a, kind: particles}\n"
      "control:\n"
      "  pose_source: selective\n";
  try {
    config::LoadConfigString<RunConfig>(text, "x.yaml");
    FAIL() << "no error";
  } catch (const config::ConfigError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("x.yaml:4:"), std::string::npos) << what;
    EXPECT_NE(what.find("slam.filters[1].update: expected one of classical, selective (got sometimes)"),
              std::string::npos) << what;
    EXPECT_NE(what.find("x.yaml:5:"), std::string::npos) << what;
    EXPECT_NE(what.find("slam.filters[2].kind"), std::string::npos) << what;
    EXPECT_NE(what.find("slam.filters[2].name"), std::string::npos) << what;
    EXPECT_NE(what.find("x.yaml:7:16: control.pose_source: expected one of a, b, a, odometry, "
                        "ground_truth (got selective)"),
              std::string::npos) << what;
  }
  const RunConfig defaults = config::LoadConfigString<RunConfig>("run: {seed: 2}\n", "y.yaml");
  EXPECT_TRUE(defaults.slam.filters.empty());
  EXPECT_EQ(config::ToYaml(defaults).find("filters"), std::string::npos);
  const RunConfig named = config::LoadConfigString<RunConfig>(
      "slam: {filters: [{name: mine, update: selective, max_updates: 3}]}\n"
      "control: {pose_source: mine}\n",
      "z.yaml");
  ASSERT_EQ(named.slam.filters.size(), 1u);
  EXPECT_EQ(named.slam.filters[0].max_updates, 3);
  EXPECT_EQ(slam::SettingsOf(named.slam, named.slam.filters[0]).slam.ekf.max_updates, 3);
  // process_noise_scale: every std of the process model's noise, of its kind.
  slam::FilterParams noisy = named.slam.filters[0];
  noisy.process_noise_scale = 2.0;
  const slam::SlamParams scaled = slam::SettingsOf(named.slam, noisy).slam;
  const auto& base = std::get<slam::CommandProcessModel>(named.slam.ekf.process_model).noise;
  const auto& twice = std::get<slam::CommandProcessModel>(scaled.ekf.process_model).noise;
  EXPECT_EQ(twice.v_std_mps, 2.0 * base.v_std_mps);
  EXPECT_EQ(twice.change_fraction, 2.0 * base.change_fraction);
  noisy.process_noise_scale = 0.0;
  ASSERT_EQ(noisy.Validate().size(), 1u);
  EXPECT_EQ(noisy.Validate()[0].key, "process_noise_scale");
  const RunConfig again = config::LoadConfigString<RunConfig>(config::ToYaml(named), "resolved");
  EXPECT_EQ(again.slam.filters[0].name, "mine");
}

// A kind registered by a test: one class, one registration, no edit to the
// bank. It reports the number of records it saw as its map size.
class CountingFilter : public slam::Filter {
 public:
  slam::StepReport Step(const SensorRecord&, const slam::ScanFeatures*) override {
    slam::StepReport report;
    report.num_features = ++steps_;
    return report;
  }
  Pose2 X_WR() const override { return Pose2(steps_, 0.0, 0.0); }
  Eigen::Matrix3d pose_covariance() const override { return Eigen::Matrix3d::Identity(); }
  std::vector<MapFeature> Map() const override { return {}; }
  int num_features() const override { return steps_; }

 private:
  int steps_ = 0;
};

const slam::FilterRegistration kCounting(
    "counting_test", [](const slam::FilterSettings&, const Pose2&, const Pose2&, Rng) {
      return std::make_unique<CountingFilter>();
    });

TEST(FilterBankTest, ARegisteredKindRunsBesideThePapersFilters) {
  slam::SlamParams params;
  params.filters = {Entry("classical", "classical"), Entry("counter", "")};
  params.filters[1].kind = "counting_test";
  ASSERT_TRUE(params.Validate().empty());
  FilterBank bank(params, ModelCost(0.05), kDt, Pose2(), Pose2(), Rng(1));
  for (const SensorRecord& record : StraightRecords(std::vector<double>(4, 0.3))) bank.Step(record);
  EXPECT_EQ(bank.filter(1).num_features(), 4);
  EXPECT_EQ(bank.Rows(Pose2())[1].num_features, 4);
  EXPECT_EQ(bank.filter(1).X_WR().x, 4.0);
}

}  // namespace
}  // namespace mjslam::app
