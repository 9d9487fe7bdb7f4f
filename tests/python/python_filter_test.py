"""examples/paper_classical_ekf.py, the paper's classical EKF in numpy, against the C++ one.

Both run in one closed loop (configs/paper.yaml: the explorer drives from the odometry, so the
path does not depend on either filter), on the same records and features. Checks every column of
trajectory.csv at every step: poses and covariances within 1e-9, NEES within 1e-9 of itself (a
ratio that reaches 1e3 and more), the counts, periods and processed flags equal; the maps within
1e-9; the innovation check's counts equal. Runs: the corridor (seeds 1 and 2, 60 s, realtime
timing as the paper's config has it, and every_scan) and the office (seed 3, 60 s). Also checks
that the filter refuses a setting it does not copy, naming the key. About 5 s.

    PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python/python_filter_test.py
"""

import os
import sys

import numpy as np
import pytest

SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(SOURCE_DIR, "examples"))

import mjslam  # noqa: E402  (build/python on PYTHONPATH)
from paper_classical_ekf import PaperClassicalEkf  # noqa: E402

PAPER = os.path.join(SOURCE_DIR, "configs", "paper.yaml")
FILTERS = ("slam.filters=[{name: classical, kind: ekf, update: classical},"
           " {name: py, kind: py_paper_classical}]")
EXACT = ("nfeat", "nmatched", "nupdated", "period", "open_loop", "processed")
CLOSE = ("x", "y", "th", "pxx", "pxy", "pxth", "pyy", "pyth", "pthth")
COUNTS = ("windows", "failed_windows", "near_miss_windows", "near_miss_failed_windows", "copies",
          "copied_scans")

mjslam.register_filter("py_paper_classical", PaperClassicalEkf)


@pytest.mark.parametrize("overrides", [
    ["run.seed=1"],
    ["run.seed=2", "slam.timing=every_scan"],
    ["run.seed=3", "run.world=%s" % os.path.join(SOURCE_DIR, "worlds", "office.xml")],
], ids=["corridor-realtime", "corridor-every-scan", "office"])
def test_the_numpy_copy_reproduces_the_cpp_classical_filter(overrides):
    loop = mjslam.Loop(PAPER, ["run.duration_s=60", "render.enabled=false", FILTERS] + overrides)
    worst = {column: 0.0 for column in EXACT + CLOSE + ("nees",)}
    skipped = matched = 0
    for step in loop:
        row = step.row
        skipped += row["py_processed"] == 0
        matched += row["py_nmatched"]
        for column in worst:
            a, b = row["classical_" + column], row["py_" + column]
            if np.isnan(a) and np.isnan(b):
                continue
            difference = abs(a - b) / (max(1.0, abs(a)) if column == "nees" else 1.0)
            worst[column] = max(worst[column], difference)
    assert loop.steps == 601
    assert all(worst[column] == 0 for column in EXACT), worst
    assert max(worst[column] for column in CLOSE + ("nees",)) <= 1e-9, worst
    # Not a comparison of two empty filters: both mapped and matched.
    assert row["py_nfeat"] >= 10 and matched > 100
    if "slam.timing=every_scan" not in overrides:
        assert skipped > 0  # realtime: both skipped the same scans
    cpp, py = loop.map("classical"), loop.map("py")
    assert cpp["type"] == py["type"] and np.array_equal(cpp["id"], py["id"])
    for key in ("params", "covariance"):
        assert np.allclose(cpp[key], py[key], rtol=0, atol=1e-9)
    assert np.allclose(cpp["segment"], py["segment"], rtol=0, atol=1e-9, equal_nan=True)
    checks = loop.summary()["filters"]
    for key in COUNTS:
        assert checks["classical"]["innovation_check"][key] == \
            checks["py"]["innovation_check"][key], key


def test_it_refuses_what_it_does_not_copy():
    # The default config predicts from the odometry: not the paper's method.
    with pytest.raises(ValueError, match="process_model"):
        mjslam.Loop(os.path.join(SOURCE_DIR, "configs", "default.yaml"),
                    [FILTERS, "control.pose_source=classical"])
    with pytest.raises(ValueError, match="duplicate_line_distance_m.*0.05"):
        mjslam.Loop(PAPER, [FILTERS, "slam.ekf.duplicate_line_distance_m=0.05"])


class BadAssociation(PaperClassicalEkf):
    def step(self, record, features):
        report = super().step(record, features)
        if "association" in report:
            report["association"]["outcome"] = ["maybe"] * len(report["association"]["outcome"])
        return report


class ShortNis(PaperClassicalEkf):
    def step(self, record, features):
        report = super().step(record, features)
        report["nearest_nis"] = report.get("nearest_nis", [])[:-1] or [1.0, 2.0, 3.0]
        return report


def test_a_bad_association_report_is_an_error_naming_the_filter():
    mjslam.register_filter("test_bad_association", BadAssociation)
    loop = mjslam.Loop(PAPER, ["slam.filters=[{name: bad, kind: test_bad_association}]"])
    with pytest.raises(RuntimeError, match="filter 'bad'.*outcome 'maybe'"):
        for _ in loop:
            pass
    mjslam.register_filter("test_short_nis", ShortNis)
    loop = mjslam.Loop(PAPER, ["slam.filters=[{name: short, kind: test_short_nis}]"])
    with pytest.raises(RuntimeError, match="filter 'short'.*nearest_nis has .* entries for "
                                           "num_observed"):
        for _ in loop:
            pass
