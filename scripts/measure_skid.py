#!/usr/bin/python3
"""Measures the robot's sideways skid in turns from the true motion of runs,
the figure behind slam.ekf.lateral_skid_s (docs/method.md, departure 13).

    scripts/measure_skid.py RUN_DIR [RUN_DIR ...] [--offset A]

For every step of each run's trajectory.csv, the axle centre (A metres
behind R, default 0.2 = robot.control_point_offset_m) moves by (fwd, lat)
along and across its mid-arc heading, while the heading changes by dth. A
unicycle has lat = 0; a skidding one lat = -c v w dt with v = fwd / dt and
w = dth / dt, the true speeds. Prints c by least squares over all steps,
the skid before and after removing c v w dt (rms, mm per step), and what is
left per radian turned, which lateral_slip_std_m_per_rad must cover. Reads
the runs with python/mjslam (Debian's Python 3 with numpy).
"""
import argparse
import math
import os
import sys

# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "python"))
import mjslam  # noqa: E402


def axle_motion(x0, y0, th0, x1, y1, th1, offset):
    """(chord, dth, lateral) of the axle centre (`offset` metres behind R)
    between two poses of R: its motion along and across the mid-arc heading,
    and the heading change."""
    dx = (x1 - offset * math.cos(th1)) - (x0 - offset * math.cos(th0))
    dy = (y1 - offset * math.sin(th1)) - (y0 - offset * math.sin(th0))
    dth = math.remainder(th1 - th0, 2.0 * math.pi)
    mid = th0 + 0.5 * dth
    return dx * math.cos(mid) + dy * math.sin(mid), dth, -dx * math.sin(mid) + dy * math.cos(mid)


def steps(run, offset):
    """(fwd, lat, dth, dt) of the axle centre for each step of a run's trajectory (its times
    increase: the reader checks them)."""
    times = run.trajectory["t"].tolist()
    poses = run.poses("true").tolist()
    for t0, t1, pose0, pose1 in zip(times, times[1:], poses, poses[1:]):
        dt = t1 - t0
        fwd, dth, lat = axle_motion(*pose0, *pose1, offset)
        yield fwd, lat, dth, dt


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("runs", nargs="+", help="run directories (with trajectory.csv)")
    parser.add_argument("--offset", type=float, default=0.2,
                        help="distance from the axle centre to R, metres")
    args = parser.parse_args()

    data = []
    for run in args.runs:
        run = mjslam.read_run(run)
        if not run.has(mjslam.TRAJECTORY_FILE):
            print(f"{run.file(mjslam.TRAJECTORY_FILE)}: no such file", file=sys.stderr)
            return 2
        data.extend(steps(run, args.offset))
    if not data:
        print("no steps", file=sys.stderr)
        return 2
    # lat = -c * (fwd / dt) * (dth / dt) * dt = -c * fwd * dth / dt
    xs = [-fwd * dth / dt for fwd, _, dth, dt in data]
    ys = [lat for _, lat, _, _ in data]
    sxx = sum(x * x for x in xs)
    if sxx == 0.0:
        print("no turns while moving: c is undetermined", file=sys.stderr)
        return 2
    c = sum(x * y for x, y in zip(xs, ys)) / sxx
    residuals = [y - c * x for x, y in zip(xs, ys)]
    n = len(data)

    def rms(values):
        return math.sqrt(sum(v * v for v in values) / len(values))

    print(f"steps: {n} from {len(args.runs)} runs")
    print(f"c = {c:.5f} s  (sideways speed of the axle, outward, = c v w)")
    print(f"sideways motion per step: rms {1000 * rms(ys):.4f} mm; "
          f"after removing c v w dt: rms {1000 * rms(residuals):.4f} mm, "
          f"largest {1000 * max(abs(r) for r in residuals):.4f} mm")
    print("left over per radian turned (by |dth| per step):")
    bins = {}
    for (_, _, dth, _), r in zip(data, residuals):
        bins.setdefault(min(int(abs(dth) / 0.02), 6), []).append((r, abs(dth)))
    for key in sorted(bins):
        values = bins[key]
        mean_turn = sum(t for _, t in values) / len(values)
        label = f"{0.02 * key:.2f}-{0.02 * (key + 1):.2f}" if key < 6 else ">= 0.12"
        print(f"  |dth| {label} rad: {len(values):6d} steps, rms {1000 * rms([r for r, _ in values]):.4f} mm, "
              f"{1000 * rms([r for r, _ in values]) / max(mean_turn, 1e-9):.2f} mm/rad")
    return 0


if __name__ == "__main__":
    sys.exit(main())
