#pragma once

// The relative-pose error metric of Kuemmerle et al. 2009 ("On measuring the
// accuracy of SLAM algorithms", Autonomous Robots 27(4)) and the reader of
// its relation files (docs/real_data.md).
#include <cstddef>
#include <string>
#include <vector>

#include "common/pose2.h"

namespace mjslam::realdata {

/// One relation: the pose of the robot at `t2_s` in its frame at `t1_s`
/// (x, y, yaw of a line `t1 t2 dx dy dz droll dpitch dyaw`).
struct Relation {
  double t1_s = 0.0;
  double t2_s = 0.0;
  Pose2 delta;
  /// Line of the file (1-based).
  int line = 0;
};

/// Reads a relations file: 8 numbers per line. Throws std::runtime_error
/// "PATH:LINE: ..." for a line that is not 8 numbers, "PATH: ..." when the
/// file cannot be read or holds no relation.
std::vector<Relation> ReadRelations(const std::string& path);

/// A pose of a trajectory at a time.
struct TimedPose {
  double t_s = 0.0;
  Pose2 pose;
};

/// How relation timestamps are matched to the poses of a trajectory: the
/// relation time t is looked up at t - time_offset_s, and matches the pose
/// nearest in time when it is at most tolerance_s away.
struct RelationMatching {
  double time_offset_s = 0.0;
  double tolerance_s = 0.006;
};

/// The errors of a trajectory over the relations both of whose ends matched
/// a pose. For each: delta = X1^-1 X2 of the matched poses, the translational
/// error |t(delta) - t(delta*)| (m) and the rotational error
/// |wrap(th(delta) - th(delta*))| (deg). Means and standard deviations (n - 1
/// in the denominator; 0 with fewer than 2) of the errors and of their
/// squares, as the paper's tables give them.
struct RelationErrors {
  int num_relations = 0;
  int num_matched = 0;
  double translation_mean_m = 0.0;
  double translation_std_m = 0.0;
  double rotation_mean_deg = 0.0;
  double rotation_std_deg = 0.0;
  double translation_sq_mean_m2 = 0.0;
  double translation_sq_std_m2 = 0.0;
  double rotation_sq_mean_deg2 = 0.0;
  double rotation_sq_std_deg2 = 0.0;
};

/// Index of the pose of `trajectory` (sorted by time) nearest to `t_s`,
/// or -1 when none is within `tolerance_s`.
int NearestPose(const std::vector<TimedPose>& trajectory, double t_s, double tolerance_s);

/// The errors of `trajectory` (sorted by time, finite poses) on
/// `relations`, matched by `matching`.
RelationErrors ScoreRelations(const std::vector<Relation>& relations,
                              const std::vector<TimedPose>& trajectory,
                              const RelationMatching& matching);

/// The default limit of BestTimeOffset's candidates: 2.5e7 (200 MB; the
/// Intel log's relations and scans need 8 million).
inline constexpr std::size_t kMaxOffsetCandidates = 25'000'000;

/// The time offset that makes the most relation timestamps fall within
/// `tolerance_s` of a pose of `trajectory`: every difference between a
/// relation time and a pose time is a candidate; the count is taken for
/// each and the best returned (ties: the smallest offset). A search, for
/// logs whose clock origin is unknown; its count is `*num_matched_times`.
/// The search holds every candidate (8 bytes each): it throws
/// std::length_error, before allocating, when relation times x poses exceed
/// `max_candidates`, and std::invalid_argument unless `tolerance_s` is
/// finite and > 0. Throws Interrupted (common/interrupt.h) on a stop request.
double BestTimeOffset(const std::vector<Relation>& relations,
                      const std::vector<TimedPose>& trajectory, double tolerance_s,
                      int* num_matched_times,
                      std::size_t max_candidates = kMaxOffsetCandidates);

}  // namespace mjslam::realdata
