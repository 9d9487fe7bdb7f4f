#!/usr/bin/python3
"""Leave-one-log-out on the real logs: each log scored with settings chosen on the others.

Usage: real_leave_one_out.py [--data DIR] [--out DIR] [--program PATH]

For every candidate setting (the odometry noise of configs/real.yaml scaled by
0.5, 1 or 2, times the line rho floor 0.01, 0.02 or 0.04 m) every log with a
reference (the corrected logs' own pose estimate) is imported with
`mjslam import --config configs/real.yaml --set ...` and scored by
`mjslam evaluate` against its reference over 1, 10 and 100 scans. A setting's
score on a log is the geometric mean, over both filters, the three spans and
translation and rotation, of the filter's mean error over the wheel
odometry's: below 1, the filters beat the odometry. For each log the setting
with the best mean score on the other logs is chosen, and the held-out log's
table printed with it. Reads each import's summary.json with python/mjslam (Debian's Python 3
with numpy, /usr/bin/python3).
"""
import argparse
import itertools
import math
import os
import subprocess
import sys

# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "python"))
import mjslam  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LOGS = {"intel": "intel-corrected.log.gz", "fr079": "freiburg-079-corrected.log.gz"}
ODOMETRY_KEYS = ["distance_std_m", "distance_std_m_per_sqrt_m", "heading_std_rad",
                 "heading_std_rad_per_sqrt_m", "heading_std_rad_per_sqrt_rad"]
# configs/real.yaml's odometry noise, scaled by the candidates below.
REAL_ODOMETRY = [0.005, 0.06, 0.005, 0.075, 0.045]
SCALES = [0.5, 1.0, 2.0]
FLOORS = [0.01, 0.02, 0.04]
LAGS = ["1", "10", "100"]


def settings():
    for scale, floor in itertools.product(SCALES, FLOORS):
        sets = [f"slam.ekf.process_model.noise.{k}={v * scale:g}"
                for k, v in zip(ODOMETRY_KEYS, REAL_ODOMETRY)]
        sets.append(f"slam.features.line_rho_floor_std_m={floor:g}")
        yield f"odometry noise x{scale:g}, line floor {floor:g} m", sets


def score(program, log_path, sets, out_dir):
    """The lag table {lag: {name: errors}} of one import."""
    command = [program, "import", "--config", os.path.join(ROOT, "configs/real.yaml"),
               "--out", out_dir, log_path]
    for s in sets:
        command += ["--set", s]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    subprocess.run([program, "evaluate", out_dir], check=True, stdout=subprocess.DEVNULL)
    summary = mjslam.read_run(out_dir).summary
    lags = summary["real"]["vs_reference_scans_apart"]
    return {lag: lags[lag] for lag in LAGS}


def ratio_score(table):
    logs = []
    for lag in LAGS:
        odometry = table[lag]["odometry"]
        for f in ("classical", "selective"):
            for key in ("translation_mean_m", "rotation_mean_deg"):
                logs.append(math.log(table[lag][f][key] / odometry[key]))
    return math.exp(sum(logs) / len(logs))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data", "real"))
    parser.add_argument("--out", default="/tmp/mjslam_leave_one_out")
    parser.add_argument("--program", default=os.path.join(ROOT, "build", "mjslam"))
    args = parser.parse_args()
    candidates = list(settings())
    tables = {}
    for log, file_name in LOGS.items():
        path = os.path.join(args.data, file_name)
        if not os.path.exists(path):
            sys.exit(f"real_leave_one_out.py: {path}: no such file")
        for i, (name, sets) in enumerate(candidates):
            tables[(log, i)] = score(args.program, path, sets, os.path.join(args.out, f"{log}_{i}"))
            print(f"{log}: {name}: score {ratio_score(tables[(log, i)]):.3f}", file=sys.stderr)
    print("| held-out log | setting (chosen on the others) | span, scans | "
          "classical trans / rot | selective trans / rot | odometry trans / rot |")
    print("|---|---|---|---|---|---|")
    for log in LOGS:
        others = [o for o in LOGS if o != log]
        best = min(range(len(candidates)),
                   key=lambda i: sum(ratio_score(tables[(o, i)]) for o in others))
        table = tables[(log, best)]
        for lag in LAGS:
            cells = []
            for name in ("classical", "selective", "odometry"):
                e = table[lag][name]
                cells.append(f"{e['translation_mean_m']:.3f} m / {e['rotation_mean_deg']:.2f} deg")
            print(f"| {log} | {candidates[best][0]} | {lag} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
