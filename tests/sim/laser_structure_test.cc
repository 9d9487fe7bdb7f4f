// The SICK's error structure (opt-in laser keys, sim/laser_noise.h): keys off
// give the same scans bit for bit; the noise's sigma grows with range as
// configured; grazing dropouts follow the configured curve; mixed pixels
// appear only where the footprint straddles a depth discontinuity and lie
// between its two ranges; rounding to the range resolution; the cast's
// incidence angles and footprint sub-rays against geometry. Statistical tests
// state their seed and bound (4 standard errors: a false failure about once
// in 16000 runs of each check; the seeds are fixed, so they never flake).

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/rng.h"
#include "sim/laser_footprint.h"
#include "sim/laser_noise.h"
#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"

namespace mjslam::sim {
namespace {

using testing::MujocoTest;
using testing::RobotModelPath;
using testing::WorldXml;
using testing::WriteTempFile;

LaserScan ExactScan(const LaserParams& laser, double range_m) {
  LaserScan scan;
  scan.angle_min_rad = laser.AngleMinRad();
  scan.angle_increment_rad = laser.AngleIncrementRad();
  scan.max_range_m = laser.max_range_m;
  scan.ranges_m.assign(laser.num_beams, range_m);
  scan.has_return.assign(laser.num_beams, 1);
  return scan;
}

// A footprint with every sub-ray at the beam's range and every incidence 0.
LaserFootprint FlatFootprint(const LaserParams& laser, const LaserScan& exact) {
  LaserFootprint footprint;
  footprint.rays_per_beam = laser.HasMixedPixels() ? laser.footprint_rays : 0;
  for (int i = 0; i < exact.size(); ++i) {
    for (int j = 0; j < footprint.rays_per_beam; ++j) {
      footprint.sub_ranges_m.push_back(exact.ranges_m[i]);
    }
  }
  if (laser.HasGrazingDropouts()) footprint.incidence_rad.assign(exact.size(), 0.0);
  return footprint;
}

TEST(LaserStructureTest, KeysOffGiveBitIdenticalScans) {
  // The existing model with everything it has on, against the same with the
  // structure's other keys moved (they must not matter while the structure
  // is off) and a footprint passed.
  LaserParams base;
  base.range_noise_std_m = 0.01;
  base.range_bias_std_m = 0.01;
  base.range_scale_std_fraction = 0.01;
  base.dropout_probability = 0.1;
  base.angle_jitter_std_deg = 0.1;
  LaserParams moved = base;
  moved.mixed_pixel_min_step_m = 0.02;
  moved.beam_divergence_deg = 3.0;
  moved.footprint_rays = 9;
  moved.grazing_dropout_start_deg = 10.0;
  LaserScan exact = ExactScan(base, 7.5);
  for (int i = 0; i < exact.size(); ++i) exact.ranges_m[i] = 0.5 + 0.1 * i;
  exact.has_return[3] = 0;
  exact.ranges_m[3] = base.max_range_m;
  LaserFootprint footprint;
  footprint.rays_per_beam = 3;
  footprint.sub_ranges_m.assign(3 * exact.size(), 1.0);
  footprint.incidence_rad.assign(exact.size(), 1.5);
  LaserNoise a(base, Rng(42));
  LaserNoise b(moved, Rng(42));
  for (int scan = 0; scan < 20; ++scan) {
    EXPECT_EQ(a.DrawAngleOffsets(), b.DrawAngleOffsets());
    const LaserScan noisy_a = a.Apply(exact);
    const LaserScan noisy_b = b.Apply(exact, &footprint);
    EXPECT_EQ(noisy_a.ranges_m, noisy_b.ranges_m) << "scan " << scan;
    EXPECT_EQ(noisy_a.has_return, noisy_b.has_return) << "scan " << scan;
  }
}

TEST(LaserStructureTest, NoiseSigmaGrowsWithRangeAsConfigured) {
  // Seed 7, 200 scans x 181 beams = 36200 samples per range; sigma(r) =
  // 0.005 + 0.002 r. Bound on the sample sigma: 4 sigma / sqrt(2 n) (1.5 %).
  LaserParams laser;
  laser.range_noise_std_m = 0.005;
  laser.range_noise_std_per_m = 0.002;
  laser.range_bias_m = 0.003;
  for (const double range : {0.5, 5.0, 15.0, 25.0}) {
    LaserNoise noise(laser, Rng(7));
    const LaserScan exact = ExactScan(laser, range);
    double sum = 0.0;
    double sum_sq = 0.0;
    int n = 0;
    for (int scan = 0; scan < 200; ++scan) {
      const LaserScan noisy = noise.Apply(exact);
      for (int i = 0; i < noisy.size(); ++i) {
        ASSERT_EQ(noisy.has_return[i], 1);
        const double error = noisy.ranges_m[i] - range;
        sum += error;
        sum_sq += error * error;
        ++n;
      }
    }
    const double mean = sum / n;
    const double sigma = std::sqrt(sum_sq / n - mean * mean);
    const double expected = 0.005 + 0.002 * range;
    std::cout << "seed 7, range " << range << " m: mean " << mean << ", sigma " << sigma
              << " (configured " << expected << ")\n";
    EXPECT_NEAR(mean, 0.003, 4.0 * expected / std::sqrt(n)) << range;
    EXPECT_NEAR(sigma, expected, 4.0 * expected / std::sqrt(2.0 * n)) << range;
  }
}

TEST(LaserStructureTest, GrazingDropoutsFollowTheConfiguredCurve) {
  // Seed 11; p(theta) = 0.8 (theta - 60) / 30 above 60 deg. Nine incidences,
  // one per beam in turn: 181 beams x 600 scans / 9 = 12000 trials each.
  // Bound: |rate - p| <= 4 sqrt(p (1 - p) / n); exactly none where p = 0.
  LaserParams laser;
  laser.range_noise_std_m = 0.0;
  laser.grazing_dropout_probability = 0.8;
  laser.grazing_dropout_start_deg = 60.0;
  const std::vector<double> incidences_deg = {0.0, 30.0, 59.0, 62.0, 70.0, 75.0, 80.0, 85.0, 89.9};
  LaserNoise noise(laser, Rng(11));
  const LaserScan exact = ExactScan(laser, 3.0);
  LaserFootprint footprint = FlatFootprint(laser, exact);
  for (int i = 0; i < exact.size(); ++i) {
    footprint.incidence_rad[i] = DegToRad(incidences_deg[i % incidences_deg.size()]);
  }
  footprint.incidence_rad[180] = std::nan("");  // unknown incidence: never a grazing dropout
  std::vector<int> dropped(incidences_deg.size(), 0);
  std::vector<int> trials(incidences_deg.size(), 0);
  for (int scan = 0; scan < 600; ++scan) {
    const LaserScan noisy = noise.Apply(exact, &footprint);
    for (int i = 0; i < 180; ++i) {
      const std::size_t k = i % incidences_deg.size();
      ++trials[k];
      if (!noisy.has_return[i]) {
        ++dropped[k];
        EXPECT_EQ(noisy.ranges_m[i], laser.max_range_m);
      } else {
        EXPECT_EQ(noisy.ranges_m[i], 3.0);
      }
    }
    EXPECT_EQ(noisy.has_return[180], 1);
  }
  for (std::size_t k = 0; k < incidences_deg.size(); ++k) {
    const double theta = incidences_deg[k];
    const double p = 0.8 * std::clamp((theta - 60.0) / 30.0, 0.0, 1.0);
    EXPECT_NEAR(noise.GrazingDropoutProbability(DegToRad(theta)), p, 1e-12);
    const double rate = static_cast<double>(dropped[k]) / trials[k];
    std::cout << "seed 11, incidence " << theta << " deg: dropout rate " << rate << " (configured " << p
              << ", " << trials[k] << " trials)\n";
    if (p == 0.0) {
      EXPECT_EQ(dropped[k], 0) << theta;
    } else {
      EXPECT_NEAR(rate, p, 4.0 * std::sqrt(p * (1.0 - p) / trials[k])) << theta;
    }
  }
}

TEST(LaserStructureTest, MixedPixelsOnlyAtDiscontinuitiesAndBetweenTheRanges) {
  // Seed 5, no range noise, mixed_pixel_probability 0.4, 5 sub-rays. Three
  // kinds of beam in turn: a footprint on one surface (sub-rays 4.00..4.04 m,
  // in line to well within the min step 0.1 m), one straddling an edge (2, 2,
  // 5, 5, 5 m: the centre at 5 m), and one whose far side has no echo (2, 2,
  // none x 3: no three hits in a row, no discontinuity seen).
  // Only the edge beams may mix, to the mean 3.8 m; their mixed fraction
  // within 4 sqrt(p (1 - p) / n) of 0.4 (60 beams x 500 scans = 30000).
  LaserParams laser;
  laser.range_noise_std_m = 0.0;
  laser.mixed_pixel_probability = 0.4;
  laser.footprint_rays = 5;
  const double far = laser.max_range_m;
  LaserScan exact = ExactScan(laser, 4.02);
  LaserFootprint footprint;
  footprint.rays_per_beam = 5;
  for (int i = 0; i < exact.size(); ++i) {
    std::vector<double> sub;
    if (i % 3 == 0) sub = {4.00, 4.01, 4.02, 4.03, 4.04};
    if (i % 3 == 1) sub = {2.0, 2.0, 5.0, 5.0, 5.0};
    if (i % 3 == 2) sub = {2.0, 2.0, far, far, far};
    exact.ranges_m[i] = sub[2] < far ? sub[2] : 2.0;
    footprint.sub_ranges_m.insert(footprint.sub_ranges_m.end(), sub.begin(), sub.end());
  }
  LaserNoise noise(laser, Rng(5));
  int edge_beams = 0;
  int mixed = 0;
  for (int scan = 0; scan < 500; ++scan) {
    const LaserScan noisy = noise.Apply(exact, &footprint);
    for (int i = 0; i < noisy.size(); ++i) {
      ASSERT_EQ(noisy.has_return[i], 1);
      if (i % 3 != 1) {
        EXPECT_EQ(noisy.ranges_m[i], exact.ranges_m[i]) << "beam " << i << " is no edge";
        continue;
      }
      ++edge_beams;
      if (noisy.ranges_m[i] != exact.ranges_m[i]) {
        ++mixed;
        EXPECT_GT(noisy.ranges_m[i], 2.0);
        EXPECT_LT(noisy.ranges_m[i], 5.0);
        EXPECT_NEAR(noisy.ranges_m[i], 3.8, 1e-12);
      }
    }
  }
  const double rate = static_cast<double>(mixed) / edge_beams;
  std::cout << "seed 5, mixed pixels: " << mixed << " of " << edge_beams << " edge beams (" << rate
            << ", configured 0.4)\n";
  EXPECT_NEAR(rate, 0.4, 4.0 * std::sqrt(0.4 * 0.6 / edge_beams));
}

TEST(LaserStructureTest, RangesAreRoundedToTheResolution) {
  LaserParams laser;
  laser.range_noise_std_m = 0.02;
  laser.range_resolution_m = 0.01;
  LaserNoise noise(laser, Rng(3));
  const LaserScan noisy = noise.Apply(ExactScan(laser, 6.123));
  for (int i = 0; i < noisy.size(); ++i) {
    const double units = noisy.ranges_m[i] / 0.01;
    EXPECT_NEAR(units, std::round(units), 1e-9) << i;
  }
}

TEST(LaserStructureTest, SameSeedSameScansWithEveryKeyOn) {
  LaserParams laser;
  laser.range_noise_std_per_m = 0.001;
  laser.range_resolution_m = 0.001;
  laser.mixed_pixel_probability = 0.5;
  laser.grazing_dropout_probability = 0.5;
  const LaserScan exact = ExactScan(laser, 2.5);
  LaserFootprint footprint = FlatFootprint(laser, exact);
  for (std::size_t k = 0; k < footprint.sub_ranges_m.size(); ++k) {
    footprint.sub_ranges_m[k] = k % 2 == 0 ? 2.5 : 4.0;
  }
  for (int i = 0; i < exact.size(); ++i) footprint.incidence_rad[i] = DegToRad(i * 0.5);
  LaserNoise a(laser, Rng(9));
  LaserNoise b(laser, Rng(9));
  LaserNoise c(laser, Rng(10));
  bool differs = false;
  for (int scan = 0; scan < 5; ++scan) {
    const LaserScan sa = a.Apply(exact, &footprint);
    const LaserScan sb = b.Apply(exact, &footprint);
    const LaserScan sc = c.Apply(exact, &footprint);
    EXPECT_EQ(sa.ranges_m, sb.ranges_m);
    EXPECT_EQ(sa.has_return, sb.has_return);
    differs = differs || sa.ranges_m != sc.ranges_m;
  }
  EXPECT_TRUE(differs);
}

class LaserStructureCastTest : public MujocoTest {};

TEST_F(LaserStructureCastTest, IncidenceAnglesMatchAFlatWall) {
  // A long wall whose face is the line x = 2.9: a beam at world bearing b
  // meets it at incidence |b|. The scan is the same with or without the
  // footprint.
  const std::string world = WriteTempFile(
      "incidence.xml",
      WorldXml("<geom type=\"box\" size=\"0.1 40 0.5\" pos=\"3 0 0.5\"/>\n"));
  Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 0.2));
  LaserParams laser;
  laser.grazing_dropout_probability = 0.5;
  LaserFootprint footprint;
  const LaserScan with = sim.CastLaser(laser, {}, &footprint);
  const LaserScan without = sim.CastLaser(laser);
  EXPECT_EQ(with.ranges_m, without.ranges_m);
  EXPECT_EQ(with.has_return, without.has_return);
  ASSERT_EQ(static_cast<int>(footprint.incidence_rad.size()), laser.num_beams);
  EXPECT_EQ(footprint.rays_per_beam, 0);
  int checked = 0;
  double largest_error = 0.0;
  for (int i = 0; i < with.size(); ++i) {
    const double bearing_W = sim.X_WS().theta + with.BeamAngle(i);
    if (!with.has_return[i]) {
      EXPECT_TRUE(std::isnan(footprint.incidence_rad[i])) << i;
      continue;
    }
    ++checked;
    const double expected = std::abs(WrapAngle(bearing_W));
    largest_error = std::max(largest_error, std::abs(footprint.incidence_rad[i] - expected));
    EXPECT_NEAR(footprint.incidence_rad[i], expected, 1e-6) << "beam " << i;
  }
  std::cout << checked << " beams on the wall, largest incidence error " << largest_error
            << " rad\n";
  EXPECT_GT(checked, 100);
}

TEST_F(LaserStructureCastTest, MixedPixelsOnlyWhereTheFootprintStraddlesAnEdge) {
  // A short wall (x 1.95..2.05, y 0.3..3.3) before a far one (face x = 5).
  // With a 1.5 deg footprint, probability 1 and no noise, a beam reads a
  // mixed range exactly when its footprint's sub-rays span one of the short
  // wall's two silhouette edges; the range lies between the near and the far
  // surface.
  const std::string world = WriteTempFile(
      "edge.xml", WorldXml("<geom type=\"box\" size=\"0.05 1.5 0.5\" pos=\"2 1.8 0.5\"/>\n"
                           "<geom type=\"box\" size=\"0.1 40 0.5\" pos=\"5.1 0 0.5\"/>\n"));
  Simulator sim(world, RobotModelPath(), SimParams{}, RobotParams{}, Pose2(0, 0, 0));
  LaserParams laser;
  laser.range_noise_std_m = 0.0;
  laser.mixed_pixel_probability = 1.0;
  laser.beam_divergence_deg = 1.5;
  laser.footprint_rays = 5;
  LaserFootprint footprint;
  const LaserScan exact = sim.CastLaser(laser, {}, &footprint);
  ASSERT_EQ(footprint.rays_per_beam, 5);
  LaserNoise noise(laser, Rng(1));
  const LaserScan noisy = noise.Apply(exact, &footprint);
  // The silhouette edges: the smallest and largest bearings of the corners.
  const Pose2 X_WS = sim.X_WS();
  double low = 1e9;
  double high = -1e9;
  for (const double x : {1.95, 2.05}) {
    for (const double y : {0.3, 3.3}) {
      const double b = std::atan2(y - X_WS.y, x - X_WS.x) - X_WS.theta;
      low = std::min(low, b);
      high = std::max(high, b);
    }
  }
  const double half = 0.5 * DegToRad(laser.beam_divergence_deg);
  int mixed = 0;
  for (int i = 0; i < exact.size(); ++i) {
    const double b = exact.BeamAngle(i);
    const double to_edge = std::min(std::abs(b - low), std::abs(b - high));
    const bool straddles = to_edge < half;
    const bool is_mixed = noisy.ranges_m[i] != exact.ranges_m[i];
    if (to_edge < half - 1e-3 || to_edge > half + 1e-3) {
      EXPECT_EQ(is_mixed, straddles) << "beam " << i << ", " << RadToDeg(to_edge)
                                     << " deg from an edge";
    }
    if (is_mixed) {
      ++mixed;
      const double* sub = footprint.sub_ranges_m.data() + 5 * i;
      const double near = *std::min_element(sub, sub + 5);
      const double far = *std::max_element(sub, sub + 5);
      EXPECT_GT(far - near, 1.0) << i;  // the two surfaces are about 2.9 m apart
      EXPECT_GT(noisy.ranges_m[i], near) << i;
      EXPECT_LT(noisy.ranges_m[i], far) << i;
    }
  }
  std::cout << mixed << " mixed pixels, edges at " << RadToDeg(low) << " and " << RadToDeg(high)
            << " deg\n";
  EXPECT_GE(mixed, 2);
}

}  // namespace
}  // namespace mjslam::sim
