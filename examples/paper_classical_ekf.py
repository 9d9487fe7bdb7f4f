"""Bring your own filter, in Python: the paper's classical EKF-SLAM, written in numpy.

A Python filter is one class, registered as a kind of filter with the closed loop (with
PYTHONPATH=build/python:examples):

    import mjslam, paper_classical_ekf
    mjslam.register_filter("py_classical", paper_classical_ekf.PaperClassicalEkf)
    mjslam.run("configs/paper.yaml", ["slam.filters=[{name: classical, kind: ekf, "
               "update: classical}, {name: py, kind: py_classical}]"], out="runs/py")

The loop (app::FilterBank) builds one object per `slam.filters` entry of the kind, as
cls(settings, X_WR0, X_RS), gives every filter the same records and the lines and corners that
C++ extracted once per scan, times each step, and writes the filter's columns of trajectory.csv
(`py_x`, ...), its map_py.csv and its summary.json entry by its name, as for the C++ filters
(examples/dead_reckoning_filter.cc and .py; python/README.md, "A filter in Python"). The object
provides:
  step(record, features)  predict over record.dt from the record's input, then, when `features`
                          is not None, correct with the scan's lines and corners (in the laser
                          frame S); returns a dict of slam::StepReport's fields (slam/ekf_slam.h),
                          which feed the command period's cost model and the innovation check;
  pose(), covariance()    the estimate (x, y, th) of R in W and its 3x3 covariance;
  num_features(), map()   the map's size, and its features as dicts.

This one copies the C++ classical filter (kind ekf, `update: classical`: EkfSlam in
slam/ekf_slam.cc and SlamState in slam/slam_state.cc) under the paper's method
(configs/paper.yaml): prediction from the held command by the forward-Euler Eq. (6); Mahalanobis
nearest-neighbour association with uniqueness and a duplicate guard; Algorithm 1, every matched
line and corner correcting in turn, each re-linearised; new features from the corrected pose by
the inverse observation models; the secondary map of seen segments. Each part names the C++
function it copies. Run beside the C++ filter it makes the same associations and the same
columns to rounding: over 20 runs of 120 s (corridor and office, realtime and every_scan timing,
seeds 1-5) x and y within 2e-13 m, th 2e-14 rad, the pose covariance 3e-18, NEES within 1e-12
of itself (tests/python/python_filter_test.py checks 1e-9). The products round in another order
than Eigen's, so the bits differ. It takes about 10 ms a step, the C++ filter 0.1 ms.

What it does not copy it refuses: the constructor checks every key of `slam.ekf` and raises
ValueError naming the key and its value for a setting whose C++ code is not copied here (odometry
input, exact integration, lateral slip and skid, self-calibration, first-estimates Jacobians,
corners from map lines, the segment gate, duplicate lines) or that it does not know, so that no
other config silently gives other results.

Symbols as in slam/README.md: the state xi = [x, y, th, f_1, ..., f_L] (the pose of R, the point of
control h, in W; a line f = (r, al), x cos al + y sin al = r; a corner f = p_WC), feature k at
indices 3 + 2k and 4 + 2k; P its covariance; z an observation in S, (rho, alpha) or (range,
bearing), R its covariance; X_WS = X_WR * X_RS, the laser's pose.

Plain numpy and the standard library, for Debian's /usr/bin/python3.
"""

import math

import numpy as np

# Association outcomes (slam/data_association.h, AssociationOutcome), as the report names them.
MATCHED, NEW, AMBIGUOUS, UNANCHORED = "matched", "new", "ambiguous", "unanchored"
# Feature types (common/map_feature.h), as map() names them.
LINE, CORNER = "line", "corner"


class SlamInputError(ValueError):
    """Bad data given to the filter (EkfSlam's SlamInputError): a non-finite record, a negative
    dt, an observation with a non-finite value or a covariance that is not positive definite."""


class PaperClassicalEkf:
    """The classical EKF-SLAM of slam/ekf_slam.cc (Algorithm 1) under configs/paper.yaml."""

    # --- construction: EkfSlam::EkfSlam, SlamState::SlamState -----------------------------------

    def __init__(self, settings, X_WR0, X_RS):
        """settings: {"filter": the slam.filters entry, "slam": the run's slam section with the
        entry's own keys applied (its process_noise_scale too), ...}, as config.yaml writes them;
        X_WR0: the known start pose of R in W; X_RS: the laser mount on R."""
        ekf = check_settings(settings)
        noise = "process_model.noise."
        self.v_std = float(ekf[noise + "v_std_mps"])
        self.v_fraction = float(ekf[noise + "v_fraction"])
        self.w_std = float(ekf[noise + "w_std_radps"])
        self.w_fraction = float(ekf[noise + "w_fraction"])
        self.change_fraction = float(ekf[noise + "change_fraction"])
        self.a = float(ekf["control_point_offset_m"])
        # The model-error variances added to each observation's covariance.
        self.extra_line = _squares(ekf["extra_line_rho_std_m"], ekf["extra_line_alpha_std_rad"])
        self.extra_corner = _squares(ekf["extra_corner_range_std_m"],
                                     ekf["extra_corner_bearing_std_rad"])
        self.gate_line_side = bool(ekf["gate_line_side"])
        self.new_features_need_match = bool(ekf["new_features_need_match"])
        self.correct_corners_of_matched_lines = bool(ekf["correct_corners_of_matched_lines"])
        # The association's chi-square (2 dof) thresholds: the gate and the duplicate guard.
        self.gate = chi_square_2_quantile(float(ekf["gate_probability"]))
        self.new_feature_threshold = chi_square_2_quantile(float(ekf["new_feature_probability"]))

        X_WR0 = [float(v) for v in X_WR0]
        self.X_RS = (float(X_RS[0]), float(X_RS[1]), wrap_angle(float(X_RS[2])))
        if not all(math.isfinite(v) for v in X_WR0 + list(self.X_RS)):
            raise SlamInputError("PaperClassicalEkf: X_WR0, X_RS: expected finite poses "
                                 "(got %r, %r)" % (X_WR0, self.X_RS))
        # The state: the start pose (Pose2 wraps its heading, SlamState again) and no features;
        # P: the start pose's covariance (zero in the paper: the start is known).
        self.x = np.array([X_WR0[0], X_WR0[1], wrap_angle_fast(wrap_angle(X_WR0[2]))])
        std_p = float(ekf["initial_position_std_m"])
        std_th = float(ekf["initial_heading_std_rad"])
        self.P = np.diag([std_p * std_p, std_p * std_p, std_th * std_th])
        # Per feature: its type, and EkfSlam::FeatureInfo (id, seen segment, seen side).
        self.types = []
        self.info = []
        self.next_id = 0
        # The command of the record before (CommandNoiseParams::change_fraction's reference).
        self.previous_command = (0.0, 0.0)

    # --- what the loop reads --------------------------------------------------------------------

    def pose(self):
        """EkfSlam::X_WR: (x, y, th) of R in W."""
        return self.x[:3].copy()

    def covariance(self):
        """EkfSlam::pose_covariance: P's 3x3 pose block."""
        return self.P[:3, :3].copy()

    def num_features(self):
        """L."""
        return len(self.types)

    def map(self):
        """EkfSlam::Map: every feature with its 2x2 marginal covariance, lines in canonical form
        (r >= 0) with their seen segments."""
        features = []
        for k, kind in enumerate(self.types):
            f = self._feature(k)
            covariance = self.P[3 + 2 * k:5 + 2 * k, 3 + 2 * k:5 + 2 * k].copy()
            item = {"id": self.info[k]["id"], "type": kind, "params": np.array(f),
                    "segment": None}
            if kind == LINE:
                r, al, sign = canonical_line(f[0], f[1])
                item["params"] = np.array([r, al])
                covariance[0, 1] *= sign  # J P J^T with J = diag(sign, 1)
                covariance[1, 0] *= sign
                # The segment's ends on the line as the state holds it (PointOnLine).
                item["segment"] = (point_on_line(f, self.info[k]["s_min"]),
                                   point_on_line(f, self.info[k]["s_max"]))
            item["covariance"] = covariance
            features.append(item)
        return features

    # --- one step: EkfSlam::Step ----------------------------------------------------------------

    def step(self, record, features):
        """record: t, dt (s), command (v m/s, w rad/s), odometry X_OR, has_scan; features: None or
        the scan's lines and corners in S (slam/observations.h, ScanFeatures, field by field)."""
        # Everything is checked before anything changes.
        increment, Q = self._command_input(record)
        observations = None if features is None else self._collect_observations(features)

        # Prediction, Eqs. (1)-(2) with (6) (EkfSlam::Predict).
        self.previous_command = (float(record.command[0]), float(record.command[1]))
        self._predict(increment, Q)
        if features is None:
            return {"num_features": self.num_features()}

        # Data association against the predicted map (MahalanobisDistances,
        # AssociateNearestNeighbour, HoldBackUnanchored).
        report = {"num_observed": len(observations), "num_matched": 0,
                  "num_redundant_corners": 0, "num_updated": 0, "num_new": 0,
                  "num_corners_from_lines": 0, "num_ambiguous": 0, "num_unanchored": 0,
                  "nis_sum": 0.0}
        d2 = self._mahalanobis_distances(observations)
        feature_of, outcome = self._associate(d2)
        if self.new_features_need_match:
            self._hold_back_unanchored(outcome)
        # What the innovation check reads (slam/innovation_check.h): the matched observations'
        # NIS, each observation's smallest NIS to any feature, and the outcomes.
        nearest_nis = [math.inf] * len(observations)
        for i in range(len(observations)):
            if outcome[i] == MATCHED:
                report["nis_sum"] += d2[i][feature_of[i]]
            for value in d2[i]:
                if value < nearest_nis[i]:
                    nearest_nis[i] = value
        report["nearest_nis"] = nearest_nis
        report["association"] = {"feature": feature_of, "outcome": outcome}

        # The matches that correct (SelectMatches), then Algorithm 1 (CorrectClassical): each
        # in turn, re-linearised at the current mean.
        matched = self._select_matches(feature_of, outcome, observations, features, report)
        for i in matched:
            self._update(feature_of[i], observations[i])
        report["num_updated"] = len(matched)

        # The secondary map: every matched line's segment grows, placed with the corrected pose.
        for i in matched:
            if observations[i]["type"] == LINE:
                self._grow_segment(feature_of[i], observations[i])

        # New features from the corrected pose (AddNewFeatures; lines first, as extracted).
        for i, observation in enumerate(observations):
            if outcome[i] == NEW:
                self._add_feature(observation)
        report["num_features"] = self.num_features()
        return report

    # --- the input: EkfSlam::CheckedMotionInput, CommandInput (slam/motion_model.cc) ------------

    def _command_input(self, record):
        """The held command as the increment (v dt, w dt) of Eq. (6) and its covariance
        Q = diag((dt sigma_v)^2, (dt sigma_w)^2), sigma_v = v_std + v_fraction |v| +
        change_fraction |v - v_before| (likewise sigma_w), v_before the record before's command."""
        dt = float(record.dt)
        if not math.isfinite(dt) or dt < 0.0:
            raise SlamInputError("record.dt_s: expected a finite value >= 0 (got %r)" % dt)
        v = float(record.command[0])
        w = float(record.command[1])
        if not (math.isfinite(v) and math.isfinite(w)):
            raise SlamInputError("record.command: expected finite values (got %r, %r)" % (v, w))
        v_before, w_before = self.previous_command
        sigma_v = self.v_std + self.v_fraction * abs(v) + self.change_fraction * abs(v - v_before)
        sigma_w = self.w_std + self.w_fraction * abs(w) + self.change_fraction * abs(w - w_before)
        Q = (dt * dt * sigma_v * sigma_v, dt * dt * sigma_w * sigma_w)
        return (v * dt, w * dt), Q

    # --- prediction: SlamState::Predict ---------------------------------------------------------

    def _predict(self, increment, Q):
        """pose <- f(pose, u); P_pp <- A P_pp A^T + W Q W^T; P_fp <- P_fp A^T. O(n): only the pose
        rows and columns change."""
        pose, A, W = predict_pose(self._pose(), increment[0], increment[1], self.a)
        self.x[:3] = pose
        P = self.P
        P_pp = A @ P[:3, :3] @ A.T
        P_pp = P_pp + W @ np.diag(Q) @ W.T
        P[:3, :3] = 0.5 * (P_pp + P_pp.T)
        if P.shape[0] > 3:
            # A is the identity but for (0, 2) and (1, 2): only the x and y columns change; the
            # pose rows mirror them (P stays exactly symmetric).
            P[3:, 0] += A[0, 2] * P[3:, 2]
            P[3:, 1] += A[1, 2] * P[3:, 2]
            P[:3, 3:] = P[3:, :3].T

    # --- the observations: EkfSlam::CollectObservations -----------------------------------------

    def _collect_observations(self, features):
        """Lines, then corners, as dicts {type, z, R, p_SA, p_SB}: z canonical, R the extractor's
        covariance plus the extra model noise, checked and exactly symmetric."""
        observations = []
        lines = np.asarray(features.line_params, dtype=float).reshape(-1, 2)
        line_covariances = np.asarray(features.line_covariances, dtype=float).reshape(-1, 2, 2)
        ends = np.asarray(features.line_endpoints, dtype=float).reshape(-1, 2, 2)
        for i in range(len(lines)):
            what = "features.lines[%d]" % i
            if not (math.isfinite(lines[i, 0]) and math.isfinite(lines[i, 1])):
                raise SlamInputError(what + ": expected a finite rho_m and alpha_rad (got %r)"
                                     % lines[i].tolist())
            if not np.all(np.isfinite(ends[i])):
                raise SlamInputError(what + ".p_SA/p_SB: expected finite points")
            rho, alpha, sign = canonical_line(float(lines[i, 0]), float(lines[i, 1]))
            R = checked_covariance(line_covariances[i] + np.diag(self.extra_line),
                                   what + ".covariance")
            R[0, 1] *= sign  # J R J^T with J = diag(sign, 1)
            R[1, 0] *= sign
            observations.append({"type": LINE, "z": np.array([rho, alpha]), "R": R,
                                 "p_SA": tuple(ends[i, 0]), "p_SB": tuple(ends[i, 1])})
        corners = np.asarray(features.corner_params, dtype=float).reshape(-1, 2)
        corner_covariances = np.asarray(features.corner_covariances, dtype=float).reshape(-1, 2, 2)
        for i in range(len(corners)):
            what = "features.corners[%d]" % i
            rng, bearing = float(corners[i, 0]), float(corners[i, 1])
            if not math.isfinite(bearing):
                raise SlamInputError(what + ".bearing_rad: expected a finite value (got %r)"
                                     % bearing)
            if not (rng > 0.0 and math.isfinite(rng)):
                raise SlamInputError(what + ".range_m: expected a finite value > 0 (got %r)"
                                     % rng)
            R = checked_covariance(corner_covariances[i] + np.diag(self.extra_corner),
                                   what + ".covariance")
            observations.append({"type": CORNER, "z": np.array([rng, wrap_angle_fast(bearing)]),
                                 "R": R})
        return observations

    # --- the state's pieces ---------------------------------------------------------------------

    def _pose(self):
        return (float(self.x[0]), float(self.x[1]), float(self.x[2]))

    def _feature(self, k):
        return (float(self.x[3 + 2 * k]), float(self.x[4 + 2 * k]))

    def _X_WS(self):
        """X_WR() * X_RS, as EkfSlam composes the Pose2s (not SensorPose)."""
        x, y, th = self._pose()
        return compose((x, y, wrap_angle(th)), self.X_RS)

    def _sensor_side_of_line(self, k):
        """EkfSlam::SensorSideOfLine: r - p_WS . (cos al, sin al), signed."""
        x_s, y_s, _ = self._X_WS()
        r, al = self._feature(k)
        return r - x_s * math.cos(al) - y_s * math.sin(al)

    def _predict_with_jacobians(self, k):
        """SlamState::PredictWithJacobians: feature k's predicted observation h at the current
        mean, H_pose and H_feature; None for a corner at the sensor (the model is undefined)."""
        pose = self._pose()
        f = self._feature(k)
        if self.types[k] == CORNER:
            p_WS, _ = sensor_pose(pose, self.X_RS)
            if math.hypot(f[0] - p_WS[0], f[1] - p_WS[1]) <= 1e-9:  # kMinCornerRange
                return None
            return predict_corner(pose, f, self.X_RS)
        return predict_line(pose, f, self.X_RS)

    def _joint_covariance(self, k):
        """SlamState::JointCovariance: P's 5x5 block of the pose and feature k."""
        index = [0, 1, 2, 3 + 2 * k, 4 + 2 * k]
        return self.P[np.ix_(index, index)]

    # --- association: EkfSlam::MahalanobisDistances, AssociateNearestNeighbour ------------------

    def _mahalanobis_distances(self, observations):
        """d2[i][k] = nu^T S^-1 nu of observation i and feature k; inf where they cannot match
        (other type, undefined prediction, a line seen from its other side)."""
        d2 = [[math.inf] * self.num_features() for _ in observations]
        for k in range(self.num_features()):
            # The prediction and H P H^T depend on the feature only: once per feature
            # (SlamState::Measure).
            predicted = self._predict_with_jacobians(k)
            if predicted is None:
                continue
            h_k, H_pose, H_feature = predicted
            H = np.hstack([H_pose, H_feature])
            HPHt = H @ self._joint_covariance(k) @ H.T
            HPHt = 0.5 * (HPHt + HPHt.T)
            for i, observation in enumerate(observations):
                if observation["type"] != self.types[k]:
                    continue
                z, R = observation["z"], observation["R"]
                h = h_k
                off_diagonal = HPHt[0, 1], HPHt[1, 0]
                if observation["type"] == LINE:
                    # A wall's face is seen from its front only: with the sensor clearly (3 sigma
                    # of the predicted rho) on the other side than when the feature was made, the
                    # observation is of another face (docs/method.md, departure 5).
                    if self.gate_line_side and self.info[k]["seen_side"] != 0:
                        side = self._sensor_side_of_line(k)
                        margin = 3.0 * math.sqrt(HPHt[0, 0] + R[0, 0])
                        if side * self.info[k]["seen_side"] < 0.0 and abs(side) > margin:
                            continue
                    # The prediction in z's polar form (ToObservation, AlignLineToObservation):
                    # the other form flips rho's sign, and that of H P H^T's off-diagonal.
                    if abs(wrap_angle_fast(z[1] - h[1])) > PI / 2.0:
                        h = (-h[0], wrap_angle_fast(h[1] + PI))
                        off_diagonal = -HPHt[0, 1], -HPHt[1, 0]
                nu0, nu1 = innovation(z, h)
                S00 = HPHt[0, 0] + R[0, 0]
                S01 = off_diagonal[0] + R[0, 1]
                S10 = off_diagonal[1] + R[1, 0]
                S11 = HPHt[1, 1] + R[1, 1]
                # nu^T S^-1 nu, the 2x2 inverse written out.
                det = S00 * S11 - S01 * S10
                d2[i][k] = (S11 * nu0 * nu0 - (S01 + S10) * nu0 * nu1 + S00 * nu1 * nu1) / det
        return d2

    def _associate(self, d2):
        """AssociateNearestNeighbour: the pairs inside the gate in increasing d2 (ties: lower i,
        then lower k), each observation and each feature once; an observation left over is new
        only when d2 >= the new-feature threshold for every feature (the duplicate guard), else
        ambiguous. Returns each observation's feature (-1: none) and outcome."""
        num_observations = len(d2)
        num_features = self.num_features()
        pairs = sorted((d2[i][k], i, k) for k in range(num_features)
                       for i in range(num_observations) if d2[i][k] < self.gate)
        feature_of = [-1] * num_observations
        outcome = [AMBIGUOUS] * num_observations
        taken = [False] * num_features
        for _, i, k in pairs:
            if feature_of[i] >= 0 or taken[k]:
                continue
            feature_of[i] = k
            outcome[i] = MATCHED
            taken[k] = True
        for i in range(num_observations):
            if feature_of[i] < 0 and all(value >= self.new_feature_threshold or math.isnan(value)
                                         for value in d2[i]):
                outcome[i] = NEW
        return feature_of, outcome

    def _hold_back_unanchored(self, outcome):
        """EkfSlam::HoldBackUnanchored: a scan of which nothing matched adds nothing while the
        map holds features (new_features_need_match)."""
        if self.num_features() == 0 or MATCHED in outcome:
            return
        for i, o in enumerate(outcome):
            if o == NEW:
                outcome[i] = UNANCHORED

    def _select_matches(self, feature_of, outcome, observations, features, report):
        """EkfSlam::SelectMatches: the indices of the matched observations that correct (all,
        but without correct_corners_of_matched_lines a corner whose two lines matched too);
        counts the outcomes in `report`."""
        num_lines = sum(1 for observation in observations if observation["type"] == LINE)
        corner_lines = np.asarray(features.corner_lines, dtype=int).reshape(-1, 2)

        def line_matched(line):
            return 0 <= line < num_lines and outcome[line] == MATCHED

        matched = []
        for i, o in enumerate(outcome):
            if o == MATCHED:
                if i >= num_lines and not self.correct_corners_of_matched_lines:
                    line_a, line_b = corner_lines[i - num_lines]
                    if line_matched(int(line_a)) and line_matched(int(line_b)):
                        report["num_redundant_corners"] += 1
                        continue
                matched.append(i)
            elif o == NEW:
                report["num_new"] += 1
            elif o == UNANCHORED:
                report["num_unanchored"] += 1
            else:
                report["num_ambiguous"] += 1
        report["num_matched"] = len(matched) + report["num_redundant_corners"]
        return matched

    # --- correction: SlamState::Update (WhitenedGain, ApplyGain, WrapAngles) --------------------

    def _update(self, k, observation):
        """One sequential EKF correction with an observation of feature k:
        nu = z - h(xi), S = H P H^T + R = L L^T, V = P H^T L^-T, xi += V L^-1 nu, P -= V V^T."""
        predicted = self._predict_with_jacobians(k)
        assert predicted is not None, "SlamState::Update: the prediction is undefined"
        h, H_pose, H_feature = predicted
        z, R = observation["z"], observation["R"]
        if self.types[k] == LINE:
            h = align_line_to_observation(z, h, H_pose, H_feature)
        nu0, nu1 = innovation(z, h)

        # U = P H^T from the 5 columns of P that H touches, O(n).
        P = self.P
        j = 3 + 2 * k
        u0 = (H_pose[0, 0] * P[:, 0] + H_pose[0, 1] * P[:, 1] + H_pose[0, 2] * P[:, 2]
              + H_feature[0, 0] * P[:, j] + H_feature[0, 1] * P[:, j + 1])
        u1 = (H_pose[1, 0] * P[:, 0] + H_pose[1, 1] * P[:, 1] + H_pose[1, 2] * P[:, 2]
              + H_feature[1, 0] * P[:, j] + H_feature[1, 1] * P[:, j + 1])
        # S = H U + R from U's pose and feature rows, symmetrised; its 2x2 Cholesky factor L.
        H = np.hstack([H_pose, H_feature])
        S = H @ np.column_stack([u0, u1])[[0, 1, 2, j, j + 1]] + R
        S = 0.5 * (S + S.T)
        l11 = math.sqrt(S[0, 0])
        l21 = S[1, 0] / l11
        schur = S[1, 1] - l21 * l21
        assert S[0, 0] > 0.0 and schur > 0.0, "SlamState::Update: S is not positive definite"
        l22 = math.sqrt(schur)
        # V = U L^-T, so that K S K^T = V V^T and K nu = V w with w = L^-1 nu.
        inv_l11 = 1.0 / l11
        inv_l22 = 1.0 / l22
        v0 = u0 * inv_l11
        v1 = (u1 - l21 * v0) * inv_l22
        w0 = nu0 * inv_l11
        w1 = (nu1 - l21 * w0) * inv_l22
        # xi <- xi + K nu; P <- P - V V^T: entry (c, r) subtracts the same products as (r, c), so
        # P stays exactly symmetric.
        self.x += v0 * w0 + v1 * w1
        P -= np.outer(v0, v0) + np.outer(v1, v1)
        # The heading and every line's alpha back into (-pi, pi].
        self.x[2] = wrap_angle_fast(self.x[2])
        for f, kind in enumerate(self.types):
            if kind == LINE:
                self.x[4 + 2 * f] = wrap_angle_fast(self.x[4 + 2 * f])

    # --- the map grows: EkfSlam::GrowSegment, EkfSlam::AddNewFeatures, SlamState::AddFeature ----

    def _grow_segment(self, k, observation):
        """The seen segment of line k covers the observation's endpoints (never shrinks)."""
        X_WS = self._X_WS()
        s_min, s_max = segment_from_points(self._feature(k),
                                           transform_point(X_WS, observation["p_SA"]),
                                           transform_point(X_WS, observation["p_SB"]))
        info = self.info[k]
        info["s_min"] = min(info["s_min"], s_min)
        info["s_max"] = max(info["s_max"], s_max)

    def _add_feature(self, observation):
        """The state augmented by the inverse model g at the current pose: f = g(pose, z),
        P_fx = G_pose P_px (all columns), P_ff = G_pose P_pp G_pose^T + G_z R G_z^T."""
        if observation["type"] == LINE:
            f, G_pose, G_z = initialize_line(self._pose(), observation["z"], self.X_RS)
        else:
            f, G_pose, G_z = initialize_corner(self._pose(), observation["z"], self.X_RS)
        n = self.P.shape[0]
        P = np.zeros((n + 2, n + 2))
        P[:n, :n] = self.P
        P[:n, n:] = P[:n, :3] @ G_pose.T  # P_xf = P_xp G_pose^T
        P[n:, :n] = P[:n, n:].T
        P_ff = G_pose @ P[:3, :3] @ G_pose.T
        P_ff = P_ff + G_z @ observation["R"] @ G_z.T
        P[n:, n:] = 0.5 * (P_ff + P_ff.T)
        self.P = P
        self.x = np.append(self.x, f)
        self.types.append(observation["type"])
        k = len(self.types) - 1
        info = {"id": self.next_id, "s_min": 0.0, "s_max": 0.0, "seen_side": 0}
        self.next_id += 1
        self.info.append(info)
        if observation["type"] == LINE:
            # The side of the line the sensor saw it from, and the seen segment.
            info["seen_side"] = -1 if self._sensor_side_of_line(k) < 0.0 else 1
            X_WS = self._X_WS()
            info["s_min"], info["s_max"] = segment_from_points(
                self._feature(k), transform_point(X_WS, observation["p_SA"]),
                transform_point(X_WS, observation["p_SB"]))


# ------------------------------------------------------------------------------------------------
# The models: Eq. (6) (slam/motion_model.cc) and Eqs. (7), (8) for the laser frame S
# (slam/observation_models.cc), each with its Jacobians as numpy arrays.
# ------------------------------------------------------------------------------------------------


def predict_pose(pose, d, dth, a):
    """PredictPose with MotionIntegration::kEuler and no skid (EulerStep, ApplyStep): the
    paper's forward-Euler Eq. (6) for the point h, `a` ahead of the axle, d along the start
    heading and a dth across it. Returns the new pose, A = d pose' / d pose and
    W = d pose' / d (d, dth)."""
    x, y, th = pose
    forward, lateral = d, a * dth
    cm = math.cos(th)
    sm = math.sin(th)
    dx, dy = forward * cm - lateral * sm, forward * sm + lateral * cm
    # A: the identity but for the heading column, the step turned by 90 degrees.
    A = np.eye(3)
    A[0, 2] = -dy
    A[1, 2] = dx
    W = np.array([[cm, -(a * sm)], [sm, a * cm], [0.0, 1.0]])
    return (x + dx, y + dy, wrap_angle_fast(th + dth)), A, W


def sensor_pose(pose, X_RS):
    """SensorPose: (x_s, y_s, th_s) of S in W and J = d(x_s, y_s, th_s) / d(x, y, th)."""
    c = math.cos(pose[2])
    s = math.sin(pose[2])
    # The mount's offset, rotated into W.
    dx_W, dy_W = X_RS[0] * c - X_RS[1] * s, X_RS[0] * s + X_RS[1] * c
    J = np.array([[1.0, 0.0, -dy_W], [0.0, 1.0, dx_W], [0.0, 0.0, 1.0]])
    return (pose[0] + dx_W, pose[1] + dy_W, wrap_angle_fast(pose[2] + X_RS[2])), J


def canonical_line(rho, alpha):
    """CanonicalLine: (-rho, alpha + pi) when rho < 0, alpha wrapped; returns (rho, alpha, sign),
    sign the Jacobian's first entry (J = diag(sign, 1))."""
    if rho < 0.0:
        return -rho, wrap_angle_fast(alpha + PI), -1.0
    return rho, wrap_angle_fast(alpha), 1.0


def predict_line(pose, line, X_RS):
    """PredictLine, Eq. (8): rho = r - x_s cos al - y_s sin al, alpha = al - th_s, canonical
    (the flip negates rho's row of the Jacobians). Returns z, H_pose, H_feature."""
    pose_WS, J_sensor = sensor_pose(pose, X_RS)
    r, al = line
    c = math.cos(al)
    s = math.sin(al)
    rho, alpha, sign = canonical_line(r - pose_WS[0] * c - pose_WS[1] * s, al - pose_WS[2])
    H_sensor = np.array([[-sign * c, -sign * s, 0.0], [0.0, 0.0, -1.0]])
    H_feature = np.array([[sign, sign * (pose_WS[0] * s - pose_WS[1] * c)], [0.0, 1.0]])
    return np.array([rho, alpha]), H_sensor @ J_sensor, H_feature


def predict_corner(pose, p_WC, X_RS):
    """PredictCorner, Eq. (7): range = |p_WC - p_WS|, bearing = atan2(...) - th_s, wrapped.
    Returns z, H_pose, H_feature."""
    pose_WS, J_sensor = sensor_pose(pose, X_RS)
    dx = p_WC[0] - pose_WS[0]
    dy = p_WC[1] - pose_WS[1]
    q = dx * dx + dy * dy
    rng = math.sqrt(q)
    z = np.array([rng, wrap_angle_fast(math.atan2(dy, dx) - pose_WS[2])])
    H_sensor = np.array([[-dx / rng, -dy / rng, 0.0], [dy / q, -dx / q, -1.0]])
    H_feature = np.array([[dx / rng, dy / rng], [-dy / q, dx / q]])
    return z, H_sensor @ J_sensor, H_feature


def initialize_line(pose, z, X_RS):
    """InitializeLine, Eq. (8) solved for the line (r, al) in W, canonical. Returns f, G_pose,
    G_z."""
    pose_WS, J_sensor = sensor_pose(pose, X_RS)
    al = z[1] + pose_WS[2]
    c = math.cos(al)
    s = math.sin(al)
    dr_dal = -pose_WS[0] * s + pose_WS[1] * c  # d r / d al at a fixed sensor position
    r, al, sign = canonical_line(z[0] + pose_WS[0] * c + pose_WS[1] * s, al)
    G_sensor = np.array([[sign * c, sign * s, sign * dr_dal], [0.0, 0.0, 1.0]])
    G_z = np.array([[sign, sign * dr_dal], [0.0, 1.0]])
    return np.array([r, al]), G_sensor @ J_sensor, G_z


def initialize_corner(pose, z, X_RS):
    """InitializeCorner, Eq. (7) solved for the corner p_WC. Returns f, G_pose, G_z."""
    pose_WS, J_sensor = sensor_pose(pose, X_RS)
    phi = z[1] + pose_WS[2]
    c = math.cos(phi)
    s = math.sin(phi)
    rng = z[0]
    G_sensor = np.array([[1.0, 0.0, -rng * s], [0.0, 1.0, rng * c]])
    G_z = np.array([[c, -rng * s], [s, rng * c]])
    p_WC = np.array([pose_WS[0] + rng * c, pose_WS[1] + rng * s])
    return p_WC, G_sensor @ J_sensor, G_z


def align_line_to_observation(z, h, H_pose, H_feature):
    """AlignLineToObservation: a line's prediction h in the polar form of the observation z it
    is compared with: when their alphas differ by more than pi/2, the same line's other form
    (-rho, alpha + pi), rho's rows of H_pose and H_feature negated (in place). Returns h."""
    if abs(wrap_angle_fast(z[1] - h[1])) <= PI / 2.0:
        return h
    H_pose[0] *= -1.0
    H_feature[0] *= -1.0
    return np.array([-h[0], wrap_angle_fast(h[1] + PI)])


def innovation(z, h):
    """Innovation: z - h, the angle wrapped."""
    return z[0] - h[0], wrap_angle_fast(z[1] - h[1])


def checked_covariance(R, what):
    """EkfSlam's CheckedCovariance: R finite, symmetric and positive definite, returned exactly
    symmetric; SlamInputError naming `what` otherwise."""
    R = np.asarray(R, dtype=float)
    finite = bool(np.all(np.isfinite(R)))
    asymmetry = abs(R[0, 1] - R[1, 0])
    scale = max(abs(R[0, 0]), abs(R[1, 1]))
    symmetric = 0.5 * (R + R.T)
    det = symmetric[0, 0] * symmetric[1, 1] - symmetric[0, 1] * symmetric[1, 0]
    if not finite or asymmetry > 1e-9 * scale or not symmetric[0, 0] > 0.0 or not det > 0.0:
        raise SlamInputError("%s: expected a finite, symmetric, positive definite matrix (got %r)"
                             % (what, R.tolist()))
    return symmetric


def _squares(*stds):
    """(s * s, ...): the variances of standard deviations, as the C++ squares them."""
    return tuple(float(std) * float(std) for std in stds)


def chi_square_2_quantile(probability):
    """ChiSquare2Quantile (slam/data_association.cc): -2 ln(1 - p), 9.21 at 0.99."""
    return -2.0 * math.log1p(-probability)


# ------------------------------------------------------------------------------------------------
# The secondary map (slam/secondary_map.h): a line's seen part as positions s along the line,
# t = (-sin al, cos al); its ends are r n + s t, always on the current line estimate.
# ------------------------------------------------------------------------------------------------


def position_along_line(line, p):
    """PositionAlongLine: s of p's projection on the line (r, al)."""
    return -math.sin(line[1]) * p[0] + math.cos(line[1]) * p[1]


def point_on_line(line, s):
    """PointOnLine: r n + s t."""
    c = math.cos(line[1])
    s_al = math.sin(line[1])
    return (line[0] * c - s * s_al, line[0] * s_al + s * c)


def segment_from_points(line, p_A, p_B):
    """SegmentFromPoints: (s_min, s_max) of two seen points."""
    s_a = position_along_line(line, p_A)
    s_b = position_along_line(line, p_B)
    return (min(s_a, s_b), max(s_a, s_b))


# ------------------------------------------------------------------------------------------------
# Angles (common/angles.h, slam/fast_wrap.h) and poses (common/pose2.h; (x, y, theta) tuples).
# ------------------------------------------------------------------------------------------------

PI = 3.14159265358979323846  # kPi, the same double as math.pi
_TWO_PI = 2.0 * PI
_THREE_PI = 3.0 * PI


def wrap_angle(angle):
    """WrapAngle: to (-pi, pi]; std::remainder and math.remainder are both IEEE's (exact)."""
    wrapped = math.remainder(angle, _TWO_PI)
    if wrapped <= -PI:
        wrapped += _TWO_PI
    return wrapped


def wrap_angle_fast(angle):
    """WrapAngleFast: WrapAngle with slam/fast_wrap.h's fast paths (the same results)."""
    if -PI < angle <= PI:
        return angle
    if PI < angle < _THREE_PI:
        return angle - _TWO_PI
    if -_THREE_PI < angle <= -PI:
        return angle + _TWO_PI
    return wrap_angle(angle)


def compose(X_AB, X_BC):
    """Pose2's X_AB * X_BC = X_AC (the constructor wraps the heading)."""
    x, y, th = X_AB
    c = math.cos(th)
    s = math.sin(th)
    return (x + c * X_BC[0] - s * X_BC[1], y + s * X_BC[0] + c * X_BC[1],
            wrap_angle(th + X_BC[2]))


def transform_point(X_AB, p_B):
    """Pose2's X_AB * p_B = p_A."""
    x, y, th = X_AB
    c = math.cos(th)
    s = math.sin(th)
    return (x + c * p_B[0] - s * p_B[1], y + s * p_B[0] + c * p_B[1])


# ------------------------------------------------------------------------------------------------
# The settings this class implements (slam/slam_params.h, EkfParams).
# ------------------------------------------------------------------------------------------------

# Each key of slam.ekf, flattened: READ (a number or switch the code above reads; any value),
# UNUSED (read by no code path of this filter; any value, may be absent), or the one value
# implemented (configs/paper.yaml's). A key not listed raises, so that a setting added to the C++
# later is not silently ignored. Of self_calibration only the five standard deviations are
# checked: while they are 0 (SelfCalibrationParams::Enabled() is false) no code path reads the
# section's other keys either.
READ, UNUSED = "read", "unused"
EKF_KEYS = {
    "process_model.kind": "command",             # the held command (not the odometry)
    "process_model.integration": "euler",        # the paper's forward-Euler Eq. (6)
    "process_model.noise.v_std_mps": READ,
    "process_model.noise.v_fraction": READ,
    "process_model.noise.w_std_radps": READ,
    "process_model.noise.w_fraction": READ,
    "process_model.noise.change_fraction": READ,
    "process_model.lateral.slip_std_m_per_rad": 0.0,   # no sideways slip (departure 10)
    "process_model.lateral.slip_std_m_per_sqrt_m": 0.0,
    "process_model.lateral.skid_s": 0.0,              # no skid (departure 13)
    "control_point_offset_m": READ,
    "axle_track_m": UNUSED,                      # self-calibration's
    "self_calibration.distance_scale_std": 0.0,  # the paper's state [pose, features]
    "self_calibration.heading_scale_std": 0.0,
    "self_calibration.heading_per_m_std_rad": 0.0,
    "self_calibration.range_bias_std_m": 0.0,
    "self_calibration.range_scale_std": 0.0,
    "jacobians": "current",                      # at the current mean (not first estimates)
    "initial_position_std_m": READ,
    "initial_heading_std_rad": READ,
    "extra_line_rho_std_m": READ,
    "extra_line_alpha_std_rad": READ,
    "extra_corner_range_std_m": READ,
    "extra_corner_bearing_std_rad": READ,
    "gate_probability": READ,
    "new_feature_probability": READ,
    "gate_line_side": READ,
    "new_features_need_match": READ,
    "correct_corners_of_matched_lines": READ,
    "corners_from_map_lines": False,             # a new corner from its own observation (12)
    "line_match_max_gap_m": 0.0,                 # infinite lines: no segment gate
    "duplicate_line_distance_m": 0.0,            # a wall mapped twice stays twice (20)
    "duplicate_line_min_overlap_m": UNUSED,      # the duplicate lines'
    "max_updates": UNUSED,                       # the selective filter's
    "selection_policy": UNUSED,                  # the selective filter's
}


def flatten(tree, prefix=""):
    """{"a": {"b": 1}} -> {"a.b": 1}."""
    flat = {}
    for key, value in tree.items():
        name = prefix + str(key)
        if isinstance(value, dict):
            flat.update(flatten(value, name + "."))
        else:
            flat[name] = value
    return flat


def check_settings(settings):
    """The flattened slam.ekf of `settings`; ValueError naming the key and value of a setting
    this class does not implement or does not know."""
    entry = settings.get("filter", {})
    update = entry.get("update", "")
    if update not in ("", "classical"):
        raise ValueError("slam.filters: %s: update: %r is not implemented by PaperClassicalEkf "
                         "(expected classical, or none)" % (entry.get("name", "?"), update))
    ekf = flatten(settings["slam"]["ekf"])
    for key, wanted in EKF_KEYS.items():
        if wanted == UNUSED:
            continue
        if key not in ekf:
            raise ValueError("slam.ekf.%s: missing from the settings" % key)
        value = ekf[key]
        if wanted == READ:
            continue
        if isinstance(wanted, str):
            same = value == wanted
        else:
            same = not isinstance(value, str) and float(value) == float(wanted)
        if not same:
            raise ValueError("slam.ekf.%s: %r is not implemented by PaperClassicalEkf (it copies "
                             "the classical filter with %r only, as configs/paper.yaml)"
                             % (key, value, wanted))
    for key, value in ekf.items():
        if key not in EKF_KEYS and not key.startswith("self_calibration."):
            raise ValueError("slam.ekf.%s: %r is a key PaperClassicalEkf does not know"
                             % (key, value))
    return ekf
