#!/usr/bin/python3
"""The paper's figures, one file each, drawn from mjslam run and sweep directories.

Used by scripts/paper_experiments.py (which says which run feeds which figure); each function
takes the files as python/mjslam reads them (a trajectory Table, a Run) and a PNG path. Needs
Debian's python3-matplotlib and python3-numpy, as renders/report.py. Every title names the paper's
figure (Auat Cheein et al., Robotica 29(2), 2011) or says that the plot is not one of the paper's.
Per-step figures come from trajectory.csv (docs/run_directory.md).
"""

import math
import os
import random
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(ROOT, "python"))
sys.path.insert(1, os.path.join(ROOT, "renders"))
import mjslam  # noqa: E402
# The run pages' plotting module: its atomic PNG writer, colours (matplotlib on Agg).
from report import COLORS, FILTERS, plot_nees, save, wrap  # noqa: E402,F401
import matplotlib  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

# The first filter drawn wider, so that it shows where the two curves coincide.
WIDTHS = {"classical": 2.6, "selective": 1.2}


# ---------------------------------------------------------------------------------------------
# Per-step quantities of one filter, from trajectory.csv.

def command_timeline(traj, name, dt):
    """The filter's own command timeline: a command is issued when the previous one's period has
    run out and is held for the period of that step. Returns per step the open-loop time so far
    counted two ways: `whole` (the paper: a command held longer than one control step is open loop
    for its whole period) and `beyond` (mjslam's f_open_loop: the period beyond the first step)."""
    periods = traj[name + "_period"]
    whole, beyond = [], []
    acc_whole = acc_beyond = 0.0
    next_issue = 0
    for s, p in enumerate(periods):
        if s >= next_issue and not math.isnan(p):
            steps = max(1, int(round(p / dt)))
            if steps > 1:
                acc_whole += steps * dt
                acc_beyond += (steps - 1) * dt
            next_issue = s + steps
        whole.append(acc_whole)
        beyond.append(acc_beyond)
    return whole, beyond


def modelled_processing(traj, name, cost):
    """Per step, the cost model's processing time of the step (control.processing: model):
    base + k * updates * n^2 with n = 3 + 2 * map size on steps where the filter processed a scan,
    0 otherwise. `cost` = (model_base_s, model_s_per_update_per_n2, steps_per_scan)."""
    base, k, steps_per_scan = cost
    processed = traj.get(name + "_processed")
    out = []
    for s, (nfeat, nupd) in enumerate(zip(traj[name + "_nfeat"], traj[name + "_nupdated"])):
        done = processed is None or processed[s] == 1
        has_scan = s % steps_per_scan == 0
        if done and has_scan:
            n = 3.0 + 2.0 * nfeat
            out.append(base + k * nupd * n * n)
        else:
            out.append(0.0)
    return out


def accumulate(values):
    total, out = 0.0, []
    for v in values:
        total += 0.0 if math.isnan(v) else v
        out.append(total)
    return out


# ---------------------------------------------------------------------------------------------
# Fig. 3: pose errors and their 2-sigma bounds.

def processed_steps(traj, name):
    """Indices of the steps where the filter processed its record: every step with
    slam.timing every_scan. On a skipped step (realtime) the filter's columns hold its last
    processed estimate, of an earlier pose: its difference from the current true pose is the
    robot's motion since then, not the filter's error."""
    processed = traj.get(name + "_processed")
    return [s for s in range(len(traj["t"])) if processed is None or processed[s] == 1]


def fig3_pose_errors(traj, path, label):
    """Fig. 3: x, y and heading error of each filter with its +-2 sigma bound on the steps where
    it processed its record (processed_steps), one column per filter, each panel on its own
    scale."""
    fig, axes = plt.subplots(3, 2, figsize=(11, 8), sharex=True)
    components = (("x", "pxx", "x error (m)"), ("y", "pyy", "y error (m)"),
                  ("th", "pthth", "heading error (rad)"))
    skipped = False
    for col, f in enumerate(FILTERS):
        steps = processed_steps(traj, f)
        skipped |= len(steps) < len(traj["t"])
        t = [traj["t"][s] for s in steps]
        for row, (c, var, ylabel) in enumerate(components):
            ax = axes[row][col]
            err = [traj["%s_%s" % (f, c)][s] - traj["true_" + c][s] for s in steps]
            if c == "th":
                err = [wrap(e) for e in err]
            bound = [2.0 * math.sqrt(max(traj["%s_%s" % (f, var)][s], 0.0)) for s in steps]
            ax.plot(t, err, color=COLORS[f], lw=1.0, label="error")
            ax.plot(t, bound, color="0.25", lw=0.8, ls="--", label="±2σ")
            ax.plot(t, [-b for b in bound], color="0.25", lw=0.8, ls="--")
            ax.axhline(0.0, color="0.6", lw=0.5)
            ax.grid(True, alpha=0.3)
            if col == 0:
                ax.set_ylabel(ylabel)
            if row == 0:
                ax.set_title(f)
                ax.legend(loc="upper left", fontsize=8)
        axes[-1][col].set_xlabel("time (s)")
    fig.suptitle("Fig. 3 of the paper: pose errors and ±2σ bounds, %s%s" % (
        label, "\nthe steps where each filter processed its record (slam.timing realtime)"
        if skipped else ""))
    fig.tight_layout()
    save(fig, path)


# ---------------------------------------------------------------------------------------------
# Fig. 4(c), 4(d): accumulated processing time and open-loop time.

def fig4c_processing(traj, path, label, cost):
    """Fig. 4(c): accumulated processing time of each filter, from the cost model."""
    t = traj["t"]
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for f in FILTERS:
        ax.plot(t, accumulate(modelled_processing(traj, f, cost)), color=COLORS[f], lw=WIDTHS[f],
                label=f)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("accumulated processing time (s)")
    ax.set_title("Fig. 4(c) of the paper: accumulated processing time, %s\n"
                 "modelled (control.processing: model, b = %g s, k = %g s)" % (label, cost[0], cost[1]))
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left")
    fig.tight_layout()
    save(fig, path)


def fig4d_open_loop(traj, path, label, dt):
    """Fig. 4(d): accumulated open-loop time of each filter's command timeline, counted as the
    paper does (whole period) and as mjslam's f_open_loop (period - one step)."""
    t = traj["t"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for f in FILTERS:
        whole, beyond = command_timeline(traj, f, dt)
        axes[0].plot(t, whole, color=COLORS[f], lw=WIDTHS[f], label=f)
        axes[1].plot(t, beyond, color=COLORS[f], lw=WIDTHS[f], label=f)
    axes[0].set_title("whole period of every held command (the paper's count)")
    axes[1].set_title("period beyond one control step (f_open_loop)")
    for ax in axes:
        ax.set_xlabel("time (s)")
        ax.set_ylabel("accumulated open-loop time (s)")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left")
    fig.suptitle("Fig. 4(d) of the paper: accumulated open-loop time, %s" % label)
    fig.tight_layout()
    save(fig, path)


# ---------------------------------------------------------------------------------------------
# Fig. 5: the Monte Carlo points on the map.

def map_segments(m):
    """Lines (as segments, [[ax, ay], [bx, by]]) and corners ([x, y]) of a map (mjslam.Map)."""
    return m.segments.tolist(), m.corners.tolist()


def fig5_points(run, path, label, num_points, margin_m, seed):
    """Fig. 5: #E points drawn uniformly in the box of the three maps (grown by the margin) over
    the maps of `run` (mjslam.Run). An illustration: Python's generator with `seed`, not the
    study's draws."""
    maps = {"truth": map_segments(mjslam.read_map(run.file(mjslam.GROUND_TRUTH_MAP_FILE))),
            "classical": map_segments(run.maps["classical"]),
            "selective": map_segments(run.maps["selective"])}
    xs = [p[0] for lines, corners in maps.values() for seg in lines for p in seg] + \
         [c[0] for _, corners in maps.values() for c in corners]
    ys = [p[1] for lines, corners in maps.values() for seg in lines for p in seg] + \
         [c[1] for _, corners in maps.values() for c in corners]
    x0, x1 = min(xs) - margin_m, max(xs) + margin_m
    y0, y1 = min(ys) - margin_m, max(ys) + margin_m
    rng = random.Random(seed)
    points = [(x0 + (x1 - x0) * rng.random(), y0 + (y1 - y0) * rng.random())
              for _ in range(num_points)]
    fig, ax = plt.subplots(figsize=(10, 10 * (y1 - y0) / (x1 - x0) + 1.2))
    ax.scatter([p[0] for p in points], [p[1] for p in points], s=1.5, color="0.55", lw=0,
               label="%d points" % num_points)
    widths = {"truth": 3.0, "classical": 1.6, "selective": 0.8}
    for name in ("truth", "classical", "selective"):
        lines, corners = maps[name]
        for k, (a, b) in enumerate(lines):
            ax.plot([a[0], b[0]], [a[1], b[1]], color=COLORS[name], lw=widths[name],
                    label=("%s map" % name) if k == 0 else None)
        ax.scatter([c[0] for c in corners], [c[1] for c in corners], s=12, color=COLORS[name],
                   marker="s" if name == "truth" else "o", lw=0)
    ax.plot([x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0], color="0.3", lw=0.8, ls=":",
            label="box (maps + %.1f m)" % margin_m)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
    ax.set_title("Fig. 5 of the paper: #E = %d Monte Carlo points on the maps, %s" % (num_points, label))
    fig.tight_layout()
    save(fig, path)


# ---------------------------------------------------------------------------------------------
# Figs. 6, 7: divergences against #E.

def read_divergence(path):
    """{pair: [(num_points, mean, variance), ...]} of a divergence.csv, sorted by #E."""
    return mjslam.divergence_by_pair(mjslam.read_divergence(path))


PAIR_LABELS = {"classical_selective": "D(classical ‖ selective)",
               "selective_classical": "D(selective ‖ classical)",
               "classical_truth": "D(classical ‖ truth)",
               "selective_truth": "D(selective ‖ truth)"}
PAIR_COLORS = {"classical_selective": COLORS["classical"], "selective_classical": COLORS["selective"],
               "classical_truth": COLORS["classical"], "selective_truth": COLORS["selective"]}


def divergence_figure(studies, pairs, path, title):
    """Mean and variance against #E of `pairs`, one line style per study. `studies`: list of
    (label, table of read_divergence)."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.6))
    styles = ("-", "--", ":", "-.")
    for (label, table), ls in zip(studies, styles):
        for pair in pairs:
            rows = table.get(pair, [])
            for ax, col in zip(axes, (1, 2)):
                ax.plot([r[0] for r in rows], [r[col] for r in rows], color=PAIR_COLORS[pair],
                        ls=ls, marker="o", ms=3, lw=1.3,
                        label="%s, %s" % (PAIR_LABELS[pair], label))
    for ax, name in zip(axes, ("mean (nats)", "variance over the realisations (nats²)")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("#E (Monte Carlo points)")
        ax.set_ylabel(name)
        ax.grid(True, alpha=0.3, which="both")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=8, loc="lower center", ncol=2)  # below, hiding no curve
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.14, 1, 1))
    save(fig, path)


# ---------------------------------------------------------------------------------------------
# Figs. 4(c)-(d) at scale: period, processing, skipped scans and open loop against map size.

def until_last_motion(traj):
    """The trajectory up to the last step with a non-zero command: a tour that has ended leaves
    the robot standing until the time limit, with nothing changing but the clock."""
    last = max((s for s, (v, w) in enumerate(zip(traj["cmd_v"], traj["cmd_w"]))
                if v != 0.0 or w != 0.0), default=len(traj["t"]) - 1)
    return traj.select(slice(0, last + 2))


def scale_series(traj, name, cost, dt):
    """Per step of one filter: map size, its command period on processed steps, accumulated
    modelled processing, scans skipped so far, open-loop time so far (whole periods)."""
    processed = traj.get(name + "_processed", [1.0] * len(traj["t"]))
    steps_per_scan = cost[2]
    skipped, acc = [], 0
    for s, p in enumerate(processed):
        if s % steps_per_scan == 0 and p != 1:
            acc += 1
        skipped.append(acc)
    whole, _ = command_timeline(traj, name, dt)
    return {"nfeat": traj[name + "_nfeat"], "period": traj[name + "_period"],
            "processed": processed,
            "processing": accumulate(modelled_processing(traj, name, cost)),
            "skipped": skipped, "open_loop": whole}


def fig4cd_scale(runs, path, cost, dt):
    """Figs. 4(c)-(d) at scale: for each (label, trajectory) of `runs`, each filter's command period
    against its map size (processed steps), and against time its map size, command period,
    accumulated processing time (modelled), skipped scans and open-loop time (whole periods)."""
    fig, axes = plt.subplots(2, 3, figsize=(16, 9))
    styles = ("-", "--", ":", "-.")
    markers = ("o", "x", "+", "^")
    for (label, traj), ls, marker in zip(runs, styles, markers):
        t = traj["t"]
        for f in FILTERS:
            s = scale_series(traj, f, cost, dt)
            name = "%s, %s" % (f, label)
            pts = [(n, p, tt) for n, p, d, tt in zip(s["nfeat"], s["period"], s["processed"], t)
                   if d == 1]
            axes[0][0].scatter([p[0] for p in pts], [p[1] for p in pts], color=COLORS[f], s=6,
                               marker=marker, lw=0.6, alpha=0.6, label=name)
            axes[0][1].plot(t, s["nfeat"], color=COLORS[f], ls=ls, lw=WIDTHS[f], label=name)
            axes[0][2].plot([p[2] for p in pts], [p[1] for p in pts], color=COLORS[f], ls=ls,
                            lw=WIDTHS[f] * 0.5, label=name)
            axes[1][0].plot(t, s["processing"], color=COLORS[f], ls=ls, lw=WIDTHS[f], label=name)
            axes[1][1].plot(t, s["skipped"], color=COLORS[f], ls=ls, lw=WIDTHS[f], label=name)
            axes[1][2].plot(t, s["open_loop"], color=COLORS[f], ls=ls, lw=WIDTHS[f], label=name)
    for ax in (axes[0][0], axes[0][2]):
        ax.axhline(0.7, color="0.4", lw=0.8, ls=":")
        ax.axhline(0.2, color="0.4", lw=0.8, ls=":")
        ax.set_yscale("log")
        ax.set_yticks([0.1, 0.2, 0.5, 0.7, 1, 2, 5, 10])
        ax.get_yaxis().set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    titles = ("command period (s) against the filter's map size\n(processed steps; dotted: the "
              "paper's 0.2 and 0.7 s)", "map size (features)",
              "command period (s), processed steps", "accumulated processing time (s), modelled",
              "scans skipped so far", "accumulated open-loop time (s), whole periods")
    for ax, title in zip([a for row in axes for a in row], titles):
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("time (s)")
        ax.grid(True, alpha=0.3, which="both")
    axes[0][0].set_xlabel("the filter's map size (features)")
    axes[0][0].legend(fontsize=7, loc="upper left", markerscale=2)
    axes[0][1].legend(fontsize=7, loc="lower right")
    fig.suptitle("Figs. 4(c)-(d) of the paper at scale: slam.timing realtime, periods and processing "
                 "from the cost model (b = %g s, k = %g s per update per n²)" % (cost[0], cost[1]))
    fig.tight_layout()
    save(fig, path)
