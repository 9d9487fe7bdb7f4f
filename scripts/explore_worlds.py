#!/usr/bin/python3
"""Explores every shipped world with the default config, 5 seeds each, and
prints the table of issue 4 (docs/results.md, "Exploring the shipped worlds").

    scripts/explore_worlds.py [--out DIR] [--runs N] [--jobs J] [--worlds W ...]
                              [--set KEY=VALUE ...] [--per-run]
                              [--duration S] [--min-explored F]

A world is a shipped world's name (worlds/NAME.xml) or the path of an MJCF
file (e.g. a building made by sim/tools/generate_building.py); --duration
sets the simulated time limit of every run (large buildings need more than
the config's 300 s).

Runs `build/mjslam sweep` once per world (seeds run.seed + 0 .. N-1, into
DIR/<world>/runs/; each --set is passed on to the sweep), then reads each
run's summary.json and trajectory.csv with python/mjslam (Debian's Python 3
with numpy). A world passes when no run has a
collision, every run has seen at least --min-explored (default 0.95) of the
reachable free area, and
both filters keep the pose error inside 2 sigma for at least 90 % of the steps
per component, the steps of its runs pooled (each run's fractions are its
summary.json's inside_2sigma, of mjslam evaluate). Exit status 0 when every world
passes, 1 otherwise.

With --per-run, a second table gives every run: its fraction of steps inside
2 sigma and the rms of error / sigma (1 for a consistent filter), per filter
and component, over the steps with a nonzero sigma. Errors as mjslam evaluate
takes them (mjslam.Run.errors): with slam.timing realtime, a step the filter
skipped compares its held estimate with the truth of its last processed step.

The column "5-seed groups" applies the 2-sigma target to each group of 5
consecutive seeds (seeds 1-5, 6-10, ...) on its own and says how many
groups meet it: with --runs 40 it shows how often 5 seeds are enough.
"""
import argparse
import math
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(ROOT, "python"))
import mjslam  # noqa: E402

WORLDS = ["room", "corridor_loop", "office", "pillars"]
FILTERS = list(mjslam.FILTER_NAMES)


def world_file(world):
    """The MJCF file of a world given by name or path."""
    if world.endswith(".xml"):
        return os.path.abspath(world)
    return os.path.join(ROOT, "worlds", world + ".xml")


def world_label(world):
    return os.path.splitext(os.path.basename(world))[0]


def sweep(world, out, runs, jobs, overrides, duration):
    command = [os.path.join(ROOT, "build", "mjslam"), "sweep",
               "--config", os.path.join(ROOT, "configs", "default.yaml"),
               "--runs", str(runs), "--jobs", str(jobs), "--out", out, "--quiet",
               "--divergence-points", "0",
               "--set", "run.world=" + world_file(world)]
    if duration is not None:
        command += ["--duration", str(duration)]
    for override in overrides:
        command += ["--set", override]
    subprocess.run(command, check=True, stdout=sys.stderr)


def inside_counts(run):
    """Steps, steps inside 2 sigma per filter and component (summary.json's
    inside_2sigma, the fraction of mjslam evaluate), and the
    [sum of (error / sigma)^2, count] per filter and component, of a run."""
    steps = len(run.trajectory)
    counts = {f: [round(run.summary["filters"][f]["inside_2sigma"][c] * steps)
                  for c in ("x", "y", "th")] for f in FILTERS}
    squares = {f: [[0.0, 0] for _ in range(3)] for f in FILTERS}
    for name in FILTERS:
        for error, variance in zip(run.errors(name).tolist(), run.variances(name).tolist()):
            for k in range(3):
                if variance[k] > 0.0:
                    squares[name][k][0] += error[k] * error[k] / variance[k]
                    squares[name][k][1] += 1
    return steps, counts, squares


def pooled_inside(runs):
    """Fractions of the steps inside 2 sigma per filter and component, the
    steps of `runs` [(steps, counts), ...] pooled."""
    steps = sum(r[0] for r in runs)
    return {f: [sum(r[1][f][k] for r in runs) / steps for k in range(3)] for f in FILTERS}


def inside_ok(inside):
    return all(v >= 0.90 for f in FILTERS for v in inside[f])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=os.path.join(ROOT, "runs", "explore_worlds"))
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--worlds", nargs="+", default=WORLDS)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="config override passed to every run")
    parser.add_argument("--per-run", action="store_true",
                        help="also print a table of every run")
    parser.add_argument("--duration", type=float, default=None,
                        help="simulated seconds of each run (default: the config's)")
    parser.add_argument("--min-explored", type=float, default=0.95,
                        help="fraction of the reachable area every run must see (default 0.95)")
    args = parser.parse_args()

    header = ("| world | runs | collisions | explored (min) | explored (mean) | end | time (mean) "
              "| classical x, y, th inside 2 sigma | selective x, y, th inside 2 sigma "
              "| 5-seed groups | pass |")
    lines = [header, "|" + "---|" * 11]
    per_run = ["| world | seed | steps | classical x, y, th inside 2 sigma "
               "| selective x, y, th inside 2 sigma | classical x, y, th rms error / sigma "
               "| selective x, y, th rms error / sigma |", "|" + "---|" * 7]
    all_pass = True
    for world in args.worlds:
        label = world_label(world)
        out = os.path.join(args.out, label)
        sweep(world, out, args.runs, args.jobs, args.set, args.duration)
        summaries = []
        runs = []  # (steps, counts) per run, in seed order
        for run in mjslam.read_sweep(out).runs:
            if run.has(mjslam.SUMMARY_FILE):
                summaries.append(run.summary)
                runs.append(inside_counts(run))
                steps, counts, squares = runs[-1]
                seed = run.manifest["seed"]
                cells = [f"`{label}`", str(seed), str(steps)]
                cells += [", ".join(f"{c / steps:.2f}" for c in counts[f]) for f in FILTERS]
                cells += [", ".join(f"{math.sqrt(q / max(n, 1)):.2f}" for q, n in squares[f])
                          for f in FILTERS]
                per_run.append("| " + " | ".join(cells) + " |")
        collisions = sum(s["run"]["collisions"] for s in summaries)
        explored = min(s["run"]["explored_fraction"] for s in summaries)
        explored_mean = sum(s["run"]["explored_fraction"] for s in summaries) / len(summaries)
        ends = sorted({s["run"]["termination_reason"] for s in summaries})
        duration = sum(s["run"]["duration_s"] for s in summaries) / len(summaries)
        inside = pooled_inside(runs)
        groups = [runs[g:g + 5] for g in range(0, len(runs) - 4, 5)]
        groups_ok = sum(1 for group in groups if inside_ok(pooled_inside(group)))
        ends = ", ".join(f"{e} {sum(1 for s in summaries if s['run']['termination_reason'] == e)}"
                         for e in ends)
        ok = (len(summaries) == args.runs and collisions == 0 and explored >= args.min_explored and
              inside_ok(inside))
        all_pass = all_pass and ok
        cells = [f"`{label}`", str(len(summaries)), str(collisions), f"{100 * explored:.1f} %",
                 f"{100 * explored_mean:.1f} %", ends, f"{duration:.0f} s"]
        cells += [", ".join(f"{v:.2f}" for v in inside[f]) for f in FILTERS]
        cells.append(f"{groups_ok} of {len(groups)}")
        cells.append("yes" if ok else "**no**")
        lines.append("| " + " | ".join(cells) + " |")
        print(lines[-1], file=sys.stderr)
    print("\n".join(lines))
    if args.per_run:
        print()
        print("\n".join(per_run))
    return 0 if all_pass else 1


if __name__ == "__main__":
    sys.exit(main())
