#!/usr/bin/env python3
"""One row of scripts/envelope_table.sh: a sweep directory's pooled figures.

Usage: envelope_row.py SWEEP_DIR NAME. Reads SWEEP_DIR/summary.json and each
run's summary.json (runs/run_*/summary.json) for the worst run's 2-sigma
fraction (the smallest of its x, y, th). Python 3 standard library.
"""
import glob
import json
import sys


def main():
    sweep_dir, name = sys.argv[1], sys.argv[2]
    try:
        summary = json.load(open(sweep_dir + "/summary.json"))
    except (OSError, ValueError) as error:
        print(f"| {name} | no summary ({error}) |")
        return
    cells = [name]
    for f in ("classical", "selective"):
        filt = summary["filters"][f]
        pooled = filt.get("inside_2sigma_pooled") or {}
        worst = 1.0
        for path in glob.glob(sweep_dir + "/runs/run_*/summary.json"):
            run = json.load(open(path))["filters"][f].get("inside_2sigma") or {}
            if run:
                worst = min(worst, min(run[c] for c in ("x", "y", "th")))
        cells.append("%.3f / %.3f, %.2f" % (filt["fraction_inside"], filt["fraction_above"],
                                            filt["mean_anees"]))
        cells.append("%.3f / %.3f / %.3f" % (pooled.get("x", 0), pooled.get("y", 0),
                                             pooled.get("th", 0)))
        cells.append("%.3f" % worst)
    print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
