#!/usr/bin/python3
"""The selective filter's choice of its MAX observations, by policy, on the same records.

    /usr/bin/python3 scripts/selection_ablation.py [--out runs/selection_ablation] [--runs 25]
                                                   [--jobs 2] [--duration S] [--pose-source P]

Runs, from the repository root, with build/mjslam (build it first), one `mjslam sweep` per
model (configs/default.yaml, configs/paper.yaml) in worlds/corridor_loop.xml whose filters
(`slam.filters`) are the classical EKF and the selective one once per `selection_policy`
(criterion, first, random, least_informative, determinant): every filter of a run sees the
same records (a paired ablation). The explorer drives from `--pose-source` (odometry by default,
which no policy changes; or one policy's filter, closed loop on it, the others still paired).

Writes DIR/<model>/ (the sweeps) and DIR/ablation.md (the table, also printed):
per model and policy, the selective filter's mean ANEES, the fraction of steps with the ANEES
inside its 95 % bounds, the fractions inside 2 sigma per component, the pose RMSE and the map's
line rho / corner RMSE (means over the runs). A sweep whose summary.json exists is not rerun.

Reads the sweeps' summary.json with python/mjslam (Debian's Python 3 with numpy).
"""

import argparse
import os
import subprocess
import sys

# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "python"))
import mjslam  # noqa: E402

MODELS = ("default", "paper")
POLICIES = ("criterion", "first", "random", "least_informative", "determinant")


# The filters of each run: the classical EKF, and the selective one named by its policy.
FILTERS = ("[{name: classical, update: classical}, " +
           ", ".join("{name: %s, update: selective, selection_policy: %s}" % (p, p) for p in POLICIES) +
           "]")


def run_sweep(program, model, args, out):
    """Runs one sweep into `out` unless its summary.json exists; returns the summary."""
    sweep = mjslam.read_sweep(out)
    if not sweep.has(mjslam.SUMMARY_FILE):
        command = [program, "sweep", "--config", "configs/%s.yaml" % model, "--runs", str(args.runs),
                   "--jobs", str(args.jobs), "--out", out, "--quiet",
                   "--set", "slam.filters=" + FILTERS,
                   "--set", "control.pose_source=%s" % args.pose_source]
        if args.duration is not None:
            command += ["--duration", str(args.duration)]
        print(" ".join(command), flush=True)
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return sweep.summary


def row(model, name, filt):
    """One table row of a sweep's filter summary."""
    mean = filt["runs_mean"]
    inside = mean["inside_2sigma"]
    rmse = mean["rmse"]
    cells = [model, name, "%.2f" % filt["mean_anees"], "%.2f" % filt["fraction_inside"],
             "%.3f / %.3f / %.3f" % (inside["x"], inside["y"], inside["th"]),
             "%.2f / %.2f / %.2f" % (1e3 * rmse["x"], 1e3 * rmse["y"], 1e3 * rmse["th"]),
             "%.2f" % (1e3 * mean["map"]["line_rho_rmse_m"]),
             "%.2f" % (1e3 * mean["map"]["corner_rmse_m"]), filt["verdict"]]
    return "| " + " | ".join(cells) + " |"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="runs/selection_ablation", help="output directory")
    parser.add_argument("--runs", type=int, default=25, help="Monte Carlo runs per sweep [25]")
    parser.add_argument("--jobs", type=int, default=2, help="runs at a time [2]")
    parser.add_argument("--duration", type=float, default=None,
                        help="simulated seconds per run (default: the config's)")
    parser.add_argument("--mjslam", default="build/mjslam", help="the program [build/mjslam]")
    parser.add_argument("--pose-source", default="odometry", choices=("odometry",) + POLICIES,
                        help="what the explorer drives from [odometry]")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    lines = ["| model | filter / policy | mean ANEES | ANEES in bounds | inside 2 sigma x / y / th "
             "| pose RMSE x / y mm / th mrad | line rho RMSE mm | corner RMSE mm | verdict |",
             "|---|---|---|---|---|---|---|---|---|"]
    bounds = None
    for model in MODELS:
        summary = run_sweep(args.mjslam, model, args, os.path.join(args.out, model))
        bounds = summary["sweep"]["completed_runs"]
        lines.append(row(model, "classical", summary["filters"]["classical"]))
        for policy in POLICIES:
            lines.append(row(model, "selective / " + policy, summary["filters"][policy]))
    text = ("Selection policies, %d runs per sweep, every policy a filter of the same runs, "
            "corridor loop, explorer on %s (scripts/selection_ablation.py)\n\n"
            % (bounds, args.pose_source)) + "\n".join(lines) + "\n"
    with open(os.path.join(args.out, "ablation.md"), "w") as f:
        f.write(text)
    sys.stdout.write(text)


if __name__ == "__main__":
    main()
