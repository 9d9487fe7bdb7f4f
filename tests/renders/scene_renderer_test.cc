// Renders a tiny world and checks pixels that must have a known colour: the
// wall, the floor, the robot, a path segment, a map corner, a laser hit.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "renders/scene_renderer.h"

namespace mjslam::renders {
namespace {

namespace fs = std::filesystem;

// A 6 x 6 m floor with one wall along x = 2 (0.2 m thick, 4 m long).
constexpr char kTinyWorld[] = R"(
<mujoco model="tiny">
  <worldbody>
    <light name="sun" directional="true" pos="0 0 8" dir="0 0 -1"/>
    <geom name="floor" type="plane" size="3 3 0.1" rgba="0.5 0.5 0.5 1"/>
    <geom name="wall" type="box" size="0.1 2 0.5" pos="2 0 0.5" rgba="0.9 0.9 0.9 1"/>
    <site name="start" pos="-1 0 0"/>
  </worldbody>
</mujoco>
)";

std::string WriteTinyWorld() {
  const fs::path dir = fs::temp_directory_path() / ("mjslam_renders_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / "tiny.xml";
  std::ofstream(path) << kTinyWorld;
  return path.string();
}

// Colour of the pixel where the floor point p appears.
Rgb ColorAt(const SceneRenderer& renderer, const Image& image, const Eigen::Vector2d& p) {
  const Eigen::Vector2d pixel = renderer.PixelOf(p);
  const int x = static_cast<int>(pixel.x()), y = static_cast<int>(pixel.y());
  return {image.At(x, y, 0) / 255.0f, image.At(x, y, 1) / 255.0f, image.At(x, y, 2) / 255.0f};
}

void ExpectColor(const Rgb& got, const Rgb& want, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(got[c], want[c], 0.08) << what << ", channel " << c;
  }
}

class SceneRendererTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new std::string(WriteTinyWorld());
    renderer_ = new SceneRenderer(
        sim::Scene(*world_, std::string(MJSLAM_SOURCE_DIR) + "/models/pioneer3dx.xml"),
        sim::SimParams{}, sim::RobotParams{}, 400, 160);
  }
  static void TearDownTestSuite() {
    delete renderer_;
    delete world_;
  }
  static std::string* world_;
  static SceneRenderer* renderer_;
};
std::string* SceneRendererTest::world_ = nullptr;
SceneRenderer* SceneRendererTest::renderer_ = nullptr;

TEST_F(SceneRendererTest, DrawsWallFloorRobotAndLayersInTheirColours) {
  SceneFrame frame;
  frame.X_WR_true = Pose2(-1.0, 0.0, 0.0);
  frame.true_path = {{-2.5, -2.0}, {0.5, -2.0}};
  FilterLayer selective;
  selective.name = "selective";
  selective.color = colors::kSelective;
  selective.path = {{-2.5, 2.0}, {0.5, 2.0}};
  selective.corners = {{0.5, 1.0}};
  frame.filters = {selective};
  frame.laser_hits = {{-2.0, 1.0}};
  const Image image = renderer_->Render(frame);
  ASSERT_EQ(image.width, 400);
  ASSERT_EQ(image.height, 160);

  // The wall is drawn dark grey, the floor light grey, whatever the world says.
  ExpectColor(ColorAt(*renderer_, image, {2.0, 1.0}), {0.30f, 0.30f, 0.30f}, "wall");
  ExpectColor(ColorAt(*renderer_, image, {0.0, -1.0}), {0.88f, 0.88f, 0.88f}, "floor");
  // The robot's top (its axle centre is 0.2 m behind R) is red.
  ExpectColor(ColorAt(*renderer_, image, {-1.25, 0.0}), colors::kRobot, "robot");
  // Paths, a map corner and a laser hit, each in its colour.
  ExpectColor(ColorAt(*renderer_, image, {-1.0, -2.0}), colors::kTruth, "true path");
  ExpectColor(ColorAt(*renderer_, image, {-1.0, 2.0}), colors::kSelective, "selective path");
  ExpectColor(ColorAt(*renderer_, image, {0.5, 1.0}), colors::kSelective, "map corner");
  ExpectColor(ColorAt(*renderer_, image, {-2.0, 1.0}), colors::kLaserHits, "laser hit");
}

TEST_F(SceneRendererTest, RobotFollowsItsPose) {
  SceneFrame frame;
  frame.X_WR_true = Pose2(0.2, 1.5, M_PI / 2);  // axle centre at (0.2, 1.3)
  const Image image = renderer_->Render(frame);
  ExpectColor(ColorAt(*renderer_, image, {0.2, 1.25}), colors::kRobot, "robot at its new pose");
  ExpectColor(ColorAt(*renderer_, image, {-1.25, 0.0}), {0.88f, 0.88f, 0.88f}, "floor at the old pose");
}

TEST_F(SceneRendererTest, PixelOfKeepsNorthUpAndEastRight) {
  const Eigen::Vector2d origin = renderer_->PixelOf({0.0, 0.0});
  EXPECT_GT(renderer_->PixelOf({1.0, 0.0}).x(), origin.x());
  EXPECT_LT(renderer_->PixelOf({0.0, 1.0}).y(), origin.y());
  // Same scale along both axes (square pixels).
  EXPECT_NEAR(renderer_->PixelOf({1.0, 0.0}).x() - origin.x(),
              origin.y() - renderer_->PixelOf({0.0, 1.0}).y(), 1e-9);
}

// Whether any pixel in columns [x0, x1) of `image` has colour `want`.
bool AnyPixelOfColour(const Image& image, int x0, int x1, const Rgb& want) {
  for (int y = 0; y < image.height; ++y) {
    for (int x = x0; x < x1; ++x) {
      bool same = true;
      for (int c = 0; c < 3; ++c) same = same && std::abs(image.At(x, y, c) / 255.0f - want[c]) < 0.05f;
      if (same) return true;
    }
  }
  return false;
}

TEST_F(SceneRendererTest, ALegendStripListsTheLayersInTheirColours) {
  SceneFrame frame;
  frame.X_WR_true = Pose2(-1.0, 0.0, 0.0);
  FilterLayer selective;
  selective.name = "selective";
  selective.color = colors::kSelective;
  frame.filters = {selective};
  const Image image = renderer_->Render(frame);
  // Right of the wall there is only floor, then the legend strip (images at
  // least 400 pixels wide) with a swatch per layer; nothing else in this
  // frame is blue or green.
  const int strip = static_cast<int>(renderer_->PixelOf({2.2, 0.0}).x());
  ASSERT_LT(strip, 400 - 100);
  EXPECT_TRUE(AnyPixelOfColour(image, strip, 400, colors::kSelective));
  EXPECT_TRUE(AnyPixelOfColour(image, strip, 400, colors::kLaserHits));
  EXPECT_FALSE(AnyPixelOfColour(image, 0, strip, colors::kSelective));
}

}  // namespace
}  // namespace mjslam::renders
