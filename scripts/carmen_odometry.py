#!/usr/bin/env python3
"""What the ODOM lines of a corrected CARMEN log are (docs/real_data.md).

The corrected logs re-anchor their odometry at every kept scan: after scan k
the ODOM lines continue from the scan's corrected pose C_k,
o(t) = C_k (+) (R(t_k)^-1 (+) R(t)), with R the robot's raw odometry. This
script checks that, rebuilds R by chaining the increments within each
segment, and prints, for the rebuilt raw odometry and for the ODOM pose
logged at each scan (what a reader that takes the ODOM lines at face value
gets), the error of the relative motion against the corrected poses over
windows of about 1, 10, 100 and 1000 s, and the noise of the increments
between consecutive scans.

Usage: scripts/carmen_odometry.py LOG.gz   (Python 3, standard library only)
"""
import gzip
import math
import statistics
import sys


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


def compose(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap(a[2] + b[2]))


def inverse(a):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2])


def between(a, b):
    return compose(inverse(a), b)


def read(path):
    """Scans (t, corrected pose, logged ODOM pose at the scan, raw pose at the scan)."""
    opener = gzip.open if path.endswith(".gz") else open
    raw = (0.0, 0.0, 0.0)
    anchor = None  # the pose the current segment's ODOM lines start from
    last_odom = None  # (t, pose) of the last ODOM line with a timestamp
    scans = []
    steps_in_segment = []  # (|step| m, step direction - heading) within segments
    first = True
    with opener(path, "rt") as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == "ODOM":
                t = float(w[7])
                pose = (float(w[1]), float(w[2]), float(w[3]))
                if t == 0.0:
                    continue  # the corrected pose again
                if first:
                    anchor, first = pose, False
                raw = compose(raw, between(anchor, pose))
                d = between(anchor, pose)
                if math.hypot(d[0], d[1]) > 0.02:
                    steps_in_segment.append(
                        (math.hypot(d[0], d[1]), wrap(math.atan2(d[1], d[0]) - d[2] / 2)))
                anchor = pose
                last_odom = (t, pose)
            elif w[0] == "FLASER":
                n = int(w[1])
                t = float(w[-3])
                corrected = (float(w[n + 5]), float(w[n + 6]), float(w[n + 7]))
                logged = last_odom[1] if last_odom and last_odom[0] == t else None
                scans.append((t, corrected, logged, raw))
                anchor = corrected
    return scans, steps_in_segment


def window_errors(scans, which, window_s):
    """Relative-motion errors against the corrected poses for scan pairs about window_s apart."""
    errs_t, errs_r, lengths = [], [], []
    j = 0
    for i in range(len(scans)):
        while j < len(scans) and scans[j][0] - scans[i][0] < window_s:
            j += 1
        if j == len(scans):
            break
        if scans[j][0] - scans[i][0] > 1.5 * window_s + 1.0:
            continue
        a, b = scans[i][which], scans[j][which]
        if a is None or b is None:
            continue
        d = between(a, b)
        ref = between(scans[i][1], scans[j][1])
        errs_t.append(math.hypot(d[0] - ref[0], d[1] - ref[1]))
        errs_r.append(abs(wrap(d[2] - ref[2])))
        lengths.append(math.hypot(ref[0], ref[1]))
    return errs_t, errs_r, lengths


def main():
    scans, steps = read(sys.argv[1])
    print(f"{sys.argv[1]}: {len(scans)} scans over {scans[-1][0] - scans[0][0]:.0f} s")
    side = [abs(s[1]) for s in steps]
    print(f"within segments: {len(steps)} ODOM steps > 2 cm; |direction - heading| "
          f"median {math.degrees(statistics.median(side)):.2f} deg, "
          f"95th percentile {math.degrees(sorted(side)[int(0.95 * len(side))]):.2f} deg")
    end_err = [(s[3], s[1]) for s in (scans[-1],)][0]
    path = sum(math.hypot(*between(a[1], b[1])[:2]) for a, b in zip(scans, scans[1:]))
    print(f"path {path:.0f} m; at the last scan the raw odometry is "
          f"{math.hypot(end_err[0][0] - end_err[1][0], end_err[0][1] - end_err[1][1]):.2f} m and "
          f"{math.degrees(abs(wrap(end_err[0][2] - end_err[1][2]))):.1f} deg from the corrected pose")
    print("window   source            pairs   trans. error m (mean / max)   rot. error deg (mean / max)   error / path")
    for window in (1, 10, 100, 1000):
        for which, name in ((3, "raw (rebuilt)"), (2, "ODOM at the scan")):
            et, er, ln = window_errors(scans, which, window)
            if not et:
                continue
            ratio = sum(et) / max(sum(ln), 1e-9)
            print(f"{window:5d} s  {name:16s} {len(et):6d}   {statistics.mean(et):8.3f} / {max(et):7.3f}"
                  f"          {math.degrees(statistics.mean(er)):8.2f} / {math.degrees(max(er)):7.2f}"
                  f"          {100 * ratio:6.1f} %")
    print("increments between consecutive scans minus the corrected ones (mean, std):")
    for which, name in ((3, "raw (rebuilt)"), (2, "ODOM at the scan")):
        along, across, head = [], [], []
        for a, b in zip(scans, scans[1:]):
            if a[which] is None or b[which] is None:
                continue
            d, ref = between(a[which], b[which]), between(a[1], b[1])
            along.append(d[0] - ref[0])
            across.append(d[1] - ref[1])
            head.append(wrap(d[2] - ref[2]))
        lag1 = statistics.correlation(head[:-1], head[1:])
        print(f"  {name:16s} along {statistics.mean(along):+.4f} {statistics.stdev(along):.4f} m, "
              f"across {statistics.mean(across):+.4f} {statistics.stdev(across):.4f} m, "
              f"heading {statistics.mean(head):+.4f} {statistics.stdev(head):.4f} rad "
              f"(lag-1 correlation of the heading errors {lag1:+.2f})")


if __name__ == "__main__":
    main()
