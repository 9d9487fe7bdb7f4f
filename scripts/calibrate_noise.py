#!/usr/bin/python3
"""Calibrates the filters' process model from the true motion of runs: the
values of slam.ekf.command_gain_v, _w, slam.ekf.command_noise.*, slam.ekf.odometry_noise.*,
slam.ekf.lateral_skid_s, slam.ekf.lateral_slip_std_m_per_rad (and by regime) and
slam.ekf.turn_centre_offset_m_per_radps (docs/method.md, "Calibrating the process noise").

    scripts/calibrate_noise.py DIR [DIR ...] [--offset A] [--window L] [--no-gain]
                               [--no-lag | --drive-lag [--no-accel-limit]]
                               [--slip-by-regime | --slip-on-the-spot] [--turn-centre]
                               [--lag-noise] [--wheel-noise] [--ramp A_V A_W]
                               [--beyond DIR [DIR ...]] [--json FILE]
    scripts/calibrate_noise.py --consistency WORK --write CONFIG [--config BASE] [--seed S]
                               [--runs N] [--jobs J] [--iterations K] [--tolerance T]
                               [--slip-on-the-spot] [--wheel-noise] [--ramp A_V A_W]

Each DIR is a run directory (with trajectory.csv) or a sweep directory (its
runs/run_*/ are taken). For every step k of a trajectory (rows k-1 and k,
dt the time between them) the script compares what the filter's prediction
is given with what the robot did, the axle centre A metres behind R
(robot.control_point_offset_m) being moved as the model moves it (a chord of
an arc along the mid-arc heading, plus a sideways skid):

- command: the filter predicts step k with the command of row k-1 held over
  dt, passed through the wheels' first-order lag (slam.ekf.command_lag_s,
  the time constant tau; FollowCommand in slam/motion_model.h: the speeds
  followed move toward the command by 1 - exp(-dt / tau) a step, from rest
  at the start; tau fitted first, by the least squared speed errors, with
  the gains by least squares at each tau; --no-lag keeps tau 0; --drive-lag
  fits the speed's lag with its change a step limited to a m/s^2 and the
  turn rate's own lag, slam.ekf.command_lag_s, command_max_accel_mps2 and
  command_lag_w_s (departure 27; with --no-accel-limit the speed's lag
  alone, the limit 0), each DIR weighted alike: the cost is the
  sum over the DIRs of log(mean e^2), so give one DIR per way of driving;
  fit_drive_lag; with --ramp A_V A_W, a robot that ramps its own set points
  toward the command at A_V m/s^2 and A_W rad/s^2, the lag follows the
  ramped set point's mean over each step, slam.ekf.command_ramp_mps2 and
  _radps2, departure 28: apply_ramp) and scaled
  by the gains g_v and g_w (slam.ekf.command_gain_v, _w: the
  robot's mean speed over its command), its noise growing with the change
  from the command of row k-2 and with the change one row earlier (row k-2
  from row k-3: the wheels still settling), with --lag-noise with the gap
  between the command and the followed speed (lag_noise_fraction), and with
  --wheel-noise (wheels that vary each on its own, departure 26) the speed's
  with the turn rate followed and the turn rate's with the speed followed
  (turn_v_noise_m_per_rad |w_f| in sigma_v, speed_w_noise_rad_per_m |v_f|
  in sigma_w; appended to the constants, after lag_noise_fraction, which is
  held at 0 without --lag-noise). The errors e_v = d / dt - g_v v_f and
  e_w = dth / dt - g_w w_f (v_f, w_f the speeds followed) of the true increment (d, dth) are modelled as
  independent zero-mean Gaussians with
      sigma_v = v_noise_std_mps + v_noise_fraction |v_f| + change_noise_fraction |v - v_prev|
                + settle_noise_fraction |v_prev - v_prev2|
      sigma_w = likewise with w_noise_std_radps, w_noise_fraction
  (slam/motion_model.h, CommandInput); the six constants and the two gains
  are fitted by maximum likelihood (alternately: the gains by weighted least
  squares with the sigmas fixed, the sigmas by Nelder-Mead with the gains
  fixed). --no-gain keeps the gains at 1 (the paper's model). The gains of
  each run on its own are printed too: a spread between runs larger than
  their standard errors is a bias that changes from run to run, which a
  constant gain cannot remove. The wheels' lag makes successive errors alike, which
  a filter that takes them as independent underrates; --window L fits the
  errors of the increments summed over L steps instead (their variance the
  sum of the steps' variances, as the filter adds them), so that the noise
  is right over L steps. The printed ratios for L = 1 .. 100 show at which
  time scale a fit holds.
- odometry: the increment between the odometry poses of rows k-1 and k,
  against the true one, modelled as in OdometryInput (variances linear in
  the distance rolled and the angle turned), fitted by maximum likelihood.
- skid: the sideways motion of the axle, -c v w dt, c by least squares
  (as scripts/measure_skid.py); what is left, per radian turned, is
  lateral_slip_std_m_per_rad (root of sum(r^2) / sum(dth^2)); with
  --slip-by-regime, instead, the slip per radian on the spot, its growth with
  the speed and the slip at a change of the turn rate
  (lateral_slip_std_m_per_rad, _per_rad_per_mps, _per_radps_change;
  docs/method.md, departure 23), by maximum likelihood (fit_slip_by_regime);
  with --slip-on-the-spot the slip per radian and at a change of the turn
  rate by maximum likelihood over the steps on the spot only, its growth
  with the speed 0 (fit_slip_on_the_spot): moving, what is left sideways
  is not per radian turned; the moving steps' rms and the model's are
  printed.
- turn centre (--turn-centre): on the spot (the command and the one before
  with v = 0) the robot turns about a point s w beside its axle
  (turn_centre_offset_m_per_radps, departure 24; slam::TurnCentre): the axle
  moves by s (w n(th') - w_prev n(th)), -s (w + w_prev) sin(dth/2) along the
  mid-arc heading and s (w - w_prev) cos(dth/2) across it (w, w_prev the
  turn-rate commands of rows k-1 and k-2, dth the true turn). s is fitted
  first (after the lag), by least squares of both components together
  (fit_turn_centre; the fits of each alone are printed too), and this mean
  motion is taken out of the true steps before everything else is fitted to
  them: the gains, the command noise and the sideways slip are those of the
  residuals.

- the range (always): the largest changes of the commanded speed and turn
  rate from one record to the next in the DIRs, command_noise.
  calibrated_change_v_mps and _w_radps: the model above holds for them; a
  larger step meets the drive's torque limit. Beyond it the noise grows by
  f c_v x in sigma_v and f c_w x in sigma_w, x the relative excess of a
  change and of the one a record earlier (CommandInput, departure 29); f
  (beyond_change_noise_fraction) is not written: it is set by the filters'
  consistency on training runs that go beyond the range (docs/method.md,
  "Calibrating the process noise", step 5), because the maximum likelihood
  value fits the typical step beyond and not the tail the filters lose
  their map on. With --beyond DIR [DIR ...], such runs (a larger world,
  where the filters take longer and the explorer's steps grow), that value
  over their steps beyond, everything else held, is printed
  (fit_beyond_change).

Prints the fitted values as the YAML of configs/default.yaml's slam.ekf
section, and for each fit the mean of (error / sigma)^2 (1 for a model that
fits) over bins of the inputs, so that a model that does not fit shows.

Consistency scale (--consistency WORK --write CONFIG): white motion noise fitted
from the true motion leaves the filters overconfident, because the linearised
EKF gains information from its corrections that it does not have
(docs/method.md, "Calibrating the process noise"). This mode runs the whole
procedure: a training sweep with --config (WORK/motion: --runs runs from
--seed), the fit above on it (with --wheel-noise and --slip-on-the-spot if
given), then sweeps of the same seeds with the fitted
model (WORK/scale_N) that set the two factors
slam.ekf.command_noise.v_noise_scale and w_noise_scale so that the training
runs' mean pose NEES per component is its dof: the position's (x, y; 2 dof)
sets the speed's factor, the heading's (1 dof) the turn rate's, each
multiplied by the square root of its mean NEES per dof (both filters' steps
pooled) until both are within --tolerance of 1 or --iterations sweeps are
done. CONFIG gets --config with the fitted values and the factors
(PyYAML). Sweeps whose sweep.json exists in WORK are reused. Never give it
the seeds a result is evaluated on.

Python 3 standard library only (the consistency mode: python3-yaml too).
"""
import argparse
import csv
import glob
import json
import math
import os
import subprocess
import sys


def run_dirs(paths):
    """The run directories named by `paths` (a sweep directory names its runs)."""
    runs = []
    for path in paths:
        if os.path.isfile(os.path.join(path, "trajectory.csv")):
            runs.append(path)
            continue
        found = sorted(glob.glob(os.path.join(path, "runs", "run_*", "trajectory.csv")))
        if not found:
            raise ValueError(f"{path}: neither a run directory (trajectory.csv) nor a sweep "
                             "directory (runs/run_*/trajectory.csv)")
        runs.extend(os.path.dirname(f) for f in found)
    return runs


def axle_motion(x0, y0, th0, x1, y1, th1, offset):
    """(chord, dth, lateral) of the axle centre (`offset` metres behind R)
    between two poses of R: its motion along and across the mid-arc heading,
    and the heading change."""
    dx = (x1 - offset * math.cos(th1)) - (x0 - offset * math.cos(th0))
    dy = (y1 - offset * math.sin(th1)) - (y0 - offset * math.sin(th0))
    dth = math.remainder(th1 - th0, 2.0 * math.pi)
    mid = th0 + 0.5 * dth
    return dx * math.cos(mid) + dy * math.sin(mid), dth, -dx * math.sin(mid) + dy * math.cos(mid)


def axle_increment(x0, y0, th0, x1, y1, th1, offset):
    """(d, dth, lateral): axle_motion with the chord turned into the arc
    length d whose chord it is (OdometryInput's inversion of the model)."""
    chord, dth, lateral = axle_motion(x0, y0, th0, x1, y1, th1, offset)
    half = 0.5 * dth
    sinc = 1.0 - half * half / 6.0 if abs(half) < 1e-4 else math.sin(half) / half
    return chord / sinc, dth, lateral


def read_steps(run, offset):
    """One dict per step of the run's trajectory.csv, from its first row: the
    robot at rest before it (the command before the first zero), as the
    filters start (slam::EkfSlam's previous command and followed speeds)."""
    path = os.path.join(run, "trajectory.csv")
    with open(path) as f:
        rows = list(csv.DictReader(f))
    steps = []
    rest = {"cmd_v": "0", "cmd_w": "0"}
    for line, (r0, r1, r2) in enumerate(zip([rest] + rows, rows, rows[1:]), start=2):
        try:
            t1, t2 = float(r1["t"]), float(r2["t"])
            true0 = [float(r1[k]) for k in ("true_x", "true_y", "true_th")]
            true1 = [float(r2[k]) for k in ("true_x", "true_y", "true_th")]
            odom0 = [float(r1[k]) for k in ("odom_x", "odom_y", "odom_th")]
            odom1 = [float(r2[k]) for k in ("odom_x", "odom_y", "odom_th")]
            v, w = float(r1["cmd_v"]), float(r1["cmd_w"])
            v_prev, w_prev = float(r0["cmd_v"]), float(r0["cmd_w"])
        except (KeyError, ValueError) as e:
            raise ValueError(f"{path}:{line + 1}: {e}") from None
        dt = t2 - t1
        if dt <= 0.0:
            continue
        d, dth, lateral = axle_increment(*true0, *true1, offset)
        d_odom, dth_odom, _ = axle_increment(*odom0, *odom1, offset)
        steps.append({"dt": dt, "v": v, "w": w, "sv": v, "sw": w,
                      "dv": abs(v - v_prev), "dw": abs(w - w_prev),
                      "on_the_spot": v == 0.0 and v_prev == 0.0, "w_prev": w_prev,
                      "d": d, "dth": dth, "lateral": lateral,
                      "d_odom": d_odom, "dth_odom": dth_odom})
    # The change of the command one row earlier (zero at the first step).
    for before, s in zip([None] + steps, steps):
        s["dv1"] = before["dv"] if before else 0.0
        s["dw1"] = before["dw"] if before else 0.0
    return steps


def nelder_mead(f, x0, step=0.5, iterations=3000, tolerance=1e-10):
    """Minimises f over R^n from x0 (Nelder-Mead, standard coefficients)."""
    n = len(x0)
    simplex = [list(x0)]
    for i in range(n):
        x = list(x0)
        x[i] += step
        simplex.append(x)
    values = [f(x) for x in simplex]
    for _ in range(iterations):
        order = sorted(range(n + 1), key=lambda i: values[i])
        simplex = [simplex[i] for i in order]
        values = [values[i] for i in order]
        if abs(values[-1] - values[0]) <= tolerance * (1.0 + abs(values[0])):
            break
        centroid = [sum(x[j] for x in simplex[:-1]) / n for j in range(n)]

        def toward(t):
            return [c + t * (w - c) for c, w in zip(centroid, simplex[-1])]

        reflected = toward(-1.0)
        fr = f(reflected)
        if fr < values[0]:
            expanded = toward(-2.0)
            fe = f(expanded)
            simplex[-1], values[-1] = (expanded, fe) if fe < fr else (reflected, fr)
        elif fr < values[-2]:
            simplex[-1], values[-1] = reflected, fr
        else:
            contracted = toward(0.5)
            fc = f(contracted)
            if fc < values[-1]:
                simplex[-1], values[-1] = contracted, fc
            else:
                best = simplex[0]
                simplex = [best] + [[b + 0.5 * (x - b) for b, x in zip(best, s)]
                                    for s in simplex[1:]]
                values = [values[0]] + [f(x) for x in simplex[1:]]
    return simplex[0]


def fit(negative_log_likelihood, initial):
    """The non-negative parameters that minimise the negative log-likelihood,
    searched over their logarithms. A parameter the data do not need can
    come out as 0 (its logarithm run off to where exp underflows); started
    again from there (the gains' rounds), it starts at the smallest positive
    double instead."""
    best = nelder_mead(lambda logs: negative_log_likelihood([math.exp(l) for l in logs]),
                       [math.log(max(x, sys.float_info.min)) for x in initial])
    return [math.exp(l) for l in best]


def gaussian_nll(errors_and_variances):
    """Negative log-likelihood (less constants) of zero-mean Gaussian errors."""
    total = 0.0
    for e, var in errors_and_variances:
        if var <= 0.0:
            return math.inf
        total += math.log(var) + e * e / var
    return 0.5 * total


def command_sigmas(s, p):
    """(sigma_v, sigma_w) of CommandInput for step s, p = (v0, kv, w0, kw, kc,
    ks[, kl[, tv, sw]]) in the order of COMMAND_NAMES: ks the settle term's
    fraction (0 when p has five values), kl the lag term's (of the gap between
    the command and the followed speed; 0 when p has six values), tv and sw
    the wheels' terms (turn_v_noise_m_per_rad, of |fw| in sigma_v, and
    speed_w_noise_rad_per_m, of |fv| in sigma_w; 0 when p has seven values
    or fewer)."""
    v0, kv, w0, kw, kc = p[:5]
    ks = p[5] if len(p) > 5 else 0.0
    kl = p[6] if len(p) > 6 else 0.0
    tv = p[7] if len(p) > 7 else 0.0
    sw = p[8] if len(p) > 8 else 0.0
    return (v0 + kv * abs(s["fv"]) + kc * s["dv"] + ks * s["dv1"] + kl * abs(s["v"] - s["fv"])
            + tv * abs(s["fw"]),
            w0 + kw * abs(s["fw"]) + kc * s["dw"] + ks * s["dw1"] + kl * abs(s["w"] - s["fw"])
            + sw * abs(s["fv"]))


def command_errors(s, gains=(1.0, 1.0)):
    """(e_v, e_w): the true speeds over the step less the speeds the model
    follows the command with (apply_lag), times the gains (g_v, g_w)."""
    return (s["d"] / s["dt"] - gains[0] * s["fv"], s["dth"] / s["dt"] - gains[1] * s["fw"])


def follow(followed, command, dt, lag, max_accel=0.0):
    """One component of slam::FollowCommand: `followed` moved toward `command`
    through a first-order lag of time constant `lag` (0: the command), its
    change then held within +-max_accel dt when `max_accel` > 0."""
    target = command if lag <= 0.0 else followed - math.expm1(-dt / lag) * (command - followed)
    if max_accel > 0.0:
        most = max_accel * dt
        target = followed + min(most, max(-most, target - followed))
    return target


def ramp(ramped, command, dt, accel):
    """(mean over the step, end) of a set point ramped from `ramped` toward
    `command` at most `accel` a second (0: the command), one component of
    slam::RampCommand."""
    if accel <= 0.0:
        return command, command
    change = max(-accel * dt, min(accel * dt, command - ramped))
    end = ramped + change
    return end - change * (abs(change) / accel) / (2.0 * dt), end


def apply_ramp(runs_steps, accel_v, accel_w):
    """Sets each step's set points (sv, sw), what the lag follows: the
    commands ramped at `accel_v` m/s^2 and `accel_w` rad/s^2 (--ramp), each
    the ramp's mean over the step, from rest at a run's first step; without
    a ramp (0) the commands themselves."""
    for steps in runs_steps:
        rv = rw = 0.0
        for s in steps:
            s["sv"], rv = ramp(rv, s["v"], s["dt"], accel_v)
            s["sw"], rw = ramp(rw, s["w"], s["dt"], accel_w)


def apply_lag(runs_steps, lag, lag_w=None, max_accel=0.0):
    """Sets each step's followed speeds (fv, fw): the set points (sv, sw;
    apply_ramp) through a first-order lag of time constant `lag` seconds
    (the turn rate's `lag_w`, None: the same), the speed's change limited to
    `max_accel` m/s^2 a second (0: no limit), from rest at a run's first
    step, as slam::FollowCommand."""
    lag_w = lag if lag_w is None else lag_w
    for steps in runs_steps:
        fv = fw = 0.0
        for s in steps:
            fv = follow(fv, s["sv"], s["dt"], lag, max_accel)
            fw = follow(fw, s["sw"], s["dt"], lag_w)
            s["fv"], s["fw"] = fv, fw


def speed_cost(groups, speed, followed):
    """sum over the groups of log(mean e^2) of one speed ("d" with "fv", or
    "dth" with "fw"), the gain by least squares over all the groups' steps:
    the Gaussian likelihood's cost with constant variances, each group
    weighted alike whatever its number of steps."""
    steps = [s for runs_steps in groups for run_steps in runs_steps for s in run_steps]
    sxx = sum(s[followed] ** 2 for s in steps)
    gain = sum(s[followed] * s[speed] / s["dt"] for s in steps) / sxx if sxx > 0 else 1.0
    cost = 0.0
    for runs_steps in groups:
        group = [s for run_steps in runs_steps for s in run_steps]
        mse = sum((s[speed] / s["dt"] - gain * s[followed]) ** 2 for s in group) / len(group)
        cost += math.log(max(mse, 1e-300))
    return cost


def lag_cost(runs_steps, lag):
    """log(mean e_v^2) + log(mean e_w^2) with the lag and the least-squares
    gains: the Gaussian likelihood's cost with constant variances."""
    apply_lag(runs_steps, lag)
    return speed_cost([runs_steps], "d", "fv") + speed_cost([runs_steps], "dth", "fw")


def golden_section(cost, lo, hi, tolerance):
    """The argument in [lo, hi] that minimises `cost` (unimodal there)."""
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
    fa, fb = cost(a), cost(b)
    while hi - lo > tolerance:
        if fa < fb:
            hi, b, fb = b, a, fa
            a = hi - ratio * (hi - lo)
            fa = cost(a)
        else:
            lo, a, fa = a, b, fb
            b = lo + ratio * (hi - lo)
            fb = cost(b)
    return 0.5 * (lo + hi)


def fit_lag(runs_steps, longest=0.5):
    """The lag time constant in [0, longest] s that minimises lag_cost
    (golden-section search; 0 if no lag fits better)."""
    best = golden_section(lambda lag: lag_cost(runs_steps, lag), 0.0, longest, 1e-4)
    return best if lag_cost(runs_steps, best) < lag_cost(runs_steps, 0.0) else 0.0


def fit_drive_lag(groups, longest=0.5, limit=True):
    """(lag_v, lag_w, max_accel): the speed's lag with its acceleration limit
    and the turn rate's own lag (departure 27), each group of runs (one
    DIR: one way of driving) weighted alike (speed_cost). The turn rate's lag
    by golden-section search over [0, longest] s. The speed's cost is flat
    in the limit above the largest change the commands ask for and steep
    below it, so the lag and limit are searched on a grid: the lag in steps
    of 5 ms up to 0.1 s, the limit from 0.2 to 5 m/s^2 in steps of 5 % and
    none (0), then around the best on a grid five times finer; without
    `limit` (--no-accel-limit) the limit is 0 and only the lag is searched.
    Each lag 0 where no lag fits better."""
    def cost_w(lag_w):
        for runs_steps in groups:
            apply_lag(runs_steps, 0.0, lag_w)
        return speed_cost(groups, "dth", "fw")

    lag_w = golden_section(cost_w, 0.0, longest, 1e-4)
    if cost_w(lag_w) >= cost_w(0.0):
        lag_w = 0.0

    def cost_v(lag_v, max_accel):
        for runs_steps in groups:
            apply_lag(runs_steps, lag_v, 0.0, max_accel)
        return speed_cost(groups, "d", "fv")

    def search(lags, limits):
        return min((cost_v(t, a), t, a) for t in lags for a in limits)

    limits = [0.2 * 1.05 ** i for i in range(int(math.log(25.0) / math.log(1.05)) + 1)]
    _, lag_v, max_accel = search([0.005 * i for i in range(21)],
                                 [0.0] + limits if limit else [0.0])
    fine_lags = [max(0.0, lag_v + 0.001 * i) for i in range(-5, 6)]
    fine_limits = [0.0] if max_accel == 0.0 else [max_accel * 1.01 ** i for i in range(-5, 6)]
    _, lag_v, max_accel = search(fine_lags, fine_limits)
    for runs_steps in groups:
        apply_lag(runs_steps, lag_v, lag_w, max_accel)
    return lag_v, lag_w, max_accel


def fit_gains(steps, p):
    """(g_v, g_w, se_v, se_w): the gains by weighted least squares of the true
    speeds on the commands, weights 1 / sigma^2 of the noise p, and their
    standard errors from the scatter of the weighted residuals."""
    result = []
    for speed, command, index in (("d", "fv", 0), ("dth", "fw", 1)):
        sxx = sxy = 0.0
        for s in steps:
            weight = 1.0 / command_sigmas(s, p)[index] ** 2
            sxx += weight * s[command] ** 2
            sxy += weight * s[command] * s[speed] / s["dt"]
        if sxx == 0.0:
            result.append(1.0)
            continue
        result.append(sxy / sxx)
    chi2 = [0.0, 0.0]
    sxx = [0.0, 0.0]
    for s in steps:
        errors = command_errors(s, result)
        sigmas = command_sigmas(s, p)
        for i, command in enumerate(("fv", "fw")):
            chi2[i] += (errors[i] / sigmas[i]) ** 2
            sxx[i] += (s[command] / sigmas[i]) ** 2
    n = max(len(steps) - 1, 1)
    return (result[0], result[1],
            math.sqrt(chi2[0] / n / sxx[0]) if sxx[0] > 0 else math.inf,
            math.sqrt(chi2[1] / n / sxx[1]) if sxx[1] > 0 else math.inf)


def windows_of(runs_steps, window):
    """The steps cut into consecutive windows of `window` steps, per run (a
    run's last, shorter window is dropped)."""
    out = []
    for steps in runs_steps:
        for i in range(0, len(steps) - window + 1, window):
            out.append(steps[i:i + window])
    return out


def window_pairs(windows, p, gains=(1.0, 1.0)):
    """(error, variance) of the increments summed over each window: the true
    distance and turn less the commanded ones (times the gains), against the
    sum of the per-step variances the filter adds (dt sigma)^2."""
    pairs = []
    for window in windows:
        ed = eth = vd = vth = 0.0
        for s in window:
            sv, sw = command_sigmas(s, p)
            ev, ew = command_errors(s, gains)
            ed += ev * s["dt"]
            eth += ew * s["dt"]
            vd += (sv * s["dt"]) ** 2
            vth += (sw * s["dt"]) ** 2
        pairs.append((ed, vd))
        pairs.append((eth, vth))
    return pairs


def fit_command(runs_steps, window, with_gains=True, rounds=3, lag_noise=False,
                wheel_noise=False):
    """(CommandNoiseParams, (g_v, g_w, se_v, se_w)) by maximum likelihood of
    the increments' errors summed over windows of `window` steps (1: every
    step on its own); the gains 1 when not `with_gains`; with `lag_noise`
    also the lag term's fraction (lag_noise_fraction, the seventh value);
    with `wheel_noise` also the wheels' terms (turn_v_noise_m_per_rad and
    speed_w_noise_rad_per_m, the eighth and ninth values; the seventh is then
    0 when not `lag_noise`, and not fitted)."""
    windows = windows_of(runs_steps, window)
    steps = [s for run_steps in runs_steps for s in run_steps]
    gains = (1.0, 1.0, 0.0, 0.0)
    p = [0.01, 0.05, 0.01, 0.05, 0.3, 0.1] + ([0.1] if lag_noise else [])
    if wheel_noise:
        p += [1e-3, 1e-2]

    def full(q):
        """The fitted constants q as command_sigmas' p (the lag term's 0
        before the wheels' terms where it is not fitted)."""
        return q[:6] + [0.0] + q[6:] if wheel_noise and not lag_noise else q

    for _ in range(rounds if with_gains else 1):
        p = fit(lambda q: gaussian_nll(window_pairs(windows, full(q), gains[:2])), p)
        if with_gains:
            gains = fit_gains(steps, full(p))
    if with_gains:
        p = fit(lambda q: gaussian_nll(window_pairs(windows, full(q), gains[:2])), p)
    return full(p), gains


def change_range(steps):
    """(c_v, c_w): the largest changes of the commanded speed and turn rate
    from one record to the next among `steps`, the range a fit of them covers
    (command_noise.calibrated_change_v_mps, _w_radps; departure 29)."""
    return max(s["dv"] for s in steps), max(s["dw"] for s in steps)


def change_excess(s, c_v, c_w):
    """x of CommandInput's departure 29: the relative excess of step s's
    change of the command, and of the one a record earlier, over (c_v, c_w)."""
    def excess(change, limit):
        return max(0.0, change - limit) / limit if limit > 0.0 else 0.0
    return (excess(s["dv"], c_v) + excess(s["dw"], c_w) + excess(s["dv1"], c_v)
            + excess(s["dw1"], c_w))


def fit_beyond_change(steps, p, gains, c_v, c_w):
    """(f, count): command_noise.beyond_change_noise_fraction by maximum
    likelihood over the steps whose changes go beyond (c_v, c_w), the rest of
    the command model (`p`, `gains`) held: sigma_v + f c_v x, sigma_w + f c_w x.
    Raises ValueError when no step goes beyond."""
    rows = []
    for s in steps:
        x = change_excess(s, c_v, c_w)
        if x > 0.0:
            rows.append((command_sigmas(s, p), command_errors(s, gains), x))
    if not rows:
        raise ValueError(f"--beyond: no command change beyond the training's range "
                         f"({c_v:.4g} m/s, {c_w:.4g} rad/s) in these runs")

    def nll(log_f):
        f = math.exp(log_f)
        return gaussian_nll([(e, (sigma + f * limit * x) ** 2)
                             for (sigmas, errors, x) in rows
                             for sigma, e, limit in zip(sigmas, errors, (c_v, c_w))])
    return math.exp(golden_section(nll, math.log(1e-4), math.log(100.0), 1e-4)), len(rows)


def variance_ratios(runs_steps, p, lengths, gains=(1.0, 1.0)):
    """For each window length: sum of the squared summed errors over the sum
    of the model's summed variances, distance and turn (1 when the errors of
    successive steps are independent and the model fits)."""
    ratios = []
    for length in lengths:
        pairs = window_pairs(windows_of(runs_steps, length), p, gains)
        d = pairs[0::2]
        th = pairs[1::2]
        ratios.append((length, sum(e * e for e, _ in d) / sum(v for _, v in d),
                       sum(e * e for e, _ in th) / sum(v for _, v in th)))
    return ratios


def odometry_variances(s, p):
    """(var_d, var_dth) of OdometryInput for step s, p = (d0, kd, th0, kthd, kthth)."""
    d0, kd, th0, kthd, kthth = p
    distance, turn = abs(s["d_odom"]), abs(s["dth_odom"])
    return (d0 * d0 + kd * kd * distance,
            th0 * th0 + kthd * kthd * distance + kthth * kthth * turn)


def fit_odometry(steps):
    def nll(p):
        pairs = []
        for s in steps:
            var_d, var_th = odometry_variances(s, p)
            pairs.append((s["d_odom"] - s["d"], var_d))
            pairs.append((s["dth_odom"] - s["dth"], var_th))
        return gaussian_nll(pairs)

    return fit(nll, [1e-4, 1e-3, 1e-4, 1e-3, 1e-3])


def fit_skid(steps):
    """(c, k): the skid constant by least squares and the slip per radian
    turned that is left."""
    xs = [-s["d"] * s["dth"] / s["dt"] for s in steps]
    ys = [s["lateral"] for s in steps]
    sxx = sum(x * x for x in xs)
    if sxx == 0.0:
        raise ValueError("no turns while moving: the skid is undetermined")
    c = sum(x * y for x, y in zip(xs, ys)) / sxx
    residual2 = sum((y - c * x) ** 2 for x, y in zip(xs, ys))
    turned2 = sum(s["dth"] ** 2 for s in steps)
    return c, math.sqrt(residual2 / turned2)


def sideways_residual(s, c):
    """What the skid c leaves of the axle's sideways motion."""
    return s["lateral"] - c * (-s["d"] * s["dth"] / s["dt"])


def turn_centre_regressors(s):
    """(along, across): the axle's motion over step s, along and across the
    mid-arc heading, per metre per rad/s of the turn centre's offset (zero
    off the spot): -(w + w_prev) sin(dth/2) and (w - w_prev) cos(dth/2)."""
    if not s["on_the_spot"]:
        return 0.0, 0.0
    half = 0.5 * s["dth"]
    return -(s["w"] + s["w_prev"]) * math.sin(half), (s["w"] - s["w_prev"]) * math.cos(half)


def fit_turn_centre(steps, c):
    """(s, s_along, s_across): the turn centre's offset per rad/s
    (--turn-centre; slam.ekf.turn_centre_offset_m_per_radps) from the axle's
    motion on the spot along and across the mid-arc heading
    (turn_centre_regressors): s_along and s_across by least squares of each
    component alone, s by weighted least squares of both together, each
    component weighted by the inverse of its mean squared residual from its
    own fit (the along component carries the wheels' forward noise, tens of
    micrometres a step, the across one a few). Along: the chord less the chord
    of the followed speed (apply_lag first); across: what the skid c leaves
    (sideways_residual)."""
    rows = {"along": [], "across": []}
    for s in steps:
        if not s["on_the_spot"]:
            continue
        x_along, x_across = turn_centre_regressors(s)
        half = 0.5 * s["dth"]
        sinc = 1.0 - half * half / 6.0 if abs(half) < 1e-4 else math.sin(half) / half
        rows["along"].append((x_along, (s["d"] - s["fv"] * s["dt"]) * sinc))
        rows["across"].append((x_across, sideways_residual(s, c)))
    alone = {}
    weighted_xx = weighted_xy = 0.0
    for key, pairs in rows.items():
        sxx = sum(x * x for x, _ in pairs)
        if sxx == 0.0:
            raise ValueError("no turn and no change of the turn rate on the spot: the turn "
                             "centre is undetermined")
        alone[key] = sum(x * y for x, y in pairs) / sxx
        mean_square = sum((y - alone[key] * x) ** 2 for x, y in pairs) / len(pairs)
        weight = 1.0 / max(mean_square, 1e-300)
        weighted_xx += weight * sxx
        weighted_xy += weight * alone[key] * sxx
    return weighted_xy / weighted_xx, alone["along"], alone["across"]


def take_out_turn_centre(steps, offset):
    """Takes the turn about the point `offset` w beside the axle out of the
    true steps (d, lateral), so that what follows is fitted to the rest."""
    for s in steps:
        x_along, x_across = turn_centre_regressors(s)
        if x_along == 0.0 and x_across == 0.0:
            continue
        half = 0.5 * s["dth"]
        sinc = 1.0 - half * half / 6.0 if abs(half) < 1e-4 else math.sin(half) / half
        s["d"] -= offset * x_along / sinc
        s["lateral"] -= offset * x_across


def fit_slip_by_regime(steps, c, gain_v):
    """(k0, k1, kc): the sideways slip by regime (--slip-by-regime), fitted
    by maximum likelihood to what the skid c leaves, r, modelled as a
    zero-mean Gaussian with variance
        (k0^2 + (k1 v)^2) dth^2 + (kc |w - w_prev|)^2
    (slam.ekf.lateral_slip_std_m_per_rad, _per_rad_per_mps,
    _per_radps_change), v = gain_v |fv| the speed the filter predicts with
    (apply_lag first), dth the true turn and w - w_prev the change of the
    turn-rate command. Steps with neither a turn nor a change carry no
    information and are left out."""
    rows = []
    for s in steps:
        r = sideways_residual(s, c)
        turn2 = s["dth"] ** 2
        if turn2 == 0.0 and s["dw"] == 0.0:
            continue
        rows.append((r, turn2, (gain_v * s["fv"]) ** 2 * turn2, s["dw"] ** 2))

    def nll(p):
        k0, k1, kc = p
        return gaussian_nll((r, k0 * k0 * t + k1 * k1 * vt + kc * kc * w)
                            for r, t, vt, w in rows)

    return fit(nll, [1e-4, 1e-3, 1e-4])


def fit_slip_on_the_spot(steps, c):
    """(k0, kc, ratio, moving_rms, moving_model_rms): the sideways slip
    fitted on the spot only (--slip-on-the-spot), by maximum likelihood to
    what the skid c leaves, r, on the steps on the spot (the command and the
    one before with v = 0) with a turn or a change of the turn rate, modelled
    as a zero-mean Gaussian with variance
        (k0 dth)^2 + (kc |w - w_prev|)^2
    (slam.ekf.lateral_slip_std_m_per_rad, _per_radps_change; the growth with
    the speed, _per_rad_per_mps, 0). Moving, what is left sideways is not per
    radian turned, so those steps are left out of the fit; `ratio` is the
    fitted steps' mean r^2 / variance (1 where the model fits), `moving_rms`
    the root mean square of r over the moving steps and `moving_model_rms`
    the root of the mean variance the model gives them."""
    rows = []
    for s in steps:
        if s["on_the_spot"] and (s["dth"] != 0.0 or s["dw"] != 0.0):
            rows.append((sideways_residual(s, c), s["dth"] ** 2, s["dw"] ** 2))
    if not rows:
        raise ValueError("no turn and no change of the turn rate on the spot: the slip on the "
                         "spot is undetermined")

    def nll(p):
        k0, kc = p
        return gaussian_nll((r, k0 * k0 * t + kc * kc * w) for r, t, w in rows)

    k0, kc = fit(nll, [1e-4, 1e-4])
    ratio = sum(r * r / (k0 * k0 * t + kc * kc * w) for r, t, w in rows) / len(rows)
    moving = [s for s in steps if not s["on_the_spot"]]
    if not moving:
        return k0, kc, ratio, 0.0, 0.0
    moving_rms = math.sqrt(sum(sideways_residual(s, c) ** 2 for s in moving) / len(moving))
    model_rms = math.sqrt(sum((k0 * s["dth"]) ** 2 + (kc * s["dw"]) ** 2 for s in moving)
                          / len(moving))
    return k0, kc, ratio, moving_rms, model_rms


def print_bins(title, steps, key, edges, normalised):
    """Mean of the squared normalised errors over bins of s[key]."""
    print(f"  {title}:")
    for lo, hi in zip(edges, edges[1:]):
        chosen = [s for s in steps if lo <= s[key] < hi]
        if not chosen:
            continue
        values = [normalised(s) for s in chosen]
        mean = sum(values) / len(values)
        print(f"    {key} in [{lo:g}, {hi:g}): {len(chosen):6d} steps, mean (e/sigma)^2 = {mean:.2f}")


def read_runs(dirs, offset):
    """(runs_steps, steps, skid c, slip k) of the runs in `dirs`; raises
    OSError or ValueError naming the file."""
    runs = run_dirs(dirs)
    runs_steps = [read_steps(run, offset) for run in runs]
    steps = [s for run_steps in runs_steps for s in run_steps]
    if len(steps) < 100:
        raise ValueError(f"only {len(steps)} steps in {len(runs)} runs: too few to fit")
    c, k = fit_skid(steps)
    return runs_steps, steps, c, k


COMMAND_NAMES = ["v_noise_std_mps", "v_noise_fraction", "w_noise_std_radps", "w_noise_fraction",
                 "change_noise_fraction", "settle_noise_fraction", "lag_noise_fraction",
                 "turn_v_noise_m_per_rad", "speed_w_noise_rad_per_m"]
ODOMETRY_NAMES = ["distance_noise_std_m", "distance_noise_std_m_per_sqrt_m",
                  "heading_noise_std_rad", "heading_noise_std_rad_per_sqrt_m",
                  "heading_noise_std_rad_per_sqrt_rad"]


# A fitted constant below this is written as 0: the fit ran it off toward 0
# (fit works on logarithms), and 1e-308 in a config reads as a value.
NEGLIGIBLE = 1e-12


def command_noise(command, lag_noise):
    """The fitted constants of fit_command's `command` as the keys of
    slam.ekf.command_noise: lag_noise_fraction only when fitted (`lag_noise`;
    fit_command holds it at 0 before the wheels' terms otherwise); those
    below NEGLIGIBLE as 0."""
    return {name: value if value >= NEGLIGIBLE else 0.0
            for name, value in zip(COMMAND_NAMES, command)
            if name != "lag_noise_fraction" or lag_noise}


def ekf_values(gains, lag, command, odometry, c, k, lag_noise):
    """The fitted values as the keys of slam.ekf (nested dicts)."""
    return {"command_gain_v": gains[0], "command_gain_w": gains[1], "command_lag_s": lag,
            "command_noise": command_noise(command, lag_noise),
            "odometry_noise": dict(zip(ODOMETRY_NAMES, odometry)),
            "lateral_skid_s": c, "lateral_slip_std_m_per_rad": k}


def set_overrides(values, prefix="slam.ekf"):
    """--set arguments of mjslam for nested `values` under `prefix`."""
    out = []
    for key, value in values.items():
        if isinstance(value, dict):
            out += set_overrides(value, f"{prefix}.{key}")
        else:
            out += ["--set", f"{prefix}.{key}={value!r}"]
    return out


def sweep(args, out, overrides):
    """Runs (or reuses, when out/sweep.json exists) a training sweep."""
    if os.path.isfile(os.path.join(out, "sweep.json")):
        print(f"# reusing {out}", flush=True)
        return
    command = [args.mjslam, "sweep", "--runs", str(args.runs), "--jobs", str(args.jobs),
               "--out", out, "--config", args.config, "--set", f"run.seed={args.seed}",
               "--set", "render.enabled=false"] + overrides
    print("# " + " ".join(command), flush=True)
    with open(out + ".log", "w") as log:
        result = subprocess.run(command, stdout=log, stderr=subprocess.STDOUT)
    if result.returncode != 0:
        raise ValueError(f"{' '.join(command)}: exit status {result.returncode} (log: {out}.log)")


def pose_nees_per_dof(dirs):
    """(position, heading) mean NEES per dof over every step of the runs in
    `dirs` and both filters whose pose covariance is positive definite: the
    mean of e_xy' P_xy^-1 e_xy / 2 and of e_th^2 / P_thth. Also the count."""
    position = heading = 0.0
    count = 0
    for run in run_dirs(dirs):
        path = os.path.join(run, "trajectory.csv")
        with open(path) as f:
            for line, r in enumerate(csv.DictReader(f), start=2):
                try:
                    for name in ("classical", "selective"):
                        pxx, pxy, pyy, ptt = (float(r[f"{name}_{k}"])
                                              for k in ("pxx", "pxy", "pyy", "pthth"))
                        det = pxx * pyy - pxy * pxy
                        if pxx <= 0.0 or det <= 0.0 or ptt <= 0.0:
                            continue
                        ex = float(r[f"{name}_x"]) - float(r["true_x"])
                        ey = float(r[f"{name}_y"]) - float(r["true_y"])
                        eth = math.remainder(float(r[f"{name}_th"]) - float(r["true_th"]),
                                             2.0 * math.pi)
                        position += (pyy * ex * ex - 2.0 * pxy * ex * ey + pxx * ey * ey) / det / 2
                        heading += eth * eth / ptt
                        count += 1
                except (KeyError, ValueError) as e:
                    raise ValueError(f"{path}:{line}: {e}") from None
    if count == 0:
        raise ValueError(f"{dirs}: no step with a positive definite pose covariance")
    return position / count, heading / count, count


def write_config(args, values, history):
    """Writes --config with slam.ekf set from `values` to --write."""
    import yaml  # python3-yaml; only this mode needs it
    with open(args.config) as f:
        config = yaml.safe_load(f) or {}
    ekf = config.setdefault("slam", {}).setdefault("ekf", {})
    for key, value in values.items():
        if isinstance(value, dict):
            ekf.setdefault(key, {}).update({k: float(f"{v:.4g}") for k, v in value.items()})
        else:
            ekf[key] = float(f"{value:.6g}")
    header = [f"# {os.path.basename(args.config)} with the process model calibrated by",
              "#   " + " ".join(sys.argv),
              f"# (docs/method.md, \"Calibrating the process noise\"): training runs of seeds "
              f"{args.seed}-{args.seed + args.runs - 1},",
              "# the fit of the true motion, then the noise's factors set against the",
              "# filters' mean pose NEES per dof (position, heading) on those runs:"]
    header += [f"#   v x{sv:.4g}, w x{sw:.4g}: position {rp:.3f}, heading {rh:.3f}"
               for sv, sw, rp, rh in history]
    # Relative paths stay relative to the written file's folder.
    base_dir = os.path.dirname(os.path.abspath(args.config))
    out_dir = os.path.dirname(os.path.abspath(args.write))
    for section, key in (("run", "world"), ("run", "robot_model")):
        path = config.get(section, {}).get(key)
        if isinstance(path, str) and not os.path.isabs(path):
            config[section][key] = os.path.relpath(os.path.join(base_dir, path), out_dir)
    with open(args.write, "w") as f:
        f.write("\n".join(header) + "\n")
        yaml.safe_dump(config, f, sort_keys=False, default_flow_style=False)


def consistency(args):
    """The whole procedure of --consistency (the module's docstring)."""
    os.makedirs(args.consistency, exist_ok=True)
    motion = os.path.join(args.consistency, "motion")
    sweep(args, motion, [])
    runs_steps, steps, c, k = read_runs([motion], args.offset)
    if args.ramp:
        apply_ramp(runs_steps, *args.ramp)
    lag = fit_lag(runs_steps)
    apply_lag(runs_steps, lag)
    command, gains = fit_command(runs_steps, 1, True, wheel_noise=args.wheel_noise)
    values = ekf_values(gains, lag, command, fit_odometry(steps), c, k, False)
    if args.ramp:
        values.update(command_ramp_mps2=args.ramp[0], command_ramp_radps2=args.ramp[1])
    if args.slip_on_the_spot:
        k0, kc = fit_slip_on_the_spot(steps, c)[:2]
        values.update(lateral_slip_std_m_per_rad=k0, lateral_slip_std_m_per_rad_per_mps=0.0,
                      lateral_slip_std_m_per_radps_change=kc)
    scale_v = scale_w = 1.0
    history = []
    for iteration in range(args.iterations):
        values["command_noise"]["v_noise_scale"] = scale_v
        values["command_noise"]["w_noise_scale"] = scale_w
        out = os.path.join(args.consistency, f"scale_{iteration}")
        sweep(args, out, set_overrides(values))
        position, heading, count = pose_nees_per_dof([out])
        history.append((scale_v, scale_w, position, heading))
        print(f"# v x{scale_v:.4g}, w x{scale_w:.4g}: mean NEES per dof position "
              f"{position:.3f}, heading {heading:.3f} ({count} filter steps)", flush=True)
        if abs(position - 1.0) <= args.tolerance and abs(heading - 1.0) <= args.tolerance:
            break
        if iteration + 1 < args.iterations:
            scale_v *= math.sqrt(position)
            scale_w *= math.sqrt(heading)
    best = min(history, key=lambda h: abs(math.log(h[2])) + abs(math.log(h[3])))
    values["command_noise"]["v_noise_scale"] = best[0]
    values["command_noise"]["w_noise_scale"] = best[1]
    write_config(args, values, history)
    print(f"# wrote {args.write}: v x{best[0]:.4g}, w x{best[1]:.4g}")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("dirs", nargs="*", help="run or sweep directories")
    parser.add_argument("--offset", type=float, default=0.2,
                        help="distance from the axle centre to R, metres (default 0.2)")
    parser.add_argument("--window", type=int, default=1,
                        help="fit the command noise to the errors summed over windows of this "
                             "many steps (default 1: each step on its own)")
    parser.add_argument("--no-gain", action="store_true",
                        help="keep the command gains at 1 (fit the noise only)")
    lag_model = parser.add_mutually_exclusive_group()
    lag_model.add_argument("--no-lag", action="store_true",
                     help="no lag of the wheels behind the command (command_lag_s 0)")
    lag_model.add_argument("--drive-lag", action="store_true",
                     help="the speed's lag with its acceleration limit and the turn rate's own "
                          "lag (command_lag_s, command_max_accel_mps2, command_lag_w_s; "
                          "departure 27), each DIR weighted alike: one DIR per way of driving")
    parser.add_argument("--no-accel-limit", action="store_true",
                        help="with --drive-lag: the speed's lag alone, no acceleration limit "
                             "(command_max_accel_mps2 0)")
    slip = parser.add_mutually_exclusive_group()
    slip.add_argument("--slip-by-regime", action="store_true",
                      help="fit the sideways slip per radian turned on the spot, its growth "
                           "with the speed and its jolt at a change of the turn rate "
                           "(fit_slip_by_regime) instead of one value per radian")
    slip.add_argument("--slip-on-the-spot", action="store_true",
                      help="fit the sideways slip per radian turned and at a change of the turn "
                           "rate on the spot only, its growth with the speed 0 "
                           "(fit_slip_on_the_spot; also with --consistency)")
    parser.add_argument("--wheel-noise", action="store_true",
                        help="also fit the command noise of wheels that vary each on its own: "
                             "the speed's growing with the turn rate and the turn rate's with "
                             "the speed (command_noise.turn_v_noise_m_per_rad, "
                             "speed_w_noise_rad_per_m; also with --consistency)")
    parser.add_argument("--turn-centre", action="store_true",
                        help="fit the point beside the axle the robot turns about on the spot "
                             "(fit_turn_centre) and take its motion out of the true steps "
                             "the slip is fitted to")
    parser.add_argument("--lag-noise", action="store_true",
                        help="also fit a command noise growing with the gap between the command "
                             "and the followed speed (command_noise.lag_noise_fraction)")
    parser.add_argument("--ramp", type=float, nargs=2, metavar=("A_V", "A_W"),
                        help="the robot ramps its set points at A_V m/s^2 and A_W rad/s^2 "
                             "(slam.ekf.command_ramp_mps2, _radps2): the followed speeds are the "
                             "ramp's means over each step, then the lag")
    parser.add_argument("--beyond", nargs="+", metavar="DIR",
                        help="runs whose command changes go beyond those of the DIRs (e.g. a "
                             "larger world, where the filters take longer and the explorer's "
                             "steps grow): print the maximum likelihood value of "
                             "command_noise.beyond_change_noise_fraction over their steps "
                             "beyond the DIRs' range, the rest held (departure 29)")
    parser.add_argument("--json", help="also write the fitted values to this JSON file")
    parser.add_argument("--consistency", metavar="WORK",
                        help="run the training sweeps in WORK and scale the noise against the "
                             "filters' NEES (the module's docstring); needs --write")
    parser.add_argument("--write", metavar="CONFIG", help="--consistency: the config written")
    parser.add_argument("--config", default="configs/default.yaml",
                        help="--consistency: the base config (default configs/default.yaml)")
    parser.add_argument("--mjslam", default="build/mjslam", help="--consistency: the binary")
    parser.add_argument("--seed", type=int, default=101,
                        help="--consistency: the training runs' first seed (default 101)")
    parser.add_argument("--runs", type=int, default=25, help="--consistency: training runs")
    parser.add_argument("--jobs", type=int, default=2, help="--consistency: runs at a time")
    parser.add_argument("--iterations", type=int, default=6,
                        help="--consistency: at most this many scaled sweeps (default 6)")
    parser.add_argument("--tolerance", type=float, default=0.1,
                        help="--consistency: stop when both means per dof are within this of 1")
    args = parser.parse_args()
    if args.ramp and not all(math.isfinite(a) and a > 0.0 for a in args.ramp):
        print(f"calibrate_noise: --ramp: expected two accelerations > 0 (got "
              f"{args.ramp[0]}, {args.ramp[1]})", file=sys.stderr)
        return 2
    if args.consistency is not None:
        if not args.write or args.dirs:
            print("calibrate_noise: --consistency needs --write CONFIG and no DIR",
                  file=sys.stderr)
            return 2
        if args.runs < 1 or args.iterations < 1 or args.tolerance <= 0.0:
            print(f"calibrate_noise: --runs, --iterations: expected >= 1, --tolerance > 0 "
                  f"(got {args.runs}, {args.iterations}, {args.tolerance})", file=sys.stderr)
            return 2
        try:
            return consistency(args)
        except (OSError, ValueError) as e:
            print(f"calibrate_noise: {e}", file=sys.stderr)
            return 2
    if not args.dirs:
        print("calibrate_noise: expected a run or sweep directory (or --consistency)",
              file=sys.stderr)
        return 2
    if args.no_accel_limit and not args.drive_lag:
        print("calibrate_noise: --no-accel-limit needs --drive-lag", file=sys.stderr)
        return 2

    try:
        runs = run_dirs(args.dirs)
        runs_steps, steps, c, k = read_runs(args.dirs, args.offset)
    except (OSError, ValueError) as e:
        print(f"calibrate_noise: {e}", file=sys.stderr)
        return 2
    if args.ramp:
        apply_ramp(runs_steps, *args.ramp)
    if args.window < 1:
        print(f"calibrate_noise: --window: expected an integer >= 1 (got {args.window})",
              file=sys.stderr)
        return 2
    drive = None  # (lag_w, max_accel) with --drive-lag
    if args.drive_lag:
        groups, start = [], 0
        for path in args.dirs:  # one group per DIR, in run_dirs' order
            count = len(run_dirs([path]))
            groups.append(runs_steps[start:start + count])
            start += count
        lag, lag_w, max_accel = fit_drive_lag(groups, limit=not args.no_accel_limit)
        drive = (lag_w, max_accel)
    else:
        lag = 0.0 if args.no_lag else fit_lag(runs_steps)
        apply_lag(runs_steps, lag)
    # The odometry against the true steps as they are (the turn centre is a
    # model of the command input only).
    odometry = fit_odometry(steps)
    turn_centre = None
    if args.turn_centre:
        try:
            turn_centre = fit_turn_centre(steps, c)
        except ValueError as e:
            print(f"calibrate_noise: {e}", file=sys.stderr)
            return 2
        take_out_turn_centre(steps, turn_centre[0])
        c, k = fit_skid(steps)
    command, gains = fit_command(runs_steps, args.window, not args.no_gain,
                                 lag_noise=args.lag_noise, wheel_noise=args.wheel_noise)
    c_v, c_w = change_range(steps)
    beyond = None  # (fraction, steps beyond, steps) with --beyond
    if args.beyond:
        try:
            beyond_runs, beyond_steps = read_runs(args.beyond, args.offset)[:2]
            if args.ramp:
                apply_ramp(beyond_runs, *args.ramp)
            if drive:
                apply_lag(beyond_runs, lag, drive[0], drive[1])
            else:
                apply_lag(beyond_runs, lag)
            beyond = (*fit_beyond_change(beyond_steps, command, gains, c_v, c_w),
                      len(beyond_steps))
        except (OSError, ValueError) as e:
            print(f"calibrate_noise: {e}", file=sys.stderr)
            return 2

    print(f"# scripts/calibrate_noise.py: {len(steps)} steps from {len(runs)} runs")
    print("slam:\n  ekf:")
    print(f"    command_gain_v: {gains[0]:.6g}   # standard error {gains[2]:.2g}")
    print(f"    command_gain_w: {gains[1]:.6g}   # standard error {gains[3]:.2g}")
    print(f"    command_lag_s: {lag:.4g}")
    if drive:
        print(f"    command_lag_w_s: {drive[0]:.4g}")
        print(f"    command_max_accel_mps2: {drive[1]:.4g}")
    if args.ramp:
        print(f"    command_ramp_mps2: {args.ramp[0]:.6g}   # --ramp, the robot's own")
        print(f"    command_ramp_radps2: {args.ramp[1]:.6g}")
    print("    command_noise:")
    for name, value in command_noise(command, args.lag_noise).items():
        print(f"      {name}: {value:.4g}")
    print(f"      calibrated_change_v_mps: {c_v:.4g}   # the largest changes fitted")
    print(f"      calibrated_change_w_radps: {c_w:.4g}")
    print("      # beyond_change_noise_fraction: set on training runs beyond the range "
          "(docs/method.md)")
    if beyond:
        print(f"# --beyond: {beyond[1]} of {beyond[2]} steps beyond the range; maximum "
              f"likelihood fraction there {beyond[0]:.4g} (the typical step, not the tail)")
    print("    odometry_noise:")
    for name, value in zip(ODOMETRY_NAMES, odometry):
        print(f"      {name}: {value:.4g}")
    print(f"    lateral_skid_s: {c:.4g}")
    slip = spot = None
    if args.slip_by_regime:
        slip = fit_slip_by_regime(steps, c, gains[0])
    elif args.slip_on_the_spot:
        try:
            spot = fit_slip_on_the_spot(steps, c)
        except ValueError as e:
            print(f"calibrate_noise: {e}", file=sys.stderr)
            return 2
        slip = (spot[0], 0.0, spot[1])
    if turn_centre:
        print(f"    turn_centre_offset_m_per_radps: {turn_centre[0]:.4g}   # along alone "
              f"{turn_centre[1]:.4g}, across alone {turn_centre[2]:.4g}")
    if slip:
        k0, k1, kc = slip
        print(f"    lateral_slip_std_m_per_rad: {k0:.4g}")
        print(f"    lateral_slip_std_m_per_rad_per_mps: {k1:.4g}")
        print(f"    lateral_slip_std_m_per_radps_change: {kc:.4g}")
    else:
        print(f"    lateral_slip_std_m_per_rad: {k:.4g}")
    if spot:
        print(f"# sideways slip fitted on the spot: mean r^2 / variance {spot[2]:.2f}; moving, "
              f"what the skid leaves sideways has rms {spot[3]:.3g} m a step, the model "
              f"{spot[4]:.3g} m")

    print(f"# command noise fitted to errors summed over {args.window} step(s)")
    print("# summed errors over windows of L steps: mean e^2 / model variance, distance and turn")
    print("# (1 where the fit holds at that time scale; growing with L: errors persist)")
    for length, rd, rth in variance_ratios(runs_steps, command, [1, 2, 5, 10, 20, 50, 100],
                                           gains[:2]):
        print(f"#   L = {length:3d}: {rd:6.2f} {rth:6.2f}")
    if not args.no_gain:
        print("# gains of each run on its own (weighted least squares, the noise above):")
        per_run = [fit_gains(run_steps, command) for run_steps in runs_steps if run_steps]
        for name, index, se in (("v", 0, 2), ("w", 1, 3)):
            values = [g[index] for g in per_run]
            mean = sum(values) / len(values)
            spread = math.sqrt(sum((x - mean) ** 2 for x in values) / max(len(values) - 1, 1))
            typical_se = math.sqrt(sum(g[se] ** 2 for g in per_run) / len(per_run))
            print(f"#   g_{name}: mean {mean:.6f}, spread between runs {spread:.2e}, "
                  f"a run's standard error {typical_se:.2e}")
    print("# fit: mean (error / sigma)^2 by bin (1 where the model fits)")

    def nv(s):
        return (command_errors(s, gains)[0] / command_sigmas(s, command)[0]) ** 2

    def nw(s):
        return (command_errors(s, gains)[1] / command_sigmas(s, command)[1]) ** 2

    for s in steps:
        s["|v|"], s["|w|"] = abs(s["v"]), abs(s["w"])
    print_bins("command v", steps, "|v|", [0, 0.05, 0.15, 0.3, 0.5, 10], nv)
    print_bins("command v", steps, "dv", [0, 1e-9, 0.05, 0.15, 0.3, 10], nv)
    print_bins("command w", steps, "|w|", [0, 0.05, 0.3, 0.8, 1.5, 10], nw)
    print_bins("command w", steps, "dw", [0, 1e-9, 0.1, 0.3, 0.8, 10], nw)
    if args.wheel_noise:  # each error against the other speed (the wheels' terms)
        print_bins("command v", steps, "|w|", [0, 0.05, 0.3, 0.8, 1.5, 10], nv)
        print_bins("command w", steps, "|v|", [0, 0.05, 0.15, 0.3, 0.5, 10], nw)
    spinning = [s for s in steps if s["on_the_spot"] and s["w"] != 0.0]
    if spinning:
        print(f"  on the spot, turning: {len(spinning)} steps, mean (e/sigma)^2 = "
              f"{sum(nv(s) for s in spinning) / len(spinning):.2f} (v), "
              f"{sum(nw(s) for s in spinning) / len(spinning):.2f} (w)")

    def nd(s):
        return (s["d_odom"] - s["d"]) ** 2 / odometry_variances(s, odometry)[0]

    def nth(s):
        return (s["dth_odom"] - s["dth"]) ** 2 / odometry_variances(s, odometry)[1]

    for s in steps:
        s["|d|"], s["|dth|"] = abs(s["d_odom"]), abs(s["dth_odom"])
    print_bins("odometry d", steps, "|d|", [0, 1e-4, 0.01, 0.03, 0.05, 10], nd)
    print_bins("odometry dth", steps, "|dth|", [0, 1e-4, 0.03, 0.08, 0.15, 10], nth)

    if args.json:
        values = {"steps": len(steps), "runs": len(runs),
                  **ekf_values(gains, lag, command, odometry, c, k, args.lag_noise)}
        if drive:
            values.update(command_lag_w_s=drive[0], command_max_accel_mps2=drive[1])
        values["command_noise"].update(calibrated_change_v_mps=c_v, calibrated_change_w_radps=c_w)
        if beyond:
            values.update(beyond_change_ml_fraction=beyond[0], beyond_steps=beyond[1])
        if args.ramp:
            values.update(command_ramp_mps2=args.ramp[0], command_ramp_radps2=args.ramp[1])
        if turn_centre:
            values["turn_centre_offset_m_per_radps"] = turn_centre[0]
            values["turn_centre_offset_along_alone"] = turn_centre[1]
            values["turn_centre_offset_across_alone"] = turn_centre[2]
        if slip:
            values.update(zip(["lateral_slip_std_m_per_rad", "lateral_slip_std_m_per_rad_per_mps",
                               "lateral_slip_std_m_per_radps_change"], slip))
        if spot:
            values.update(slip_on_the_spot_ratio=spot[2], moving_sideways_rms_m=spot[3],
                          moving_sideways_model_rms_m=spot[4])
        with open(args.json, "w") as f:
            json.dump(values, f, indent=2)
            f.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
