#pragma once

#include <Eigen/Core>

#include "common/pose2.h"
#include "common/records.h"

namespace mjslam::explorer {

/// Inverts the unicycle kinematics of the point of control h (the paper's
/// Eq. (6)): the velocity of h in the world, `p_dot = J(th) [v, w]^T` with
///
///     J(th) = [cos th   -a sin th]
///             [sin th    a cos th],   det J = a > 0,
///
/// so any desired velocity of h maps to one command (v, w). This is why the
/// paper controls a point ahead of the axle instead of the axle itself.
/// `a` is the offset of h ahead of the axle centre, metres (> 0).
Twist2 CommandForPointVelocity(const Pose2& X_WR, const Eigen::Vector2d& v_W_desired,
                               double a_m);

/// Scales (v, w) down by one common factor so that |v| <= max_v and
/// |w| <= max_w: the direction of the command (its curvature) is kept.
Twist2 SaturateKeepingCurvature(const Twist2& command, double max_v_mps,
                                double max_w_radps);

/// Moves `previous` toward `target` by at most `max_dv` in v and `max_dw` in w
/// (acceleration limits over one control period).
Twist2 RateLimit(const Twist2& previous, const Twist2& target, double max_dv_mps,
                 double max_dw_radps);

}  // namespace mjslam::explorer
