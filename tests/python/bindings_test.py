"""The extension mjslam._mjslam (python/bindings.cc): the closed loop, runs and Python filters.

Checks that a loop stepped from Python is `mjslam run`'s loop (its rows are the run's
trajectory.csv, bit for bit); that Loop.run() and stepping agree; that a record and a scan's
features reach a Python filter as the C++ filters see them; that a Python filter runs beside the
C++ ones in a loop and in a run directory, and that examples/dead_reckoning_filter.py reproduces
the C++ kind dead_reckoning's columns to 1e-9; and that bad input raises errors naming the key,
the filter or the method. About 10 s.

    PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python/bindings_test.py
"""

import math
import os
import subprocess
import sys

import numpy as np
import pytest

SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(SOURCE_DIR, "examples"))

import mjslam  # noqa: E402  (build/python on PYTHONPATH)
from dead_reckoning_filter import DeadReckoningFilter  # noqa: E402

DEFAULT = os.path.join(SOURCE_DIR, "configs", "default.yaml")
SHORT = ["run.duration_s=6", "render.enabled=false"]
FILTER_SUFFIXES = [s for s in mjslam.FILTER_COLUMN_SUFFIXES if s != "us"]  # "us" is measured


def filters(*entries, drive="classical"):
    """Overrides: slam.filters of `entries` (name, kind[, update]) and the driving filter."""
    items = ["{name: %s, kind: %s%s}" % (e[0], e[1], ", update: %s" % e[2] if len(e) > 2 else "")
             for e in entries]
    return ["slam.filters=[%s]" % ", ".join(items), "control.pose_source=" + drive]


def test_the_extension_is_built():
    assert mjslam.HAS_EXTENSION, "build/python/mjslam/_mjslam*.so missing: cmake --build build"
    assert {"ekf", "dead_reckoning"} <= set(mjslam.filter_kinds())


def test_a_stepped_loop_is_the_run_of_the_same_config(tmp_path):
    # The same config through mjslam.run (C++ loop, files) and stepped from Python: every
    # column of every row but the measured microseconds is the same number.
    result = mjslam.run(DEFAULT, SHORT, out=str(tmp_path / "run"))
    assert result["status"] == "completed" and result["steps"] == 61
    trajectory = mjslam.read_run(str(tmp_path / "run")).trajectory
    loop = mjslam.Loop(DEFAULT, SHORT)
    assert loop.filter_names == ["classical", "selective"] and loop.num_steps == 61
    rows = [step.row for step in loop]
    assert loop.done and loop.steps == 61 and len(rows) == len(trajectory["t"])
    for column in trajectory.columns:
        if column.endswith("_us"):
            continue
        stepped = np.array([row[column] for row in rows], dtype=float)
        assert np.array_equal(stepped, trajectory[column], equal_nan=True), column
    # The filters' state after the last step is what the last row says.
    assert loop.pose("selective") == pytest.approx(
        [rows[-1]["selective_x"], rows[-1]["selective_y"], rows[-1]["selective_th"]], abs=0)
    P = loop.covariance("classical")
    assert P.shape == (3, 3) and P[0, 0] == rows[-1]["classical_pxx"]
    assert P[1, 2] == rows[-1]["classical_pyth"] == P[2, 1]
    assert loop.num_features("classical") == rows[-1]["classical_nfeat"]
    summary = loop.summary()
    assert set(summary["filters"]) == {"classical", "selective"}


def test_run_in_cpp_after_stepping_ends_where_stepping_does():
    stepped = mjslam.Loop(DEFAULT, SHORT)
    for _ in stepped:
        pass
    mixed = mjslam.Loop(DEFAULT, SHORT)
    for _ in range(10):
        mixed.step()
    assert mixed.run() == 51 and mixed.done
    assert np.array_equal(mixed.pose("classical"), stepped.pose("classical"))
    with pytest.raises(StopIteration):
        mixed.step()


def test_the_map_as_arrays_is_map_csv(tmp_path):
    mjslam.run(DEFAULT, SHORT, out=str(tmp_path / "run"))
    written = mjslam.read_run(str(tmp_path / "run")).maps["classical"]
    loop = mjslam.Loop(DEFAULT, SHORT)
    loop.run()
    m = loop.map("classical")
    assert len(m["type"]) == len(written["id"]) > 0
    assert list(m["type"]) == list(written["type"])
    assert np.array_equal(m["params"][:, 0], written["p0"])
    assert np.array_equal(m["covariance"][:, 0, 1], written["c01"])
    lines = np.array(m["type"]) == "line"
    assert np.array_equal(m["segment"][lines, 0, 0], written["ax"][lines])
    assert np.all(np.isnan(m["segment"][~lines]))


class Recorder:
    """A Python filter that keeps what it is given and reports the true... nothing: it stays
    at its start pose, with a fixed covariance."""
    seen = []

    def __init__(self, settings, X_WR0, X_RS):
        self.X_WR0, self.X_RS, self.settings = X_WR0, X_RS, settings
        Recorder.seen = [(settings, X_WR0, X_RS)]

    def step(self, record, features):
        Recorder.seen.append((record, features))
        return {"num_observed": 0 if features is None else
                len(features.line_params) + len(features.corner_params)}

    def pose(self):
        return self.X_WR0

    def covariance(self):
        return np.diag([1.0, 2.0, 3.0])

    def num_features(self):
        return 7

    def map(self):
        return [{"type": "line", "params": (1.0, 0.5), "covariance": np.eye(2),
                 "segment": ((0.0, 1.0), (2.0, 3.0))},
                {"id": 9, "type": "corner", "params": (4.0, 5.0), "covariance": 2 * np.eye(2)}]


def test_a_python_filter_gets_the_records_and_features_of_the_cpp_ones():
    mjslam.register_filter("test_recorder", Recorder)
    loop = mjslam.Loop(DEFAULT, SHORT + filters(("classical", "ekf", "classical"),
                                                ("rec", "test_recorder")))
    steps = list(loop)
    settings, X_WR0, X_RS = Recorder.seen[0]
    assert settings["filter"]["name"] == "rec" and settings["filter"]["kind"] == "test_recorder"
    assert settings["slam"]["ekf"]["control_point_offset_m"] == 0.2
    assert isinstance(settings["seed"], int)
    assert np.array_equal(X_WR0, steps[0].true_pose)
    assert np.array_equal(X_RS, loop.laser_mount)
    records = Recorder.seen[1:]
    assert len(records) == len(steps)
    scans = 0
    for step, (record, features) in zip(steps, records):
        assert record.t == step.t and np.array_equal(record.odometry, step.odometry)
        assert record.has_scan == (features is not None) == (record.ranges is not None)
        if features is None:
            continue
        scans += 1
        assert record.ranges.shape == (181,)
        n, m = len(features.line_params), len(features.corner_params)
        assert features.line_covariances.shape == (n, 2, 2)
        assert features.line_endpoints.shape == (n, 2, 2) and features.line_beams.shape == (n, 2)
        assert features.corner_covariances.shape == (m, 2, 2)
        # Lines: rho >= 0, covariances symmetric positive definite, the endpoints on the line.
        rho, alpha = features.line_params[:, 0], features.line_params[:, 1]
        assert np.all(rho >= 0) and np.all(np.abs(alpha) <= math.pi)
        assert np.all(np.linalg.eigvalsh(features.line_covariances) > 0)
        normal = np.stack([np.cos(alpha), np.sin(alpha)], axis=1)
        for end in range(2):
            on_line = np.sum(features.line_endpoints[:, end, :] * normal, axis=1)
            assert np.allclose(on_line, rho, atol=1e-9)
        assert np.all(features.line_beams[:, 0] <= features.line_beams[:, 1])
        # Corners: the point in range-bearing form, two valid lines.
        r, b = features.corner_params[:, 0], features.corner_params[:, 1]
        assert np.allclose(features.corner_points,
                           np.stack([r * np.cos(b), r * np.sin(b)], axis=1), atol=1e-9)
        assert np.all((features.corner_lines >= 0) & (features.corner_lines < n))
        assert features.corner_convex.dtype == bool
    assert loop.config["laser"]["rate_hz"] == 10.0 and scans == 61  # a scan at every step
    # What the filter reported is its row.
    last = steps[-1].row
    assert last["rec_nfeat"] == 7 and last["rec_pyy"] == 2.0 and last["rec_x"] == X_WR0[0]
    m = loop.map("rec")
    assert list(m["id"]) == [0, 9] and m["type"] == ["line", "corner"]
    assert np.array_equal(m["segment"][0], [[0.0, 1.0], [2.0, 3.0]])


def test_the_python_dead_reckoning_reproduces_the_cpp_one():
    mjslam.register_filter("py_dead_reckoning", DeadReckoningFilter)
    loop = mjslam.Loop(DEFAULT, ["run.duration_s=60"] + filters(
        ("classical", "ekf", "classical"), ("cpp", "dead_reckoning"),
        ("py", "py_dead_reckoning")))
    worst = {suffix: 0.0 for suffix in FILTER_SUFFIXES}
    for step in loop:
        row = step.row
        for suffix in FILTER_SUFFIXES:
            worst[suffix] = max(worst[suffix], abs(row["cpp_" + suffix] - row["py_" + suffix]))
    assert loop.steps == 601
    assert max(worst.values()) <= 1e-9, worst
    # It drifts: the comparison is not of two constant columns.
    assert row["py_pxx"] > 1e-4 and abs(row["py_x"] - row["true_x"]) > 1e-4


def test_a_run_directory_with_a_python_filter(tmp_path):
    mjslam.register_filter("py_dead_reckoning", DeadReckoningFilter)
    out = str(tmp_path / "run")
    result = mjslam.run(DEFAULT, SHORT + filters(("classical", "ekf", "classical"),
                                                 ("py", "py_dead_reckoning")), out=out)
    assert result["status"] == "completed"
    run = mjslam.read_run(out)
    assert list(run.filter_names) == ["classical", "py"]
    assert len(run.maps["py"]["id"]) == 0
    assert run.summary["filters"]["py"]["num_features"] == 0
    assert np.all(np.isfinite(run.trajectory["py_nees"][10:]))  # once it has moved


class Broken(Recorder):
    def pose(self):
        return (1.0, 2.0)


class Failing(Recorder):
    def step(self, record, features):
        if record.t >= 1.0:
            raise ZeroDivisionError("this filter's own bug")
        return None


class BadMap(Recorder):
    def map(self):
        return [(1.0, 2.0)]


class UnknownField(Recorder):
    def step(self, record, features):
        return {"num_matches": 1}


def test_bad_input_names_what_is_wrong(tmp_path):
    with pytest.raises(mjslam.ConfigError, match="run.duration_s"):
        mjslam.Loop(DEFAULT, ["run.duration_s=-1"])
    with pytest.raises(mjslam.ConfigError, match="kind.*no_such_kind"):
        mjslam.Loop(DEFAULT, filters(("classical", "ekf", "classical"), ("x", "no_such_kind")))
    with pytest.raises(ValueError, match="C\\+\\+ filter kind"):
        mjslam.register_filter("ekf", Recorder)
    with pytest.raises(TypeError):
        mjslam.register_filter("test_not_callable", 3)
    mjslam.register_filter("test_broken", Broken)
    loop = mjslam.Loop(DEFAULT, SHORT + filters(("classical", "ekf", "classical"),
                                                ("b", "test_broken")))
    with pytest.raises(RuntimeError, match="filter 'b' \\(kind test_broken\\): pose\\(\\) must "
                                           "give 3 numbers, not shape \\(2,\\)"):
        loop.step()
    mjslam.register_filter("test_unknown_field", UnknownField)
    loop = mjslam.Loop(DEFAULT, SHORT + filters(("classical", "ekf", "classical"),
                                                ("u", "test_unknown_field")))
    with pytest.raises(RuntimeError, match="unknown field 'num_matches'"):
        loop.step()
    with pytest.raises(KeyError, match="no filter 'nope'.*classical, u"):
        loop.pose("nope")
    mjslam.register_filter("test_bad_map", BadMap)
    loop = mjslam.Loop(DEFAULT, SHORT + filters(("classical", "ekf", "classical"),
                                                ("m", "test_bad_map")))
    loop.step()
    with pytest.raises(RuntimeError, match="filter 'm' \\(kind test_bad_map\\): map\\(\\) "
                                           "feature 0 is \\(1.0, 2.0\\), expected a dict"):
        loop.map("m")
    # A filter's own exception reaches the caller as it was raised; the run directory keeps
    # every complete row and its manifest says the run failed.
    mjslam.register_filter("test_failing", Failing)
    loop = mjslam.Loop(DEFAULT, SHORT + filters(("classical", "ekf", "classical"),
                                                ("f", "test_failing")))
    with pytest.raises(ZeroDivisionError, match="own bug"):
        for _ in loop:
            pass
    out = str(tmp_path / "failed")
    with pytest.raises(ZeroDivisionError):
        mjslam.run(DEFAULT, SHORT + filters(("classical", "ekf", "classical"),
                                            ("f", "test_failing")), out=out)
    run = mjslam.read_run(out)
    assert run.manifest["status"] == "failed"
    assert len(run.trajectory["t"]) == 10 and run.trajectory["t"][-1] == pytest.approx(0.9)


def test_the_notebook_example_runs(tmp_path):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [os.path.dirname(os.path.dirname(mjslam.__file__)), os.path.join(SOURCE_DIR, "examples")]))
    result = subprocess.run([sys.executable, os.path.join(SOURCE_DIR, "examples", "notebook.py"),
                             "--duration", "8", "--out", str(tmp_path)], env=env,
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr[-3000:]
    assert "completed 81 steps" in result.stdout
    assert (tmp_path / "errors.png").stat().st_size > 10000
    assert mjslam.read_run(str(tmp_path / "run")).filter_names == (
        "classical", "selective", "dead_reckoning")


def test_the_cost_scripts_print_their_figures():
    # scripts/python_step_overhead.py and scripts/filter_bank_cost.py on short runs: each line of
    # figures is there and its numbers are positive.
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(mjslam.__file__)))
    overhead = subprocess.run(
        [sys.executable, os.path.join(SOURCE_DIR, "scripts", "python_step_overhead.py"),
         "--duration", "3", "--repeats", "1", "--config", DEFAULT], env=env, capture_output=True,
        text=True)
    assert overhead.returncode == 0, overhead.stderr[-3000:]
    lines = [line for line in overhead.stdout.splitlines() if " us " in line]
    assert len(lines) == 3 and all(float(line.split()[-2]) > 0 for line in lines), overhead.stdout
    cost = subprocess.run(
        [sys.executable, os.path.join(SOURCE_DIR, "scripts", "filter_bank_cost.py"),
         "--duration", "3", "--repeats", "1"], env=env, capture_output=True, text=True)
    assert cost.returncode == 0, cost.stderr[-3000:]
    ratio = [line for line in cost.stdout.splitlines() if "together / sum alone" in line]
    assert len(ratio) == 1 and 0 < float(ratio[0].split()[-1]) < 2, cost.stdout
