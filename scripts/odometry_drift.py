#!/usr/bin/python3
"""Wheel odometry's drift per metre and per radian, simulated or real.

Usage: odometry_drift.py RUN_DIR [RUN_DIR ...]

For each run directory, the odometry's relative motion over windows of 1 m
driven, and of 1 rad turned, against the reference's: the true pose of a
simulated run (trajectory.csv's true_* columns) or, for an imported log, the
log's own pose estimate (reference.csv, at the scans). Windows start every
0.5 m (and 0.5 rad) of the reference's path. Prints per run directory the RMS
over windows of the translation error (m per m driven) and of the heading
error (deg per m driven and deg per rad turned), and the number of windows.
Reads the runs with python/mjslam (Debian's Python 3 with numpy, /usr/bin/python3).
"""
import math
import os
import sys

# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "python"))
import mjslam  # noqa: E402


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


def relative(a, b):
    """b in a's frame: (dx, dy, dth)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    c, s = math.cos(a[2]), math.sin(a[2])
    return (c * dx + s * dy, -s * dx + c * dy, wrap(b[2] - a[2]))


def read_pairs(run_dir):
    """(reference pose, odometry pose) pairs in time order."""
    run = mjslam.read_run(run_dir)
    truth = [tuple(p) for p in run.poses("true").tolist()]
    odometry = [tuple(p) for p in run.poses("odom").tolist()]
    if not math.isnan(truth[0][0]):
        pairs = list(zip(truth, odometry))
    elif run.reference is not None:
        # The log's poses at the scans, each with the odometry of the step at its time.
        odometry_at = dict(zip(run.trajectory["t"].tolist(), odometry))
        reference = run.reference
        poses = zip(reference["x"].tolist(), reference["y"].tolist(), reference["th"].tolist())
        pairs = [(pose, odometry_at[t]) for t, pose in zip(reference["t"].tolist(), poses)
                 if t in odometry_at]
    else:
        sys.exit(f"odometry_drift.py: {run_dir}: no true pose and no reference.csv")
    return pairs


def windows(pairs, measure, length, stride):
    """Index pairs (i, j): the reference's `measure` from i to j reaches `length`."""
    cumulative = [0.0]
    for k in range(1, len(pairs)):
        cumulative.append(cumulative[-1] + measure(pairs[k - 1][0], pairs[k][0]))
    out = []
    next_start = 0.0
    j = 0
    for i in range(len(pairs)):
        if cumulative[i] < next_start:
            continue
        while j < len(pairs) and cumulative[j] - cumulative[i] < length:
            j += 1
        if j >= len(pairs):
            break
        out.append((i, j, cumulative[j] - cumulative[i]))
        next_start = cumulative[i] + stride
    return out


def drift(pairs):
    dist = lambda a, b: math.hypot(b[0] - a[0], b[1] - a[1])
    turn = lambda a, b: abs(wrap(b[2] - a[2]))
    trans, head_m, head_rad = [], [], []
    for i, j, along in windows(pairs, dist, 1.0, 0.5):
        r = relative(pairs[i][0], pairs[j][0])
        o = relative(pairs[i][1], pairs[j][1])
        trans.append(math.hypot(r[0] - o[0], r[1] - o[1]) / along)
        head_m.append(math.degrees(abs(wrap(r[2] - o[2]))) / along)
    for i, j, turned in windows(pairs, turn, 1.0, 0.5):
        r = relative(pairs[i][0], pairs[j][0])
        o = relative(pairs[i][1], pairs[j][1])
        head_rad.append(math.degrees(abs(wrap(r[2] - o[2]))) / turned)
    rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v)) if v else float("nan")
    return rms(trans), rms(head_m), len(trans), rms(head_rad), len(head_rad)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    print("| run | translation, m per m | heading, deg per m | windows (m) | heading, deg per rad | windows (rad) |")
    print("|---|---|---|---|---|---|")
    for run_dir in sys.argv[1:]:
        t, hm, nm, hr, nr = drift(read_pairs(run_dir))
        print(f"| {run_dir} | {t:.4f} | {hm:.3f} | {nm} | {hr:.3f} | {nr} |")


if __name__ == "__main__":
    main()
