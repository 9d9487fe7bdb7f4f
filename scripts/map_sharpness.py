#!/usr/bin/python3
"""How sharp the map of an imported run is with each trajectory (docs/real_data.md).

Places every scan's returns (ranges below the maximum) with the odometry's,
the classical filter's, the selective filter's and (when the run has one) the
reference's pose at the scan, and
counts the grid cells (CELL metres, default 0.05) they fall in: the same
points on fewer cells is a sharper map (walls seen twice land on the same
cells). Prints also each path's length and the distance and heading between
its first and last pose (whether the path closes) and, with a reference, the
mean and largest distance of each pose from the reference's at the scan.

Usage: scripts/map_sharpness.py RUN_DIR [CELL]   (reads the run with python/mjslam: Debian's
Python 3 with numpy, /usr/bin/python3)
"""
import math
import os
import sys

# python/mjslam, the reader of run directories, found from this file: no build, no PYTHONPATH.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "python"))
import mjslam  # noqa: E402


def main():
    path = sys.argv[1]
    cell = float(sys.argv[2]) if len(sys.argv) > 2 else 0.05
    run = mjslam.read_run(path)
    manifest = run.manifest
    mount = manifest["laser_mount"]  # the laser in frame R
    angle_min = math.radians(manifest["angle_min_deg"])
    step = math.radians(manifest["angle_step_deg"])
    max_range = manifest["max_range_m"]
    n = manifest["num_beams"]
    # The fan of config.laser is centred on the mount's x axis: beam b at
    # -fov/2 + b step in S (the mount's turn holds the log's own offset).
    half_fov = 0.5 * (n - 1) * step
    # Each source's poses, by the row of trajectory.csv (the step at a scan's time).
    row_at = {t: i for i, t in enumerate(run.trajectory["t"].tolist())}
    sources = ["odom", "classical", "selective"]
    poses = {s: run.poses(s).tolist() for s in sources}
    reference = run.reference
    if reference is not None:  # the log's own estimate, at the scans, in frame R
        poses["reference"] = {row_at[t]: pose for t, pose in zip(
            reference["t"].tolist(),
            zip(reference["x"].tolist(), reference["y"].tolist(), reference["th"].tolist()))}
        sources.append("reference")
    cells = {s: set() for s in sources}
    paths = {s: [] for s in sources}
    points = 0
    scans = run.scans
    for t, ranges in zip(scans.t.tolist(), scans.ranges[:, :n].tolist()):
        row = row_at[t]
        for s in sources:
            x, y, th = poses[s][row]
            paths[s].append((x, y, th))
            c, si = math.cos(th), math.sin(th)
            sx = x + c * mount["x"] - si * mount["y"]
            sy = y + si * mount["x"] + c * mount["y"]
            sth = th + mount["th"]
            for b, r in enumerate(ranges):
                if not r < max_range:
                    continue
                a = sth - half_fov + b * step
                cells[s].add((math.floor((sx + r * math.cos(a)) / cell),
                              math.floor((sy + r * math.sin(a)) / cell)))
        points += sum(1 for r in ranges if r < max_range)
    print(f"{path}: {points} returns of {len(paths['odom'])} scans on {cell:.2f} m cells")
    print("trajectory   cells    returns/cell   path m   first-to-last m   heading deg"
          "   from the reference m (mean / max)")
    for s in sources:
        p = paths[s]
        length = sum(math.dist(a[:2], b[:2]) for a, b in zip(p, p[1:]))
        gap = math.dist(p[0][:2], p[-1][:2])
        turn = math.degrees(math.atan2(math.sin(p[-1][2] - p[0][2]), math.cos(p[-1][2] - p[0][2])))
        line = (f"{s:10s} {len(cells[s]):7d}   {points / len(cells[s]):10.2f}   {length:8.1f}   "
                f"{gap:10.2f}        {turn:7.1f}")
        if "reference" in paths:
            d = [math.dist(a[:2], b[:2]) for a, b in zip(p, paths["reference"])]
            line += f"        {sum(d) / len(d):6.2f} / {max(d):6.2f}"
        print(line)


if __name__ == "__main__":
    main()
