#!/usr/bin/python3
"""What running several filters on one closed loop costs against running each alone.

Runs examples/selection_policies.yaml (six filters: the classical EKF and the selective one
under five selection policies) with the explorer on odometry, so that every run drives the same
path whatever its filters; then the same config with each filter alone. From each loop's CPU
time by phase (mjslam.Loop.cpu), prints the six-filter run's filters phase against the sum of the
single-filter runs' filters phases, and the rest of the step (physics, laser, odometry, coverage,
driver) of each. Repeated --repeats times alternately; medians.

    PYTHONPATH=build/python /usr/bin/python3 scripts/filter_bank_cost.py [--duration 120]
"""

import argparse
import os
import statistics
import sys

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPOSITORY, "build", "python"))
import mjslam  # noqa: E402

CONFIG = os.path.join(REPOSITORY, "examples", "selection_policies.yaml")
FILTERS = ["{name: classical, update: classical}"] + [
    "{name: %s, update: selective, selection_policy: %s}" % (policy, policy)
    for policy in ("criterion", "first", "random", "least_informative", "determinant")]


def cpu_of(overrides):
    loop = mjslam.Loop(CONFIG, overrides)
    loop.run()
    cpu = loop.cpu
    return cpu["filters"], sum(cpu.values()) - cpu["filters"], loop.steps


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=120.0)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    common = ["run.duration_s=%g" % args.duration, "render.enabled=false",
              "control.pose_source=odometry"]
    together, rest_together, alone, rest_alone = [], [], [[] for _ in FILTERS], []
    for _ in range(args.repeats):
        filters_s, rest_s, steps = cpu_of(common)
        together.append(filters_s)
        rest_together.append(rest_s)
        for i, entry in enumerate(FILTERS):
            filters_s, rest_s, single_steps = cpu_of(common + ["slam.filters=[%s]" % entry])
            assert single_steps == steps
            alone[i].append(filters_s)
            rest_alone.append(rest_s)
    sum_alone = sum(statistics.median(a) for a in alone)
    print("examples/selection_policies.yaml, explorer on odometry, %d steps, %d repeats "
          "(medians, CPU seconds):" % (steps, args.repeats))
    for entry, a in zip(FILTERS, alone):
        name = entry.split(",")[0].split(": ")[1]
        print("  %-17s alone: filters %.3f" % (name, statistics.median(a)))
    print("  sum of the six alone: filters %.3f; the rest of a step, per run: %.3f"
          % (sum_alone, statistics.median(rest_alone)))
    print("  the six together:     filters %.3f; the rest: %.3f"
          % (statistics.median(together), statistics.median(rest_together)))
    print("  together / sum alone (filters): %.2f" % (statistics.median(together) / sum_alone))


if __name__ == "__main__":
    main()
