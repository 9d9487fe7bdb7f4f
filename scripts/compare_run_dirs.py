#!/usr/bin/python3
"""compare_run_dirs.py BEFORE AFTER [SRC_BEFORE SRC_AFTER]: byte-identity of two outputs of
scripts/reference_runs.sh (or any two folders of run directories).
Ignored: what no rerun repeats, as python/mjslam defines it (measured times: CSV columns *_us,
plot_processing_time.png; the manifest's start_time, end_time, command_line, git_commit).
Source-tree paths are normalised. CSV files are compared field by field as text."""
import csv, io, json, os, sys
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import mjslam  # noqa: E402  (python/mjslam, found from this file: no build, no PYTHONPATH)
a, b = sys.argv[1], sys.argv[2]
srcs = sys.argv[3:5] if len(sys.argv) >= 5 else [".", "."]
def norm(path, src):
    top = a if path.startswith(os.path.join(a, '')) else b
    return (open(path, 'rb').read().replace(os.path.realpath(top).encode(), b'OUT')
            .replace(os.path.realpath(src).encode(), b'SRC'))
bad = 0
files_a = sorted(os.path.relpath(os.path.join(r, f), a) for r, _, fs in os.walk(a) for f in fs)
files_b = sorted(os.path.relpath(os.path.join(r, f), b) for r, _, fs in os.walk(b) for f in fs)
for f in sorted(set(files_a) ^ set(files_b)):
    print("ONLY IN ONE:", f); bad += 1
for f in sorted(set(files_a) & set(files_b)):
    if f.endswith("plot_processing_time.png"): continue
    x, y = norm(os.path.join(a, f), srcs[0]), norm(os.path.join(b, f), srcs[1])
    if f.endswith(mjslam.MANIFEST_FILE):
        jx, jy = json.loads(x), json.loads(y)
        for k in mjslam.MANIFEST_VOLATILE_KEYS:
            jx.pop(k, None); jy.pop(k, None)
        same = jx == jy
    elif f.endswith(".csv"):
        def strip(t):
            rows = list(csv.reader(io.StringIO(t.decode())))
            if not rows: return rows
            keep = [i for i, c in enumerate(rows[0]) if not mjslam.is_measured_column(c)]
            return [[r[i] if i < len(r) else None for i in keep] for r in rows]
        same = strip(x) == strip(y)
    else:
        same = x == y
    if not same:
        print("DIFF:", f); bad += 1
print(f"{len(files_a)} files compared, {bad} differ")
sys.exit(1 if bad else 0)
