// Each stage of ExtractFeatures on its own (slam/feature_extraction_stages.h),
// on small hand-made inputs whose right answer is known: exact points on
// straight walls, a concave and a convex corner, outliers, gaps.

#include "slam/feature_extraction_stages.h"

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/laser_scan.h"

namespace mjslam::slam::extraction {
namespace {

constexpr double kTight = 1e-9;

// A point of beam `beam` at (x, y) in S.
ScanPoint Point(double x, double y, int beam) {
  const double range = std::hypot(x, y);
  return {x, y, range, 1.0 / (range * range), beam};
}

// Points at (x0 + i dx, y0 + i dy), i = 0 .. count - 1, beams from `beam0`.
std::vector<ScanPoint> PointsAlong(double x0, double y0, double dx, double dy, int count,
                                   int beam0 = 0) {
  std::vector<ScanPoint> points;
  for (int i = 0; i < count; ++i) points.push_back(Point(x0 + i * dx, y0 + i * dy, beam0 + i));
  return points;
}

// Appends `more` to `points`.
void Append(const std::vector<ScanPoint>& more, std::vector<ScanPoint>* points) {
  points->insert(points->end(), more.begin(), more.end());
}

Segment RunOf(int first, int last, int cluster) {
  Segment run;
  run.first = first;
  run.last = last;
  run.cluster = cluster;
  return run;
}

// (first, last, cluster) of a run.
std::array<int, 3> Bounds(const Segment& run) { return {run.first, run.last, run.cluster}; }

// A scan with every beam returning, from `angle_min_deg`, 1 degree apart.
LaserScan Scan(const std::vector<double>& ranges_m, double angle_min_deg) {
  LaserScan scan;
  scan.angle_min_rad = DegToRad(angle_min_deg);
  scan.angle_increment_rad = DegToRad(1.0);
  scan.max_range_m = 30.0;
  scan.ranges_m = ranges_m;
  scan.has_return.assign(ranges_m.size(), 1);
  return scan;
}

// Range along bearing `phi` (radians) to the polar line (rho, alpha).
double RangeToLine(double rho, double alpha, double phi) { return rho / std::cos(phi - alpha); }

// Beams from -25 to 60 degrees into the concave corner (2, 1) of the walls
// x = 2 and y = 1.
LaserScan ConcaveCornerScan() {
  std::vector<double> ranges;
  for (int deg = -25; deg <= 60; ++deg) {
    const double phi = DegToRad(deg);
    ranges.push_back(std::tan(phi) <= 0.5 ? RangeToLine(2.0, 0.0, phi)
                                          : RangeToLine(1.0, kPi / 2.0, phi));
  }
  return Scan(ranges, -25.0);
}

// Beams from -18 to 18 degrees onto the convex corner (2, 0) of a box whose
// faces run to (3, -1) and (3, 1).
LaserScan ConvexCornerScan() {
  std::vector<double> ranges;
  for (int deg = -18; deg <= 18; ++deg) {
    const double phi = DegToRad(deg);
    ranges.push_back(deg < 0 ? RangeToLine(std::sqrt(2.0), kPi / 4.0, phi)
                             : RangeToLine(std::sqrt(2.0), -kPi / 4.0, phi));
  }
  return Scan(ranges, -18.0);
}

// The stages up to the lines, as ExtractFeatures runs them.
struct Lines {
  std::vector<ScanPoint> points;
  std::vector<ClusterBounds> clusters;
  std::vector<Segment> runs;
  std::vector<int> line_of_run;
  std::vector<LineObservation> lines;
};

Lines LinesOf(const LaserScan& scan, const FeatureExtractionParams& params) {
  const NoiseModel noise = MakeNoiseModel(params);
  Lines out;
  out.points = ScanPoints(scan);
  out.clusters = FindClusters(out.points, scan.angle_increment_rad, params);
  out.runs = SplitClusters(out.points, out.clusters, params.split_distance_m);
  MergeRuns(out.points, noise, params.split_distance_m, &out.runs);
  SplitInconsistentRuns(out.points, noise, params.fit_test_probability, &out.runs);
  const std::vector<char> is_vertex =
      SeparateVertexPoints(static_cast<int>(out.points.size()), &out.runs);
  FitRuns(out.points, noise, params.min_points, &out.runs);
  TrimRuns(out.points, noise, params, &out.runs);
  GrowRuns(out.points, noise, params, out.clusters, is_vertex, &out.runs);
  out.lines = KeepLines(out.points, params, &out.runs, &out.line_of_run);
  return out;
}

// ---------------------------------------------------------------------------
// Points (step 1).

TEST(ScanPointsTest, DropsNoReturnShortAndNonFiniteBeams) {
  // Beams at 0, 90, 180, 270, 360, 450 degrees.
  LaserScan scan;
  scan.angle_min_rad = 0.0;
  scan.angle_increment_rad = kPi / 2.0;
  scan.max_range_m = 30.0;
  scan.ranges_m = {1.0, 2.0, std::numeric_limits<double>::quiet_NaN(), 0.0005, 3.0, 4.0};
  // Beam 4 has no return; beam 5 lies past the end of has_return.
  scan.has_return = {1, 1, 1, 1, 0};
  const std::vector<ScanPoint> points = ScanPoints(scan);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0].beam, 0);
  EXPECT_NEAR(points[0].x, 1.0, 1e-15);
  EXPECT_NEAR(points[0].y, 0.0, 1e-15);
  EXPECT_EQ(points[1].beam, 1);
  EXPECT_NEAR(points[1].x, 0.0, 1e-15);
  EXPECT_NEAR(points[1].y, 2.0, 1e-15);
  EXPECT_EQ(points[1].range, 2.0);
  EXPECT_EQ(points[1].inverse_range2, 0.25);
}

TEST(ScanPointsTest, RotatedBeamDirectionsMatchExactOnes) {
  // 40 beams: the directions between the anchors come from rotations.
  std::vector<double> ranges;
  for (int i = 0; i < 40; ++i) ranges.push_back(1.0 + 0.1 * i);
  LaserScan scan = Scan(ranges, -20.0);
  scan.angle_increment_rad = -0.013;  // a clockwise scan
  const std::vector<ScanPoint> points = ScanPoints(scan);
  ASSERT_EQ(points.size(), 40u);
  for (int i = 0; i < 40; ++i) {
    EXPECT_NEAR(points[i].x, ranges[i] * std::cos(scan.BeamAngle(i)), 1e-13) << i;
    EXPECT_NEAR(points[i].y, ranges[i] * std::sin(scan.BeamAngle(i)), 1e-13) << i;
  }
}

// ---------------------------------------------------------------------------
// Clusters (step 2).

TEST(FindClustersTest, BreaksAtARangeJump) {
  // Beams -10..-1 deg on the wall x = 2, then 0..10 deg on the wall x = 4.
  std::vector<double> ranges;
  for (int deg = -10; deg <= 10; ++deg) {
    ranges.push_back(RangeToLine(deg < 0 ? 2.0 : 4.0, 0.0, DegToRad(deg)));
  }
  const LaserScan scan = Scan(ranges, -10.0);
  const std::vector<ClusterBounds> clusters =
      FindClusters(ScanPoints(scan), scan.angle_increment_rad, FeatureExtractionParams{});
  ASSERT_EQ(clusters.size(), 2u);
  EXPECT_EQ(clusters[0].first, 0);
  EXPECT_EQ(clusters[0].last, 9);
  EXPECT_EQ(clusters[1].first, 10);
  EXPECT_EQ(clusters[1].last, 20);
}

TEST(FindClustersTest, BridgesShortGapsAndDropsSmallClusters) {
  // 21 beams on the wall x = 2.
  std::vector<double> ranges;
  for (int deg = -10; deg <= 10; ++deg) ranges.push_back(RangeToLine(2.0, 0.0, DegToRad(deg)));
  FeatureExtractionParams params;  // max_missing_beams 2, min_points 6
  // Two lost echoes (beams 5, 6): one cluster of 19 points.
  LaserScan scan = Scan(ranges, -10.0);
  scan.has_return[5] = scan.has_return[6] = 0;
  std::vector<ClusterBounds> clusters =
      FindClusters(ScanPoints(scan), scan.angle_increment_rad, params);
  ASSERT_EQ(clusters.size(), 1u);
  EXPECT_EQ(clusters[0].first, 0);
  EXPECT_EQ(clusters[0].last, 18);
  // Three (beams 5-7): the 5 points before the gap are too few for a line.
  scan.has_return[7] = 0;
  clusters = FindClusters(ScanPoints(scan), scan.angle_increment_rad, params);
  ASSERT_EQ(clusters.size(), 1u);
  EXPECT_EQ(clusters[0].first, 5);
  EXPECT_EQ(clusters[0].last, 17);
}

// ---------------------------------------------------------------------------
// Split (step 3).

TEST(SplitClustersTest, SplitsAtTheVertexAndKeepsStraightClustersWhole) {
  // Cluster 0: an L, (2, -1) .. (2, 0) .. (1, 0), vertex at point 5.
  // Cluster 1: a straight wall.
  std::vector<ScanPoint> points = PointsAlong(2.0, -1.0, 0.0, 0.2, 6);
  Append(PointsAlong(1.8, 0.0, -0.2, 0.0, 5, 6), &points);
  Append(PointsAlong(3.0, 1.0, 0.0, 0.1, 10, 11), &points);
  const std::vector<Segment> runs = SplitClusters(points, {{0, 10}, {11, 20}}, 0.03);
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_EQ(Bounds(runs[0]), (std::array<int, 3>{0, 5, 0}));
  EXPECT_EQ(Bounds(runs[1]), (std::array<int, 3>{5, 10, 0}));
  EXPECT_EQ(Bounds(runs[2]), (std::array<int, 3>{11, 20, 1}));
}

// ---------------------------------------------------------------------------
// Merge (step 4).

TEST(MergeRunsTest, MergesStraightNeighboursOfOneClusterOnly) {
  const FeatureExtractionParams params;
  const NoiseModel noise = MakeNoiseModel(params);
  // One straight wall cut in three runs of cluster 0, and a run of cluster 1
  // on the same line that shares the boundary point.
  const std::vector<ScanPoint> points = PointsAlong(2.0, -1.0, 0.0, 0.1, 21);
  std::vector<Segment> runs = {RunOf(0, 5, 0), RunOf(5, 10, 0), RunOf(10, 15, 0), RunOf(15, 20, 1)};
  MergeRuns(points, noise, params.split_distance_m, &runs);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(Bounds(runs[0]), (std::array<int, 3>{0, 15, 0}));
  EXPECT_EQ(Bounds(runs[1]), (std::array<int, 3>{15, 20, 1}));
}

TEST(MergeRunsTest, KeepsTheTwoWallsOfACorner) {
  const FeatureExtractionParams params;
  std::vector<ScanPoint> points = PointsAlong(2.0, -1.0, 0.0, 0.2, 6);
  Append(PointsAlong(1.8, 0.0, -0.2, 0.0, 5, 6), &points);
  std::vector<Segment> runs = {RunOf(0, 5, 0), RunOf(5, 10, 0)};
  MergeRuns(points, MakeNoiseModel(params), params.split_distance_m, &runs);
  EXPECT_EQ(runs.size(), 2u);
}

// ---------------------------------------------------------------------------
// Fit test (step 4b).

// A wall x = 2 seen from y = -2 to 1.9 (40 points), then a parallel wall
// `step_m` further away for 8 points: a pilaster or a thicker wall beside it.
std::vector<ScanPoint> SteppedWall(double step_m) {
  std::vector<ScanPoint> points = PointsAlong(2.0, -2.0, 0.0, 0.1, 40);
  Append(PointsAlong(2.0 + step_m, 2.0, 0.0, 0.1, 8, 40), &points);
  return points;
}

TEST(SplitInconsistentRunsTest, SplitsAStepThatTheChordTestMerges) {
  const FeatureExtractionParams params;
  const NoiseModel noise = MakeNoiseModel(params);
  const std::vector<ScanPoint> points = SteppedWall(0.05);
  // The merge of split-and-merge joins the two walls into one (tilted) run.
  std::vector<Segment> runs = {RunOf(0, 39, 0), RunOf(39, 47, 0)};
  MergeRuns(points, noise, params.split_distance_m, &runs);
  ASSERT_EQ(runs.size(), 1u);
  SplitInconsistentRuns(points, noise, params.fit_test_probability, &runs);
  ASSERT_EQ(runs.size(), 2u);
  // Split at the last point of the near wall or the first of the far one,
  // shared by both runs as a split point is.
  EXPECT_EQ(runs[0].first, 0);
  EXPECT_EQ(runs[1].last, 47);
  EXPECT_EQ(runs[0].last, runs[1].first);
  EXPECT_GE(runs[0].last, 39);
  EXPECT_LE(runs[0].last, 40);
  EXPECT_EQ(runs[1].cluster, 0);
}

TEST(SplitInconsistentRunsTest, KeepsNoisyStraightWallsWholeAndIsOffAtZero) {
  FeatureExtractionParams params;
  const NoiseModel noise = MakeNoiseModel(params);
  // 100 walls of 60 points with range noise of the model's size: at the
  // default 0.99999 a wall is split with probability 1e-5 (a fixed seed).
  std::mt19937 engine(7);
  std::normal_distribution<double> normal(0.0, params.range_noise_std_m);
  int split = 0;
  for (int wall = 0; wall < 100; ++wall) {
    std::vector<ScanPoint> points;
    for (int i = 0; i < 60; ++i) {
      const double phi = DegToRad(-30.0 + i);
      const double range = RangeToLine(3.0, 0.0, phi) + normal(engine);
      points.push_back(Point(range * std::cos(phi), range * std::sin(phi), i));
    }
    std::vector<Segment> runs = {RunOf(0, 59, 0)};
    SplitInconsistentRuns(points, noise, params.fit_test_probability, &runs);
    if (runs.size() != 1u) ++split;
  }
  EXPECT_LE(split, 1);
  params.fit_test_probability = 0.0;
  const std::vector<ScanPoint> points = SteppedWall(0.05);
  std::vector<Segment> runs = {RunOf(0, 47, 0)};
  SplitInconsistentRuns(points, noise, params.fit_test_probability, &runs);
  EXPECT_EQ(runs.size(), 1u);
}

// ---------------------------------------------------------------------------
// Vertex points (step 5).

TEST(SeparateVertexPointsTest, TakesSharedPointsFromBothRuns) {
  std::vector<Segment> runs = {RunOf(0, 5, 0), RunOf(5, 10, 0), RunOf(11, 15, 1), RunOf(15, 20, 2)};
  const std::vector<char> is_vertex = SeparateVertexPoints(21, &runs);
  ASSERT_EQ(is_vertex.size(), 21u);
  for (int i = 0; i < 21; ++i) EXPECT_EQ(is_vertex[i], i == 5 ? 1 : 0) << i;
  EXPECT_EQ(runs[0].last, 4);
  EXPECT_EQ(runs[1].first, 6);
  // Point 15 ends runs of two clusters: no vertex, both keep it.
  EXPECT_EQ(runs[2].last, 15);
  EXPECT_EQ(runs[3].first, 15);
}

// ---------------------------------------------------------------------------
// Fit (steps 5-6).

TEST(FitRunsTest, FitsRunsWithEnoughPoints) {
  const FeatureExtractionParams params;  // min_points 6
  const NoiseModel noise = MakeNoiseModel(params);
  // The wall x = 2 (rho 2, alpha 0), then 8 copies of one point.
  std::vector<ScanPoint> points = PointsAlong(2.0, -0.5, 0.0, 0.1, 11);
  Append(PointsAlong(1.0, 1.0, 0.0, 0.0, 8, 11), &points);
  std::vector<Segment> runs = {RunOf(0, 10, 0), RunOf(0, 4, 0), RunOf(11, 18, 1)};
  FitRuns(points, noise, params.min_points, &runs);
  ASSERT_TRUE(runs[0].valid);
  EXPECT_NEAR(runs[0].fit.rho, 2.0, kTight);
  EXPECT_NEAR(runs[0].fit.alpha, 0.0, kTight);
  EXPECT_GT(runs[0].fit.covariance(0, 0), 0.0);
  EXPECT_GT(runs[0].fit.covariance(1, 1), 0.0);
  EXPECT_FALSE(runs[1].valid);  // 5 points
  EXPECT_FALSE(runs[2].valid);  // no direction
}

// ---------------------------------------------------------------------------
// Trim (step 5).

TEST(TrimRunsTest, DropsAnOutlierEnd) {
  const FeatureExtractionParams params;
  const NoiseModel noise = MakeNoiseModel(params);
  // The wall x = 2, its last point 5 cm behind it (10 range deviations).
  std::vector<ScanPoint> points = PointsAlong(2.0, -0.5, 0.0, 0.1, 11);
  points[10] = Point(2.05, 0.5, 10);
  std::vector<Segment> runs = {RunOf(0, 10, 0)};
  FitRuns(points, noise, params.min_points, &runs);
  TrimRuns(points, noise, params, &runs);
  ASSERT_TRUE(runs[0].valid);
  EXPECT_EQ(runs[0].first, 0);
  EXPECT_EQ(runs[0].last, 9);
  EXPECT_NEAR(runs[0].fit.rho, 2.0, kTight);
  EXPECT_NEAR(runs[0].fit.alpha, 0.0, kTight);
}

TEST(TrimRunsTest, DropsAnEndThatFitsTheNeighbouringLineToo) {
  const FeatureExtractionParams params;
  const NoiseModel noise = MakeNoiseModel(params);
  // Wall a: x = 2 up to (2, 0.4); wall b: y = 0.5 from the vertex (2, 0.5).
  std::vector<ScanPoint> points = PointsAlong(2.0, -0.5, 0.0, 0.1, 10);
  Append(PointsAlong(2.0, 0.5, -0.1, 0.0, 10, 10), &points);
  std::vector<Segment> runs = {RunOf(0, 9, 0), RunOf(10, 19, 0)};
  FitRuns(points, noise, params.min_points, &runs);
  TrimRuns(points, noise, params, &runs);
  ASSERT_TRUE(runs[0].valid);
  ASSERT_TRUE(runs[1].valid);
  EXPECT_EQ(runs[0].last, 9);    // (2, 0.4) is 0.1 m off wall b
  EXPECT_EQ(runs[1].first, 11);  // the vertex lies on both
  EXPECT_EQ(runs[1].last, 19);
}

TEST(TrimRunsTest, InvalidatesARunTrimmedBelowMinPoints) {
  FeatureExtractionParams params;
  params.min_points = 6;
  const NoiseModel noise = MakeNoiseModel(params);
  // Six points, the last an outlier.
  std::vector<ScanPoint> points = PointsAlong(2.0, -0.5, 0.0, 0.1, 6);
  points[5] = Point(2.2, 0.0, 5);
  std::vector<Segment> runs = {RunOf(0, 5, 0)};
  FitRuns(points, noise, params.min_points, &runs);
  ASSERT_TRUE(runs[0].valid);
  TrimRuns(points, noise, params, &runs);
  EXPECT_FALSE(runs[0].valid);
}

// ---------------------------------------------------------------------------
// Grow (step 5).

TEST(GrowRunsTest, GrowsIntoFittingPointsUpToVertexPointsAndOutliers) {
  const FeatureExtractionParams params;
  const NoiseModel noise = MakeNoiseModel(params);
  // The wall x = 2, cluster [0, 12]; point 12 is 5 cm off it.
  std::vector<ScanPoint> points = PointsAlong(2.0, -0.6, 0.0, 0.1, 13);
  points[12] = Point(2.05, 0.6, 12);
  std::vector<char> is_vertex(13, 0);
  std::vector<Segment> runs = {RunOf(3, 8, 0)};
  FitRuns(points, noise, params.min_points, &runs);
  // Free ends: down to the cluster's first point, up to the outlier.
  std::vector<Segment> grown = runs;
  GrowRuns(points, noise, params, {{0, 12}}, is_vertex, &grown);
  EXPECT_EQ(grown[0].first, 0);
  EXPECT_EQ(grown[0].last, 11);
  EXPECT_NEAR(grown[0].fit.rho, 2.0, kTight);
  // A vertex point stops it.
  is_vertex[1] = 1;
  grown = runs;
  GrowRuns(points, noise, params, {{0, 12}}, is_vertex, &grown);
  EXPECT_EQ(grown[0].first, 2);
  EXPECT_EQ(grown[0].last, 11);
  // So does the cluster's end.
  is_vertex[1] = 0;
  grown = runs;
  GrowRuns(points, noise, params, {{2, 10}}, is_vertex, &grown);
  EXPECT_EQ(grown[0].first, 2);
  EXPECT_EQ(grown[0].last, 10);
}

// ---------------------------------------------------------------------------
// Keep lines (step 7).

TEST(KeepLinesTest, KeepsLongEnoughValidRunsWithTheirSeenSegments) {
  FeatureExtractionParams params;  // min_length_m 0.25
  const NoiseModel noise = MakeNoiseModel(params);
  // A 1 m wall x = 2, a 5 cm one, and one run too short to be fitted.
  std::vector<ScanPoint> points = PointsAlong(2.0, -0.5, 0.0, 0.1, 11);
  Append(PointsAlong(3.0, 1.0, 0.0, 0.01, 6, 11), &points);
  std::vector<Segment> runs = {RunOf(0, 10, 0), RunOf(11, 16, 1), RunOf(0, 3, 0)};
  FitRuns(points, noise, params.min_points, &runs);
  std::vector<int> line_of_run;
  const std::vector<LineObservation> lines = KeepLines(points, params, &runs, &line_of_run);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(line_of_run, (std::vector<int>{0, -1, -1}));
  EXPECT_FALSE(runs[1].valid);
  EXPECT_NEAR(lines[0].rho_m, 2.0, kTight);
  EXPECT_NEAR(lines[0].p_SA.x(), 2.0, kTight);
  EXPECT_NEAR(lines[0].p_SA.y(), -0.5, kTight);
  EXPECT_NEAR(lines[0].p_SB.x(), 2.0, kTight);
  EXPECT_NEAR(lines[0].p_SB.y(), 0.5, kTight);
  EXPECT_EQ(lines[0].first_beam, 0);
  EXPECT_EQ(lines[0].last_beam, 10);
  // The model-error floor is on the covariance, symmetric.
  const double rho_floor = params.line_rho_floor_std_m;
  EXPECT_GE(lines[0].covariance(0, 0), runs[0].fit.covariance(0, 0) + rho_floor * rho_floor);
  EXPECT_EQ(lines[0].covariance(0, 1), lines[0].covariance(1, 0));
}

// ---------------------------------------------------------------------------
// Corners (step 8).

// The corners of a scan with the default params, from its two lines.
std::vector<CornerObservation> CornersOf(const LaserScan& scan) {
  const FeatureExtractionParams params;
  const Lines found = LinesOf(scan, params);
  EXPECT_EQ(found.lines.size(), 2u);
  return FindCorners(found.points, MakeNoiseModel(params), params, scan.angle_increment_rad,
                     found.runs, found.line_of_run, found.lines);
}

TEST(FindCornersTest, FindsAConcaveCornerAtTheVertex) {
  const std::vector<CornerObservation> corners = CornersOf(ConcaveCornerScan());
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_EQ(corners[0].kind, CornerKind::kConcave);
  EXPECT_NEAR(corners[0].p_SC.x(), 2.0, 1e-6);
  EXPECT_NEAR(corners[0].p_SC.y(), 1.0, 1e-6);
  EXPECT_NEAR(corners[0].range_m, std::sqrt(5.0), 1e-6);
  EXPECT_NEAR(corners[0].bearing_rad, std::atan2(1.0, 2.0), 1e-6);
  EXPECT_EQ(corners[0].line_a, 0);
  EXPECT_EQ(corners[0].line_b, 1);
  EXPECT_GT(corners[0].covariance.determinant(), 0.0);
}

TEST(FindCornersTest, FindsAConvexCornerPointingAtTheSensor) {
  const std::vector<CornerObservation> corners = CornersOf(ConvexCornerScan());
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_EQ(corners[0].kind, CornerKind::kConvex);
  EXPECT_NEAR(corners[0].p_SC.x(), 2.0, 1e-6);
  EXPECT_NEAR(corners[0].p_SC.y(), 0.0, 1e-6);
}

// The first two runs of a scan with their lines (default params), and
// whether CornerBetween makes them a corner.
struct LinePair {
  FeatureExtractionParams params;
  double increment_rad = 0.0;
  std::vector<ScanPoint> points;
  Segment run_a;
  Segment run_b;
  LineObservation line_a;
  LineObservation line_b;

  bool IsCorner() const {
    return CornerBetween(points, MakeNoiseModel(params), params, increment_rad, run_a, run_b,
                         line_a, line_b)
        .has_value();
  }
};

LinePair FirstPair(const LaserScan& scan) {
  LinePair pair;
  const Lines found = LinesOf(scan, pair.params);
  EXPECT_EQ(found.lines.size(), 2u);
  EXPECT_EQ(found.runs.size(), 2u);
  pair.increment_rad = scan.angle_increment_rad;
  pair.points = found.points;
  pair.run_a = found.runs.at(0);
  pair.run_b = found.runs.at(1);
  pair.line_a = found.lines.at(0);
  pair.line_b = found.lines.at(1);
  return pair;
}

TEST(CornerBetweenTest, RejectsLinesThatEndFarFromTheirIntersection) {
  // The concave corner with the beams of wall x = 2 above y = 0.45 lost:
  // wall a stops 0.55 m short of the vertex (an occlusion edge, not a
  // corner), and the gap splits the clusters.
  LaserScan scan = ConcaveCornerScan();
  for (int i = 0; i < scan.size(); ++i) {
    const double phi = scan.BeamAngle(i);
    if (std::tan(phi) <= 0.5 && std::tan(phi) > 0.225) scan.has_return[i] = 0;
  }
  const FeatureExtractionParams params;
  const Lines found = LinesOf(scan, params);
  ASSERT_EQ(found.runs.size(), 2u);
  EXPECT_NE(found.runs[0].cluster, found.runs[1].cluster);
  EXPECT_TRUE(FindCorners(found.points, MakeNoiseModel(params), params, scan.angle_increment_rad,
                          found.runs, found.line_of_run, found.lines)
                  .empty());
  LinePair pair = FirstPair(scan);
  EXPECT_FALSE(pair.IsCorner());
  // With the tolerance widened past the gap, the same pair is a corner.
  pair.params.corner_max_endpoint_distance_m = 0.6;
  EXPECT_TRUE(pair.IsCorner());
}

TEST(CornerBetweenTest, RejectsPointsBetweenTheLinesBehindTheirLine) {
  // The concave corner with the last 3 points of wall a (x = 2) taken from
  // its run: on the wall they pass; 10 cm behind it (as where a box face
  // ends in front of a wall) they make the pair an occlusion edge.
  LinePair pair = FirstPair(ConcaveCornerScan());
  pair.run_a.last -= 3;
  EXPECT_TRUE(pair.IsCorner());
  for (int i = pair.run_a.last + 1; i <= pair.run_a.last + 3; ++i) {
    const ScanPoint p = pair.points[i];
    pair.points[i] = Point(p.x + 0.1, p.y, p.beam);
  }
  EXPECT_FALSE(pair.IsCorner());
}

TEST(CornerBetweenTest, RejectsLinesAtTooSmallAnAngle) {
  LinePair pair = FirstPair(ConcaveCornerScan());
  ASSERT_TRUE(pair.IsCorner());
  // Line b turned about the vertex (2, 1) to 20 degrees from line a (x = 2):
  // everything else still passes, but the smallest angle allowed is
  // corner_min_angle_deg, 30.
  pair.line_b.alpha_rad = DegToRad(20.0);
  pair.line_b.rho_m = 2.0 * std::cos(pair.line_b.alpha_rad) + 1.0 * std::sin(pair.line_b.alpha_rad);
  EXPECT_FALSE(pair.IsCorner());
  pair.params.corner_min_angle_deg = 15.0;
  EXPECT_TRUE(pair.IsCorner());
}

}  // namespace
}  // namespace mjslam::slam::extraction
