#!/usr/bin/env python3
"""Plots and index.html of an mjslam run directory or sweep directory.

    python3 renders/report.py run RUN_DIR
    python3 renders/report.py sweep SWEEP_DIR

Called by `mjslam render` (and `mjslam run` when render.enabled), with
/usr/bin/python3. Reads the files described in docs/run_directory.md with
python/mjslam; the columns the
closed-loop integration adds (explored, f_period, f_open_loop, f_nees) and the files
summary.json, explorer.csv, nees.csv, divergence.csv are optional. Every
output is written to a temporary name and renamed. Exits 1 with a message
naming the file on bad input.
"""
import html
import itertools
import math
import os
import signal
import sys

# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "python"))
import mjslam  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")  # no display
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

# The renders' colours (renders/scene_renderer.h, namespace colors).
COLORS = {"truth": "#0d0d0d", "classical": "#ff8000", "selective": "#0066ff"}
FILTERS = mjslam.FILTER_NAMES  # the default filters (the paper's scripts use them)
# Any other filter's colour, in turn (renders/filter_colors.cc, FilterColors).
OTHER_COLORS = ("#009999", "#8c4d1a", "#808c00", "#f266a6", "#808080")


def filters_of(table, suffix):
    """The filters of a trajectory (suffix "x") or nees table (suffix "anees"): the prefixes f of
    its f_<suffix> columns, in order, other than true and odom."""
    names = [c[:-len(suffix) - 1] for c in table.columns if c.endswith("_" + suffix)]
    return [f for f in names if f not in ("true", "odom")]


def colors_of(names):
    """Each filter's colour: classical and selective their own, the others OTHER_COLORS in turn."""
    others = itertools.cycle(OTHER_COLORS)
    return {f: COLORS[f] if f in FILTERS else next(others) for f in names}
DPI = 100


def remove_quietly(path):
    try:
        os.remove(path)
    except OSError:
        pass


def save(fig, path):
    """Saves a figure atomically (temporary name, then rename); an error or a
    stop (SIGTERM, Ctrl-C) leaves no temporary file."""
    temp = path + ".tmp.png"
    try:
        fig.savefig(temp, dpi=DPI, format="png", metadata={"Software": None})
        plt.close(fig)
        os.replace(temp, path)
    except BaseException:
        remove_quietly(temp)
        raise


def write_text(path, text):
    temp = path + ".tmp"
    try:
        with open(temp, "w") as f:
            f.write(text)
        os.replace(temp, path)
    except BaseException:
        remove_quietly(temp)
        raise


def wrap(angle):
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def plot_pose_errors(traj, path):
    """Pose error per component against +-2 sigma, both filters (Fig. 3c-e)."""
    t = traj["t"]
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    components = (("x", "pxx", "x error (m)"), ("y", "pyy", "y error (m)"),
                  ("th", "pthth", "heading error (rad)"))
    names = filters_of(traj, "x")
    colors = colors_of(names)
    for ax, (c, var, label) in zip(axes, components):
        for f in names:
            err = [e - g for e, g in zip(traj[f"{f}_{c}"], traj[f"true_{c}"])]
            if c == "th":
                err = [wrap(e) for e in err]
            bound = [2.0 * math.sqrt(max(v, 0.0)) for v in traj[f"{f}_{var}"]]
            ax.plot(t, err, color=colors[f], lw=1.2, label=f"{f} error")
            ax.plot(t, bound, color=colors[f], lw=0.9, ls="--", label=f"{f} ±2σ")
            ax.plot(t, [-b for b in bound], color=colors[f], lw=0.9, ls="--")
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0].legend(loc="upper left", ncol=2, fontsize=8)
    axes[0].set_title("Pose error of each filter and its ±2σ bound")
    axes[-1].set_xlabel("time (s)")
    fig.tight_layout()
    save(fig, path)


def plot_processing(traj, path):
    """Accumulated processing time of both filters (Fig. 4c)."""
    t = traj["t"]
    fig, ax = plt.subplots(figsize=(8, 4))
    names = filters_of(traj, "x")
    colors = colors_of(names)
    for f in names:
        total, acc = 0.0, []
        for us in traj[f"{f}_us"]:
            total += 0.0 if math.isnan(us) else us * 1e-6
            acc.append(total)
        ax.plot(t, acc, color=colors[f], lw=1.5, label=f)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("accumulated processing time (s)")
    ax.set_title("Accumulated processing time, measured on this machine\n(feature extraction + filter step)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left")
    fig.tight_layout()
    save(fig, path)


def plot_open_loop(traj, path):
    """Accumulated open-loop time, f_open_loop (Fig. 4d)."""
    t = traj["t"]
    fig, ax = plt.subplots(figsize=(8, 4))
    names = filters_of(traj, "x")
    colors = colors_of(names)
    for f in names:
        ax.plot(t, traj[f"{f}_open_loop"], color=colors[f], lw=1.5, label=f)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("accumulated open-loop time (s)")
    ax.set_title("Accumulated open-loop time (command period beyond 0.1 s)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left")
    fig.tight_layout()
    save(fig, path)


def plot_explored(traj, path):
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(traj["t"], [100.0 * e for e in traj["explored"]], color=COLORS["truth"], lw=1.5,
            label="explored")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("explored free area (%)")
    ax.set_ylim(0, 105)
    ax.set_title("Explored fraction of the reachable free area")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right")
    fig.tight_layout()
    save(fig, path)


def plot_nees(nees, path, where=""):
    """Average NEES with its chi-square bounds over time (a consistency test; not a figure of the
    paper)."""
    fig, ax = plt.subplots(figsize=(8, 4))
    t = nees["t"]
    names = filters_of(nees, "anees")
    colors = colors_of(names)
    for f in names:
        ax.plot(t, nees[f"{f}_anees"], color=colors[f], lw=1.2, label=f"{f} ANEES")
    ax.plot(t, nees["lower"], color="0.3", lw=1.0, ls="--", label="95 % bounds")
    ax.plot(t, nees["upper"], color="0.3", lw=1.0, ls="--")
    n_runs = [n for n in nees["n_runs"] if not math.isnan(n)]
    ax.set_xlabel("time (s)")
    ax.set_ylabel("average pose NEES (3 dof)")
    ax.set_yscale("log")
    # Plain numbers on the log axis (not 4x10^0).
    plain = matplotlib.ticker.FuncFormatter(lambda value, _: f"{value:g}")
    ax.yaxis.set_major_formatter(plain)
    # Minor ticks labelled only where the axis spans about a decade; over several decades their
    # labels would overlap.
    low, high = ax.get_ylim()
    if high <= 20.0 * low:
        ax.yaxis.set_minor_formatter(plain)
        ax.tick_params(axis="y", which="minor", labelsize=7)
    else:
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_title(f"Average NEES over {int(max(n_runs)) if n_runs else 0} runs{where}\n"
                 "(a consistency test, not a figure of the paper)")
    ax.grid(True, alpha=0.3, which="both")
    ax.legend(loc="best")
    fig.tight_layout()
    save(fig, path)


def plot_divergence(div, path):
    """Divergence mean and variance against #E of every pair (the paper's Figs. 6 and 7 together;
    scripts/paper_experiments.py draws them apart)."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    pairs = sorted(set(div["pair"]))
    try:
        first, second = mjslam.divergence_pair(div)
        names = {f"{first}_{second}": f"{first} vs {second}",
                 f"{second}_{first}": f"{second} vs {first}",
                 f"{first}_truth": f"{first} vs truth", f"{second}_truth": f"{second} vs truth"}
    except mjslam.RunFormatError:  # not every row there: labels split at each '_'
        names = {}
    for ax, key in zip(axes, ("mean", "variance")):
        for pair in pairs:
            rows = sorted((n, v) for n, v, p in zip(div["num_points"], div[key], div["pair"]) if p == pair)
            ax.plot([r[0] for r in rows], [r[1] for r in rows], marker="o", ms=3, lw=1.2,
                    label=names.get(pair, pair.replace("_", " vs ")))
        ax.set_xscale("log")
        ax.set_xlabel("#E (Monte Carlo points)")
        ax.set_ylabel(f"divergence {key} (nats)" if key == "mean" else "divergence variance (nats²)")
        ax.grid(True, alpha=0.3, which="both")
    axes[0].legend(fontsize=8)
    fig.suptitle("Map divergence (KL) between the filters' maps and to the ground truth "
                 "(paper Figs. 6 and 7 together)")
    fig.tight_layout()
    save(fig, path)


PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: sans-serif; margin: 1.5em; max-width: 1100px; color: #222; }}
table {{ border-collapse: collapse; margin: 0.5em 0 1em; }}
td, th {{ border: 1px solid #ccc; padding: 0.2em 0.6em; text-align: left; font-size: 0.9em; }}
img, video {{ max-width: 100%; border: 1px solid #ddd; margin: 0.3em 0; }}
</style></head>
<body data-status="loading">
<h1>{title}</h1>
{body}
<script>
// Marks the page: data-status="ok" once every image has pixels and the video
// its metadata, "error: ..." otherwise (checked by the tests in headless
// Chromium).
(function () {{
  var problems = [];
  window.addEventListener("error", function (e) {{ problems.push("script: " + e.message); }});
  function check() {{
    var waits = [];
    Array.prototype.forEach.call(document.images, function (img) {{
      waits.push(new Promise(function (done) {{
        function look() {{ if (img.naturalWidth === 0) problems.push("image: " + img.getAttribute("src")); done(); }}
        if (img.complete) look(); else {{ img.onload = look; img.onerror = look; }}
      }}));
    }});
    Array.prototype.forEach.call(document.querySelectorAll("video"), function (v) {{
      waits.push(new Promise(function (done) {{
        if (v.readyState >= 1) {{ done(); return; }}
        v.addEventListener("loadedmetadata", function () {{ done(); }});
        v.addEventListener("error", function () {{ problems.push("video: " + v.getAttribute("src")); done(); }});
        setTimeout(function () {{ if (v.readyState < 1) problems.push("video timeout: " + v.getAttribute("src")); done(); }}, 5000);
      }}));
    }});
    Promise.all(waits).then(function () {{
      document.body.setAttribute("data-status", problems.length ? "error: " + problems.join("; ") : "ok");
    }});
  }}
  if (document.readyState === "complete") check(); else window.addEventListener("load", check);
}})();
</script>
</body></html>
"""


def table(rows):
    cells = "".join(f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(str(v))}</td></tr>" for k, v in rows)
    return f"<table>{cells}</table>"


def flatten(prefix, value, out):
    if isinstance(value, dict):
        for k, v in value.items():
            flatten(f"{prefix}.{k}" if prefix else k, v, out)
    else:
        if isinstance(value, float):
            value = f"{value:.6g}"
        out.append((prefix, value))


def summary_rows(directory):
    for name in (mjslam.SUMMARY_FILE, mjslam.MANIFEST_FILE):
        path = os.path.join(directory, name)
        if os.path.exists(path):
            data = mjslam.read_json_object(path)
            if name == mjslam.MANIFEST_FILE:
                keep = ("status", "seed", "world_file", "sim_time_s", "steps", "mjslam_version",
                        "git_commit", "mujoco_version", "start_time", "end_time", "error")
                data = {k: data[k] for k in keep if k in data}
            rows = []
            flatten("", data, rows)
            return name, rows
    return None, []


def links(directory, names):
    items = "".join(f'<li><a href="{html.escape(n)}">{html.escape(n)}</a></li>' for n in names)
    return f"<ul>{items}</ul>"


def data_files(directory):
    return sorted(n for n in os.listdir(directory)
                  if n.endswith((".csv", ".json", ".yaml")) and ".tmp" not in n)


def run_report(directory):
    traj = mjslam.read_run(directory).trajectory
    plots = [("plot_pose_error.png", "Pose error and ±2σ bounds (paper Fig. 3c-e)", plot_pose_errors),
             ("plot_processing_time.png", "Accumulated processing time (Fig. 4c)", plot_processing)]
    if all(f"{f}_open_loop" in traj for f in filters_of(traj, "x")):
        plots.append(("plot_open_loop_time.png", "Accumulated open-loop time (Fig. 4d)", plot_open_loop))
    if "explored" in traj:
        plots.append(("plot_explored.png", "Explored fraction", plot_explored))
    body = []
    source, rows = summary_rows(directory)
    if rows:
        body.append(f"<h2>Summary ({source})</h2>" + table(rows))
    if os.path.exists(os.path.join(directory, "final.png")):
        body.append('<h2>The whole run</h2><img src="final.png" alt="final image of the run">')
    if os.path.exists(os.path.join(directory, "video.mp4")):
        body.append('<h2>Video</h2><video src="video.mp4" controls muted preload="metadata"></video>')
    body.append("<h2>Plots</h2>")
    for name, caption, draw in plots:
        draw(traj, os.path.join(directory, name))
        body.append(f'<h3>{html.escape(caption)}</h3><img src="{name}" alt="{html.escape(caption)}">')
    body.append("<h2>Files</h2>" + links(directory, data_files(directory)))
    title = "mjslam run " + os.path.basename(os.path.abspath(directory))
    write_text(os.path.join(directory, "index.html"), PAGE.format(title=html.escape(title), body="\n".join(body)))


def sweep_report(directory):
    body = []
    source, rows = summary_rows(directory)
    if rows:
        body.append(f"<h2>Summary ({source})</h2>" + table(rows))
    sweep = mjslam.read_sweep(directory)
    body.append("<h2>Plots</h2>")
    if sweep.has(mjslam.NEES_FILE):
        plot_nees(sweep.nees, os.path.join(directory, "plot_nees.png"))
        body.append('<h3>Average NEES and 95 % bounds (not a figure of the paper)</h3><img src="plot_nees.png" alt="average NEES">')
    if sweep.divergence is not None:
        plot_divergence(sweep.divergence, os.path.join(directory, "plot_divergence.png"))
        body.append('<h3>Divergence against #E (paper Figs. 6 and 7 together)</h3><img src="plot_divergence.png" alt="divergence">')
    runs_dir = os.path.join(directory, mjslam.SWEEP_RUNS_FOLDER)
    if os.path.isdir(runs_dir):
        items = []
        for name in sorted(os.listdir(runs_dir)):
            page = os.path.join("runs", name, "index.html")
            target = page if os.path.exists(os.path.join(directory, page)) else os.path.join("runs", name)
            items.append(f'<li><a href="{html.escape(target)}">{html.escape(name)}</a></li>')
        body.append("<h2>Runs</h2><ul>" + "".join(items) + "</ul>")
    body.append("<h2>Files</h2>" + links(directory, data_files(directory)))
    title = "mjslam sweep " + os.path.basename(os.path.abspath(directory))
    write_text(os.path.join(directory, "index.html"), PAGE.format(title=html.escape(title), body="\n".join(body)))


def main(argv):
    if len(argv) != 3 or argv[1] not in ("run", "sweep"):
        print(__doc__, file=sys.stderr)
        return 2
    try:
        (run_report if argv[1] == "run" else sweep_report)(argv[2])
    except (OSError, ValueError, KeyError) as error:
        print(f"report.py: {argv[2]}: {error}", file=sys.stderr)
        return 1
    return 0


def stop(signum, frame):
    """SIGTERM (mjslam stopping): unwind, so that temporary files are removed."""
    sys.exit(130)


if __name__ == "__main__":
    signal.signal(signal.SIGTERM, stop)
    sys.exit(main(sys.argv))
