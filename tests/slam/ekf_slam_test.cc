// EkfSlam end to end on hand-made scans: parameters, bad input, data
// association (gate, same type, nearest neighbour, duplicate guard), both
// correction modes and the secondary map. The prediction is in
// ekf_slam_prediction_test.cc.

#include "slam/ekf_slam.h"
#include "slam/motion_model.h"

#include <cmath>
#include <limits>
#include <string>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/params.h"
#include "slam/data_association.h"
#include "slam/slam_params.h"
#include "slam/slam_state.h"

namespace mjslam::slam {
namespace {

constexpr double kRhoStd = 0.01;
constexpr double kAlphaStd = 0.002;

LineObservation Line(double rho, double alpha, const Eigen::Vector2d& p_SA,
                     const Eigen::Vector2d& p_SB) {
  LineObservation line;
  line.rho_m = rho;
  line.alpha_rad = alpha;
  line.covariance = Eigen::Vector2d(kRhoStd * kRhoStd, kAlphaStd * kAlphaStd).asDiagonal();
  line.p_SA = p_SA;
  line.p_SB = p_SB;
  return line;
}

// The wall x = 2 seen from the origin facing +x, from y = y0 to y = y1.
LineObservation WallAtTwo(double rho_offset, double y0 = -1.0, double y1 = 1.0) {
  return Line(2.0 + rho_offset, 0.0, Eigen::Vector2d(2.0, y0), Eigen::Vector2d(2.0, y1));
}

CornerObservation Corner(double range, double bearing) {
  CornerObservation corner;
  corner.range_m = range;
  corner.bearing_rad = bearing;
  corner.covariance = Eigen::Vector2d(0.02 * 0.02, 0.005 * 0.005).asDiagonal();
  corner.p_SC = range * Eigen::Vector2d(std::cos(bearing), std::sin(bearing));
  return corner;
}

// A record with no motion (dt = 0), so that the map and pose covariance do
// not change between scans.
SensorRecord Still() { return SensorRecord{}; }

TEST(EkfParamsTest, DefaultsAreValidAndBadValuesAreNamed) {
  EXPECT_TRUE(EkfParams().Validate().empty());
  EkfParams params;
  CommandProcessModel command;
  command.integration = "rk4";
  command.noise.v_fraction = -1.0;
  command.lateral.slip_std_m_per_rad = -0.1;
  params.process_model = command;
  params.control_point_offset_m = 0.0;
  params.gate_probability = 1.0;
  params.new_feature_probability = 0.5;
  params.max_updates = 0;
  params.duplicate_line_distance_m = -0.05;
  params.duplicate_line_min_overlap_m = 0.0;
  const std::vector<ParamProblem> problems = params.Validate();
  std::string keys;
  for (const ParamProblem& problem : problems) keys += problem.key + " ";
  EXPECT_NE(keys.find("process_model.integration"), std::string::npos) << keys;
  EXPECT_NE(keys.find("control_point_offset_m"), std::string::npos) << keys;
  EXPECT_NE(keys.find("gate_probability"), std::string::npos) << keys;
  EXPECT_NE(keys.find("new_feature_probability"), std::string::npos) << keys;
  EXPECT_NE(keys.find("max_updates"), std::string::npos) << keys;
  EXPECT_NE(keys.find("duplicate_line_distance_m"), std::string::npos) << keys;
  EXPECT_NE(keys.find("duplicate_line_min_overlap_m"), std::string::npos) << keys;
  EXPECT_NE(keys.find("process_model.noise.v_fraction"), std::string::npos) << keys;
  EXPECT_NE(keys.find("process_model.lateral.slip_std_m_per_rad"), std::string::npos) << keys;
  EXPECT_THROW(params.ValidateOrThrow(), ParamError);
}

TEST(EkfParamsTest, MotionIntegrationAndSelectionPolicyAreNamedChoices) {
  EkfParams params;
  EXPECT_EQ(IntegrationOf(params.process_model), "exact");  // today's behaviour
  EXPECT_FALSE(PredictsFromOdometry(params.process_model));  // the paper's commands
  EXPECT_EQ(params.selection_policy, "criterion");  // the paper's
  EXPECT_EQ(MotionIntegrationFromName("exact"), MotionIntegration::kExact);
  EXPECT_EQ(MotionIntegrationFromName("euler"), MotionIntegration::kEuler);
  EXPECT_EQ(SelectionPolicyFromName("criterion"), SelectionPolicy::kCriterion);
  EXPECT_EQ(SelectionPolicyFromName("first"), SelectionPolicy::kFirst);
  EXPECT_EQ(SelectionPolicyFromName("random"), SelectionPolicy::kRandom);
  EXPECT_EQ(SelectionPolicyFromName("least_informative"), SelectionPolicy::kLeastInformative);
  EXPECT_EQ(SelectionPolicyFromName("determinant"), SelectionPolicy::kDeterminant);
  EXPECT_THROW(MotionIntegrationFromName("rk4"), ParamError);
  EXPECT_THROW(SelectionPolicyFromName("best"), ParamError);
  std::get<CommandProcessModel>(params.process_model).integration = "rk4";
  params.selection_policy = "best";
  std::string keys;
  for (const ParamProblem& problem : params.Validate()) keys += problem.key + " ";
  EXPECT_NE(keys.find("process_model.integration"), std::string::npos) << keys;
  EXPECT_NE(keys.find("selection_policy"), std::string::npos) << keys;
  std::get<CommandProcessModel>(params.process_model).integration = "euler";
  params.selection_policy = "least_informative";
  EXPECT_TRUE(params.Validate().empty());
}

TEST(EkfSlamTest, MotionIntegrationKeyChoosesThePrediction) {
  // A turning command: the filter's pose is PredictPose's of the chosen
  // integration, and the two differ.
  SensorRecord record;
  record.dt_s = 0.1;
  record.command = Twist2{0.5, 1.2};
  const Pose2 start(1.0, 2.0, 0.3);
  const Eigen::Vector2d increment(0.05, 0.12);
  for (const MotionIntegration integration :
       {MotionIntegration::kExact, MotionIntegration::kEuler}) {
    EkfParams params;
    CommandProcessModel command;
    command.lateral.skid_s = 0.0;
    command.integration = integration == MotionIntegration::kEuler ? "euler" : "exact";
    params.process_model = command;
    EkfSlam filter(params, CorrectionMode::kSelective, start, Pose2());
    filter.Step(record, nullptr);
    const Eigen::Vector3d expected =
        PredictPose(Eigen::Vector3d(start.x, start.y, start.theta), increment,
                    params.control_point_offset_m, nullptr, nullptr, 0.0, integration);
    EXPECT_NEAR(filter.X_WR().x, expected.x(), 1e-12);
    EXPECT_NEAR(filter.X_WR().y, expected.y(), 1e-12);
    EXPECT_NEAR(filter.X_WR().theta, expected.z(), 1e-12);
  }
  EkfParams exact;
  EkfParams euler;
  std::get<CommandProcessModel>(euler.process_model).integration = "euler";
  EkfSlam a(exact, CorrectionMode::kClassical, start, Pose2());
  EkfSlam b(euler, CorrectionMode::kClassical, start, Pose2());
  a.Step(record, nullptr);
  b.Step(record, nullptr);
  EXPECT_GT(std::abs(a.X_WR().y - b.X_WR().y) + std::abs(a.X_WR().x - b.X_WR().x), 1e-4);
}

TEST(SlamParamsTest, MergesBothPartsWithPrefixes) {
  SlamParams params;
  EXPECT_TRUE(params.Validate().empty());
  params.ekf.max_updates = 0;
  params.features.min_points = 1;
  std::string keys;
  for (const ParamProblem& problem : params.Validate()) keys += problem.key + " ";
  EXPECT_NE(keys.find("ekf.max_updates"), std::string::npos) << keys;
  EXPECT_NE(keys.find("features.min_points"), std::string::npos) << keys;
  EXPECT_THROW(params.ValidateOrThrow(), ParamError);
}

TEST(EkfSlamTest, ConstructorRejectsInvalidParams) {
  EkfParams params;
  std::get<CommandProcessModel>(params.process_model).integration = "wheels";
  try {
    EkfSlam filter(params, CorrectionMode::kClassical, Pose2(), Pose2());
    FAIL() << "no exception";
  } catch (const ParamError& error) {
    EXPECT_NE(std::string(error.what()).find("slam.ekf: process_model.integration"), std::string::npos)
        << error.what();
    EXPECT_NE(std::string(error.what()).find("wheels"), std::string::npos) << error.what();
  }
  EXPECT_THROW(EkfSlam(EkfParams(), CorrectionMode::kClassical, Pose2(NAN, 0, 0), Pose2()),
               SlamInputError);
}

TEST(EkfSlamTest, RejectsBadInputAndStaysUnchanged) {
  EkfSlam filter(EkfParams(), CorrectionMode::kClassical, Pose2(), Pose2());
  ScanFeatures features;
  features.lines.push_back(WallAtTwo(0.0));
  filter.Step(Still(), &features);
  const Eigen::VectorXd state = filter.state();

  SensorRecord negative_dt;
  negative_dt.dt_s = -0.1;
  EXPECT_THROW(filter.Step(negative_dt, nullptr), SlamInputError);

  SensorRecord moving;
  moving.dt_s = 0.1;
  moving.command = Twist2{0.5, 0.0};
  ScanFeatures bad = features;
  bad.lines[0].covariance(0, 0) = NAN;
  EXPECT_THROW(filter.Step(moving, &bad), SlamInputError);
  bad = features;
  bad.lines[0].covariance = Eigen::Matrix2d::Zero();
  EXPECT_THROW(filter.Step(moving, &bad), SlamInputError);
  ScanFeatures bad_corner;
  bad_corner.corners.push_back(Corner(-1.0, 0.0));
  EXPECT_THROW(filter.Step(moving, &bad_corner), SlamInputError);

  // Nothing changed, not even the prediction.
  EXPECT_TRUE((filter.state().array() == state.array()).all());
}

TEST(EkfSlamTest, FirstScanAddsFeaturesAndTheSecondMatchesThem) {
  for (const CorrectionMode mode : {CorrectionMode::kClassical, CorrectionMode::kSelective}) {
    EkfSlam filter(EkfParams(), mode, Pose2(), Pose2(0.1, 0.0, 0.0));
    ScanFeatures features;
    features.lines.push_back(Line(2.0, 0.0, {2.0, -1.0}, {2.0, 1.0}));
    features.lines.push_back(Line(1.5, kPi / 2.0, {-1.0, 1.5}, {1.0, 1.5}));
    features.lines.push_back(Line(1.0, -kPi / 2.0, {-1.0, -1.0}, {1.0, -1.0}));
    features.corners.push_back(Corner(2.5, 0.6));
    StepReport report = filter.Step(Still(), &features);
    EXPECT_EQ(report.num_observed, 4);
    EXPECT_EQ(report.num_new, 4);
    EXPECT_EQ(report.num_matched, 0);
    EXPECT_EQ(report.num_features, 4);

    report = filter.Step(Still(), &features);
    EXPECT_EQ(report.num_matched, 4);
    EXPECT_EQ(report.num_new, 0);
    EXPECT_EQ(report.num_features, 4);
    EXPECT_EQ(report.num_updated, mode == CorrectionMode::kClassical ? 4 : 2);
  }
}

// Two walls meeting at (2, 1.5), seen from the origin, and their corner,
// observed at x = corner_x (2 where the lines meet).
ScanFeatures TwoWallsAndTheirCorner(double corner_x = 2.0) {
  ScanFeatures features;
  features.lines.push_back(Line(2.0, 0.0, {2.0, -1.0}, {2.0, 1.5}));
  features.lines.push_back(Line(1.5, kPi / 2.0, {0.0, 1.5}, {2.0, 1.5}));
  CornerObservation corner = Corner(std::hypot(corner_x, 1.5), std::atan2(1.5, corner_x));
  corner.line_a = 0;
  corner.line_b = 1;
  features.corners.push_back(corner);
  return features;
}

TEST(EkfSlamTest, CornerOfTwoMatchedLinesDoesNotCorrectTwice) {
  // Two walls meeting at (2, 1.5) and their corner. On the second look both
  // lines match, so the corner adds nothing new: it is matched but left out
  // of the correction, unless the config asks for it.
  for (const bool correct_anyway : {false, true}) {
    EkfParams params;
    params.correct_corners_of_matched_lines = correct_anyway;
    EkfSlam filter(params, CorrectionMode::kClassical, Pose2(), Pose2());
    const ScanFeatures features = TwoWallsAndTheirCorner();
    filter.Step(Still(), &features);
    const StepReport report = filter.Step(Still(), &features);
    EXPECT_EQ(report.num_matched, 3);
    EXPECT_EQ(report.num_redundant_corners, correct_anyway ? 0 : 1);
    EXPECT_EQ(report.num_updated, correct_anyway ? 3 : 2);
  }
  // A corner whose line is new this time still corrects.
  EkfSlam filter(EkfParams(), CorrectionMode::kClassical, Pose2(), Pose2());
  const ScanFeatures second = TwoWallsAndTheirCorner();
  ScanFeatures first = second;  // without the second wall
  first.lines.pop_back();
  first.corners[0].line_b = -1;
  filter.Step(Still(), &first);
  const StepReport report = filter.Step(Still(), &second);
  EXPECT_EQ(report.num_new, 1);
  EXPECT_EQ(report.num_redundant_corners, 0);
  EXPECT_EQ(report.num_updated, 2);
}

TEST(EkfSlamTest, NewCornerIsWhereItsMapLinesMeetAndMovesWithThem) {
  // TwoWallsAndTheirCorner seen from the known start; the corner's own
  // observation is 1 cm off the lines' meeting point
  // (inside its noise). From the map lines (default), the corner is their
  // meeting point and is correlated with them, so a later correction of one
  // line moves it too; from its own observation, it stays where it was seen.
  for (const bool from_lines : {true, false}) {
    EkfParams params;
    params.corners_from_map_lines = from_lines;
    EkfSlam filter(params, CorrectionMode::kClassical, Pose2(), Pose2());
    const ScanFeatures first = TwoWallsAndTheirCorner(2.01);
    StepReport report = filter.Step(Still(), &first);
    EXPECT_EQ(report.num_new, 3);
    EXPECT_EQ(report.num_corners_from_lines, from_lines ? 1 : 0);
    const Eigen::Vector2d seen = filter.Map()[2].params;
    EXPECT_NEAR(seen.x(), from_lines ? 2.0 : 2.01, 1e-9);
    EXPECT_NEAR(seen.y(), 1.5, 1e-9);
    const Eigen::Matrix2d corner_line = filter.covariance().block<2, 2>(
        filter.slam_state().FeatureIndex(2), filter.slam_state().FeatureIndex(0));
    if (from_lines) {
      // x of the corner is rho - 1.5 alpha of the east wall (x cos al +
      // y sin al = rho at y = 1.5, al = 0).
      EXPECT_NEAR(corner_line(0, 0), kRhoStd * kRhoStd, 1e-12);
      EXPECT_NEAR(filter.Map()[2].covariance(0, 0),
                  kRhoStd * kRhoStd + 1.5 * 1.5 * kAlphaStd * kAlphaStd, 1e-12);
    } else {
      EXPECT_EQ(corner_line.cwiseAbs().maxCoeff(), 0.0);  // known pose: independent
    }

    // The east wall alone, seen 5 mm further: the wall moves out, and the
    // corner with it only if it was placed from the lines.
    ScanFeatures second;
    second.lines.push_back(Line(2.005, 0.0, {2.005, -1.0}, {2.005, 1.5}));
    report = filter.Step(Still(), &second);
    ASSERT_EQ(report.num_matched, 1);
    const double wall_moved = filter.Map()[0].params.x() - 2.0;
    const double corner_moved = filter.Map()[2].params.x() - seen.x();
    EXPECT_GT(wall_moved, 0.001);
    if (from_lines) {
      EXPECT_NEAR(corner_moved, wall_moved, 1e-9);
    } else {
      EXPECT_NEAR(corner_moved, 0.0, 1e-9);
    }
  }
}

TEST(EkfSlamTest, GatesByMahalanobisDistanceWithADuplicateGuard) {
  // Known pose, no motion: S_rho = 2 kRhoStd^2 for the second look at the
  // wall, so d2 = (offset / kRhoStd)^2 / 2. Gate 9.21 (99 %), new-feature
  // threshold 18.4 (99.99 %). The scan holds this one line, so the rule
  // that a scan matching nothing adds nothing is off here (tested below).
  struct Case {
    double offset_sigmas;
    int matched;
    int ambiguous;
    int added;
  };
  for (const Case& c : {Case{4.0, 1, 0, 0}, Case{5.0, 0, 1, 0}, Case{7.0, 0, 0, 1}}) {
    EkfParams params;
    params.new_features_need_match = false;
    EkfSlam filter(params, CorrectionMode::kClassical, Pose2(), Pose2());
    ScanFeatures first;
    first.lines.push_back(WallAtTwo(0.0));
    filter.Step(Still(), &first);
    ScanFeatures second;
    second.lines.push_back(WallAtTwo(c.offset_sigmas * kRhoStd));
    const StepReport report = filter.Step(Still(), &second);
    EXPECT_EQ(report.num_matched, c.matched) << c.offset_sigmas << " sigma";
    EXPECT_EQ(report.num_ambiguous, c.ambiguous) << c.offset_sigmas << " sigma";
    EXPECT_EQ(report.num_new, c.added) << c.offset_sigmas << " sigma";
    EXPECT_EQ(filter.num_features(), 1 + c.added);
  }
  // A stricter gate rejects the 4-sigma one too.
  EkfParams strict;
  strict.gate_probability = 0.95;  // 5.99 < 8
  EkfSlam filter(strict, CorrectionMode::kClassical, Pose2(), Pose2());
  ScanFeatures first;
  first.lines.push_back(WallAtTwo(0.0));
  filter.Step(Still(), &first);
  ScanFeatures second;
  second.lines.push_back(WallAtTwo(4.0 * kRhoStd));
  EXPECT_EQ(filter.Step(Still(), &second).num_matched, 0);
}

TEST(EkfSlamTest, LineSeenFromTheOtherSideIsAnotherFace) {
  // The wall x = 2 is seen from the origin; the robot then drives to
  // x = 4.3 with 0.1 m of uncertainty, and sees the wall's back face, the
  // line x = 2.15, behind it: 0.15 m from the feature's prediction, inside
  // the gate (d2 about 2.2). It is another face of the wall: with
  // gate_line_side (the default) it becomes a new feature; without, it is
  // matched to the front face and pulls the pose 0.15 m off. (The scan
  // holds this one line: new_features_need_match is off to let it be added.)
  for (const bool gate_line_side : {true, false}) {
    EkfParams params;
    params.gate_line_side = gate_line_side;
    params.new_features_need_match = false;
    CommandNoiseParams& noise = std::get<CommandProcessModel>(params.process_model).noise;
    noise.v_std_mps = 0.1;
    noise.v_fraction = 0.0;
    noise.change_fraction = 0.0;
    EkfSlam filter(params, CorrectionMode::kClassical, Pose2(), Pose2());
    ScanFeatures first;
    first.lines.push_back(WallAtTwo(0.0));
    filter.Step(Still(), &first);
    SensorRecord drive;
    drive.dt_s = 1.0;
    drive.command.v_mps = 4.3;
    ScanFeatures back;
    back.lines.push_back(Line(2.15, kPi, Eigen::Vector2d(-2.15, 1.0), Eigen::Vector2d(-2.15, -1.0)));
    const StepReport report = filter.Step(drive, &back);
    EXPECT_EQ(report.num_matched, gate_line_side ? 0 : 1) << gate_line_side;
    EXPECT_EQ(report.num_new, gate_line_side ? 1 : 0) << gate_line_side;
    EXPECT_EQ(filter.num_features(), gate_line_side ? 2 : 1) << gate_line_side;
    // From the same side as before, the front face still matches.
    if (gate_line_side) {
      ScanFeatures front;
      front.lines.push_back(WallAtTwo(0.0));
      SensorRecord back_home;
      back_home.dt_s = 1.0;
      back_home.command.v_mps = -4.3;
      EXPECT_EQ(filter.Step(back_home, &front).num_matched, 1);
    }
  }
}

TEST(EkfSlamTest, ScanThatMatchesNothingAddsNothing) {
  // The map holds the wall x = 2. A scan with only the wall y = 3 (far from
  // it) matched nothing: it cannot tell new structure from a pose error, so
  // the wall is held back (kUnanchored). The next scan sees both walls: x = 2
  // matches, and y = 3 is added. Without the rule it is added at once; the
  // first scan of an empty map is always added.
  const LineObservation side_wall =
      Line(3.0, kPi / 2.0, Eigen::Vector2d(-1.0, 3.0), Eigen::Vector2d(1.0, 3.0));
  for (const bool need_match : {true, false}) {
    EkfParams params;
    params.new_features_need_match = need_match;
    EkfSlam filter(params, CorrectionMode::kClassical, Pose2(), Pose2());
    ScanFeatures first;
    first.lines.push_back(WallAtTwo(0.0));
    EXPECT_EQ(filter.Step(Still(), &first).num_new, 1);
    ScanFeatures alone;
    alone.lines.push_back(side_wall);
    const StepReport held = filter.Step(Still(), &alone);
    EXPECT_EQ(held.num_unanchored, need_match ? 1 : 0);
    EXPECT_EQ(held.num_new, need_match ? 0 : 1);
    EXPECT_EQ(held.num_ambiguous, 0);
    EXPECT_EQ(held.association.outcome[0],
              need_match ? AssociationOutcome::kUnanchored : AssociationOutcome::kNew);
    EXPECT_EQ(filter.num_features(), need_match ? 1 : 2);
    ScanFeatures both;
    both.lines.push_back(WallAtTwo(0.0));
    both.lines.push_back(side_wall);
    const StepReport anchored = filter.Step(Still(), &both);
    EXPECT_EQ(anchored.num_matched, need_match ? 1 : 2);
    EXPECT_EQ(anchored.num_new, need_match ? 1 : 0);
    EXPECT_EQ(filter.num_features(), 2);
  }
}

TEST(EkfSlamTest, MatchesOnlyFeaturesOfTheSameType) {
  // A corner observation with the very numbers of the line's prediction
  // (seen with the wall, so that the scan matches and may add features).
  EkfSlam filter(EkfParams(), CorrectionMode::kClassical, Pose2(), Pose2());
  ScanFeatures first;
  first.lines.push_back(WallAtTwo(0.0));
  filter.Step(Still(), &first);
  ScanFeatures second;
  second.lines.push_back(WallAtTwo(0.0));
  second.corners.push_back(Corner(2.0, 0.0));
  const StepReport report = filter.Step(Still(), &second);
  EXPECT_EQ(report.num_matched, 1);  // the wall
  EXPECT_EQ(report.association.outcome[1], AssociationOutcome::kNew);
  EXPECT_EQ(report.num_new, 1);
  EXPECT_EQ(filter.Map().back().type, MapFeature::Type::kCorner);
  // And a corner matches a corner.
  const StepReport again = filter.Step(Still(), &second);
  EXPECT_EQ(again.num_matched, 2);
  EXPECT_EQ(again.num_new, 0);
}

TEST(EkfSlamTest, NearestNeighbourTakesEachFeatureOnce) {
  EkfSlam filter(EkfParams(), CorrectionMode::kClassical, Pose2(), Pose2());
  ScanFeatures first;
  first.lines.push_back(WallAtTwo(0.0));
  filter.Step(Still(), &first);
  // Two observations inside the gate of the one wall: the nearer one (listed
  // second) wins, the other is neither matched nor added.
  ScanFeatures second;
  second.lines.push_back(WallAtTwo(2.0 * kRhoStd));
  second.lines.push_back(WallAtTwo(-1.0 * kRhoStd));
  const StepReport report = filter.Step(Still(), &second);
  EXPECT_EQ(report.num_matched, 1);
  EXPECT_EQ(report.num_ambiguous, 1);
  EXPECT_EQ(report.num_new, 0);
  // The estimate moved towards the nearer observation (-1 sigma), not the other.
  EXPECT_LT(filter.Map()[0].params.x(), 2.0);
}

TEST(DataAssociationTest, ChiSquareQuantilesOfTwoDof) {
  EXPECT_NEAR(ChiSquare2Quantile(0.95), 5.991, 1e-3);
  EXPECT_NEAR(ChiSquare2Quantile(0.99), 9.210, 1e-3);
  EXPECT_NEAR(ChiSquare2Quantile(0.9999), 18.421, 1e-3);
}

TEST(DataAssociationTest, GreedyNearestNeighbourWithUniquenessAndGuard) {
  const double inf = std::numeric_limits<double>::infinity();
  // Rows: observations; columns: features. Observation 1 is nearest to
  // feature 0 (0.5) and takes it; observation 0 then falls back to its next
  // feature inside the gate, 1 (5.0), which observation 1 no longer needs.
  Eigen::MatrixXd d2(5, 3);
  d2 << 1.0, 5.0, inf,
        0.5, 3.0, inf,
        inf, inf, 12.0,   // between gate and new threshold: ambiguous
        inf, inf, 30.0,   // far from everything: new
        NAN, 20.0, 19.0;  // NaN ignored, the rest beyond the threshold: new
  const Association association = AssociateNearestNeighbour(d2, 9.21, 18.42);
  EXPECT_EQ(association.feature[1], 0);
  EXPECT_EQ(association.outcome[1], AssociationOutcome::kMatched);
  EXPECT_EQ(association.feature[0], 1);
  EXPECT_EQ(association.outcome[0], AssociationOutcome::kMatched);
  EXPECT_EQ(association.outcome[2], AssociationOutcome::kAmbiguous);
  EXPECT_EQ(association.feature[2], -1);
  EXPECT_EQ(association.outcome[3], AssociationOutcome::kNew);
  EXPECT_EQ(association.outcome[4], AssociationOutcome::kNew);

  // A lost contest inside the gate is ambiguous, not new.
  Eigen::MatrixXd contest(2, 1);
  contest << 2.0, 1.0;
  const Association lost = AssociateNearestNeighbour(contest, 9.21, 18.42);
  EXPECT_EQ(lost.outcome[1], AssociationOutcome::kMatched);
  EXPECT_EQ(lost.outcome[0], AssociationOutcome::kAmbiguous);
}

TEST(EkfSlamTest, SecondaryMapExtendsAndFollowsTheLine) {
  EkfSlam filter(EkfParams(), CorrectionMode::kClassical, Pose2(), Pose2());
  ScanFeatures first;
  first.lines.push_back(WallAtTwo(0.0, -1.0, 1.0));
  filter.Step(Still(), &first);
  MapFeature wall = filter.Map()[0];
  ASSERT_TRUE(wall.has_segment);
  EXPECT_NEAR((wall.p_WA - Eigen::Vector2d(2.0, -1.0)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((wall.p_WB - Eigen::Vector2d(2.0, 1.0)).norm(), 0.0, 1e-9);

  // More of the wall seen, slightly off the line: the segment grows to
  // y = 3 and stays on the corrected line estimate.
  ScanFeatures second;
  second.lines.push_back(Line(2.0 + 0.5 * kRhoStd, 0.001, {2.0, 0.0}, {2.0, 3.0}));
  EXPECT_EQ(filter.Step(Still(), &second).num_matched, 1);
  wall = filter.Map()[0];
  const Eigen::Vector2d normal(std::cos(wall.params.y()), std::sin(wall.params.y()));
  EXPECT_NEAR(normal.dot(wall.p_WA), wall.params.x(), 1e-12);
  EXPECT_NEAR(normal.dot(wall.p_WB), wall.params.x(), 1e-12);
  EXPECT_NEAR(wall.p_WA.y(), -1.0, 0.02);
  EXPECT_NEAR(wall.p_WB.y(), 3.0, 0.02);
  EXPECT_NE(wall.params.x(), 2.0);  // the line was corrected

  // A shorter look does not shrink it.
  ScanFeatures third;
  third.lines.push_back(WallAtTwo(0.0, 0.5, 1.0));
  filter.Step(Still(), &third);
  EXPECT_NEAR(filter.Map()[0].p_WA.y(), -1.0, 0.02);
  EXPECT_NEAR(filter.Map()[0].p_WB.y(), 3.0, 0.02);
}

// A wall seen in two pieces farther apart than the segment gate becomes two
// map lines; once a scan shows it whole, their segments overlap and, with
// duplicate_line_distance_m, the less certain line is removed and the kept
// one's segment covers both. A parallel wall 0.1 m behind the first (a step
// in the wall), seen over the same stretch, is another line and stays.
TEST(EkfSlamTest, AWallMappedTwiceKeepsItsMoreCertainLine) {
  for (const double distance : {0.0, 0.05}) {
    EkfParams params;
    params.line_match_max_gap_m = 0.5;
    params.duplicate_line_distance_m = distance;
    EkfSlam filter(params, CorrectionMode::kClassical, Pose2(), Pose2());
    ScanFeatures first;
    first.lines.push_back(WallAtTwo(0.0, -1.0, 1.0));
    filter.Step(Still(), &first);
    ScanFeatures pieces;
    pieces.lines.push_back(WallAtTwo(0.0, -1.0, 1.0));
    pieces.lines.push_back(WallAtTwo(0.0, 2.0, 3.0));  // 1 m beyond the first piece
    const StepReport second = filter.Step(Still(), &pieces);
    EXPECT_EQ(second.num_matched, 1);
    EXPECT_EQ(second.num_new, 1);
    ASSERT_EQ(filter.num_features(), 2);
    const std::vector<MapFeature> before = filter.Map();

    ScanFeatures whole;
    whole.lines.push_back(WallAtTwo(0.0, -1.0, 3.0));
    filter.Step(Still(), &whole);
    if (distance == 0.0) {
      EXPECT_EQ(filter.num_features(), 2);
      continue;
    }
    ASSERT_EQ(filter.num_features(), 1);
    // The first line, seen twice, is the more certain one.
    const MapFeature wall = filter.Map()[0];
    EXPECT_EQ(wall.id, before[0].id);
    EXPECT_NEAR(std::min(wall.p_WA.y(), wall.p_WB.y()), -1.0, 0.02);
    EXPECT_NEAR(std::max(wall.p_WA.y(), wall.p_WB.y()), 3.0, 0.02);
    EXPECT_EQ(filter.covariance().rows(), 3 + 2);

    ScanFeatures step;
    step.lines.push_back(WallAtTwo(0.0, -1.0, 3.0));
    step.lines.push_back(Line(2.1, 0.0, {2.1, -1.0}, {2.1, 3.0}));
    filter.Step(Still(), &step);
    EXPECT_EQ(filter.num_features(), 2);
  }
}

TEST(EkfSlamTest, MapIsCanonicalWithStableIds) {
  // From (3, 0) facing -x the wall x = 1 is seen as rho = 2, alpha = 0; the
  // inverse model gives r = 2 + 3 cos(pi) = -1 at al = pi, canonical (1, 0).
  EkfSlam filter(EkfParams(), CorrectionMode::kClassical, Pose2(3.0, 0.0, kPi), Pose2());
  ScanFeatures features;
  features.lines.push_back(Line(2.0, 0.0, {2.0, 1.0}, {2.0, -1.0}));
  features.corners.push_back(Corner(1.0, 0.3));
  filter.Step(Still(), &features);
  const std::vector<MapFeature> map = filter.Map();
  ASSERT_EQ(map.size(), 2u);
  EXPECT_EQ(map[0].id, 0);
  EXPECT_EQ(map[1].id, 1);
  EXPECT_NEAR(map[0].params.x(), 1.0, 1e-12);
  EXPECT_NEAR(map[0].params.y(), 0.0, 1e-12);
  EXPECT_FALSE(map[1].has_segment);
  EXPECT_GT(map[0].covariance.determinant(), 0.0);
}

}  // namespace
}  // namespace mjslam::slam
