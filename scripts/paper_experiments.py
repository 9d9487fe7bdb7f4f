#!/usr/bin/python3
"""Reproduces the paper's evaluation on the shipped worlds and prints a claim-by-claim table.

    /usr/bin/python3 scripts/paper_experiments.py [--out runs/paper] [--runs 25] [--jobs 2]
                                                  [--duration S]

Runs, from the repository root, with build/mjslam (build it first):

1. Consistency (paper Fig. 3): `mjslam sweep` of the default config (frontier explorer driven
   by the selective filter) in worlds/corridor_loop.xml, N runs -> DIR/consistency.
2. Cost and open loop (Figs. 4c, 4d): the same runs' accumulated processing time, open-loop
   time and largest command period, plus one longer run in worlds/office.xml -> DIR/office.
3. Map divergence (Figs. 6, 7): `mjslam divergence` of the office run -> DIR/divergence.csv,
   copied to DIR/consistency/divergence.csv; `mjslam render DIR/consistency` then draws
   plot_nees.png (Fig. 3 as average NEES) and plot_divergence.png (the office study).
4. DIR/claims.md: the table "claim | paper | mjslam | reproduced?", also printed.

Python 3 standard library only. Nothing is tuned: the runs use configs/default.yaml as shipped.
"""

import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FILTERS = ("classical", "selective")
PAIRS = ("classical_selective", "selective_classical", "classical_truth", "selective_truth")
DEFAULT_POINTS = (100, 200, 500, 1000, 2000, 5000, 10000, 20000)


def log(message):
    print(message, file=sys.stderr, flush=True)


def run_command(command, log_path=None):
    """Runs a command from the repository root; raises on failure. Returns seconds taken."""
    log("$ " + " ".join(command))
    start = time.monotonic()
    if log_path:
        with open(log_path, "w") as out:
            result = subprocess.run(command, cwd=ROOT, stdout=out, stderr=subprocess.STDOUT)
    else:
        result = subprocess.run(command, cwd=ROOT)
    if result.returncode != 0:
        raise SystemExit("failed (exit %d): %s%s" % (result.returncode, " ".join(command),
                                                     (" (see %s)" % log_path) if log_path else ""))
    return time.monotonic() - start


def read_json(path):
    with open(path) as f:
        return json.load(f)


def mean(values):
    values = [v for v in values if v is not None and not (isinstance(v, float) and math.isnan(v))]
    return sum(values) / len(values) if values else float("nan")


def trajectory_stats(run_dir):
    """Per filter: largest command period, measured processing (sum of f_us) in the first and
    second half of the steps, number of steps."""
    stats = {f: {"max_period_s": float("nan"), "us_first": 0.0, "us_second": 0.0} for f in FILTERS}
    with open(os.path.join(run_dir, "trajectory.csv")) as f:
        rows = list(csv.DictReader(f))
    half = len(rows) // 2
    for name in FILTERS:
        periods = [float(r[name + "_period"]) for r in rows if r.get(name + "_period", "") != ""]
        stats[name]["max_period_s"] = max(periods) if periods else float("nan")
        us = [float(r[name + "_us"]) for r in rows]
        stats[name]["us_first"] = sum(us[:half]) * 1e-6
        stats[name]["us_second"] = sum(us[half:]) * 1e-6
    stats["steps"] = len(rows)
    stats["duration_s"] = float(rows[-1]["t"]) if rows else 0.0
    return stats


def run_metrics(run_dir):
    """What one run directory says about cost, open loop and 2 sigma."""
    summary = read_json(os.path.join(run_dir, "summary.json"))
    traj = trajectory_stats(run_dir)
    out = {"duration_s": summary.get("run", {}).get("duration_s", traj["duration_s"]),
           "termination": summary.get("run", {}).get("termination_reason"),
           "explored": summary.get("run", {}).get("explored_fraction")}
    for f in FILTERS:
        s = summary["filters"][f]
        out[f] = {"processing_s": s.get("processing_s"),
                  "open_loop_s": s.get("open_loop_s"),
                  "max_period_s": traj[f]["max_period_s"],
                  "measured_first_s": traj[f]["us_first"],
                  "measured_second_s": traj[f]["us_second"],
                  "inside_2sigma": s.get("inside_2sigma", {}),
                  "num_features": s.get("num_features"),
                  "mean_nees": s.get("mean_nees")}
    out["divergence"] = summary.get("divergence")
    return out


def read_divergence_csv(path):
    """{num_points: {pair: (mean, variance)}}"""
    table = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            table.setdefault(int(r["num_points"]), {})[r["pair"]] = (float(r["mean"]),
                                                                      float(r["variance"]))
    return table


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    if x != 0 and (abs(x) >= 1e4 or abs(x) < 1e-3):
        return "%.2e" % x
    return ("%%.%dg" % digits) % x


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="runs/paper", help="output directory [runs/paper]")
    parser.add_argument("--runs", type=int, default=25, help="Monte Carlo runs [25]")
    parser.add_argument("--jobs", type=int, default=2, help="runs at a time [2]")
    parser.add_argument("--duration", type=float, default=None,
                        help="time limit of each consistency run, s [run.duration_s of the config]")
    parser.add_argument("--office-duration", type=float, default=600.0,
                        help="time limit of the office run, s [600]")
    parser.add_argument("--points", type=int, nargs="+", default=list(DEFAULT_POINTS),
                        help="#E list of the divergence study [%s]" %
                        " ".join(str(p) for p in DEFAULT_POINTS))
    parser.add_argument("--realisations", type=int, default=100,
                        help="realisations per #E of the divergence study [100]")
    parser.add_argument("--mjslam", default="build/mjslam", help="the program [build/mjslam]")
    args = parser.parse_args()

    mjslam = os.path.join(ROOT, args.mjslam) if not os.path.isabs(args.mjslam) else args.mjslam
    if not os.access(mjslam, os.X_OK):
        raise SystemExit("%s not found: build it first (cmake --build build -j2)" % mjslam)
    out = args.out if os.path.isabs(args.out) else os.path.join(ROOT, args.out)
    os.makedirs(out, exist_ok=True)
    timings = {}
    start_all = time.monotonic()

    # 1. Consistency sweep (also gives cost and open loop per run, and each run's divergence).
    sweep_dir = os.path.join(out, "consistency")
    command = [mjslam, "sweep", "--config", "configs/default.yaml", "--runs", str(args.runs),
               "--jobs", str(args.jobs), "--out", sweep_dir,
               "--set", "run.world=worlds/corridor_loop.xml", "--set", "render.enabled=false",
               "--divergence-points", "20000", "--quiet"]
    if args.duration is not None:
        command += ["--duration", str(args.duration)]
    timings["sweep"] = run_command(command)

    # 2. One longer run in the bigger office map.
    office_dir = os.path.join(out, "office")
    command = [mjslam, "run", "--config", "configs/default.yaml", "--world", "worlds/office.xml",
               "--seed", "1", "--duration", str(args.office_duration), "--out", office_dir,
               "--set", "render.enabled=false", "--no-render", "--quiet"]
    timings["office"] = run_command(command, os.path.join(out, "office.log"))

    # 3. Divergence study on the office run.
    divergence_csv = os.path.join(out, "divergence.csv")
    command = [mjslam, "divergence", office_dir, "--points"] + [str(p) for p in args.points] + \
              ["--realisations", str(args.realisations), "--out", divergence_csv]
    timings["divergence"] = run_command(command, os.path.join(out, "divergence.log"))
    timings["total"] = time.monotonic() - start_all

    # The sweep's plots (Fig. 3's average NEES, Figs. 6-7 from the office study copied into the
    # sweep directory, where `mjslam render` looks for divergence.csv). Not fatal.
    shutil.copyfile(divergence_csv, os.path.join(sweep_dir, "divergence.csv"))
    try:
        run_command([mjslam, "render", sweep_dir, "--quiet"], os.path.join(out, "render.log"))
    except SystemExit as error:
        log("render failed, continuing: %s" % error)

    # Gather.
    sweep = read_json(os.path.join(sweep_dir, "summary.json"))
    runs_root = os.path.join(sweep_dir, "runs")
    run_dirs = sorted(os.path.join(runs_root, d) for d in os.listdir(runs_root)
                      if os.path.isdir(os.path.join(runs_root, d)))
    runs = [run_metrics(d) for d in run_dirs]
    office = run_metrics(office_dir)
    div = read_divergence_csv(divergence_csv)
    largest = max(div)
    n_runs = sweep["sweep"]["completed_runs"]

    results = {"timings_s": timings, "runs": len(runs), "filters": {}, "office": office,
               "divergence_study": {str(k): v for k, v in div.items()}}
    cons = {}
    for f in FILTERS:
        s = sweep["filters"][f]
        inside = {c: mean([r[f]["inside_2sigma"].get(c) for r in runs]) for c in ("x", "y", "th")}
        cons[f] = {
            "fraction_inside": s["fraction_inside"], "mean_anees": s["mean_anees"],
            "verdict": s["verdict"], "inside_2sigma": inside,
            "processing_s": mean([r[f]["processing_s"] for r in runs]),
            "open_loop_s": mean([r[f]["open_loop_s"] for r in runs]),
            "max_period_s": max(r[f]["max_period_s"] for r in runs),
            "measured_s": mean([r[f]["measured_first_s"] + r[f]["measured_second_s"] for r in runs]),
            "measured_growth": mean([r[f]["measured_second_s"] / r[f]["measured_first_s"]
                                     for r in runs if r[f]["measured_first_s"] > 0]),
            "divergence_truth": mean([(r["divergence"] or {}).get(f + "_truth") for r in runs]),
            "num_features": mean([r[f]["num_features"] for r in runs]),
        }
        results["filters"][f] = cons[f]
    mean_duration = mean([r["duration_s"] for r in runs])
    bounds = "[%s, %s]" % tuple(fmt(b, 4) for b in chi2_bounds(sweep_dir))

    # Per-filter numbers (printed before the claims).
    lines = []
    lines.append("Consistency and cost: %d runs in worlds/corridor_loop.xml (mean length %.0f s), "
                 "office: 1 run of %.0f s (%s)." % (n_runs, mean_duration, office["duration_s"],
                                                    office["termination"]))
    lines.append("")
    lines.append("| filter | steps with ANEES in %s | mean ANEES | verdict | inside 2 sigma x / y / th "
                 "| processing s (model) | measured s | open loop s | max period s "
                 "| office: processing / open loop / max period |" % bounds)
    lines.append("|---|---|---|---|---|---|---|---|---|---|")
    for f in FILTERS:
        c = cons[f]
        o = office[f]
        lines.append("| %s | %s | %s | %s | %s / %s / %s | %s | %s | %s | %s | %s / %s / %s |" % (
            f, fmt(c["fraction_inside"]), fmt(c["mean_anees"]), c["verdict"],
            fmt(c["inside_2sigma"]["x"]), fmt(c["inside_2sigma"]["y"]), fmt(c["inside_2sigma"]["th"]),
            fmt(c["processing_s"]), fmt(c["measured_s"]), fmt(c["open_loop_s"]),
            fmt(c["max_period_s"]), fmt(o["processing_s"]), fmt(o["open_loop_s"]),
            fmt(o["max_period_s"])))
    lines.append("")
    lines.append("Divergence study of the office run (nats, mean (variance) over %d realisations):"
                 % args.realisations)
    lines.append("")
    lines.append("| #E | " + " | ".join("D(%s)" % p.replace("_", " \u2016 ") for p in PAIRS) + " |")
    lines.append("|---|" + "---|" * len(PAIRS))
    for e in sorted(div):
        lines.append("| %d | " % e + " | ".join(
            "%s (%s)" % (fmt(div[e][p][0]), fmt(div[e][p][1])) for p in PAIRS) + " |")

    # Claims.
    claims = []
    # (a) consistency.
    both_consistent = all(cons[f]["verdict"] == "consistent" for f in FILTERS)
    any_consistent = any(cons[f]["verdict"] == "consistent" for f in FILTERS)
    two_sigma_ok = all(cons[f]["inside_2sigma"][c] >= 0.9 for f in FILTERS for c in ("x", "y", "th"))
    verdict = "yes" if both_consistent and two_sigma_ok else (
        "partly" if any_consistent or two_sigma_ok else "no")
    claims.append((
        "(a) both filters consistent",
        "x, y, heading errors inside +-2 sigma (Fig. 3)",
        "ANEES inside %s for %s (classical) / %s (selective) of the steps, mean ANEES %s / %s, "
        "verdicts %s / %s; steps inside 2 sigma x/y/th: classical %s/%s/%s, selective %s/%s/%s "
        "(%d runs)" % (bounds, fmt(cons["classical"]["fraction_inside"]),
                       fmt(cons["selective"]["fraction_inside"]),
                       fmt(cons["classical"]["mean_anees"]), fmt(cons["selective"]["mean_anees"]),
                       cons["classical"]["verdict"], cons["selective"]["verdict"],
                       *[fmt(cons[f]["inside_2sigma"][c]) for f in FILTERS for c in ("x", "y", "th")],
                       n_runs),
        verdict))
    # (b) processing time.
    pc, ps = cons["classical"]["processing_s"], cons["selective"]["processing_s"]
    mc, ms = cons["classical"]["measured_s"], cons["selective"]["measured_s"]
    gc, gs = cons["classical"]["measured_growth"], cons["selective"]["measured_growth"]
    oc, os_ = office["classical"]["processing_s"], office["selective"]["processing_s"]
    model_yes = pc > ps and oc > os_
    measured_yes = mc > ms and gc > gs
    claims.append((
        "(b) classical processing time grows faster",
        "accumulated time grows faster (quadratic) for classical (Fig. 4c)",
        "cost model (control.processing: model): corridor %s s vs %s s (x%s), office %s s vs %s s "
        "(x%s); measured sum of f_us: corridor %s s vs %s s, second half / first half of a run "
        "%s vs %s; final maps of %s (corridor, mean) and %d (office) features" % (
            fmt(pc), fmt(ps), fmt(pc / ps if ps else float("nan")), fmt(oc), fmt(os_),
            fmt(oc / os_ if os_ else float("nan")), fmt(mc), fmt(ms), fmt(gc), fmt(gs),
            fmt(cons["classical"]["num_features"]), office["classical"]["num_features"]),
        "yes" if model_yes and measured_yes else ("partly" if model_yes or measured_yes else "no")))
    # (c) command period and open loop.
    pmc, pms = cons["classical"]["max_period_s"], cons["selective"]["max_period_s"]
    omc, oms = office["classical"]["max_period_s"], office["selective"]["max_period_s"]
    olc, ols = cons["classical"]["open_loop_s"], cons["selective"]["open_loop_s"]
    oolc, ools = office["classical"]["open_loop_s"], office["selective"]["open_loop_s"]
    selective_short = max(pms, oms) <= 0.2 + 1e-9
    classical_grows = max(pmc, omc) > 0.2 + 1e-9
    open_loop_larger = olc > ols and oolc > ools
    n_ok = sum([selective_short, classical_grows, open_loop_larger])
    claims.append((
        "(c) classical period grows, selective stays 0.2 s; open loop larger for classical",
        "classical periods up to 0.7 s, selective 0.2 s (Fig. 4d)",
        "periods from the cost model (0.11 s + 4e-6 s x updates x n^2 per scan step, defaults set to emulate "
        "the paper's computer, so the selective 0.2 s is by construction): largest period classical %s s (corridor) / %s s (office), selective %s / %s s; "
        "open-loop time classical %s s vs selective %s s (corridor), %s vs %s s (office)" % (
            fmt(pmc), fmt(omc), fmt(pms), fmt(oms), fmt(olc), fmt(ols), fmt(oolc), fmt(ools)),
        # The paper's classical periods reached 0.7 s; a classical maximum far below that (under
        # 0.5 s) reproduces the direction of the claim, not its size.
        "yes" if n_ok == 3 and max(pmc, omc) >= 0.5 - 1e-9 else ("no" if n_ok == 0 else "partly")))
    # (d) selective map closer to the truth.
    dsel, dcls = div[largest]["selective_truth"], div[largest]["classical_truth"]
    swc, sws = cons["classical"]["divergence_truth"], cons["selective"]["divergence_truth"]
    pairs_runs = [((r["divergence"] or {}).get("selective_truth"),
                   (r["divergence"] or {}).get("classical_truth")) for r in runs]
    pairs_runs = [p for p in pairs_runs if p[0] is not None and p[1] is not None]
    closer_runs = sum(1 for s_, c_ in pairs_runs if s_ < c_)
    office_yes = dsel[0] < dcls[0]
    sweep_yes = sws < swc and closer_runs > len(pairs_runs) / 2
    claims.append((
        "(d) selective map closer to the ground truth",
        "selective map closer to the real building (Sec. 4)",
        "office run, #E = %d: D(selective ‖ truth) %s (var %s), D(classical ‖ truth) %s (var %s); "
        "D(classical ‖ selective) %s, D(selective ‖ classical) %s; corridor runs (mean of %d, "
        "#E = 20000, 1 realisation each): D(selective ‖ truth) %s, D(classical ‖ truth) %s, "
        "selective closer in %d of %d runs" % (
            largest, fmt(dsel[0]), fmt(dsel[1]), fmt(dcls[0]), fmt(dcls[1]),
            fmt(div[largest]["classical_selective"][0]), fmt(div[largest]["selective_classical"][0]),
            n_runs, fmt(sws, 4), fmt(swc, 4), closer_runs, len(pairs_runs)),
        "yes" if office_yes and sweep_yes else ("partly" if office_yes or sweep_yes else "no")))
    # (e) stability of the estimate at #E = 2x10^4: the mean moves little from the previous #E and
    # the spread over realisations is small against the mean.
    keys = sorted(div)
    stable = []  # per pair: (mean settled, spread small)
    details = []
    if len(keys) >= 2:
        prev = keys[-2]
        for p in PAIRS:
            m_last, v_last = div[largest][p]
            m_prev = div[prev][p][0]
            change = abs(m_last - m_prev) / abs(m_last) if m_last else float("inf")
            cv = math.sqrt(max(v_last, 0.0)) / abs(m_last) if m_last else float("inf")
            stable.append((change <= 0.05, cv <= 0.05))
            details.append("%s: mean %s -> %s (%s %%), sd/mean %s" % (
                p.replace("_", " \u2016 "), fmt(m_prev), fmt(m_last), fmt(100 * change, 2), fmt(cv, 2)))
    claims.append((
        "(e) divergence stable from #E = 2x10^4",
        "estimate stable from #E = 2x10^4 (Figs. 6, 7)",
        "from #E = %s to %d (criteria: the mean changes by <= 5 %%, and one realisation's sd is "
        "<= 5 %% of the mean): %s" % (
            keys[-2] if len(keys) >= 2 else "-", largest, "; ".join(details)),
        "yes" if stable and all(a and b for a, b in stable) else (
            "partly" if any(a or b for a, b in stable) else "no")))

    table = ["| claim | paper | mjslam | reproduced? |", "|---|---|---|---|"]
    for claim in claims:
        table.append("| %s | %s | %s | %s |" % claim)
    results["claims"] = [dict(zip(("claim", "paper", "mjslam", "reproduced"), c)) for c in claims]

    header = ["# The paper's experiments, reproduced by mjslam", "",
              "Command: `/usr/bin/python3 scripts/paper_experiments.py --out %s --runs %d --jobs %d%s` "
              "(wall time %.0f s: sweep %.0f s, office run %.0f s, divergence study %.0f s; plots in "
              "consistency/plot_nees.png and consistency/plot_divergence.png)." % (
                  args.out, args.runs, args.jobs,
                  (" --duration %g" % args.duration) if args.duration is not None else "",
                  timings["total"], timings["sweep"], timings["office"], timings["divergence"]),
              ""]
    text = "\n".join(header + table + [""] + lines) + "\n"
    with open(os.path.join(out, "claims.md"), "w") as f:
        f.write(text)
    with open(os.path.join(out, "claims.json"), "w") as f:
        json.dump(results, f, indent=1, default=str)
    print(text)


def chi2_bounds(sweep_dir):
    """The chi-square bounds for all runs (the rows of nees.csv with the most runs)."""
    best = (0, float("nan"), float("nan"))
    with open(os.path.join(sweep_dir, "nees.csv")) as f:
        for r in csv.DictReader(f):
            n = int(float(r["n_runs"]))
            if n > best[0]:
                best = (n, float(r["lower"]), float(r["upper"]))
    return best[1], best[2]


if __name__ == "__main__":
    main()
