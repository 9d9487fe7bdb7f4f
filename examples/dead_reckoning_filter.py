"""Bring your own filter, in Python: dead_reckoning_filter.cc's estimator, line for line.

A filter written in Python is a class with the methods below. Registered as a kind,

    import mjslam
    from dead_reckoning_filter import DeadReckoningFilter
    mjslam.register_filter("py_dead_reckoning", DeadReckoningFilter)

it can be named in `slam.filters` like a C++ kind, and the closed loop (mjslam.Loop,
mjslam.run) runs it beside the C++ filters on the same records: its columns of
trajectory.csv (`<name>_x`, ...), its map_<name>.csv and its entry of summary.json, the NEES,
`mjslam evaluate`, the plots, all by its name (python/README.md, "A filter in Python").

This one ignores the scans: it integrates the wheel odometry with the paper's motion model
(Eq. 6, slam/motion_model.cc: OdometryInput, PredictPose) and propagates the pose covariance as
the EKF's prediction does, without ever correcting. Its trajectory columns equal those of the
C++ kind dead_reckoning to rounding (tests/python/bindings_test.py checks 1e-9).
"""

import math

import numpy as np


def wrap_angle(angle):
    """The angle in (-pi, pi], as common/angles.h's WrapAngle."""
    wrapped = math.remainder(angle, 2.0 * math.pi)
    return wrapped + 2.0 * math.pi if wrapped <= -math.pi else wrapped


def compose(a, b):
    """X_AC = X_AB * X_BC of (x, y, theta) tuples, as common/pose2.h."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap_angle(a[2] + b[2]))


def inverse(a):
    """X_BA from X_AB, as common/pose2.h."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], wrap_angle(-a[2]))


class DeadReckoningFilter:
    def __init__(self, settings, X_WR0, X_RS):
        # settings["slam"] is the run's `slam` section as config.yaml writes it, with this
        # entry's own keys (settings["filter"]) applied; X_WR0 the known start pose of R, X_RS
        # the laser mount (unused: no scans).
        ekf = settings["slam"]["ekf"]
        self.a_m = ekf["control_point_offset_m"]
        model = ekf["process_model"]
        if model["kind"] != "odometry" or model["integration"] != "exact":
            raise ValueError("DeadReckoningFilter: slam.ekf.process_model is kind %r, integration "
                             "%r; it implements kind odometry, integration exact"
                             % (model["kind"], model["integration"]))
        self.noise = model["noise"]
        self.X_WR = np.array(X_WR0, dtype=float)
        self.P = np.diag([ekf["initial_position_std_m"] ** 2] * 2 +
                         [ekf["initial_heading_std_rad"] ** 2])
        self.X_OR_previous = None

    def step(self, record, features):
        # The increment since the last record and its covariance Q; the first record is the
        # odometry's reference (no motion).
        X_OR = tuple(record.odometry)
        previous = X_OR if self.X_OR_previous is None else self.X_OR_previous
        increment, Q = self._odometry_input(previous, X_OR)
        # pose' = f(pose, u); P' = A P A^T + W Q W^T.
        self.X_WR, A, W = self._predict_pose(self.X_WR, increment)
        self.P = A @ self.P @ A.T + W @ Q @ W.T
        self.X_OR_previous = X_OR
        return None  # nothing matched or updated: every count 0, num_features() features

    def pose(self):
        return self.X_WR

    def covariance(self):
        return self.P

    def num_features(self):
        return 0

    def map(self):
        return []

    # slam::OdometryInput: the chord of the axle centre between two odometry poses, and the
    # random-walk variances of distance and heading.
    def _odometry_input(self, X_OR_previous, X_OR):
        a_m, noise = self.a_m, self.noise
        x, y, dth = compose(inverse(X_OR_previous), X_OR)
        half = 0.5 * dth
        axle_dx = x - a_m * (math.cos(dth) - 1.0)
        axle_dy = y - a_m * math.sin(dth)
        chord = axle_dx * math.cos(half) + axle_dy * math.sin(half)
        sinc = 1.0 - half * half / 6.0 if abs(half) < 1e-4 else math.sin(half) / half
        d = chord / sinc
        distance, turn = abs(d), abs(dth)
        variance_d = (noise["distance_std_m"] * noise["distance_std_m"] +
                      noise["distance_std_m_per_sqrt_m"] * noise["distance_std_m_per_sqrt_m"] *
                      distance +
                      noise["distance_std_m_per_sqrt_rad"] *
                      noise["distance_std_m_per_sqrt_rad"] * turn)
        variance_th = (noise["heading_std_rad"] * noise["heading_std_rad"] +
                       noise["heading_std_rad_per_sqrt_m"] * noise["heading_std_rad_per_sqrt_m"] *
                       distance +
                       noise["heading_std_rad_per_sqrt_rad"] *
                       noise["heading_std_rad_per_sqrt_rad"] * turn)
        return (d, dth), np.diag([variance_d, variance_th])

    # slam::PredictPose, exact integration without skid: the axle centre on the arc, R moving
    # by the chord along the mid-arc heading and swinging about the axle; A = d pose'/d pose,
    # W = d pose'/d (d, dth).
    def _predict_pose(self, pose, increment):
        d, dth = increment
        half = 0.5 * dth
        if abs(half) < 1e-4:
            sinc, dsinc = 1.0 - half * half / 6.0, -half / 6.0
        else:
            sinc = math.sin(half) / half
            dsinc = 0.5 * (half * math.cos(half) - math.sin(half)) / (half * half)
        phi = pose[2] + half
        forward, dforward_dd, dforward_ddth = d * sinc, sinc, d * dsinc
        lateral, dlateral_ddth = 2.0 * self.a_m * math.sin(half), self.a_m * math.cos(half)
        cm, sm = math.cos(phi), math.sin(phi)
        dx = forward * cm - lateral * sm
        dy = forward * sm + lateral * cm
        predicted = np.array([pose[0] + dx, pose[1] + dy, wrap_angle(pose[2] + dth)])
        A = np.eye(3)
        A[0, 2], A[1, 2] = -dy, dx
        W = np.array([[dforward_dd * cm, dforward_ddth * cm - dlateral_ddth * sm - 0.5 * dy],
                      [dforward_dd * sm, dforward_ddth * sm + dlateral_ddth * cm + 0.5 * dx],
                      [0.0, 1.0]])
        return predicted, A, W
