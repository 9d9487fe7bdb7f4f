#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/pose2.h"
#include "renders/image.h"
#include "sim/scene.h"
#include "sim/sim_params.h"

namespace mjslam::renders {

/// A colour, red, green, blue in 0..1.
using Rgb = std::array<float, 3>;

/// The colours of the renders (and of the plots, renders/report.py), chosen
/// to stay apart from each other, from the red robot, the dark walls and the
/// grey floor.
namespace colors {
inline constexpr Rgb kTruth = {0.05f, 0.05f, 0.05f};       // black
inline constexpr Rgb kClassical = {1.00f, 0.50f, 0.00f};   // orange
inline constexpr Rgb kSelective = {0.00f, 0.40f, 1.00f};   // blue
inline constexpr Rgb kLaserHits = {0.00f, 0.80f, 0.20f};   // green
inline constexpr Rgb kFrontier = {0.90f, 0.00f, 0.90f};    // magenta
inline constexpr Rgb kGoal = {0.90f, 0.00f, 0.90f};        // magenta, larger
inline constexpr Rgb kPlannedPath = {0.55f, 0.00f, 0.75f}; // purple
inline constexpr Rgb kRobot = {0.85f, 0.05f, 0.05f};       // red
}  // namespace colors

/// A segment p_a - p_b in the world frame W, metres.
struct Segment2 {
  Eigen::Vector2d a;
  Eigen::Vector2d b;
};

/// What one filter contributes to a frame.
struct FilterLayer {
  /// Legend name ("classical", "selective").
  std::string name;
  Rgb color{};
  /// Estimated positions of R so far, in order, W frame.
  std::vector<Eigen::Vector2d> path;
  /// Estimated pose of R now and the covariance of its position (x, y), m^2.
  std::optional<Pose2> X_WR;
  Eigen::Matrix2d P_xy = Eigen::Matrix2d::Zero();
  /// Map: line features as their seen segments, corners as points, W frame.
  std::vector<Segment2> lines;
  std::vector<Eigen::Vector2d> corners;
  /// A filter of submaps: its estimated pose where each submap began, drawn
  /// as a bar across its path.
  std::vector<Pose2> submap_starts;
};

/// The explorer's current sets (explorer.csv), W frame.
struct ExplorerLayer {
  std::vector<Eigen::Vector2d> frontier;
  std::optional<Eigen::Vector2d> goal;
  std::vector<Eigen::Vector2d> path;
};

/// Everything drawn into one frame on top of the world.
struct SceneFrame {
  /// Time shown in the frame, seconds.
  double t_s = 0.0;
  /// True pose of R (the robot is drawn there) and the true path so far.
  Pose2 X_WR_true;
  std::vector<Eigen::Vector2d> true_path;
  /// Both filters (drawn in order; the legend lists them).
  std::vector<FilterLayer> filters;
  /// End points of the returns of the current scan, W frame.
  std::vector<Eigen::Vector2d> laser_hits;
  std::optional<ExplorerLayer> explorer;
  /// Factor the 2-sigma ellipses are drawn at (stated in the legend).
  double ellipse_scale = 1.0;
};

/// Top-down off-screen renders of a world with the robot in it, through OSMesa
/// (software OpenGL, no display, no GPU) and MuJoCo's own mjv/mjr functions.
///
/// The camera looks straight down on the floor from 200 m with a narrow
/// frustum (nearly orthographic: a 1 m wall top is displaced by 0.5 % of its
/// distance from the image centre) framing the world's obstacles with a
/// margin, north (+y) up, east (+x) right. Walls are drawn dark grey. No
/// shadows, reflections, skybox or multisampling (each costs several times
/// the frame time in software rendering). One SceneRenderer owns the
/// process's current OpenGL context; use one at a time per thread.
class SceneRenderer {
 public:
  /// Draws `scene` (a copy of its loaded model, in plain colours) in a
  /// `width` x `height` off-screen context. The robot is drawn as it rests
  /// on the floor: a sim::Simulator with `sim` and `robot` settles it once
  /// at the scene's start (its height and wheel angles; the start also
  /// bounds the view). Throws ParamError for invalid params, sim::SimError
  /// when the robot does not settle or MuJoCo raises an error, and
  /// std::runtime_error when OSMesa or MuJoCo's renderer cannot start.
  SceneRenderer(const sim::Scene& scene, const sim::SimParams& sim,
                const sim::RobotParams& robot, int width, int height);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// Renders `frame`: the world, the robot at frame.X_WR_true, the layers,
  /// a legend (right-hand strip) and the time (top left). Throws
  /// sim::SimError when MuJoCo raises an error or a warning.
  Image Render(const SceneFrame& frame);

  /// Pixel (column, row from the top, fractional) where the floor point p_W
  /// appears in every render.
  Eigen::Vector2d PixelOf(const Eigen::Vector2d& p_W) const;

  int width() const;
  int height() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mjslam::renders
