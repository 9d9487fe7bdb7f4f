// The CARMEN reader on small synthetic logs: every message type, gzip,
// truncated and bad lines, a log without odometry, beam counts and layouts.
#include "realdata/carmen_log.h"

#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace mjslam::realdata {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

std::string TempPath(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "mjslam_carmen_test";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

std::string WritePlain(const std::string& name, const std::string& text) {
  const std::string path = TempPath(name);
  std::ofstream(path) << text;
  return path;
}

std::string WriteGzip(const std::string& name, const std::string& text) {
  const std::string path = TempPath(name);
  gzFile file = gzopen(path.c_str(), "wb");
  gzwrite(file, text.data(), static_cast<unsigned>(text.size()));
  gzclose(file);
  return path;
}

// `n` ranges r0, r0 + 0.01, ...
std::string Ranges(int n, double r0 = 1.0) {
  std::ostringstream out;
  for (int i = 0; i < n; ++i) out << ' ' << r0 + 0.01 * i;
  return out.str();
}

std::string Flaser(const char* kind, int n, double t, const std::string& poses = "1 2 0.5 3 4 0.6") {
  std::ostringstream out;
  out << kind << ' ' << n << Ranges(n) << ' ' << poses << ' ' << t << " host " << t << '\n';
  return out.str();
}

// RAWLASERk / ROBOTLASERk with 2 remissions.
std::string NewLaser(const std::string& kind, int n, double t, double start, double fov,
                     double step, double max_range) {
  std::ostringstream out;
  out << kind << " 0 " << start << ' ' << fov << ' ' << step << ' ' << max_range << " 0.01 0 "
      << n << Ranges(n) << " 2 7 8";
  if (kind.rfind("ROBOTLASER", 0) == 0) out << " 1 2 0.5 3 4 0.6 0.1 0.2 0.3 0.4 0.5";
  out << ' ' << t << " host " << t << '\n';
  return out.str();
}

const char kOdom[] = "ODOM 1.5 -2 0.25 0.3 0.1 0 10.0 host 10.0\n";

TEST(CarmenLogTest, ReadsEveryMessageType) {
  std::string text = "# comment\nPARAM robot_frontlaser_offset 0.12 host 1\n";
  text += kOdom;
  text += Flaser("FLASER", 180, 10.0);
  text += Flaser("RLASER", 181, 10.0);
  for (int k = 1; k <= 4; ++k) {
    text += NewLaser("RAWLASER" + std::to_string(k), 10, 10.0, -1.0, 2.0, 0.2, 30.0);
  }
  text += NewLaser("ROBOTLASER1", 12, 10.0, -2.0, 4.0, 0.3, 20.0);
  text += NewLaser("ROBOTLASER2", 12, 10.0, -2.0, 4.0, 0.3, 20.0);
  text += "NEFF 12.5\nTRUEPOS 1 2 3 4 5 6 10 host 10\n";
  const CarmenLog log = ReadCarmenLog(WritePlain("all.log", text));

  EXPECT_EQ(log.params.at("robot_frontlaser_offset"), "0.12");
  ASSERT_EQ(log.odometry.size(), 1u);
  EXPECT_EQ(log.odometry[0].pose.x, 1.5);
  EXPECT_EQ(log.odometry[0].pose.y, -2.0);
  EXPECT_EQ(log.odometry[0].pose.theta, 0.25);
  EXPECT_EQ(log.odometry[0].tv_mps, 0.3);
  EXPECT_EQ(log.odometry[0].rv_radps, 0.1);
  EXPECT_EQ(log.odometry[0].t_s, 10.0);
  EXPECT_EQ(log.odometry[0].line, 3);

  const LaserMessage& front = log.lasers.at("FLASER").at(0);
  EXPECT_EQ(front.ranges_m.size(), 180u);
  EXPECT_DOUBLE_EQ(front.ranges_m[179], 1.0 + 0.01 * 179);
  EXPECT_DOUBLE_EQ(front.angle_min_rad, -90 * kDeg);
  EXPECT_DOUBLE_EQ(front.angle_increment_rad, 1 * kDeg);
  EXPECT_DOUBLE_EQ(front.max_range_m, 81.83);  // no PARAM robot_front_laser_max
  EXPECT_EQ(front.laser_pose.x, 1.0);
  EXPECT_EQ(front.robot_pose.y, 4.0);
  EXPECT_TRUE(front.has_odometry_at_scan);  // the ODOM line just before, same time
  EXPECT_EQ(front.odometry_at_scan.x, 1.5);
  EXPECT_EQ(log.lasers.at("RLASER").at(0).ranges_m.size(), 181u);
  EXPECT_FALSE(log.lasers.at("RLASER").at(0).has_odometry_at_scan);  // FLASER in between

  for (int k = 1; k <= 4; ++k) {
    const LaserMessage& raw = log.lasers.at("RAWLASER" + std::to_string(k)).at(0);
    EXPECT_EQ(raw.ranges_m.size(), 10u);
    EXPECT_EQ(raw.angle_min_rad, -1.0);
    EXPECT_EQ(raw.angle_increment_rad, 0.2);
    EXPECT_EQ(raw.max_range_m, 30.0);
    EXPECT_FALSE(raw.has_poses);
  }
  for (const char* kind : {"ROBOTLASER1", "ROBOTLASER2"}) {
    const LaserMessage& robot = log.lasers.at(kind).at(0);
    EXPECT_EQ(robot.ranges_m.size(), 12u);
    EXPECT_EQ(robot.angle_increment_rad, 0.3);
    EXPECT_EQ(robot.max_range_m, 20.0);
    EXPECT_TRUE(robot.has_poses);
    EXPECT_EQ(robot.laser_pose.theta, 0.5);
    EXPECT_EQ(robot.robot_pose.x, 3.0);
    EXPECT_EQ(robot.t_s, 10.0);
  }
  EXPECT_EQ(log.skipped.at("NEFF: not read"), 1);
  EXPECT_EQ(log.skipped.at("TRUEPOS: not read"), 1);
  EXPECT_EQ(log.num_lines, 13);
}

TEST(CarmenLogTest, GzipReadsLikePlain) {
  const std::string text = std::string(kOdom) + Flaser("FLASER", 361, 10.0);
  const CarmenLog plain = ReadCarmenLog(WritePlain("same.log", text));
  const CarmenLog gzip = ReadCarmenLog(WriteGzip("same.log.gz", text));
  ASSERT_EQ(gzip.lasers.at("FLASER").size(), 1u);
  EXPECT_EQ(gzip.lasers.at("FLASER")[0].ranges_m, plain.lasers.at("FLASER")[0].ranges_m);
  EXPECT_EQ(gzip.odometry[0].pose.x, plain.odometry[0].pose.x);
}

TEST(CarmenLogTest, TruncatedLineIsAnErrorNamingTheLineOrACountedSkip) {
  std::string text = std::string(kOdom) + Flaser("FLASER", 180, 11.0);
  const std::string whole = Flaser("FLASER", 180, 12.0);
  text += whole.substr(0, whole.size() / 2);  // the log was cut in the middle of a line
  const std::string path = WriteGzip("truncated.log.gz", text);
  try {
    ReadCarmenLog(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path + ":3: FLASER: expected 191 fields for 180 beams"),
              std::string::npos)
        << message;
  }
  CarmenReadOptions skip;
  skip.skip_bad_lines = true;
  const CarmenLog log = ReadCarmenLog(path, skip);
  EXPECT_EQ(log.lasers.at("FLASER").size(), 1u);
  EXPECT_EQ(log.skipped.at("bad line"), 1);
  ASSERT_EQ(log.bad_lines.size(), 1u);
  EXPECT_EQ(log.bad_lines[0].rfind(path + ":3:", 0), 0u);
}

TEST(CarmenLogTest, BadNumberNamesLineAndField) {
  const std::string path = WritePlain("bad_number.log", "ODOM 1 2 x 0 0 0 5 host 5\n");
  EXPECT_THROW(
      {
        try {
          ReadCarmenLog(path);
        } catch (const std::runtime_error& e) {
          EXPECT_STREQ(e.what(), (path + ":1: ODOM: field 3: expected a number (got 'x')").c_str());
          throw;
        }
      },
      std::runtime_error);
  EXPECT_THROW(ReadCarmenLog(TempPath("missing.log")), std::runtime_error);
}

TEST(CarmenLogTest, LogWithoutOdometryKeepsTheLaserPoses) {
  const std::string text = Flaser("FLASER", 180, 1.0, "0 0 0 0 0 0") +
                           Flaser("FLASER", 180, 2.0, "1 0 0 1 0 0");
  const CarmenLog log = ReadCarmenLog(WritePlain("no_odom.log", text));
  EXPECT_TRUE(log.odometry.empty());
  ASSERT_EQ(log.lasers.at("FLASER").size(), 2u);
  EXPECT_EQ(log.lasers.at("FLASER")[1].robot_pose.x, 1.0);
  EXPECT_FALSE(log.lasers.at("FLASER")[1].has_odometry_at_scan);
}

TEST(CarmenLogTest, TimestampsThatDoNotIncreaseAreCountedSkips) {
  const std::string text =
      "ODOM 0 0 0 0 0 0 1.0 h 1.0\nODOM 0 0 0 0 0 0 0 h 0\nODOM 0 0 0 0 0 0 0.5 h 0.5\n"
      "ODOM 0 0 0 0 0 0 2.0 h 2.0\n";
  const CarmenLog log = ReadCarmenLog(WritePlain("stamps.log", text));
  ASSERT_EQ(log.odometry.size(), 2u);
  EXPECT_EQ(log.odometry[1].t_s, 2.0);
  EXPECT_EQ(log.skipped.at("ODOM: timestamp <= 0"), 1);
  EXPECT_EQ(log.skipped.at("ODOM: timestamp before the previous one"), 1);
  EXPECT_EQ(SkipReport(log).size(), 2u);
}

// A log printed with few significant digits: several messages share a
// stamp. They are kept, in line order, their times spread between the
// neighbouring stamps, and a warning says so. Shown to fail with ties
// skipped as before (3 of 6 ODOM kept, no warning).
TEST(CarmenLogTest, TimestampsOfLowPrecisionAreSpreadInLineOrderWithAWarning) {
  const std::string text =
      "ODOM 0 0 0 0 0 0 10 h 10\nODOM 1 0 0 0 0 0 10 h 10\nODOM 2 0 0 0 0 0 10 h 10\n"
      "ODOM 3 0 0 0 0 0 20 h 20\nODOM 4 0 0 0 0 0 30 h 30\nODOM 5 0 0 0 0 0 30 h 30\n";
  const CarmenLog log = ReadCarmenLog(WritePlain("low_precision.log", text));
  ASSERT_EQ(log.odometry.size(), 6u);
  const double expected[] = {10.0, 10.0 + 10.0 / 3.0, 10.0 + 20.0 / 3.0, 20.0, 30.0, 35.0};
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(log.odometry[i].t_s, expected[i], 1e-12) << i;
    EXPECT_EQ(log.odometry[i].pose.x, i) << "line order";
  }
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("ODOM: 3 of 6 messages share their timestamp"),
            std::string::npos)
      << log.warnings[0];
  EXPECT_TRUE(log.skipped.empty());
}

// An ODOM line in CARMEN's format at `pose`, time `t`.
std::string OdomLine(const Pose2& pose, double t) {
  std::ostringstream out;
  out.precision(17);
  out << "ODOM " << pose.x << ' ' << pose.y << ' ' << pose.theta << " 0 0 0 " << t << " h " << t
      << '\n';
  return out.str();
}

// A corrected log restarts its odometry at each scan's corrected pose C:
// after the scan (and its ODOM copy of C), the ODOM lines are C (+) the wheel
// odometry's motion since the scan. The wheel odometry is rebuilt from the
// increments, in log order, the line whose timestamp runs backwards included.
TEST(CarmenLogTest, OdometryRestartedAtEachScanIsRebuilt) {
  const Pose2 corrected(1.1, 0.1, 0.1);
  std::ostringstream laser_poses;
  laser_poses.precision(17);
  for (int k = 0; k < 2; ++k) {
    laser_poses << corrected.x << ' ' << corrected.y << ' ' << corrected.theta << (k ? "" : " ");
  }
  // Wheel odometry: (0,0,0) at t=1, (1,0,0) at the scan (t=2), then (1,0,0.5),
  // (1,0,0) and (1,0,0) more, each in the robot's frame.
  const Pose2 at3 = corrected * Pose2(1, 0, 0.5);
  const Pose2 at29 = at3 * Pose2(1, 0, 0);
  const Pose2 at4 = at29 * Pose2(1, 0, 0);
  std::string text = OdomLine(Pose2(0, 0, 0), 1.0) + OdomLine(Pose2(1, 0, 0), 2.0) +
                     Flaser("FLASER", 180, 2.0, laser_poses.str()) +
                     OdomLine(corrected, 0.0) + "NEFF 10\n" + OdomLine(at3, 3.0) +
                     OdomLine(at29, 2.9) + OdomLine(at4, 4.0);
  const std::string path = WritePlain("restarted.log", text);
  const CarmenLog log = ReadCarmenLog(path);
  EXPECT_TRUE(log.reanchored);
  EXPECT_EQ(log.skipped.at("ODOM: the scan's corrected pose (restarts the logged odometry)"), 1);
  EXPECT_EQ(log.skipped.at("ODOM: timestamp before the previous one"), 1);
  ASSERT_EQ(log.odometry.size(), 4u);
  const LaserMessage& scan = log.lasers.at("FLASER").at(0);
  EXPECT_TRUE(scan.has_odometry_at_scan);
  EXPECT_EQ(scan.odometry_at_scan.x, 1.0);
  // By hand: (1,0,0) (+) (1,0,0.5) = (2, 0, 0.5); then 2 m ahead at 0.5 rad.
  EXPECT_NEAR(log.odometry[2].pose.x, 2.0, 1e-12);
  EXPECT_NEAR(log.odometry[2].pose.y, 0.0, 1e-12);
  EXPECT_NEAR(log.odometry[2].pose.theta, 0.5, 1e-12);
  EXPECT_NEAR(log.odometry[3].pose.x, 2.0 + 2.0 * std::cos(0.5), 1e-12);
  EXPECT_NEAR(log.odometry[3].pose.y, 2.0 * std::sin(0.5), 1e-12);
  EXPECT_NEAR(log.odometry[3].pose.theta, 0.5, 1e-12);

  // As logged: the poses of the lines themselves.
  CarmenReadOptions as_logged;
  as_logged.odometry_as_logged = true;
  const CarmenLog logged = ReadCarmenLog(path, as_logged);
  EXPECT_TRUE(logged.reanchored);
  ASSERT_EQ(logged.odometry.size(), 4u);
  EXPECT_EQ(logged.odometry[3].pose.x, at4.x);
  EXPECT_EQ(logged.odometry[3].pose.y, at4.y);
}

// A log whose ODOM lines never repeat a scan's pose is read as logged.
TEST(CarmenLogTest, OrdinaryOdometryIsKeptAsLogged) {
  const std::string text = OdomLine(Pose2(0.5, 0.25, 0.125), 1.0) +
                           Flaser("FLASER", 180, 1.5, "9 9 1 9 9 1") +
                           OdomLine(Pose2(0.75, 0.5, 0.25), 2.0);
  const CarmenLog log = ReadCarmenLog(WritePlain("ordinary.log", text));
  EXPECT_FALSE(log.reanchored);
  ASSERT_EQ(log.odometry.size(), 2u);
  EXPECT_EQ(log.odometry[1].pose.x, 0.75);
  EXPECT_EQ(log.odometry[1].pose.y, 0.5);
  EXPECT_EQ(log.odometry[1].pose.theta, 0.25);
}

// FLASER beam counts: the step CARMEN implies (or the user's), beam 0 at -90.
TEST(CarmenLogTest, BeamCountsAndLayouts) {
  struct Case {
    int n;
    double step_deg;
  };
  for (const Case c : {Case{180, 1.0}, Case{181, 1.0}, Case{360, 0.5}, Case{361, 0.5},
                       Case{682, 180.0 / 681}}) {
    const CarmenLog log =
        ReadCarmenLog(WritePlain("beams.log", Flaser("FLASER", c.n, 1.0)));
    const LaserMessage& scan = log.lasers.at("FLASER").at(0);
    EXPECT_EQ(scan.ranges_m.size(), static_cast<std::size_t>(c.n));
    EXPECT_DOUBLE_EQ(scan.angle_increment_rad, c.step_deg * kDeg) << c.n;
    EXPECT_DOUBLE_EQ(scan.angle_min_rad, -90 * kDeg);
  }
  // The Hokuyo URG-04LX layout, given by the user: 682 beams over 240 deg.
  CarmenReadOptions hokuyo;
  hokuyo.angle_min_deg = -120.0;
  hokuyo.angle_step_deg = 240.0 / 681;
  hokuyo.max_range_m = 4.0;
  const LaserMessage scan =
      ReadCarmenLog(WritePlain("hokuyo.log", Flaser("FLASER", 682, 1.0)), hokuyo)
          .lasers.at("FLASER")
          .at(0);
  EXPECT_DOUBLE_EQ(scan.angle_min_rad, -120 * kDeg);
  EXPECT_DOUBLE_EQ(scan.angle_min_rad + 681 * scan.angle_increment_rad, 120 * kDeg);
  EXPECT_EQ(scan.max_range_m, 4.0);
  // The log's own maximum range.
  const LaserMessage with_param =
      ReadCarmenLog(WritePlain("param.log", "PARAM robot_front_laser_max 50.0\n" +
                                                Flaser("FLASER", 180, 1.0)))
          .lasers.at("FLASER")
          .at(0);
  EXPECT_EQ(with_param.max_range_m, 50.0);
}

}  // namespace
}  // namespace mjslam::realdata
