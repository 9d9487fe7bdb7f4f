#!/usr/bin/python3
"""Statistics of laser scans, simulated or real, side by side (docs/results.md, "The SICK's error structure").

For each run directory (a simulated run of `mjslam run`, or a real log turned into
one by `mjslam import LOG --out DIR`) it reads, with python/mjslam, `scans.csv` (ranges
r0..r<n-1>, docs/run_directory.md) and the beam layout from the directory's `config.yaml`
(`laser.num_beams`, `laser.fov_deg`, `laser.max_range_m`; an import writes the log's
layout there: 180 beams at 1 deg for Intel, 360 at 0.5 deg for FR079, 81.83 m), and
measures in the sensor frame, scan by scan (no poses needed):

- **Residuals about fitted lines.** Consecutive returns are cut where two neighbours
  are farther apart than BREAK (0.05 m + 20 beam steps of arc at their range, so a
  wall seen at up to 87 deg stays one piece; gaps of up to 3 no-return beams are bridged),
  the pieces are split and merged (iterative end-point fit, split at more than
  SPLIT = 0.04 m), and a total-least-squares line is fitted to every piece of at
  least 8 points and 0.3 m. Residual = signed distance of a point from its piece's
  line. Reported per range bin as a robust standard deviation (1.4826 x median
  absolute deviation), in mm.
- **Dropouts by incidence.** Within the span of each fitted line (first to last beam),
  every beam is given its incidence angle (between the beam and the line's normal);
  the no-return beams inside the span are the dropouts. Rate = dropouts / beams in
  the span, per incidence bin. Also the no-return (maximum-range) fraction of all beams.
- **Mixed pixels.** In the sensor frame. A discontinuity is a jump of more than
  JUMP = 0.3 m in range between two returning neighbours whose points do not line up
  with the surface on either side (a wall seen at a grazing angle has range jumps, but
  its points lie on one line: no discontinuity). A mixed pixel is a return i, with
  i-2..i+2 all returning, whose range lies between those of i-1 and i+1 (which differ
  by more than JUMP) with more than 0.1 m and 10 % of their difference to each, and
  whose point lies more than
  0.1 m off both the line through i-2, i-1 and the line through i+2, i+1: an isolated
  point between two depth levels, on neither surface. Rate = mixed pixels /
  (discontinuities without one + mixed pixels), and per 1000 returns. A single beam on
  a third surface (a wall's end, a door frame, a chair leg, a wall seen at a grazing
  angle by one beam) passes the same test: the simulated runs without mixed pixels
  give that floor for their world.

Thresholds are the same for every data set; the real logs' ranges are in whole
centimetres (the SICK's cm mode), so their residuals carry 1 cm / sqrt(12) = 2.9 mm of
quantisation on top of the sensor's noise.

Usage (Debian's Python 3 with numpy, PyYAML and matplotlib, /usr/bin/python3):
    scripts/scan_statistics.py [--max-scans N] [--out FIG.png] [--csv TABLE.csv] \\
        LABEL=RUN_DIR [LABEL=RUN_DIR ...]
Prints a table (one row per data set) and writes the figure (three panels: residual
std by range, dropout rate by incidence, mixed-pixel rate).
"""
import argparse
import csv
import math
import os
import sys

import numpy as np

# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "python"))
import mjslam  # noqa: E402

BREAK_M = 0.05          # base of the break distance between neighbours
BREAK_STEPS = 20.0      # ... plus this many beam steps of arc at the range
MAX_GAP_BEAMS = 3       # no-return beams bridged inside a piece
SPLIT_M = 0.04          # split-and-merge threshold
MIN_POINTS = 8
MIN_LENGTH_M = 0.3
JUMP_M = 0.3            # a discontinuity
MIXED_STEP_M = 0.1      # a mixed pixel's distance to each neighbour and to their extrapolations
MIXED_FRACTION = 0.1    # ... and at least this fraction of the jump from each
RANGE_BINS = [0.0, 1.0, 2.0, 4.0, 8.0, 16.0, 1000.0]
INCIDENCE_BINS_DEG = [0.0, 30.0, 50.0, 60.0, 70.0, 75.0, 80.0, 85.0, 90.0]


def read_layout(run):
    """num_beams, fov_deg, max_range_m of the run's laser, from its config.yaml."""
    layout = {"num_beams": 181, "fov_deg": 180.0, "max_range_m": 30.0}
    for key in layout:
        try:
            layout[key] = type(layout[key])(run.setting("laser." + key))
        except KeyError:
            raise SystemExit("%s: laser.%s missing" % (run.file(mjslam.CONFIG_FILE), key))
    return layout


def read_scans(run, max_scans):
    """The ranges of (at most max_scans, evenly spread) scans, one row each."""
    ranges = run.scans.ranges
    if max_scans and len(ranges) > max_scans:
        keep = np.linspace(0, len(ranges) - 1, max_scans).round().astype(int)
        ranges = ranges[keep]
    return ranges, len(ranges)


def split_and_merge(points, lo, hi, out):
    """Iterative end-point fit of points[lo:hi]: appends (lo, hi) pieces to out."""
    if hi - lo < 3:
        out.append((lo, hi))
        return
    a, b = points[lo], points[hi - 1]
    d = b - a
    norm = math.hypot(d[0], d[1])
    if norm < 1e-9:
        out.append((lo, hi))
        return
    seg = points[lo:hi]
    dist = np.abs(d[0] * (seg[:, 1] - a[1]) - d[1] * (seg[:, 0] - a[0])) / norm
    k = int(np.argmax(dist))
    if dist[k] > SPLIT_M and 0 < k < hi - lo - 1:
        split_and_merge(points, lo, lo + k + 1, out)
        split_and_merge(points, lo + k, hi, out)
    else:
        out.append((lo, hi))


def fit_line(seg):
    """Total least squares: centroid and unit normal of the points' line."""
    c = seg.mean(axis=0)
    _, _, vt = np.linalg.svd(seg - c, full_matrices=False)
    return c, vt[1]


def scan_statistics(ranges, layout):
    """Accumulates residuals, dropouts and mixed pixels over the scans."""
    n = layout["num_beams"]
    max_range = layout["max_range_m"]
    step = math.radians(layout["fov_deg"]) / (n - 1)
    angles = -0.5 * math.radians(layout["fov_deg"]) + step * np.arange(n)
    cos_a, sin_a = np.cos(angles), np.sin(angles)
    res_r, res_e = [], []                       # range of a point, its residual
    inc_beams, inc_drop = [], []                # incidence of span beams, whether dropped
    mixed = jumps = returns = no_returns = 0
    for r in ranges:
        r = r[:n]
        valid = (r > 0.0) & (r < max_range)
        returns += int(valid.sum())
        no_returns += int(n - valid.sum())
        # Mixed pixels and discontinuities (in the sensor frame, so that a wall
        # seen at a grazing angle, whose ranges jump but whose points line up,
        # is neither).
        px, py = r * cos_a, r * sin_a

        def off_line(k, a, b):
            """Whether point k lies farther than MIXED_STEP_M from the line a-b."""
            dx, dy = px[b] - px[a], py[b] - py[a]
            norm = math.hypot(dx, dy)
            if norm < 1e-9:
                return True
            return abs(dx * (py[k] - py[a]) - dy * (px[k] - px[a])) / norm > MIXED_STEP_M

        is_mixed = np.zeros(n, bool)
        for i in range(2, n - 2):
            if not valid[i - 2:i + 3].all():
                continue
            lo, hi = sorted((r[i - 1], r[i + 1]))
            margin = max(MIXED_STEP_M, MIXED_FRACTION * (hi - lo))
            if not (lo + margin < r[i] < hi - margin and hi - lo > JUMP_M):
                continue
            if off_line(i, i - 2, i - 1) and off_line(i, i + 2, i + 1):
                is_mixed[i] = True
        mixed += int(is_mixed.sum())
        for a in range(n - 1):
            b = a + 1
            if not (valid[a] and valid[b]) or abs(r[b] - r[a]) <= JUMP_M:
                continue
            if is_mixed[a] or is_mixed[b]:
                continue
            if a >= 1 and valid[a - 1] and not off_line(b, a - 1, a):
                continue  # b continues a's surface
            if b + 1 < n and valid[b + 1] and not off_line(a, b + 1, b):
                continue
            jumps += 1
        # Pieces of consecutive returns (small no-return gaps bridged).
        idx = np.flatnonzero(valid)
        pieces, current = [], []
        for i in idx:
            if current:
                j = current[-1]
                gap = i - j
                limit = BREAK_M + BREAK_STEPS * gap * step * max(r[i], r[j])
                px = (r[i] * cos_a[i] - r[j] * cos_a[j], r[i] * sin_a[i] - r[j] * sin_a[j])
                if gap - 1 > MAX_GAP_BEAMS or math.hypot(*px) > limit:
                    pieces.append(current)
                    current = []
            current.append(i)
        if current:
            pieces.append(current)
        for piece in pieces:
            if len(piece) < MIN_POINTS:
                continue
            beams = np.array(piece)
            pts = np.column_stack((r[beams] * cos_a[beams], r[beams] * sin_a[beams]))
            parts = []
            split_and_merge(pts, 0, len(beams), parts)
            for lo, hi in parts:
                if hi - lo < MIN_POINTS:
                    continue
                seg = pts[lo:hi]
                if math.dist(seg[0], seg[-1]) < MIN_LENGTH_M:
                    continue
                c, normal = fit_line(seg)
                res_r.append(r[beams[lo:hi]])
                res_e.append((seg - c) @ normal)
                # Every beam of the span, returned or not: its incidence on the line.
                span = np.arange(beams[lo], beams[hi - 1] + 1)
                u = np.column_stack((cos_a[span], sin_a[span]))
                inc_beams.append(np.degrees(np.arccos(np.clip(np.abs(u @ normal), 0.0, 1.0))))
                inc_drop.append(~valid[span])
    return {
        "res_r": np.concatenate(res_r) if res_r else np.zeros(0),
        "res_e": np.concatenate(res_e) if res_e else np.zeros(0),
        "inc": np.concatenate(inc_beams) if inc_beams else np.zeros(0),
        "drop": np.concatenate(inc_drop) if inc_drop else np.zeros(0, bool),
        "mixed": mixed, "jumps": jumps, "returns": returns, "no_returns": no_returns,
    }


def robust_std(x):
    return 1.4826 * float(np.median(np.abs(x - np.median(x)))) if len(x) else float("nan")


def summarise(s):
    """Per-bin numbers of one data set."""
    out = {"res_std_mm": [], "res_n": [], "drop_rate": [], "drop_n": []}
    for lo, hi in zip(RANGE_BINS[:-1], RANGE_BINS[1:]):
        sel = (s["res_r"] >= lo) & (s["res_r"] < hi)
        out["res_std_mm"].append(1000.0 * robust_std(s["res_e"][sel]) if sel.sum() >= 50
                                 else float("nan"))
        out["res_n"].append(int(sel.sum()))
    for lo, hi in zip(INCIDENCE_BINS_DEG[:-1], INCIDENCE_BINS_DEG[1:]):
        sel = (s["inc"] >= lo) & (s["inc"] < hi)
        k = int(sel.sum())
        out["drop_n"].append(k)
        out["drop_rate"].append(float(s["drop"][sel].mean()) if k >= 20 else float("nan"))
    out["res_all_mm"] = 1000.0 * robust_std(s["res_e"])
    out["no_return"] = s["no_returns"] / max(1, s["returns"] + s["no_returns"])
    edges = s["jumps"] + s["mixed"]  # clean discontinuities, and those with a mixed pixel
    out["mixed_per_jump"] = s["mixed"] / edges if edges > 0 else float("nan")
    out["mixed_per_1000"] = 1000.0 * s["mixed"] / max(1, s["returns"])
    out["mixed"], out["jumps"] = s["mixed"], edges
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("runs", nargs="+", help="LABEL=RUN_DIR")
    parser.add_argument("--max-scans", type=int, default=1000,
                        help="at most this many scans per data set, evenly spread (0: all)")
    parser.add_argument("--out", help="figure PNG")
    parser.add_argument("--csv", help="the table as CSV")
    args = parser.parse_args()
    results = []
    for spec in args.runs:
        label, _, run_dir = spec.partition("=")
        if not run_dir:
            sys.exit(f"expected LABEL=RUN_DIR, got {spec}")
        run = mjslam.read_run(run_dir)
        layout = read_layout(run)
        ranges, used = read_scans(run, args.max_scans)
        s = scan_statistics(ranges, layout)
        results.append((label, layout, used, summarise(s)))

    range_names = [f"{lo:g}-{hi:g}" if hi < 1000 else f">{lo:g}"
                   for lo, hi in zip(RANGE_BINS[:-1], RANGE_BINS[1:])]
    inc_names = [f"{lo:g}-{hi:g}" for lo, hi in zip(INCIDENCE_BINS_DEG[:-1], INCIDENCE_BINS_DEG[1:])]
    table = []
    print("data set | beams x step | scans | residual std mm (all) | by range m: "
          + " ".join(range_names) + " | no-return | dropout by incidence deg: "
          + " ".join(inc_names) + " | mixed / discontinuity | mixed per 1000 returns")
    for label, layout, used, o in results:
        step = layout["fov_deg"] / (layout["num_beams"] - 1)
        row = {"data set": label, "beams": layout["num_beams"], "step_deg": round(step, 3),
               "scans": used, "residual_std_mm": round(o["res_all_mm"], 2)}
        for name, v in zip(range_names, o["res_std_mm"]):
            row[f"res_mm_{name}"] = round(v, 2)
        row["no_return"] = round(o["no_return"], 4)
        for name, v in zip(inc_names, o["drop_rate"]):
            row[f"drop_{name}"] = round(v, 4)
        for name, k in zip(inc_names, o["drop_n"]):
            row[f"beams_{name}"] = k
        row["mixed_per_discontinuity"] = round(o["mixed_per_jump"], 4)
        row["mixed_per_1000_returns"] = round(o["mixed_per_1000"], 3)
        row["mixed"], row["discontinuities"] = o["mixed"], o["jumps"]
        table.append(row)
        print(f"{label} | {layout['num_beams']} x {step:.2f} deg | {used} | "
              f"{o['res_all_mm']:.1f} | " + " ".join(f"{v:.1f}" for v in o["res_std_mm"])
              + f" | {100 * o['no_return']:.1f} % | "
              + " ".join(f"{100 * v:.1f}" for v in o["drop_rate"])
              + f" % | {o['mixed']}/{o['jumps']} = {o['mixed_per_jump']:.3f}"
              f" | {o['mixed_per_1000']:.2f}")
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(table[0].keys()))
            writer.writeheader()
            writer.writerows(table)
    if args.out:
        plot(results, args.out)


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(12.0, 3.6))
    centres_r = [0.5 * (lo + min(hi, 30.0)) for lo, hi in zip(RANGE_BINS[:-1], RANGE_BINS[1:])]
    centres_i = [0.5 * (lo + hi) for lo, hi in zip(INCIDENCE_BINS_DEG[:-1], INCIDENCE_BINS_DEG[1:])]
    markers = ["o", "s", "^", "D", "v", "x"]
    for k, (label, _, _, o) in enumerate(results):
        axes[0].plot(centres_r, o["res_std_mm"], marker=markers[k % 6], label=label)
        axes[1].plot(centres_i, [100 * v for v in o["drop_rate"]], marker=markers[k % 6],
                     label=label)
    axes[0].set_xscale("log")
    axes[0].set_xlabel("range (m), bins " + ", ".join(f"{b:g}" for b in RANGE_BINS[1:-1]))
    axes[0].set_ylabel("residual about fitted lines,\nrobust std (mm)")
    axes[0].set_title("Residuals by range")
    axes[1].set_xlabel("incidence on the fitted line (deg)")
    axes[1].set_ylabel("no-return beams within lines (%)")
    axes[1].set_yscale("symlog", linthresh=0.1)
    axes[1].set_title("Dropouts by incidence")
    labels = [r[0] for r in results]
    x = np.arange(len(results))
    axes[2].bar(x - 0.2, [100 * r[3]["mixed_per_jump"] for r in results], 0.4,
                label="per discontinuity (%)")
    axes[2].bar(x + 0.2, [r[3]["mixed_per_1000"] for r in results], 0.4,
                label="per 1000 returns")
    axes[2].set_xticks(x)
    axes[2].set_xticklabels(labels, rotation=20, ha="right", fontsize=8)
    axes[2].set_title("Mixed pixels")
    axes[2].legend(fontsize=7)
    axes[0].legend(fontsize=7)
    for ax in axes[:2]:
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=72)


if __name__ == "__main__":
    main()
