#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/pose2.h"
#include "eval/map_types.h"
#include "renders/scene_renderer.h"

namespace mjslam::app {

/// Pieces of a renders::SceneFrame shared by `mjslam render` (from a run's
/// files) and the video `mjslam run` renders as it goes (from its state).

/// One layer per filter of `names`, in order, named and coloured
/// (renders::FilterColors: classical orange, selective blue, any other the
/// next colour of a fixed palette).
std::vector<renders::FilterLayer> FilterLayers(const std::vector<std::string>& names);

/// The length of one pixel of `renderer`'s view, metres: paths keep a point
/// once it is a pixel away from the last one kept.
double PixelSizeM(const renders::SceneRenderer& renderer);

/// Appends p_W to `path` when it is at least `min_step_m` from the last point
/// kept, or when `force`.
void AppendPathPoint(std::vector<Eigen::Vector2d>* path, const Eigen::Vector2d& p_W,
                     double min_step_m, bool force = false);

/// Replaces the lines (their seen segments) and corners of `layer` by those
/// of `map`.
void SetMapLayer(const eval::Map& map, renders::FilterLayer* layer);

/// The echoes in W of a scan cast from X_WS: the ranges below
/// `max_range_m`, beam i at angle_min_rad + i angle_increment_rad.
std::vector<Eigen::Vector2d> LaserHits(const Pose2& X_WS, const std::vector<double>& ranges_m,
                                       double max_range_m, double angle_min_rad,
                                       double angle_increment_rad);

}  // namespace mjslam::app
