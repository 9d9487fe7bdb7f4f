// mjslam import on small synthetic CARMEN logs of a robot in a rectangular
// room: every beam count, a log without odometry, a log with a reference,
// and evaluate and render of the result.
#include "app/jobs/import_log.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "app/jobs/evaluate_real.h"
#include "app/jobs/render_real.h"
#include "renders/image.h"
#include "rundir/csv_reader.h"
#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/map_csv.h"

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

std::string FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "mjslam_import_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir.string();
}

// Range from `p` along `angle` to the walls of the room [-4, 4] x [-3, 3].
double RoomRange(const Eigen::Vector2d& p, double angle) {
  const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
  double best = 1e9;
  for (int axis = 0; axis < 2; ++axis) {
    const double half = axis == 0 ? 4.0 : 3.0;
    for (double wall : {-half, half}) {
      if (std::abs(d[axis]) < 1e-12) continue;
      const double t = (wall - p[axis]) / d[axis];
      if (t > 0.0) best = std::min(best, t);
    }
  }
  return best;
}

struct LogShape {
  int num_beams = 181;
  double angle_min_deg = -90.0;
  double step_deg = 1.0;
  bool odometry = true;
  // The laser poses differ from the odometry by this drift per step (a
  // corrected log's reference) or equal it (0).
  double drift_per_step_m = 0.0;
};

// The robot centre after k arcs of 0.1 m turning 0.03 rad from (-1, -0.5, 0).
Pose2 PoseAfter(int k) {
  const double d = 0.1, dth = 0.03;
  const Pose2 arc(d * std::sin(dth) / dth, d * (1.0 - std::cos(dth)) / dth, dth);
  Pose2 pose(-1.0, -0.5, 0.0);
  for (int i = 0; i < k; ++i) pose = pose * arc;
  return pose;
}

// 25 steps along PoseAfter; an ODOM line and a FLASER line each.
std::string WriteLog(const std::string& dir, const LogShape& shape) {
  std::ostringstream log;
  log.precision(12);
  log << "PARAM robot_frontlaser_offset 0.0 host 0\n";
  for (int k = 0; k < 25; ++k) {
    const double t = 100.0 + k;
    const Pose2 odom = PoseAfter(k);
    const Pose2 truth(odom.x, odom.y + shape.drift_per_step_m * k, odom.theta);
    if (shape.odometry) log << "ODOM " << odom.x << ' ' << odom.y << ' ' << odom.theta
                            << " 0.1 0.03 0 " << t << " host " << t << '\n';
    log << "FLASER " << shape.num_beams;
    for (int b = 0; b < shape.num_beams; ++b) {
      const double bearing = (shape.angle_min_deg + b * shape.step_deg) * kPi / 180.0;
      log << ' ' << RoomRange(truth.translation(), truth.theta + bearing);
    }
    log << ' ' << truth.x << ' ' << truth.y << ' ' << truth.theta << ' ' << truth.x << ' '
        << truth.y << ' ' << truth.theta << ' ' << t << " host " << t << '\n';
  }
  const std::string path = dir + ".log";
  std::ofstream(path) << log.str();
  return path;
}

RunConfig RealConfig() {
  return LoadRunConfig(std::string(MJSLAM_SOURCE_DIR) + "/configs/real.yaml", {});
}

ImportOptions Options(const std::string& log, const std::string& dir) {
  ImportOptions options;
  options.log_path = log;
  options.out_dir = dir;
  return options;
}

TEST(ImportLogTest, EveryBeamCountRunsBothFilters) {
  for (const int n : {180, 181, 360, 361, 682}) {
    const std::string dir = FreshDir("beams_" + std::to_string(n));
    LogShape shape;
    shape.num_beams = n;
    ImportOptions options = Options("", dir);
    if (n == 682) {  // a Hokuyo URG: 240 deg, given by the user
      shape.angle_min_deg = -120.0;
      shape.step_deg = 240.0 / 681;
      options.read.angle_min_deg = -120.0;
      options.read.angle_step_deg = 240.0 / 681;
      options.read.max_range_m = 20.0;
    } else {
      shape.step_deg = realdata::CarmenDefaultStepDeg(n);
    }
    options.log_path = WriteLog(dir, shape);
    const ImportReport report = ImportLog(RealConfig(), options);
    EXPECT_EQ(report.num_beams, n);
    EXPECT_EQ(report.num_scans, 25);
    EXPECT_EQ(report.num_steps, 25);  // each scan at its odometry's time
    EXPECT_FALSE(report.has_reference);  // the laser poses are the odometry
    const rundir::CsvTable scans = rundir::ReadCsv(rundir::PathIn(dir, rundir::kScansFile));
    EXPECT_EQ(scans.columns.size(), static_cast<std::size_t>(rundir::kScanRangesStart + n));
    const nlohmann::json manifest = rundir::ReadManifest(dir);
    EXPECT_EQ(manifest["mode"], "import");
    EXPECT_EQ(manifest["status"], "completed");
    EXPECT_EQ(manifest["num_beams"], n);
    // The whole fan: the config's layout turned by the mount is the log's.
    const RunConfig written = LoadRunConfig(rundir::PathIn(dir, rundir::kConfigFile), {});
    EXPECT_EQ(written.laser.num_beams, n);
    const double first_beam = written.laser.AngleMinRad() + manifest["laser_mount"]["th"].get<double>();
    EXPECT_NEAR(first_beam, shape.angle_min_deg * kPi / 180.0, 1e-9) << n;
    // Both filters saw the room's four walls from every scan: the map has them.
    for (const std::string& name : rundir::DefaultFilterNames()) {
      int lines = 0;
      for (const MapFeature& f : rundir::ReadMapCsv(rundir::PathIn(dir, rundir::MapFile(name)))) {
        lines += f.type == FeatureType::kLine ? 1 : 0;
      }
      EXPECT_GE(lines, 3) << name << " with " << n << " beams";
    }
    const rundir::CsvTable trajectory =
        rundir::ReadCsv(rundir::PathIn(dir, rundir::kTrajectoryFile));
    ASSERT_EQ(trajectory.rows.size(), 25u);
    // The filters end near the odometry (exact here) in this noise-free room.
    const std::vector<double>& last = trajectory.rows.back();
    const int odom_x = 4, classical_x = 10;
    EXPECT_NEAR(last[classical_x], last[odom_x], 0.01) << n;
    EXPECT_NEAR(last[classical_x + 1], last[odom_x + 1], 0.01) << n;
  }
}

TEST(ImportLogTest, LogWithoutOdometryUsesTheLaserPoses) {
  const std::string dir = FreshDir("no_odometry");
  LogShape shape;
  shape.odometry = false;
  const ImportReport report = ImportLog(RealConfig(), Options(WriteLog(dir, shape), dir));
  EXPECT_EQ(report.num_odometry, 25);
  EXPECT_EQ(report.num_scans, 25);
  EXPECT_FALSE(report.has_reference);
  EXPECT_FALSE(fs::exists(rundir::PathIn(dir, rundir::kReferenceFile)));
}

TEST(ImportLogTest, ReferenceIsWrittenScoredAndDrawn) {
  const std::string dir = FreshDir("reference");
  LogShape shape;
  shape.drift_per_step_m = 0.01;  // the odometry drifts 1 cm a step from the laser poses
  const std::string log = WriteLog(dir, shape);
  // Relations of the laser poses themselves, on a clock 5 s ahead.
  const std::string relations = dir + ".relations";
  {
    std::ofstream out(relations);
    out.precision(12);
    for (int k = 0; k + 3 < 25; ++k) {
      const Pose2 a = Pose2(0, 0.01 * k, 0) * PoseAfter(k);
      const Pose2 b = Pose2(0, 0.01 * (k + 3), 0) * PoseAfter(k + 3);
      const Pose2 d = a.Inverse() * b;
      out << 105.0 + k << ' ' << 108.0 + k << ' ' << d.x << ' ' << d.y << " 0 0 0 " << d.theta
          << '\n';
    }
  }
  ImportOptions options = Options(log, dir);
  options.relations_path = relations;  // the offset is searched
  const ImportReport report = ImportLog(RealConfig(), options);
  EXPECT_TRUE(report.has_reference);
  EXPECT_NEAR(report.time_offset_s, 5.0, 0.006);

  const RealEvaluation evaluation = EvaluateImportedRun(dir);
  EXPECT_EQ(evaluation.relation_times, 25);
  EXPECT_EQ(evaluation.relation_times_at_scans, 25);
  ASSERT_EQ(evaluation.at_scans.size(), 4u);
  const ScoredTrajectory& odometry = evaluation.at_scans[2];
  const ScoredTrajectory& reference = evaluation.at_scans[3];
  EXPECT_EQ(reference.name, "reference");
  EXPECT_EQ(reference.errors.num_matched, 22);
  EXPECT_LT(reference.errors.translation_mean_m, 1e-9);  // the relations are its own
  // The odometry misses the drift: 3 steps of 1 cm sideways.
  EXPECT_NEAR(odometry.errors.translation_mean_m, 0.03, 0.005);
  EXPECT_EQ(evaluation.not_positive_semidefinite, std::vector<int>({0, 0}));
  EXPECT_TRUE(IsImportedRun(dir));

  renders::RenderParams params;
  params.height = 200;
  params.video = true;
  EXPECT_EQ(RenderImportedRun(dir, params), 25);  // a frame per scan
  EXPECT_TRUE(fs::exists(rundir::PathIn(dir, rundir::kVideoFile)));
  // Three square panels side by side.
  const renders::Image image = renders::ReadPng(rundir::PathIn(dir, rundir::kFinalImageFile));
  EXPECT_EQ(image.width, 600);
  EXPECT_EQ(image.height, 200);
}

// A BreezySLAM log (found by its shape) of the rover driving straight
// through the room: 400 ticks a line on both wheels, the Hokuyo 0.145 m
// ahead of the axle. Both filters map the walls and end on the odometry.
TEST(ImportLogTest, BreezySlamLogRunsBothFilters) {
  const std::string dir = FreshDir("breezyslam");
  const double step_m = 0.077 * 2.0 * kPi / 2000.0 * 400.0;
  std::ostringstream log;
  for (int k = 0; k < 25; ++k) {
    log << 5000000 + 100000 * k << " 0 " << 1000 + 400 * k << ' ' << 7000 + 400 * k;
    for (int i = 4; i < 24; ++i) log << " 0";
    const Eigen::Vector2d laser(-1.0 + step_m * k + 0.145, -0.5);
    for (int b = 0; b < 682; ++b) {
      const double bearing = (-120.0 + b * 240.0 / 681.0) * kPi / 180.0;
      log << ' ' << std::lround(1000.0 * RoomRange(laser, bearing));
    }
    log << " 0\n";
  }
  const std::string path = dir + ".dat";
  std::ofstream(path) << log.str();
  ImportOptions options = Options(path, dir);
  options.read.max_range_m = 20.0;  // the room is larger than the URG's 4 m
  const ImportReport report = ImportLog(RealConfig(), options);
  EXPECT_EQ(report.laser, realdata::kBreezySlamLaser);
  EXPECT_EQ(report.num_beams, 682);
  EXPECT_EQ(report.num_scans, 25);
  EXPECT_FALSE(report.has_reference);
  const nlohmann::json manifest = rundir::ReadManifest(dir);
  EXPECT_EQ(manifest["laser_offset_m"], 0.145);
  for (const std::string& name : rundir::DefaultFilterNames()) {
    int lines = 0;
    for (const MapFeature& f : rundir::ReadMapCsv(rundir::PathIn(dir, rundir::MapFile(name)))) {
      lines += f.type == FeatureType::kLine ? 1 : 0;
    }
    EXPECT_GE(lines, 3) << name;
  }
  const rundir::CsvTable trajectory = rundir::ReadCsv(rundir::PathIn(dir, rundir::kTrajectoryFile));
  const std::vector<double>& last = trajectory.rows.back();
  const int odom_x = 4, classical_x = 10;
  // The log's odometry frame: the first line at the origin; frame R 0.2 m ahead.
  EXPECT_NEAR(last[odom_x], 24 * step_m + 0.2, 1e-9);
  EXPECT_NEAR(last[classical_x], last[odom_x], 0.02);
  EXPECT_NEAR(last[classical_x + 1], last[odom_x + 1], 0.02);
}

TEST(ImportLogTest, BadLogsAreErrorsNamingTheFile) {
  const std::string dir = FreshDir("bad");
  const std::string only_odometry = dir + "_odom.log";
  std::ofstream(only_odometry) << "ODOM 0 0 0 0 0 0 1 host 1\n";
  try {
    ImportLog(RealConfig(), Options(only_odometry, dir));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(only_odometry + ": no laser messages"), std::string::npos);
  }
  const std::string raw = dir + "_raw.log";
  std::ofstream(raw) << "RAWLASER1 0 -1.5 3 0.5 30 0.01 0 7 1 1 1 1 1 1 1 0 1 host 1\n";
  try {
    ImportLog(RealConfig(), Options(raw, dir));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(raw + ": no odometry"), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(dir));  // nothing written
}

}  // namespace
}  // namespace mjslam::app
