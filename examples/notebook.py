#!/usr/bin/python3
# %% [markdown]
# # mjslam from Python, a notebook
#
# Each `# %%` cell runs in Jupyter or VS Code as it is; the whole file also runs as a script:
#
#     PYTHONPATH=build/python:examples /usr/bin/python3 examples/notebook.py --out runs/notebook
#
# It steps the closed loop of the default config from Python, then runs a filter written in
# Python (examples/dead_reckoning_filter.py) beside the paper's two, and plots what each filter
# made of the same run. `python/README.md` is the reference.

# %%
import argparse
import os

import matplotlib
matplotlib.use("Agg")  # files, no window: a script on a headless machine
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import mjslam  # noqa: E402
from dead_reckoning_filter import DeadReckoningFilter  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("--out", default="runs/notebook", help="folder for the run and the figure")
parser.add_argument("--duration", type=float, default=120.0, help="simulated seconds")
args, _ = parser.parse_known_args()  # a notebook kernel passes arguments of its own
REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONFIG = os.path.join(REPOSITORY, "configs", "default.yaml")
os.makedirs(args.out, exist_ok=True)

# %% [markdown]
# ## A config, resolved
# `load_config` gives every key as the run will see it (`mjslam config` prints the same).

# %%
config = mjslam.load_config(CONFIG, ["run.duration_s=%g" % args.duration])
print("world:", os.path.basename(config["run"]["world"]),
      "| laser:", config["laser"]["num_beams"], "beams at", config["laser"]["rate_hz"], "Hz",
      "| the explorer drives from:", config["control"]["pose_source"])

# %% [markdown]
# ## The closed loop, one step at a time
# A `Loop` is `mjslam run`'s loop without its files. Each step returns the record the filters
# ran on and trajectory.csv's row; the loop gives each filter's pose, covariance and map as
# numpy arrays. Here: the selective filter's error and its 2-sigma bound along x.

# %%
loop = mjslam.Loop(CONFIG, ["run.duration_s=%g" % args.duration])
t, error_x, bound_x = [], [], []
for step in loop:
    estimate = loop.pose("selective")
    t.append(step.t)
    error_x.append(estimate[0] - step.true_pose[0])
    bound_x.append(2.0 * np.sqrt(loop.covariance("selective")[0, 0]))
inside = np.mean(np.abs(error_x) <= np.array(bound_x))
print("%d steps, %.1f%% explored; selective x inside 2 sigma for %.3f of the steps; %d features"
      % (loop.steps, 100 * step.explored, inside, loop.num_features("selective")))

# %% [markdown]
# ## A filter of your own, beside the paper's two
# `register_filter` makes a Python class a filter kind; `slam.filters` then names it like the
# C++ kinds. `mjslam.run` writes the run directory, with the Python filter's columns, map and
# summary by its name, and evaluates it as `mjslam run` does.

# %%
mjslam.register_filter("py_dead_reckoning", DeadReckoningFilter)
run_dir = os.path.join(args.out, "run")
result = mjslam.run(CONFIG, [
    "run.duration_s=%g" % args.duration, "render.enabled=false",
    "slam.filters=[{name: classical, kind: ekf, update: classical},"
    " {name: selective, kind: ekf, update: selective},"
    " {name: dead_reckoning, kind: py_dead_reckoning}]"], out=run_dir)
print(run_dir, result["status"], result["steps"], "steps")

# %% [markdown]
# ## The run directory as numpy arrays
# `read_run` reads any run directory (this one, or one `mjslam run` wrote).

# %%
run = mjslam.read_run(run_dir)
figure, axes = plt.subplots(1, 2, figsize=(11, 4))
for name in run.filter_names:
    errors = run.errors(name)
    axes[0].plot(run.trajectory["t"], np.hypot(errors[:, 0], errors[:, 1]), label=name)
    axes[1].plot(run.trajectory["t"], run.nees(name), label=name)
    print("%-15s mean position error %.4f m, x inside 2 sigma for %.3f of the steps"
          % (name, np.mean(np.hypot(errors[:, 0], errors[:, 1])),
             run.summary["filters"][name]["inside_2sigma"]["x"]))
axes[0].set(xlabel="t (s)", ylabel="position error (m)", yscale="log", title="Error")
axes[1].set(xlabel="t (s)", ylabel="pose NEES (3 dof)", yscale="log", title="NEES")
axes[0].legend()
figure.tight_layout()
figure.savefig(os.path.join(args.out, "errors.png"), dpi=90)
print("wrote", os.path.join(args.out, "errors.png"))
