#!/usr/bin/python3
"""What stepping the closed loop from Python costs over the C++ loop, per control step.

The same config is run side by side, alternately, --repeats times each way: mjslam.Loop.run()
(every step in C++), a Python loop of Loop.step() (`for step in loop`), and a Python loop that
also reads every filter's pose and covariance and the step's trajectory row, as a notebook
would. The runs are identical (same seed): only the stepping differs. Prints, per step, the
median over the repeats of: the process's CPU time; its difference from the C++ loop's (side by
side, so within the machine's noise); and the CPU time outside the C++ steps (the process's
less Loop.cpu, the steps' own CPU time by phase): what the stepping itself adds, free of the
noise in the steps' work.

    PYTHONPATH=build/python /usr/bin/python3 scripts/python_step_overhead.py \
        [--config configs/default.yaml] [--duration 120] [--repeats 5]
"""

import argparse
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "build", "python"))
import mjslam  # noqa: E402


def cpp_loop(loop):
    loop.run()


def python_loop(loop):
    for _ in loop:
        pass


def python_loop_reading(loop):
    names = loop.filter_names
    for step in loop:
        step.row
        for name in names:
            loop.pose(name)
            loop.covariance(name)


WAYS = (("C++ loop (Loop.run)", cpp_loop), ("Python loop of Loop.step", python_loop),
        ("Python loop, reading poses, covariances, row", python_loop_reading))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--config", default="configs/default.yaml")
    parser.add_argument("--duration", type=float, default=120.0)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--set", action="append", default=[], help="another config override")
    args = parser.parse_args()
    overrides = ["run.duration_s=%g" % args.duration, "render.enabled=false"] + args.set
    seconds = {name: [] for name, _ in WAYS}
    outside = {name: [] for name, _ in WAYS}
    steps = None
    for _ in range(args.repeats):
        for name, way in WAYS:
            loop = mjslam.Loop(args.config, overrides)
            start = time.process_time()
            way(loop)
            seconds[name].append(time.process_time() - start)
            outside[name].append(seconds[name][-1] - sum(loop.cpu.values()))
            assert steps in (None, loop.steps)
            steps = loop.steps
    base = statistics.median(seconds[WAYS[0][0]]) / steps
    print("%s, %s, %d steps, median of %d repeats, CPU time per step:"
          % (args.config, " ".join(overrides), steps, args.repeats))
    print("  %-46s %9s %10s %13s" % ("", "total", "- C++ loop", "outside steps"))
    for name, _ in WAYS:
        per_step = statistics.median(seconds[name]) / steps
        print("  %-46s %6.1f us %+7.1f us %10.1f us"
              % (name, per_step * 1e6, (per_step - base) * 1e6,
                 statistics.median(outside[name]) / steps * 1e6))


if __name__ == "__main__":
    main()
