#!/usr/bin/python3
"""One row of scripts/envelope_table.sh: a sweep directory's pooled figures.

Usage: envelope_row.py SWEEP_DIR NAME. Reads, with python/mjslam, SWEEP_DIR/summary.json
and each run's summary.json (runs/run_*/summary.json) for the worst run's 2-sigma
fraction (the smallest of its x, y, th) and the line observations against the true walls
(their NIS pooled over the runs, weighted by the lines matched, and the largest). Debian's Python 3 with numpy (/usr/bin/python3).
"""
import os
import sys

# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "python"))
import mjslam  # noqa: E402


def main():
    sweep_dir, name = sys.argv[1], sys.argv[2]
    sweep = mjslam.read_sweep(sweep_dir)
    try:
        summary = sweep.summary
    except (OSError, ValueError) as error:
        print(f"| {name} | no summary ({error}) |")
        return
    runs = [r for r in sweep.runs if r.has(mjslam.SUMMARY_FILE)]
    cells = [name]
    for f in mjslam.FILTER_NAMES:
        filt = summary["filters"][f]
        pooled = filt.get("inside_2sigma_pooled") or {}
        worst = 1.0
        for run in runs:
            inside = run.summary["filters"][f].get("inside_2sigma") or {}
            if inside:
                worst = min(worst, min(inside[c] for c in ("x", "y", "th")))
        cells.append("%.3f / %.3f, %.2f" % (filt["fraction_inside"], filt["fraction_above"],
                                            filt["mean_anees"]))
        cells.append("%.3f / %.3f / %.3f" % (pooled.get("x", 0), pooled.get("y", 0),
                                             pooled.get("th", 0)))
        cells.append("%.3f" % worst)
    # The line observations against the true walls (mjslam evaluate's `observations`),
    # pooled over the runs: the mean NIS (2 when the extractor's covariances hold) and the
    # largest.
    observed = [run.summary.get("observations") or {} for run in runs]
    weights = [o.get("matched") or 0 for o in observed]
    nis = [(o.get("mean_nis"), w) for o, w in zip(observed, weights) if o.get("mean_nis") is not None]
    if nis and sum(w for _, w in nis) > 0:
        mean = sum(m * w for m, w in nis) / sum(w for _, w in nis)
        largest = max(o.get("max_nis") or 0.0 for o in observed)
        cells.append("%.2f, %.0f" % (mean, largest))
    else:
        cells.append("-")
    print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
