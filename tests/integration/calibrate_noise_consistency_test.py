#!/usr/bin/python3
"""Test of scripts/calibrate_noise.py --consistency end to end on tiny settings: two runs of
20 s of the corridor loop (seeds 101-102), at most two scaled sweeps.

    /usr/bin/python3 tests/integration/calibrate_noise_consistency_test.py SOURCE_DIR MJSLAM

Asserted: the script exits 0; the second sweep's factors are the first's times the square root
of its mean NEES per dof (position for the speed, heading for the turn rate; to the printed
digits); the written config loads (`mjslam config`) with the factors of the sweep whose means
are nearest 1 and the fitted gains; a second call reuses every sweep. Shown by hand to fail
with the update's square root left out (the factors then follow the NEES itself).

Exit status 0 when all hold, 1 with the reasons otherwise.
"""
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile


def main(source_dir, mjslam):
    out = tempfile.mkdtemp(prefix="calibrate_noise_consistency_test_")
    try:
        with open(os.path.join(source_dir, "configs", "default.yaml")) as f:
            text = f.read()
        text = text.replace("duration_s: 300.0", "duration_s: 20.0")
        text = text.replace("../worlds/", os.path.join(source_dir, "worlds") + "/")
        text = text.replace("../models/", os.path.join(source_dir, "models") + "/")
        base = os.path.join(out, "base.yaml")
        with open(base, "w") as f:
            f.write(text)
        written = os.path.join(out, "calibrated.yaml")
        command = ["/usr/bin/python3", os.path.join(source_dir, "scripts", "calibrate_noise.py"),
                   "--consistency", os.path.join(out, "work"), "--write", written,
                   "--config", base, "--mjslam", mjslam, "--runs", "2", "--jobs", "2",
                   "--iterations", "2", "--tolerance", "1e-6"]
        first = subprocess.run(command, capture_output=True, text=True)
        print(first.stdout + first.stderr)
        if first.returncode != 0:
            return 1
        problems = []
        sweeps = [tuple(float(x) for x in m) for m in re.findall(
            r"# v x(\S+), w x(\S+): mean NEES per dof position (\S+), heading (\S+) \(",
            first.stdout)]
        if len(sweeps) != 2:
            problems.append(f"expected 2 scaled sweeps, found {len(sweeps)}")
        else:
            (v0, w0, p0, h0), (v1, w1, _, _) = sweeps
            for name, got, want in (("v", v1, v0 * math.sqrt(p0)), ("w", w1, w0 * math.sqrt(h0))):
                if abs(got / want - 1.0) > 2e-3:
                    problems.append(f"second sweep's {name} factor {got}, expected {want:.4g}")
            best = min(sweeps, key=lambda s: abs(math.log(s[2])) + abs(math.log(s[3])))
            resolved = subprocess.run([mjslam, "config", "--config", written],
                                      capture_output=True, text=True)
            if resolved.returncode != 0:
                problems.append(f"the written config does not load: {resolved.stderr}")
            else:
                for key, want in (("v_noise_scale", best[0]), ("w_noise_scale", best[1])):
                    m = re.search(rf"{key}: (\S+)", resolved.stdout)
                    if m is None or abs(float(m.group(1)) / want - 1.0) > 2e-3:
                        problems.append(f"{key} in the written config: "
                                        f"{m.group(1) if m else 'missing'}, expected {want}")
                m = re.search(r"command_gain_v: (\S+)", resolved.stdout)
                if m is None or float(m.group(1)) == 1.0:
                    problems.append("the written config lacks the fitted command_gain_v")
        again = subprocess.run(command, capture_output=True, text=True)
        if again.returncode != 0 or again.stdout.count("# reusing") != 3:
            problems.append(f"a second call did not reuse the 3 sweeps:\n{again.stdout}")
        for problem in problems:
            print(problem)
        return 1 if problems else 0
    finally:
        shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
