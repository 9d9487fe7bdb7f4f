#!/usr/bin/python3
"""Smoke test of scripts/paper_experiments.py: tiny settings, then checks that the claims table
has every claim with a verdict under both models, that every figure is a PNG, that the
study with the paper's Gaussians drew its own number of realisations, and that --readme
replaces the table between a README's markers and nothing else.

    /usr/bin/python3 tests/integration/paper_experiments_smoke_test.py SOURCE_DIR MJSLAM

Exit status 0 when everything is there, 1 with the reasons otherwise.
"""
import os
import shutil
import subprocess
import sys
import tempfile

# python/mjslam, the reader of run files, found from this file (as the scripts find it).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "python"))
import mjslam  # noqa: E402

FIGURES = ["fig3_pose_errors", "fig4c_processing", "fig4d_open_loop", "fig5_points",
           "fig6_intermap", "fig7_to_truth", "anees_corridor"]
VERDICTS = ("**yes**", "**partly**", "**no**")


def main(source_dir, program):
    out = tempfile.mkdtemp(prefix="paper_smoke_")
    readme = os.path.join(out, "README.md")
    with open(readme, "w") as f:
        f.write("before\n<!-- claims table: made by scripts/paper_experiments.py --readme; "
                "do not edit -->\nold table\n<!-- end of claims table -->\nafter\n")
    try:
        command = ["/usr/bin/python3", os.path.join(source_dir, "scripts", "paper_experiments.py"),
                   "--out", out, "--mjslam", program, "--runs", "2", "--jobs", "2",
                   "--duration", "8", "--office-runs", "1", "--office-duration", "8",
                   "--points", "100", "20000", "25000", "--realisations", "2",
                   "--paper-study-realisations", "1", "--scale-duration", "8",
                   "--readme", readme]
        result = subprocess.run(command, cwd=source_dir, capture_output=True, text=True)
        problems = []
        if result.returncode != 0:
            problems.append("exit %d: %s" % (result.returncode, result.stderr[-2000:]))
        claims = os.path.join(out, "claims.md")
        text = open(claims).read() if os.path.exists(claims) else ""
        rows = [line for line in text.splitlines() if line.startswith("| (")]
        if len(rows) != 5:
            problems.append("claims.md: %d claim rows, expected 5" % len(rows))
        for row in rows:
            if sum(row.count(v) for v in VERDICTS) != 2:
                problems.append("claims.md: not one verdict per model in: %s" % row[:80])
        lines = open(readme).read().splitlines()
        table = [line for line in lines if line.startswith("| (")]
        if (lines[0] != "before" or lines[-1] != "after" or "old table" in lines
                or len(table) != 5 or any(sum(r.count(v) for v in VERDICTS) != 2 for r in table)):
            problems.append("--readme: the README is not the table between its markers:\n%s"
                            % "\n".join(lines[:12]))
        names = ["%s_%s.png" % (f, m) for f in FIGURES for m in ("default", "paper")]
        for name in names + ["fig4cd_scale.png"]:
            path = os.path.join(out, "figures", name)
            if not os.path.exists(path):
                problems.append("missing figure %s" % name)
                continue
            with open(path, "rb") as f:
                if f.read(8) != b"\x89PNG\r\n\x1a\n":
                    problems.append("not a PNG: %s" % name)
        # --paper-study-realisations: one realisation has variance 0, two almost never.
        for model in ("default", "paper"):
            for study, single in (("floor", False), ("paper", True)):
                path = os.path.join(out, model, "divergence_%s.csv" % study)
                if not os.path.exists(path):
                    problems.append("missing %s" % path)
                    continue
                variances = mjslam.read_divergence(path)["variance"].tolist()
                if single != all(v == 0.0 for v in variances):
                    problems.append("%s: variances %s, expected %s realisation(s)" % (
                        path, variances[:4], 1 if single else 2))
        for p in problems:
            print(p)
        print("%d problems" % len(problems))
        return 1 if problems else 0
    finally:
        shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
