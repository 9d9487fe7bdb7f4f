// The BreezySLAM log reader on hand-made logs: odometry from the tick counts
// (checked by hand), ranges and beam layout, the detection margin, and the
// errors for a truncated line, a field that is not an integer and a
// timestamp that does not increase.
#include "realdata/breezyslam_log.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace mjslam::realdata {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Write(const std::string& name, const std::string& text) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "mjslam_breezyslam_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

// A log line: time (µs), ticks, 20 unused fields (one not an integer, as in
// the real log), 682 ranges of `range_mm` (beam b: range_mm + b), a trailing 0.
std::string Line(long long t_us, long long left, long long right, int range_mm = 1000,
                 int num_ranges = 682) {
  std::ostringstream out;
  out << t_us << " 14554 " << left << ' ' << right << " 0 0 0 167.2";
  for (int i = 8; i < 24; ++i) out << " 0";
  for (int b = 0; b < num_ranges; ++b) out << ' ' << range_mm + b;
  out << " 0\n";
  return out.str();
}

TEST(BreezySlamLogTest, OdometryFromTicksByHand) {
  // Line 2: both wheels 500 ticks (a quarter turn of a 77 mm wheel) ahead:
  // straight 0.077 pi / 2 m. Line 3: the right wheel 1000 ticks (half a turn),
  // the left none: the centre 0.077 pi / 2 m ahead along the step's mean
  // heading, turning 0.077 pi / 0.33 rad.
  const std::string path = Write("three.dat", Line(1000000, 1000, 2000) +
                                                  Line(1100000, 1500, 2500) +
                                                  Line(1200000, 1500, 3500));
  ASSERT_TRUE(LooksLikeBreezySlamLog(path));
  const CarmenLog log = ReadBreezySlamLog(path);
  ASSERT_EQ(log.odometry.size(), 3u);
  const double step = 0.077 * kPi / 2.0;
  const double turn = 0.077 * kPi / 0.33;
  EXPECT_EQ(log.odometry[0].pose.x, 0.0);
  EXPECT_NEAR(log.odometry[1].pose.x, step, 1e-12);
  EXPECT_NEAR(log.odometry[1].pose.y, 0.0, 1e-12);
  EXPECT_NEAR(log.odometry[1].pose.theta, 0.0, 1e-12);
  EXPECT_NEAR(log.odometry[2].pose.x, step + step * std::cos(turn / 2), 1e-12);
  EXPECT_NEAR(log.odometry[2].pose.y, step * std::sin(turn / 2), 1e-12);
  EXPECT_NEAR(log.odometry[2].pose.theta, turn, 1e-12);
  EXPECT_DOUBLE_EQ(log.odometry[2].t_s, 1.2);
  EXPECT_EQ(log.odometry[2].line, 3);

  // Scans: mm to m, the detection margin (beams 0..70 and 612..681) as no
  // return, 240 deg from -120, each with its line's odometry.
  const LaserMessage& scan = log.lasers.at(kBreezySlamLaser).at(2);
  ASSERT_EQ(scan.ranges_m.size(), 682u);
  EXPECT_EQ(scan.ranges_m[70], 0.0);
  EXPECT_DOUBLE_EQ(scan.ranges_m[71], 1.071);
  EXPECT_DOUBLE_EQ(scan.ranges_m[611], 1.611);
  EXPECT_EQ(scan.ranges_m[612], 0.0);
  EXPECT_DOUBLE_EQ(scan.angle_min_rad, -120.0 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(scan.angle_min_rad + 681 * scan.angle_increment_rad, 120.0 * kPi / 180.0);
  EXPECT_EQ(scan.max_range_m, 4.0);
  EXPECT_FALSE(scan.has_poses);
  EXPECT_TRUE(scan.has_odometry_at_scan);
  EXPECT_EQ(scan.odometry_at_scan.theta, log.odometry[2].pose.theta);
  EXPECT_EQ(log.params.at("robot_frontlaser_offset"), "0.145");
}

TEST(BreezySlamLogTest, TruncatedLineIsAnErrorNamingTheLine) {
  const std::string path =
      Write("truncated.dat", Line(1000000, 0, 0) + Line(1100000, 10, 10, 1000, 300));
  try {
    ReadBreezySlamLog(path);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), (path + ":2: expected 707 fields for 682 beams (got 325; "
                                   "truncated line?)").c_str());
  }
}

TEST(BreezySlamLogTest, BadFieldsAndTimestampsAreErrorsNamingTheLine) {
  std::string bad = Line(1000000, 0, 0);
  bad.replace(bad.find(" 1000 "), 6, " 1x00 ");  // the first range
  const std::string bad_path = Write("bad.dat", bad);
  EXPECT_FALSE(LooksLikeBreezySlamLog(bad_path));
  try {
    ReadBreezySlamLog(bad_path);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 (bad_path + ":1: field 24: expected an integer (got '1x00')").c_str());
  }
  const std::string back = Write("back.dat", Line(2000000, 0, 0) + Line(2000000, 5, 5));
  try {
    ReadBreezySlamLog(back);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 (back + ":2: timestamp 2000000 us not after the line before's").c_str());
  }
  EXPECT_THROW(ReadBreezySlamLog(Write("empty.dat", "\n")), std::runtime_error);
  // A CARMEN log is not taken for one.
  EXPECT_FALSE(LooksLikeBreezySlamLog(Write("carmen.log", "ODOM 0 0 0 0 0 0 1 h 1\n")));
}

}  // namespace
}  // namespace mjslam::realdata
