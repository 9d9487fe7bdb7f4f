#!/usr/bin/python3
"""Reproduces the paper's evaluation under two models, prints a claim-by-claim table, draws the
paper's figures.

    /usr/bin/python3 scripts/paper_experiments.py [--out runs/paper] [--runs 25] [--jobs 2]
        [--duration S] [--office-runs 10] [--office-duration 600] [--points E ...]
        [--realisations 100] [--paper-study-realisations K] [--models default paper]
        [--scale-worlds W ...]
        [--scale-duration S]

Runs, from the repository root, with build/mjslam (build it first), for each model M (the
config configs/M.yaml as shipped: `default` is the project's model, `paper` the paper's method as
published, docs/method.md):

1. Consistency (Fig. 3): `mjslam sweep` of configs/M.yaml in worlds/corridor_loop.xml, --runs
   runs (seeds run.seed + i), each evaluated with the map metrics and a divergence at 20000
   points -> DIR/M/corridor.
2. The office: `mjslam sweep` of --office-runs runs in worlds/office.xml -> DIR/M/office (its
   consistency, and the cost and open loop of Figs. 4(c)-(d) from its first run).
3. Map divergence (Figs. 5-7): `mjslam divergence` of the office's first run for the #E list,
   twice: with the project's Gaussians (2 cm floor on every Gaussian, `mjslam divergence`'s
   defaults) -> DIR/M/divergence_floor.csv, and with the paper's (each estimated feature with
   its own covariance, the truth 1 mm wide: --floor-std 0 --truth-std 0.001) ->
   DIR/M/divergence_paper.csv. Each study draws --realisations realisations per #E, the paper's
   study --paper-study-realisations if given (it costs about six times the floor's per point).
4. The figures, one PNG each under DIR/figures/ (names below), and DIR/claims.md (the table
   "claim | paper | default model | paper model", also printed) and DIR/claims.json.

Then, once (Figs. 4(c)-(d) at scale): one `mjslam run` per --scale-worlds world (WORLD or
WORLD:SECONDS, its time limit) with configs/default.yaml, `slam.timing: realtime` and the world's
tour once (control.driver: tour, driver.loop: false; not evaluated) -> DIR/scale/<world>, read up
to the tour's last command (the robot then stands until the time limit); fig4cd_scale.png
(period against map size per filter; map size, period, processing, skipped scans and open loop
against time) and the table "first step where the classical period reaches 0.7 s".

Figures (M = default or paper): fig3_pose_errors_M.png (corridor, seed run.seed),
fig4c_processing_M.png and fig4d_open_loop_M.png (office, first run), fig5_points_M.png (office
maps and 20000 points), fig6_intermap_M.png and fig7_to_truth_M.png (the two divergence
studies), anees_corridor_M.png (the average NEES; not a figure of the paper), fig4cd_scale.png.
The processing times of every figure and table are the cost model's (control.processing:
model), never the measured ones. Nothing is tuned: the configs are used as shipped; noise comes
from them. A sweep or run whose summary.json exists is not run again (delete it to redo).
"""

import argparse
import json
import math
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(ROOT, "python"))
sys.path.insert(1, os.path.dirname(os.path.abspath(__file__)))
import mjslam  # noqa: E402
import paper_figures as figs  # noqa: E402

FILTERS = figs.FILTERS
PAIRS = ("classical_selective", "selective_classical", "classical_truth", "selective_truth")
DEFAULT_POINTS = (100, 200, 500, 1000, 2000, 5000, 10000, 20000, 50000, 100000)
# The paper's Gaussians for the divergence (docs/method.md, "Map divergence"): each estimated
# feature with its own covariance, the exact truth 1 mm wide.
PAPER_DIVERGENCE = ["--floor-std", "0", "--truth-std", "0.001"]
STUDIES = (("floor", "2 cm floor", []), ("paper", "own covariance, truth 1 mm", PAPER_DIVERGENCE))


def log(message):
    print(message, file=sys.stderr, flush=True)


def run_command(command, log_path=None):
    """Runs a command from the repository root; raises SystemExit on failure. Returns seconds."""
    log("$ " + " ".join(command))
    start = time.monotonic()
    with open(log_path, "w") if log_path else open(os.devnull, "w") as out:
        result = subprocess.run(command, cwd=ROOT, stdout=out, stderr=subprocess.STDOUT)
    if result.returncode != 0:
        raise SystemExit("failed (exit %d): %s%s" % (result.returncode, " ".join(command),
                                                     (" (see %s)" % log_path) if log_path else ""))
    return time.monotonic() - start


def finite(values):
    return [v for v in values if v is not None and not (isinstance(v, float) and math.isnan(v))]


def mean(values):
    values = finite(values)
    return sum(values) / len(values) if values else float("nan")


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    if isinstance(x, int):
        return str(x)
    if x != 0 and (abs(x) >= 1e4 or abs(x) < 1e-3):
        return "%.2e" % x
    return ("%%.%dg" % digits) % x


def timing_of(run):
    """(cost, dt): the cost model (base, k, steps per scan) and the control period of a run
    (mjslam.Run), from its resolved config.yaml."""
    control_rate_hz = float(run.setting("run.control_rate_hz"))
    dt = 1.0 / control_rate_hz
    steps_per_scan = max(1, int(round(control_rate_hz / float(run.setting("laser.rate_hz")))))
    cost = (float(run.setting("control.model_base_s")),
            float(run.setting("control.model_s_per_update_per_n2")), steps_per_scan)
    return cost, dt


# ---------------------------------------------------------------------------------------------
# Experiments.

def sweep(program, config, world, runs, jobs, out, duration, extra=()):
    """One evaluated sweep into `out`, unless its summary.json exists. Returns its summary."""
    if not os.path.exists(os.path.join(out, mjslam.SUMMARY_FILE)):
        command = [program, "sweep", "--config", config, "--runs", str(runs), "--jobs", str(jobs),
                   "--out", out, "--set", "run.world=" + world, "--set", "render.enabled=false",
                   "--divergence-points", "20000", "--quiet"] + list(extra)
        if duration is not None:
            command += ["--duration", str(duration)]
        run_command(command, out + ".log")
    return mjslam.read_sweep(out).summary


def divergence_study(program, run_dir, points, realisations, out, options):
    if not os.path.exists(out):
        run_command([program, "divergence", run_dir, "--points"] + [str(p) for p in points] +
                    ["--realisations", str(realisations), "--out", out] + options,
                    out + ".log")
    return figs.read_divergence(out)


def processed_consistency(traj, name):
    """Pose consistency of one filter pooled over the steps where it processed its record
    (figs.processed_steps): {"steps", "inside" (x, y, th counts inside 2 sigma), "nees_sum",
    "nees_steps"}. summary.json counts every step, and under slam.timing realtime a skipped
    step compares the last processed estimate, of an earlier pose, with the current true pose."""
    steps = figs.processed_steps(traj, name)
    inside = [0, 0, 0]
    nees_sum, nees_steps = 0.0, 0
    for s in steps:
        errors = (traj[name + "_x"][s] - traj["true_x"][s], traj[name + "_y"][s] - traj["true_y"][s],
                  figs.wrap(traj[name + "_th"][s] - traj["true_th"][s]))
        for k, (e, var) in enumerate(zip(errors, ("pxx", "pyy", "pthth"))):
            inside[k] += abs(e) <= 2.0 * math.sqrt(max(traj[name + "_" + var][s], 0.0)) + 1e-12
        if not math.isnan(traj[name + "_nees"][s]):
            nees_sum += traj[name + "_nees"][s]
            nees_steps += 1
    return {"steps": len(steps), "inside": inside, "nees_sum": nees_sum, "nees_steps": nees_steps}


def run_metrics(run):
    """Cost, open loop (both counts), map metrics and 2 sigma of one run (mjslam.Run)."""
    summary = run.summary
    traj = run.trajectory
    cost, dt = timing_of(run)
    half = len(traj["t"]) // 2
    out = {"duration_s": summary["run"]["duration_s"], "divergence": summary.get("divergence")}
    for f in FILTERS:
        s = summary["filters"][f]
        modelled = figs.modelled_processing(traj, f, cost)
        whole, beyond = figs.command_timeline(traj, f, dt)
        measured = [0.0 if math.isnan(u) else u * 1e-6 for u in traj[f + "_us"]]
        first, second = sum(measured[:half]), sum(measured[half:])
        out[f] = {"processing_s": s.get("processing_s"), "modelled_s": sum(modelled),
                  "measured_s": first + second,
                  "measured_growth": second / first if first > 0 else float("nan"),
                  "open_loop_s": s.get("open_loop_s"), "open_loop_whole_s": whole[-1],
                  "open_loop_beyond_s": beyond[-1],
                  "max_period_s": max(finite(traj[f + "_period"]) or [float("nan")]),
                  "scans_processed": s.get("scans_processed"),
                  "scans_skipped": s.get("scans_skipped"),
                  "inside_2sigma": s.get("inside_2sigma", {}), "map": s.get("map", {}),
                  "num_features": s.get("num_features"),
                  "processed": processed_consistency(traj, f), "steps": len(traj["t"]),
                  "nees": [float(v) for v in traj[f + "_nees"]]}
        # The cost model recomputed from trajectory.csv must give summary.json's figure.
        if s.get("processing_s") is not None and \
                abs(sum(modelled) - s["processing_s"]) > 1e-6 * max(1.0, s["processing_s"]):
            log("note: %s: %s processing from trajectory.csv %.6f s, summary.json %.6f s "
                "(control.processing is not model?)" % (run.path, f, sum(modelled),
                                                        s["processing_s"]))
    return out


def model_results(args, program, model):
    """Runs (or reuses) one model's experiments; returns what the table and figures need."""
    out = os.path.join(args.out, model)
    os.makedirs(out, exist_ok=True)
    config = "configs/%s.yaml" % model
    res = {"model": model, "dir": out}
    res["corridor"] = sweep(program, config, "worlds/corridor_loop.xml", args.runs, args.jobs,
                            os.path.join(out, "corridor"), args.duration)
    res["office"] = sweep(program, config, "worlds/office.xml", args.office_runs, args.jobs,
                          os.path.join(out, "office"), args.office_duration)
    corridor_runs = mjslam.read_sweep(os.path.join(out, "corridor")).runs
    office_runs = mjslam.read_sweep(os.path.join(out, "office")).runs
    res["corridor_runs"] = [run_metrics(r) for r in corridor_runs]
    res["office_runs"] = [run_metrics(r) for r in office_runs]
    office_first = office_runs[0]
    res["office_first"] = office_first
    res["corridor_first"] = corridor_runs[0]
    res["studies"] = {}
    for key, _, options in STUDIES:
        realisations = args.realisations
        if key == "paper" and args.paper_study_realisations is not None:
            realisations = args.paper_study_realisations
        res["studies"][key] = divergence_study(
            program, office_first.path, args.points, realisations,
            os.path.join(out, "divergence_%s.csv" % key), options)
    return res


# ---------------------------------------------------------------------------------------------
# The claims.

def per_filter(res, world, key, sub=None):
    """Mean over a world's runs of run_metrics()[filter][key] (or [key][sub]), per filter."""
    runs = res[world + "_runs"]
    return {f: mean([(r[f][key] or {}).get(sub) if sub else r[f][key] for r in runs])
            for f in FILTERS}


def chi2_quantile(p, k):
    """The p-quantile of chi-square with k dof (Wilson-Hilferty; within 0.1 % for k >= 30)."""
    z = math.sqrt(2.0) * erfinv(2.0 * p - 1.0)
    return k * (1.0 - 2.0 / (9.0 * k) + z * math.sqrt(2.0 / (9.0 * k))) ** 3


def erfinv(y):
    """Inverse error function by bisection on math.erf (to 1e-12)."""
    lo, hi = -10.0, 10.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if math.erf(mid) < y:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def fraction_inside(nees_runs):
    """The fraction of steps whose average NEES over the runs reaching the step (3 dof; steps
    where any of them has none left out) lies in its two-sided 95 % bounds, as mjslam sweep."""
    inside = steps = 0
    for i in range(max(len(n) for n in nees_runs)):
        values = [n[i] for n in nees_runs if i < len(n)]
        if any(math.isnan(v) for v in values):
            continue
        k = 3 * len(values)
        anees = sum(values) / len(values)
        inside += chi2_quantile(0.025, k) / len(values) <= anees <= \
            chi2_quantile(0.975, k) / len(values)
        steps += 1
    return inside / steps if steps else float("nan")


def inside_interval(res, world, f, replicates=200, seed=1):
    """95 % percentile bootstrap interval over the runs (resampled with replacement, seeded) of
    the fraction of steps with the ANEES in its bounds."""
    import random
    rng = random.Random(seed)
    runs = [r[f]["nees"] for r in res[world + "_runs"]]
    values = sorted(fraction_inside([rng.choice(runs) for _ in runs]) for _ in range(replicates))
    return values[int(0.025 * replicates)], values[int(0.975 * replicates) - 1]


def sweep_filter(res, world, f):
    return res[world]["filters"][f]


def claim_a(res):
    """(a) both filters consistent: ANEES against the bounds and 2 sigma, corridor and office."""
    parts, two_sigma_ok, anees_ok = [], True, True
    for world in ("corridor", "office"):
        cells = []
        for f in FILTERS:
            s = sweep_filter(res, world, f)
            inside = s["runs_mean"]["inside_2sigma"]
            lo, hi = inside_interval(res, world, f)
            cells.append("%s ANEES %s (in bounds %s, 95 %% interval over runs %s-%s, %s), "
                         "2σ %s/%s/%s" % (
                f, fmt(s["mean_anees"]), fmt(s["fraction_inside"]), fmt(lo), fmt(hi), s["verdict"],
                fmt(inside["x"]), fmt(inside["y"]), fmt(inside["th"])))
            two_sigma_ok &= all(inside[c] >= 0.9 for c in ("x", "y", "th"))
            if world == "corridor":
                anees_ok &= s["verdict"] == "consistent"
        parts.append("%s (%d runs): %s" % (world, res[world]["sweep"]["completed_runs"],
                                           "; ".join(cells)))
    # Under slam.timing realtime, the same pooled over the steps each filter processed.
    for world in ("corridor", "office"):
        runs = res[world + "_runs"]
        if all(r[f]["processed"]["steps"] == r[f]["steps"] for r in runs for f in FILTERS):
            continue
        cells = []
        for f in FILTERS:
            steps = sum(r[f]["processed"]["steps"] for r in runs)
            inside = [sum(r[f]["processed"]["inside"][k] for r in runs) / steps for k in range(3)]
            nees = (sum(r[f]["processed"]["nees_sum"] for r in runs) /
                    max(1, sum(r[f]["processed"]["nees_steps"] for r in runs)))
            cells.append("%s mean NEES %s, 2σ %s/%s/%s (%d of %d steps)" % (
                f, fmt(nees), fmt(inside[0]), fmt(inside[1]), fmt(inside[2]), steps,
                sum(r[f]["steps"] for r in runs)))
        parts.append("%s, the steps each filter processed (realtime): %s" % (world, "; ".join(cells)))
    verdict = "yes" if two_sigma_ok and anees_ok else ("partly" if two_sigma_ok or anees_ok
                                                       else "no")
    return "; ".join(parts), verdict


def claim_b(res):
    """(b) the classical filter's accumulated processing time grows faster."""
    pc = per_filter(res, "office", "modelled_s")
    cc = per_filter(res, "corridor", "modelled_s")
    mc = per_filter(res, "corridor", "measured_s")
    gc = per_filter(res, "corridor", "measured_growth")
    model_yes = pc["classical"] > pc["selective"] and cc["classical"] > cc["selective"]
    measured_yes = mc["classical"] > mc["selective"] and gc["classical"] > gc["selective"]
    text = ("modelled: corridor %s vs %s s, office %s vs %s s (x%s); measured on this machine "
            "(corridor, sum of f_us): %s vs %s s, second half / first half %s vs %s; maps of %s "
            "(corridor) and %s (office) features" % (
                fmt(cc["classical"]), fmt(cc["selective"]), fmt(pc["classical"]),
                fmt(pc["selective"]), fmt(pc["classical"] / pc["selective"]),
                fmt(mc["classical"]), fmt(mc["selective"]), fmt(gc["classical"]),
                fmt(gc["selective"]),
                fmt(per_filter(res, "corridor", "num_features")["classical"]),
                fmt(per_filter(res, "office", "num_features")["classical"])))
    return text, "yes" if model_yes and measured_yes else ("partly" if model_yes or measured_yes
                                                          else "no")


def claim_c(res):
    """(c) the classical period grows to 0.7 s, the selective stays at 0.2 s; more open loop."""
    pmax = {f: max(max(r[f]["max_period_s"] for r in res[w + "_runs"])
                   for w in ("corridor", "office")) for f in FILTERS}
    whole = per_filter(res, "office", "open_loop_whole_s")
    beyond = per_filter(res, "office", "open_loop_beyond_s")
    cwhole = per_filter(res, "corridor", "open_loop_whole_s")
    skipped = per_filter(res, "office", "scans_skipped")
    text = ("modelled periods: largest classical %s s, selective %s s (corridor and office); "
            "office open loop, whole periods (the paper's count): classical %s s, selective %s s; "
            "period - 0.1 s (f_open_loop): %s vs %s s; corridor, whole periods: %s vs %s s; "
            "office scans skipped: %s vs %s" % (
                fmt(pmax["classical"]), fmt(pmax["selective"]), fmt(whole["classical"]),
                fmt(whole["selective"]), fmt(beyond["classical"]), fmt(beyond["selective"]),
                fmt(cwhole["classical"]), fmt(cwhole["selective"]), fmt(skipped["classical"]),
                fmt(skipped["selective"])))
    ok = [pmax["classical"] >= 0.7 - 1e-9, pmax["selective"] <= 0.2 + 1e-9,
          whole["classical"] > whole["selective"]]
    return text, "yes" if all(ok) else ("no" if not any(ok) else "partly")


def claim_d(res):
    """(d) the selective map is closer to the truth: direct map metrics beside the divergence."""
    runs = res["corridor_runs"]
    m = {f: {k: mean([r[f]["map"].get(k) for r in runs])
             for k in ("line_rho_rmse_m", "line_alpha_rmse_rad", "corner_rmse_m",
                       "matched_fraction")} for f in FILTERS}
    rho_better = sum(1 for r in runs if r["selective"]["map"].get("line_rho_rmse_m", 1e9) <
                     r["classical"]["map"].get("line_rho_rmse_m", -1))
    corner_better = sum(1 for r in runs if r["selective"]["map"].get("corner_rmse_m", 1e9) <
                        r["classical"]["map"].get("corner_rmse_m", -1))
    div = [(r["divergence"] or {}) for r in runs]
    div_better = sum(1 for d in div if d.get("selective_truth", 1e9) < d.get("classical_truth", -1))
    studies = []
    study_yes = []
    for key, label, _ in STUDIES:
        table = res["studies"][key]
        e, sel = table["selective_truth"][-1][0], table["selective_truth"][-1][1]
        cls = table["classical_truth"][-1][1]
        studies.append("%s: D(sel ‖ truth) %s, D(cls ‖ truth) %s" % (label, fmt(sel), fmt(cls)))
        study_yes.append(sel < cls)
    text = ("corridor (%d runs), selective vs classical: line rho RMSE %s vs %s mm (selective "
            "better in %d runs), alpha %s vs %s mrad, corner RMSE %s vs %s mm (better in %d), "
            "matched fraction %s vs %s; divergence to the truth (2 cm floor, #E 20000) lower for "
            "the selective map in %d runs; office first run, #E %d: %s" % (
                len(runs), fmt(1e3 * m["selective"]["line_rho_rmse_m"]),
                fmt(1e3 * m["classical"]["line_rho_rmse_m"]), rho_better,
                fmt(1e3 * m["selective"]["line_alpha_rmse_rad"]),
                fmt(1e3 * m["classical"]["line_alpha_rmse_rad"]),
                fmt(1e3 * m["selective"]["corner_rmse_m"]),
                fmt(1e3 * m["classical"]["corner_rmse_m"]), corner_better,
                fmt(m["selective"]["matched_fraction"]), fmt(m["classical"]["matched_fraction"]),
                div_better, e, "; ".join(studies)))
    direct_yes = rho_better > len(runs) / 2 and corner_better > len(runs) / 2
    divergence_yes = div_better > len(runs) / 2 and all(study_yes)
    return text, "yes" if direct_yes and divergence_yes else (
        "partly" if direct_yes or divergence_yes else "no")


def claim_e(res):
    """(e) the divergence estimate is stable from #E = 2x10^4."""
    details, ok = [], []
    for key, label, _ in STUDIES:
        table = res["studies"][key]
        for pair in ("classical_truth", "selective_truth"):
            rows = {r[0]: r for r in table[pair]}
            if 20000 not in rows or max(rows) <= 20000:
                continue
            last = rows[max(rows)]
            at = rows[20000]
            change = abs(last[1] - at[1]) / abs(last[1]) if last[1] else float("inf")
            cv = math.sqrt(max(at[2], 0.0)) / abs(at[1]) if at[1] else float("inf")
            ok.append(change <= 0.05 and cv <= 0.05)
            details.append("%s, %s: mean %s at 2x10^4, %s at %d (%s %%), sd/mean at 2x10^4 %s" % (
                label, figs.PAIR_LABELS[pair], fmt(at[1]), fmt(last[1]), last[0],
                fmt(100 * change, 2), fmt(cv, 2)))
    if not ok:
        return "the #E list must include 20000 and a larger value", "n/a"
    return "; ".join(details), "yes" if all(ok) else ("partly" if any(ok) else "no")


CLAIMS = (("(a) both filters consistent", "errors inside ±2σ (Fig. 3)", claim_a),
          ("(b) classical processing time grows faster", "faster, quadratic growth (Fig. 4c)",
           claim_b),
          ("(c) classical period grows, selective stays; more open loop",
           "classical periods up to 0.7 s, selective 0.2 s (Fig. 4d)", claim_c),
          ("(d) selective map closer to the truth", "closer to the building (Sec. 4, Fig. 7)",
           claim_d),
          ("(e) divergence stable from #E = 2x10^4", "stable from 2x10^4 (Figs. 6, 7)", claim_e))


# ---------------------------------------------------------------------------------------------
# Figures.

def draw_model_figures(res, fig_dir, points_margin_m=0.5):
    model = res["model"]
    corridor = res["corridor_first"]
    office = res["office_first"]
    cost, dt = timing_of(office)
    label = "%s model" % model
    traj = corridor.trajectory
    seed = corridor.manifest.get("seed")
    figs.fig3_pose_errors(traj, os.path.join(fig_dir, "fig3_pose_errors_%s.png" % model),
                          "%s, corridor loop, seed %s" % (label, seed))
    traj = office.trajectory
    seed = office.manifest.get("seed")
    where = "%s, office, seed %s" % (label, seed)
    figs.fig4c_processing(traj, os.path.join(fig_dir, "fig4c_processing_%s.png" % model), where,
                          cost)
    figs.fig4d_open_loop(traj, os.path.join(fig_dir, "fig4d_open_loop_%s.png" % model), where, dt)
    figs.fig5_points(office, os.path.join(fig_dir, "fig5_points_%s.png" % model), where, 20000,
                     points_margin_m, 1)
    studies = [(label_, res["studies"][key]) for key, label_, _ in STUDIES]
    figs.divergence_figure(studies, ("classical_selective", "selective_classical"),
                           os.path.join(fig_dir, "fig6_intermap_%s.png" % model),
                           "Fig. 6 of the paper: divergence between the two maps against #E, %s" % where)
    figs.divergence_figure(studies, ("classical_truth", "selective_truth"),
                           os.path.join(fig_dir, "fig7_to_truth_%s.png" % model),
                           "Fig. 7 of the paper: divergence of each map to the truth against #E, %s"
                           % where)
    nees = mjslam.read_sweep(os.path.join(res["dir"], "corridor")).nees
    # nees.csv (mjslam sweep) averages every step; under realtime a skipped step holds the
    # estimate of its last processed step, compared with that step's truth, so say so.
    stale = any(r[f]["processed"]["steps"] < r[f]["steps"] for r in res["corridor_runs"]
                for f in FILTERS)
    figs.plot_nees(nees, os.path.join(fig_dir, "anees_corridor_%s.png" % model),
                   ", %s, corridor loop%s" % (label, ",\nevery step (realtime: a skipped step "
                                              "counts the estimate it holds)" if stale else ""))


# ---------------------------------------------------------------------------------------------
# Figs. 4(c)-(d) at scale (issue 12 item 5).

def scale_study(args, program, fig_dir):
    """One realtime tour per world; returns the table lines and draws fig4cd_scale.png."""
    runs, lines = [], []
    lines.append("| world | driven (run's end) | final map classical / selective | scans skipped classical / "
                 "selective | open loop (whole periods) s | first step with classical period "
                 ">= 0.7 s: t, map sizes, selective period | first step with selective period "
                 "> 0.2 s: t, selective map |")
    lines.append("|---|---|---|---|---|---|---|")
    for item in args.scale_worlds:
        world, _, seconds = item.partition(":")
        duration = float(seconds) if seconds else args.scale_duration
        name = os.path.splitext(os.path.basename(world))[0]
        out = os.path.join(args.out, "scale", name)
        if not os.path.exists(os.path.join(out, mjslam.SUMMARY_FILE)):
            os.makedirs(os.path.dirname(out), exist_ok=True)
            command = [program, "run", "--config", "configs/default.yaml", "--world", world,
                       "--set", "slam.timing=realtime", "--set", "control.driver=tour",
                       "--set", "driver.loop=false", "--set", "render.enabled=false",
                       "--no-render", "--no-evaluate", "--quiet", "--out", out]
            command += ["--duration", str(duration)]
            run_command(command, out + ".log")
        run = mjslam.read_run(out)
        traj = figs.until_last_motion(run.trajectory)
        cost, dt = timing_of(run)
        runs.append((name, traj))
        summary = run.summary
        t = traj["t"]
        first_c = next((s for s, p in enumerate(traj["classical_period"]) if p >= 0.7 - 1e-9),
                       None)
        first_s = next((s for s, p in enumerate(traj["selective_period"]) if p > 0.2 + 1e-9),
                       None)
        whole = {f: figs.command_timeline(traj, f, dt)[0][-1] for f in FILTERS}
        cell_c = ("t %s s, maps %d / %d, selective %s s" % (
            fmt(t[first_c]), traj["classical_nfeat"][first_c], traj["selective_nfeat"][first_c],
            fmt(traj["selective_period"][first_c])) if first_c is not None else "never")
        cell_s = ("t %s s, map %d" % (fmt(t[first_s]), traj["selective_nfeat"][first_s])
                  if first_s is not None else "never")
        skipped = {f: figs.scale_series(traj, f, cost, dt)["skipped"][-1] for f in FILTERS}
        lines.append("| %s | %s s (%s) | %d / %d | %d / %d | %s / %s | %s | %s |" % (
            name, fmt(t[-1]), summary["run"]["termination_reason"], traj["classical_nfeat"][-1],
            traj["selective_nfeat"][-1], skipped["classical"], skipped["selective"],
            fmt(whole["classical"]), fmt(whole["selective"]), cell_c, cell_s))
    if runs:
        figs.fig4cd_scale(runs, os.path.join(fig_dir, "fig4cd_scale.png"), cost, dt)
    return lines


# ---------------------------------------------------------------------------------------------

def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="runs/paper", help="output directory [runs/paper]")
    parser.add_argument("--runs", type=int, default=25, help="corridor Monte Carlo runs [25]")
    parser.add_argument("--jobs", type=int, default=2, help="runs at a time [2]")
    parser.add_argument("--duration", type=float, default=None,
                        help="time limit of each corridor run, s [run.duration_s of the config]")
    parser.add_argument("--office-runs", type=int, default=10, help="office runs [10]")
    parser.add_argument("--office-duration", type=float, default=600.0,
                        help="time limit of each office run, s [600]")
    parser.add_argument("--points", type=int, nargs="+", default=list(DEFAULT_POINTS),
                        help="#E of the divergence studies [%s]" %
                        " ".join(str(p) for p in DEFAULT_POINTS))
    parser.add_argument("--realisations", type=int, default=100,
                        help="realisations per #E of the divergence studies [100]")
    parser.add_argument("--paper-study-realisations", type=int, default=None,
                        help="realisations per #E of the study with the paper's Gaussians "
                        "[--realisations]")
    parser.add_argument("--models", nargs="+", default=["default", "paper"],
                        choices=["default", "paper"], help="configs/M.yaml [default paper]")
    parser.add_argument("--scale-worlds", nargs="*", default=["worlds/office.xml:300"],
                        help="worlds of the realtime study at scale, each WORLD or WORLD:SECONDS "
                        "(its time limit) [worlds/office.xml:300]")
    parser.add_argument("--scale-duration", type=float, default=3000.0,
                        help="time limit of a scale run without its own, s [3000]")
    parser.add_argument("--mjslam", default="build/mjslam", help="the program [build/mjslam]")
    parser.add_argument("--readme", default=None,
                        help="also write the short verdict table into this file (README.md) "
                        "between its claims markers")
    args = parser.parse_args()

    program = args.mjslam if os.path.isabs(args.mjslam) else os.path.join(ROOT, args.mjslam)
    if not os.access(program, os.X_OK):
        raise SystemExit("%s not found: build it first (cmake --build build -j2)" % program)
    args.out = args.out if os.path.isabs(args.out) else os.path.join(ROOT, args.out)
    fig_dir = os.path.join(args.out, "figures")
    os.makedirs(fig_dir, exist_ok=True)
    start = time.monotonic()

    results = {m: model_results(args, program, m) for m in args.models}
    for res in results.values():
        draw_model_figures(res, fig_dir)
    scale_lines = scale_study(args, program, fig_dir)

    header = "| claim | paper | " + " | ".join("%s model | verdict" % m for m in args.models) + " |"
    table = [header, "|---|---|" + "---|---|" * len(args.models)]
    claims_json = []
    for name, paper, judge in CLAIMS:
        cells, entry = [], {"claim": name, "paper": paper}
        for m in args.models:
            text, verdict = judge(results[m])
            cells += [text, "**%s**" % verdict]
            entry[m] = {"mjslam": text, "reproduced": verdict}
        table.append("| %s | %s | %s |" % (name, paper, " | ".join(cells)))
        claims_json.append(entry)

    command = "/usr/bin/python3 scripts/paper_experiments.py " + " ".join(sys.argv[1:])
    text = "\n".join(
        ["# The paper's experiments, reproduced by mjslam", "",
         "Command: `%s` (%.0f s wall). Models: %s (configs/M.yaml as shipped). Figures in "
         "figures/. Processing times: the cost model's (control.processing: model)." % (
             command.strip(), time.monotonic() - start, ", ".join(args.models)), ""] + table +
        ["", "Figs. 4(c)-(d) at scale: configs/default.yaml, slam.timing realtime, the world's "
         "tour.", ""] + scale_lines) + "\n"
    with open(os.path.join(args.out, "claims.md"), "w") as f:
        f.write(text)
    with open(os.path.join(args.out, "claims.json"), "w") as f:
        json.dump({"claims": claims_json,
                   "studies": {m: results[m]["studies"] for m in args.models}}, f, indent=1)
    print(text)
    if args.readme:
        write_readme_table(args.readme, results, args.models, command.strip())


README_BEGIN = "<!-- claims table: made by scripts/paper_experiments.py --readme; do not edit -->\n"
README_END = "<!-- end of claims table -->\n"


def short(text):
    """The first part of a claim's figures (up to its first ';'), for the README."""
    first = text.split("; ")[0]
    return first if len(first) <= 200 else first[:197] + "..."


def write_readme_table(path, results, models, command):
    """Replaces the table between the README's claims markers with verdicts and
    their first figures, dated and with the commit of the program."""
    with open(path) as f:
        readme = f.read()
    if README_BEGIN not in readme or README_END not in readme:
        raise SystemExit("%s: no claims markers ('%s' ... '%s')" % (
            path, README_BEGIN.strip(), README_END.strip()))
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip() or "unknown"
    lines = ["Made on %s at commit %s by `%s --readme README.md`." % (
        time.strftime("%Y-%m-%d", time.gmtime()), commit, command.split(" --readme")[0]), "",
             "| Claim of the paper | " + " | ".join("%s model" % m for m in models) + " |",
             "|---|" + "---|" * len(models)]
    for name, _, judge in CLAIMS:
        cells = []
        for m in models:
            text, verdict = judge(results[m])
            cells.append("**%s**: %s" % (verdict, short(text)))
        lines.append("| %s | %s |" % (name, " | ".join(cells)))
    begin = readme.index(README_BEGIN) + len(README_BEGIN)
    end = readme.index(README_END)
    with open(path + ".tmp", "w") as f:
        f.write(readme[:begin] + "\n".join(lines) + "\n" + readme[end:])
    os.replace(path + ".tmp", path)


if __name__ == "__main__":
    main()
