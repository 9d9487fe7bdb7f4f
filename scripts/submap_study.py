#!/usr/bin/python3
"""Where does selecting features pay once the map is bounded?

Runs the campaign configs/campaigns/submap_sizes.yaml (the paper's two
update rules in one map and inside submaps of 20-160 features, in the office
and both buildings, real-time timing, driven from the true pose) unless OUT
already holds it, then prints one markdown table row per world, map and rule
and draws OUT/submap_sizes.png:

    scripts/submap_study.py --out DIR [--runs N] [--duration S]

Per cell and rule: the fraction of scans processed (real-time timing skips
the scans that arrive while the filter is busy), the cost model's processing
time per processed scan, the pooled fraction of steps with the pose inside
2 sigma per component, the fraction of the steps whose ANEES is inside its
bounds, and the final map's matched fraction of the true features and
duplicates (run means), from the campaign's summary.json files.
"""
import argparse
import csv
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RULES = ("classical", "selective")


def run_campaign(out, runs, duration):
    command = [os.environ.get("MJSLAM", os.path.join(ROOT, "build", "mjslam")), "sweep", "--campaign",
               os.path.join(ROOT, "configs", "campaigns", "submap_sizes.yaml"),
               "--config", os.path.join(ROOT, "configs", "submaps.yaml"),
               "--set", "control.pose_source=ground_truth",
               "--set", "run.duration_s=%g" % duration, "--out", out]
    if runs:
        command += ["--runs", str(runs)]
    with open(os.path.join(out, "campaign.log"), "w") as log:
        subprocess.run(command, stdout=log, stderr=subprocess.STDOUT, check=False)


def cell_rows(out):
    """(world, map, rule, figures) per cell and rule, in the campaign's order."""
    rows = []
    with open(os.path.join(out, "campaign.csv")) as f:
        cells = [row[0] for row in csv.reader(f)][1:]
    for cell in cells:
        world, condition = cell.split("__", 1)
        condition = condition.split("=", 1)[-1]
        cell_dir = os.path.join(out, "cells", cell)
        summary_path = os.path.join(cell_dir, "summary.json")
        if not os.path.exists(summary_path):
            continue
        with open(summary_path) as f:
            summary = json.load(f)
        processed = {r: 0 for r in RULES}
        skipped = {r: 0 for r in RULES}
        runs = 0
        runs_dir = os.path.join(cell_dir, "runs")
        for run in sorted(os.listdir(runs_dir)):
            path = os.path.join(runs_dir, run, "summary.json")
            if not os.path.exists(path):
                continue
            runs += 1
            with open(path) as f:
                filters = json.load(f)["filters"]
            for r in RULES:
                processed[r] += filters[r]["scans_processed"]
                skipped[r] += filters[r]["scans_skipped"]
        for r in RULES:
            s = summary["filters"][r]
            pooled = s["inside_2sigma_pooled"]
            m = s["runs_mean"]["map"]
            rows.append((world, condition, r, {
                "processed": processed[r] / max(1, processed[r] + skipped[r]),
                # processing_s is the runs' mean.
                "per_scan_s": s["processing_s"] * runs / max(1, processed[r]),
                "two_sigma": (pooled["x"], pooled["y"], pooled["th"]),
                "anees_inside": s["fraction_inside"],
                "matched": m["matched_fraction"],
                "duplicates": m["duplicates"],
            }))
    return rows


def size_of(condition):
    return None if condition == "one_map" else int(condition.rsplit("_", 1)[1])


def draw(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    worlds = list(dict.fromkeys(r[0] for r in rows))
    sizes = sorted({size_of(r[1]) for r in rows if size_of(r[1])})
    one_map_x = 2 * sizes[-1]  # drawn to the right of the largest submap
    panels = [("processed", "scans processed"), ("per_scan_s", "model time per scan, s"),
              ("two_sigma", "pose inside 2 sigma (worst component)"),
              ("matched", "true features matched")]
    figure, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    styles = {"classical": ("tab:orange", "o-"), "selective": ("tab:blue", "s--")}
    shades = [1.0, 0.65, 0.35]
    for ax, (key, label) in zip(axes.flat, panels):
        for w, world in enumerate(worlds):
            for rule in RULES:
                points = [(size_of(c) or one_map_x,
                           min(f[key]) if key == "two_sigma" else f[key])
                          for (wo, c, r, f) in rows if wo == world and r == rule]
                points.sort()
                color, style = styles[rule]
                ax.plot([p[0] for p in points], [p[1] for p in points], style, color=color,
                        alpha=shades[w % len(shades)], label="%s, %s" % (world, rule))
        ax.set_xscale("log", base=2)
        ax.set_xticks(sizes + [one_map_x])
        ax.set_xticklabels([str(s) for s in sizes] + ["one map"])
        ax.set_xlabel("submap size, features")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=7)
    figure.suptitle("The paper's two update rules in one map and inside submaps (real-time timing)")
    figure.tight_layout()
    figure.savefig(path, dpi=100)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--runs", type=int, default=0, help="runs per cell (default: the file's)")
    parser.add_argument("--duration", type=float, default=1500.0)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    if not os.path.exists(os.path.join(args.out, "campaign.csv")):
        run_campaign(args.out, args.runs, args.duration)
    rows = cell_rows(args.out)
    if not rows:
        sys.exit("%s: no cell finished (see campaign.log)" % args.out)
    print("| world | map | rule | scans processed | model s per scan | 2-sigma x / y / th "
          "| ANEES inside | matched | duplicates |")
    print("|---|---|---|---|---|---|---|---|---|")
    for world, condition, rule, f in rows:
        print("| %s | %s | %s | %.2f | %.2f | %.2f / %.2f / %.2f | %.2f | %.2f | %.1f |" % (
            world, condition.replace("_", " "), rule, f["processed"], f["per_scan_s"],
            *f["two_sigma"], f["anees_inside"], f["matched"], f["duplicates"]))
    draw(rows, os.path.join(args.out, "submap_sizes.png"))
    print("\nfigure: %s" % os.path.join(args.out, "submap_sizes.png"))


if __name__ == "__main__":
    main()
