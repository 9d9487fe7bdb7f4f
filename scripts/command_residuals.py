#!/usr/bin/python3
"""The true heading increments of a run against its commands, normalised by
the filters' command-noise model, grouped by control periods since the last
change of the turn command (docs/results.md, "The maze map loss").

    scripts/command_residuals.py RUN_DIR [W_STD W_FRACTION CHANGE_FRACTION]

The defaults are the built-in slam.ekf.process_model.noise of kind command
(w_std_radps 0.03, w_fraction 0.1, change_fraction 0.5). Reads
RUN_DIR/trajectory.csv (t, true_th, cmd_w; the command of row i is held from
t_i to t_(i+1)) with python/mjslam. Prints, per period since the change, the
steps and those beyond 3 and 4 sigma, then each step beyond 3 sigma. Debian's
Python 3 with numpy (/usr/bin/python3).
"""
import math
import os
import sys

# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "python"))
import mjslam  # noqa: E402


def main():
    if len(sys.argv) not in (2, 5):
        sys.exit(__doc__)
    w_std, w_fraction, change_fraction = (0.03, 0.1, 0.5) if len(sys.argv) == 2 else map(
        float, sys.argv[2:5])
    trajectory = mjslam.read_run(sys.argv[1]).trajectory
    rows = list(zip(*(trajectory[c].tolist() for c in ("t", "true_th", "cmd_w"))))
    groups = {}
    outliers = []
    since = 99
    for i in range(2, len(rows)):
        t, th, _ = rows[i]
        t_prev, th_prev, w = rows[i - 1]
        w_before = rows[i - 2][2]
        dt = t - t_prev
        since = 0 if w != w_before else since + 1
        dth = math.remainder(th - th_prev, 2.0 * math.pi)
        sigma = (w_std + w_fraction * abs(w) + change_fraction * abs(w - w_before)) * dt
        z = (dth - w * dt) / sigma
        g = groups.setdefault(min(since, 5), [0, 0, 0])
        g[0] += 1
        g[1] += abs(z) > 3.0
        g[2] += abs(z) > 4.0
        if abs(z) > 3.0:
            outliers.append((t, z, since, dth, w * dt))
    for since, (n, over3, over4) in sorted(groups.items()):
        label = f"{since}" if since < 5 else "5 or more"
        print(f"periods since the turn command changed: {label}: {n} steps, "
              f"{over3} beyond 3 sigma, {over4} beyond 4 sigma")
    for t, z, since, dth, commanded in outliers:
        print(f"  t = {t:.1f} s: {z:+.1f} sigma ({since} periods after a change): "
              f"turned {dth:+.4f} rad, commanded {commanded:+.4f} rad")


if __name__ == "__main__":
    main()
