#!/usr/bin/python3
"""Calibrates the filters' process noise from the true motion of runs: the
values of slam.ekf.command_noise.*, slam.ekf.odometry_noise.*,
slam.ekf.lateral_skid_s and slam.ekf.lateral_slip_std_m_per_rad
(docs/method.md, "Calibrating the process noise").

    scripts/calibrate_noise.py DIR [DIR ...] [--offset A] [--window L] [--json FILE]

Each DIR is a run directory (with trajectory.csv) or a sweep directory (its
runs/run_*/ are taken). For every step k of a trajectory (rows k-1 and k,
dt the time between them) the script compares what the filter's prediction
is given with what the robot did, the axle centre A metres behind R
(robot.control_point_offset_m) being moved as the model moves it (a chord of
an arc along the mid-arc heading, plus a sideways skid):

- command: the filter predicts step k with the command of row k-1 held over
  dt, its noise growing with the change from the command of row k-2. The
  errors e_v = d / dt - v and e_w = dth / dt - w of the true increment (d,
  dth) are modelled as independent zero-mean Gaussians with
      sigma_v = v_noise_std_mps + v_noise_fraction |v| + change_noise_fraction |v - v_prev|
      sigma_w = w_noise_std_radps + w_noise_fraction |w| + change_noise_fraction |w - w_prev|
  (slam/motion_model.h, CommandInput), and the five constants are fitted by
  maximum likelihood. The wheels' lag makes successive errors alike, which
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
  lateral_slip_std_m_per_rad (root of sum(r^2) / sum(dth^2)).

Prints the fitted values as the YAML of configs/default.yaml's slam.ekf
section, and for each fit the mean of (error / sigma)^2 (1 for a model that
fits) over bins of the inputs, so that a model that does not fit shows.
Python 3 standard library only.
"""
import argparse
import csv
import glob
import json
import math
import os
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
    """One dict per step of the run's trajectory.csv (from its third row)."""
    path = os.path.join(run, "trajectory.csv")
    with open(path) as f:
        rows = list(csv.DictReader(f))
    steps = []
    for line, (r0, r1, r2) in enumerate(zip(rows, rows[1:], rows[2:]), start=3):
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
        steps.append({"dt": dt, "v": v, "w": w, "dv": abs(v - v_prev), "dw": abs(w - w_prev),
                      "d": d, "dth": dth, "lateral": lateral,
                      "d_odom": d_odom, "dth_odom": dth_odom})
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
    searched over their logarithms."""
    best = nelder_mead(lambda logs: negative_log_likelihood([math.exp(l) for l in logs]),
                       [math.log(x) for x in initial])
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
    """(sigma_v, sigma_w) of CommandInput for step s, p = (v0, kv, w0, kw, kc)."""
    v0, kv, w0, kw, kc = p
    return (v0 + kv * abs(s["v"]) + kc * s["dv"], w0 + kw * abs(s["w"]) + kc * s["dw"])


def command_errors(s):
    """(e_v, e_w): the true speeds over the step less the command held."""
    return (s["d"] / s["dt"] - s["v"], s["dth"] / s["dt"] - s["w"])


def windows_of(runs_steps, window):
    """The steps cut into consecutive windows of `window` steps, per run (a
    run's last, shorter window is dropped)."""
    out = []
    for steps in runs_steps:
        for i in range(0, len(steps) - window + 1, window):
            out.append(steps[i:i + window])
    return out


def window_pairs(windows, p):
    """(error, variance) of the increments summed over each window: the true
    distance and turn less the commanded ones, against the sum of the
    per-step variances the filter adds (dt sigma)^2."""
    pairs = []
    for window in windows:
        ed = eth = vd = vth = 0.0
        for s in window:
            sv, sw = command_sigmas(s, p)
            ev, ew = command_errors(s)
            ed += ev * s["dt"]
            eth += ew * s["dt"]
            vd += (sv * s["dt"]) ** 2
            vth += (sw * s["dt"]) ** 2
        pairs.append((ed, vd))
        pairs.append((eth, vth))
    return pairs


def fit_command(runs_steps, window):
    """CommandNoiseParams by maximum likelihood of the increments' errors
    summed over windows of `window` steps (1: every step on its own)."""
    windows = windows_of(runs_steps, window)
    return fit(lambda p: gaussian_nll(window_pairs(windows, p)), [0.01, 0.05, 0.01, 0.05, 0.3])


def variance_ratios(runs_steps, p, lengths):
    """For each window length: sum of the squared summed errors over the sum
    of the model's summed variances, distance and turn (1 when the errors of
    successive steps are independent and the model fits)."""
    ratios = []
    for length in lengths:
        pairs = window_pairs(windows_of(runs_steps, length), p)
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


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("dirs", nargs="+", help="run or sweep directories")
    parser.add_argument("--offset", type=float, default=0.2,
                        help="distance from the axle centre to R, metres (default 0.2)")
    parser.add_argument("--window", type=int, default=1,
                        help="fit the command noise to the errors summed over windows of this "
                             "many steps (default 1: each step on its own)")
    parser.add_argument("--json", help="also write the fitted values to this JSON file")
    args = parser.parse_args()

    try:
        runs = run_dirs(args.dirs)
        runs_steps = [read_steps(run, args.offset) for run in runs]
        steps = [s for run_steps in runs_steps for s in run_steps]
        if len(steps) < 100:
            raise ValueError(f"only {len(steps)} steps in {len(runs)} runs: too few to fit")
        c, k = fit_skid(steps)
    except (OSError, ValueError) as e:
        print(f"calibrate_noise: {e}", file=sys.stderr)
        return 2
    if args.window < 1:
        print(f"calibrate_noise: --window: expected an integer >= 1 (got {args.window})",
              file=sys.stderr)
        return 2
    command = fit_command(runs_steps, args.window)
    odometry = fit_odometry(steps)

    print(f"# scripts/calibrate_noise.py: {len(steps)} steps from {len(runs)} runs")
    print("slam:\n  ekf:")
    names = ["v_noise_std_mps", "v_noise_fraction", "w_noise_std_radps", "w_noise_fraction",
             "change_noise_fraction"]
    print("    command_noise:")
    for name, value in zip(names, command):
        print(f"      {name}: {value:.4g}")
    odometry_names = ["distance_noise_std_m", "distance_noise_std_m_per_sqrt_m",
                      "heading_noise_std_rad", "heading_noise_std_rad_per_sqrt_m",
                      "heading_noise_std_rad_per_sqrt_rad"]
    print("    odometry_noise:")
    for name, value in zip(odometry_names, odometry):
        print(f"      {name}: {value:.4g}")
    print(f"    lateral_skid_s: {c:.4g}")
    print(f"    lateral_slip_std_m_per_rad: {k:.4g}")

    print(f"# command noise fitted to errors summed over {args.window} step(s)")
    print("# summed errors over windows of L steps: mean e^2 / model variance, distance and turn")
    print("# (1 where the fit holds at that time scale; growing with L: errors persist)")
    for length, rd, rth in variance_ratios(runs_steps, command, [1, 2, 5, 10, 20, 50, 100]):
        print(f"#   L = {length:3d}: {rd:6.2f} {rth:6.2f}")
    print("# fit: mean (error / sigma)^2 by bin (1 where the model fits)")

    def nv(s):
        return (command_errors(s)[0] / command_sigmas(s, command)[0]) ** 2

    def nw(s):
        return (command_errors(s)[1] / command_sigmas(s, command)[1]) ** 2

    for s in steps:
        s["|v|"], s["|w|"] = abs(s["v"]), abs(s["w"])
    print_bins("command v", steps, "|v|", [0, 0.05, 0.15, 0.3, 0.5, 10], nv)
    print_bins("command v", steps, "dv", [0, 1e-9, 0.05, 0.15, 0.3, 10], nv)
    print_bins("command w", steps, "|w|", [0, 0.05, 0.3, 0.8, 1.5, 10], nw)
    print_bins("command w", steps, "dw", [0, 1e-9, 0.1, 0.3, 0.8, 10], nw)

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
                  "command_noise": dict(zip(names, command)),
                  "odometry_noise": dict(zip(odometry_names, odometry)),
                  "lateral_skid_s": c, "lateral_slip_std_m_per_rad": k}
        with open(args.json, "w") as f:
            json.dump(values, f, indent=2)
            f.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
