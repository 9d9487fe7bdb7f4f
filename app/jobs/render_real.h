#pragma once

#include <string>

#include "renders/render_params.h"

namespace mjslam::app {

/// Renders an imported run (`mjslam import`), which has no MuJoCo world:
/// final.png, square panels of `params.height` pixels side by side, odometry
/// alone, then each filter of trajectory.csv's header in its order (classical,
/// selective by default; coloured by renders::FilterColors): the scan points
/// placed with that trajectory's pose at each scan, the reference path
/// (black, when there is one), the trajectory's path, and the filter's map on
/// top (lines dark, corners as squares); and, when params.video, video.mp4:
/// the filters' panels as the replay goes, one frame per scan or per
/// ceil(scans / 900) scans, at params.fps. Returns the video's frames.
/// Throws std::runtime_error naming a missing or bad file.
int RenderImportedRun(const std::string& run_dir, const renders::RenderParams& params);

}  // namespace mjslam::app
