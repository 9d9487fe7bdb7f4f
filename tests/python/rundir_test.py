"""The Python reader of run directories (python/mjslam) against the program that writes them.

Makes, with build/mjslam: a 4 s run of configs/default.yaml (evaluated: ground_truth_map.csv and
the metrics in summary.json), an 8 s run of configs/paper.yaml (realtime: skipped steps), a sweep
of two 2 s runs (nees.csv), a divergence study (divergence.csv) and an import of the Intel log
(reference.csv), and a run and a sweep with named filters (slam.filters). Then checks that the module's column lists are exactly the headers the program
wrote, for every CSV file in those directories; that the values read give mjslam evaluate's
figures in summary.json (2 sigma, RMSE, mean NEES, final error, map sizes); and that bad files
raise errors naming file, line, column and value. About 5 s.

    /usr/bin/python3 -m pytest tests/python/rundir_test.py

The program is $MJSLAM_PROGRAM (CTest sets it), else build/mjslam; mjslam is imported from
PYTHONPATH (CTest: build/python, the build's copy), else from python/.
"""

import math
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PROGRAM = os.environ.get("MJSLAM_PROGRAM", os.path.join(SOURCE_DIR, "build", "mjslam"))
REAL_DATA = os.path.join(SOURCE_DIR, "..", "shared", "data", "real")

try:
    import mjslam
except ImportError:
    sys.path.insert(0, os.path.join(SOURCE_DIR, "python"))
    import mjslam


def program(*args):
    """Runs build/mjslam from the source tree; fails the test with its output on an error."""
    result = subprocess.run([PROGRAM] + list(args), cwd=SOURCE_DIR, capture_output=True,
                            text=True)
    assert result.returncode == 0, "mjslam %s: exit %d\n%s" % (" ".join(args), result.returncode,
                                                               result.stderr[-3000:])


@pytest.fixture(scope="session")
def out(tmp_path_factory):
    assert os.access(PROGRAM, os.X_OK), "%s: not built (cmake --build build)" % PROGRAM
    return tmp_path_factory.mktemp("rundir")


@pytest.fixture(scope="session")
def run(out):
    """An evaluated 4 s run of the default config (slam.timing every_scan)."""
    path = str(out / "run")
    program("run", "--quiet", "--config", "configs/default.yaml", "--duration", "4",
            "--set", "render.enabled=false", "--out", path)
    program("divergence", path, "--points", "100", "200", "--realisations", "2")
    return mjslam.read_run(path)


@pytest.fixture(scope="session")
def realtime_run(out):
    """An evaluated 8 s run of the paper's config: realtime timing, the filters skip scans."""
    path = str(out / "realtime")
    program("run", "--quiet", "--config", "configs/paper.yaml", "--duration", "8",
            "--set", "render.enabled=false", "--out", path)
    return mjslam.read_run(path)


@pytest.fixture(scope="session")
def sweep(out):
    path = str(out / "sweep")
    program("sweep", "--quiet", "--config", "configs/default.yaml", "--runs", "2", "--jobs", "2",
            "--duration", "2", "--set", "render.enabled=false", "--out", path)
    return mjslam.read_sweep(path)


@pytest.fixture(scope="session")
def imported(out):
    """The Intel log imported (no true pose; reference.csv)."""
    log = os.path.join(REAL_DATA, "intel-corrected.log.gz")
    assert os.path.exists(log), "the real data is missing: %s" % log
    path = str(out / "intel")
    program("import", "--out", path, log)
    return mjslam.read_run(path)


# ---------------------------------------------------------------------------------------------
# Column lists: the module's against the headers the program wrote.

def declared_columns(run_dir, name):
    """The module's columns of the CSV file `name` of a run or sweep directory; None when it
    declares none."""
    fixed = {mjslam.TRAJECTORY_FILE: mjslam.TRAJECTORY_COLUMNS,
             mjslam.EXPLORER_FILE: mjslam.EXPLORER_COLUMNS,
             mjslam.GROUND_TRUTH_MAP_FILE: mjslam.MAP_COLUMNS,
             mjslam.REFERENCE_FILE: mjslam.REFERENCE_COLUMNS,
             mjslam.DIVERGENCE_FILE: mjslam.DIVERGENCE_COLUMNS,
             mjslam.NEES_FILE: mjslam.NEES_COLUMNS}
    fixed.update({mjslam.map_file(f): mjslam.MAP_COLUMNS for f in mjslam.FILTER_NAMES})
    if name == mjslam.SCANS_FILE:
        return mjslam.scan_columns(int(mjslam.read_run(run_dir).setting("laser.num_beams")))
    return fixed.get(name)


def csv_files(top):
    return sorted(os.path.join(root, name) for root, _, names in os.walk(top) for name in names
                  if name.endswith(".csv"))


def test_every_csv_file_has_exactly_the_declared_columns(run, realtime_run, sweep, imported):
    files = []
    for top in (run.path, realtime_run.path, sweep.path, imported.path):
        files += csv_files(top)
    names = {os.path.basename(f) for f in files}
    # Every kind of CSV file a run directory or sweep directory holds was made.
    assert names == {mjslam.TRAJECTORY_FILE, mjslam.SCANS_FILE, mjslam.EXPLORER_FILE,
                     mjslam.GROUND_TRUTH_MAP_FILE, mjslam.REFERENCE_FILE, mjslam.DIVERGENCE_FILE,
                     mjslam.NEES_FILE} | {mjslam.map_file(f) for f in mjslam.FILTER_NAMES}
    for path in files:
        expected = declared_columns(os.path.dirname(path), os.path.basename(path))
        assert expected is not None, "%s: the module declares no columns for this file" % path
        with open(path, newline="") as f:
            header = f.readline()
        assert header == ",".join(expected) + "\n", path


def test_layout_constants(run):
    assert mjslam.FILTER_NAMES == ("classical", "selective")
    assert run.filter_names == mjslam.FILTER_NAMES
    assert mjslam.TRAJECTORY_COLUMNS[:len(mjslam.RECORDED_TRAJECTORY_COLUMNS)] == \
        mjslam.RECORDED_TRAJECTORY_COLUMNS
    assert len(mjslam.TRAJECTORY_COLUMNS) == len(set(mjslam.TRAJECTORY_COLUMNS))
    for name in ("config.yaml", "manifest.json", "summary.json", "trajectory.csv", "scans.csv"):
        assert run.has(name), name
    assert [c for c in mjslam.TRAJECTORY_COLUMNS if mjslam.is_measured_column(c)] == \
        ["classical_us", "selective_us"]


def test_package_is_the_builds_copy_of_the_source():
    """Under CTest mjslam comes from build/python, the copy the build made of python/mjslam."""
    package = os.path.dirname(os.path.abspath(mjslam.__file__))
    source = os.path.join(SOURCE_DIR, "python", "mjslam")
    for name in ("__init__.py", "rundir.py"):
        with open(os.path.join(package, name), "rb") as a, \
                open(os.path.join(source, name), "rb") as b:
            assert a.read() == b.read(), "%s: stale copy of %s (rebuild)" % (package, name)


# ---------------------------------------------------------------------------------------------
# Values: what the module reads gives the program's own figures.

def inside_2sigma(errors, variances):
    """Fraction of steps with |error| <= 2 sigma per component (eval/pose_metrics.cc)."""
    bound = 2.0 * np.sqrt(np.maximum(variances, 0.0)) + 1e-12
    return (np.abs(errors) <= bound).mean(axis=0)


def rmse(errors):
    """Per component, summed step by step as eval/pose_metrics.cc does."""
    return [math.sqrt(sum(e * e for e in errors[:, k].tolist()) / len(errors)) for k in range(3)]


def xyz(values):
    return [values[c] for c in ("x", "y", "th")]


def test_pose_metrics_are_those_of_mjslam_evaluate(run):
    """summary.json's inside_2sigma, rmse, mean_nees and final_pose_error (mjslam evaluate) from
    the trajectory as the module reads it: the pose, covariance and NEES columns."""
    for name in run.filter_names:
        s = run.summary["filters"][name]
        errors = run.errors(name)
        assert list(inside_2sigma(errors, run.variances(name))) == xyz(s["inside_2sigma"])
        assert rmse(errors) == pytest.approx(xyz(s["rmse"]), rel=1e-12)
        assert list(errors[-1]) == xyz(s["final_pose_error"])
        nees = run.nees(name)
        finite = np.isfinite(nees)
        assert finite.sum() > 0
        assert sum(nees[finite].tolist()) / finite.sum() == pytest.approx(s["mean_nees"], rel=1e-12)
        # The NEES column is error^T P^-1 error of the pose and covariance columns.
        covariances = run.covariances(name)
        assert np.array_equal(covariances, covariances.transpose(0, 2, 1))
        assert np.array_equal(np.diagonal(covariances, axis1=1, axis2=2), run.variances(name))
        mine = [e @ np.linalg.solve(p, e) for e, p in zip(errors[finite], covariances[finite])]
        assert mine == pytest.approx(nees[finite].tolist(), rel=1e-9)


def test_held_estimates_of_realtime_timing_as_evaluate_compares_them(realtime_run):
    """Realtime: a skipped step holds the last processed estimate; mjslam evaluate compares it
    with the truth of that processed step, as Run.errors does."""
    run = realtime_run
    for name in run.filter_names:
        s = run.summary["filters"][name]
        processed = run.processed(name)
        assert 0 < processed.sum() < len(processed)
        assert processed.sum() == s["scans_processed"]
        errors = run.errors(name)
        assert list(inside_2sigma(errors, run.variances(name))) == xyz(s["inside_2sigma"])
        assert rmse(errors) == pytest.approx(xyz(s["rmse"]), rel=1e-12)
        # On processed steps: the estimate against the step's own truth.
        own = run.poses(name) - run.poses("true")
        own[:, 2] = mjslam.wrap_angle(own[:, 2])
        assert np.array_equal(errors[processed], own[processed])
        assert not np.array_equal(errors, own)


def test_run_files_agree_with_the_summary_and_each_other(run):
    summary = run.summary
    trajectory = run.trajectory
    assert trajectory["t"][-1] == summary["run"]["duration_s"]
    assert trajectory["explored"][-1] == summary["run"]["explored_fraction"]
    assert len(trajectory) == run.manifest["steps"]
    for name in run.filter_names:
        s = summary["filters"][name]
        assert len(run.maps[name]) == s["num_features"] == trajectory[name + "_nfeat"][-1]
        assert s["map"]["num_truth"] == len(run.true_map)
        assert trajectory[name + "_open_loop"][-1] == s["open_loop_s"]
        assert run.processed(name).all()
    # scans.csv: the laser pose is the true pose of R at the scan composed with the mount.
    scans = run.scans
    assert scans.ranges.shape == (len(scans), int(run.setting("laser.num_beams")))
    assert ((scans.ranges >= 0.0) & (scans.ranges <= run.setting("laser.max_range_m"))).all()
    rows = np.searchsorted(trajectory["t"], scans.t)
    assert np.array_equal(trajectory["t"][rows], scans.t)
    x, y, th = run.poses("true")[rows].T
    mount = run.manifest["laser_mount"]
    expected = np.column_stack((x + np.cos(th) * mount["x"] - np.sin(th) * mount["y"],
                                y + np.sin(th) * mount["x"] + np.cos(th) * mount["y"],
                                th + mount["th"]))
    assert np.allclose(scans.poses, expected, rtol=0.0, atol=1e-9)


def test_maps_explorer_and_divergence(run):
    for name, m in list(run.maps.items()) + [("truth", run.true_map)]:
        # A line's seen segment lies on it: x cos(alpha) + y sin(alpha) = rho.
        lines = (m["type"] == "line") & np.isfinite(m["ax"])
        assert lines.sum() > 0 and len(m.corners) > 0, name
        assert len(m.segments) == lines.sum()
        rho, alpha = m["p0"][lines], m["p1"][lines]
        for end in m.segments.transpose(1, 0, 2):
            assert np.allclose(end[:, 0] * np.cos(alpha) + end[:, 1] * np.sin(alpha), rho,
                               rtol=0.0, atol=1e-9), name
    assert np.array_equal(run.true_map["c00"], np.zeros(len(run.true_map)))
    explorer = run.explorer
    assert set(explorer["kind"]) <= {"frontier", "goal", "path"}
    assert (explorer["t"] <= run.trajectory["t"][-1]).all()
    table = mjslam.divergence_by_pair(run.divergence)
    assert sorted(table) == sorted(["classical_selective", "selective_classical",
                                    "classical_truth", "selective_truth"])
    assert all([r[0] for r in rows] == [100, 200] for rows in table.values())
    assert all(isinstance(r[0], int) and isinstance(r[1], float) for r in table["classical_truth"])
    assert mjslam.divergence_pair(run.divergence) == ("classical", "selective")


def test_sweep(sweep):
    assert [os.path.basename(r.path) for r in sweep.runs] == ["run_000", "run_001"]
    seeds = [r.manifest["seed"] for r in sweep.runs]
    assert seeds == [seeds[0], seeds[0] + 1]
    nees = sweep.nees
    assert len(nees) > 0 and set(nees["n_runs"]) <= {1.0, 2.0}
    assert (nees["lower"] < nees["upper"]).all()
    assert sweep.summary["sweep"]["completed_runs"] == 2
    assert sweep.divergence is None


def test_named_filters(out):
    """examples/dead_reckoning.yaml (three filters) and a sweep of two of its filters by other
    names: filter_names, maps, errors and nees.csv go by the run's filters' names."""
    path = str(out / "named")
    program("run", "--quiet", "--config", "examples/dead_reckoning.yaml", "--duration", "3",
            "--set", "render.enabled=false", "--out", path)
    run = mjslam.read_run(path)
    assert run.filter_names == ("classical", "selective", "dead_reckoning")
    assert set(run.maps) == set(run.filter_names) and len(run.maps["dead_reckoning"]) == 0
    assert run.errors("dead_reckoning").shape == (len(run.trajectory), 3)
    assert set(run.summary["filters"]) == set(run.filter_names)
    # The divergence of a pair named on the command line, its labels by name.
    program("divergence", path, "--points", "100", "--realisations", "2",
            "--pair", "selective", "classical")
    divergence = mjslam.read_run(path).divergence
    assert mjslam.divergence_pair(divergence) == ("selective", "classical")
    assert list(divergence["pair"]) == ["selective_classical", "classical_selective",
                                        "selective_truth", "classical_truth"]
    sweep_path = str(out / "named_sweep")
    program("sweep", "--quiet", "--config", "examples/dead_reckoning.yaml", "--runs", "2",
            "--jobs", "2", "--duration", "2", "--set", "render.enabled=false",
            "--set", "slam.filters=[{name: a, update: classical}, {name: dr, kind: dead_reckoning}]",
            "--set", "control.pose_source=a", "--out", sweep_path)
    sweep = mjslam.read_sweep(sweep_path)
    assert sweep.nees.columns == ("t", "a_anees", "dr_anees", "lower", "upper", "n_runs")
    assert sweep.runs[0].filter_names == ("a", "dr")


def test_divergence_pair_of_names_with_underscores(tmp_path):
    path = tmp_path / "divergence.csv"
    path.write_text("num_points,pair,mean,variance\n"
                    "10,dead_reckoning_ekf_b,1,0\n10,ekf_b_dead_reckoning,1,0\n"
                    "10,dead_reckoning_truth,1,0\n10,ekf_b_truth,1,0\n")
    table = mjslam.read_divergence(str(path))
    assert mjslam.divergence_pair(table) == ("dead_reckoning", "ekf_b")
    path.write_text("num_points,pair,mean,variance\n10,a_b,1,0\n10,a_truth,1,0\n")
    with pytest.raises(mjslam.RunFormatError, match="divergence.csv: pair: expected"):
        mjslam.divergence_pair(mjslam.read_divergence(str(path)))


def test_imported_log(imported):
    trajectory = imported.trajectory
    assert np.isnan(trajectory["true_x"]).all() and np.isnan(imported.scans.poses).all()
    reference = imported.reference
    assert len(reference) == len(imported.scans) > 0
    assert np.array_equal(reference["t"], imported.scans.t)
    assert np.isin(reference["t"], trajectory["t"]).all()
    assert imported.scans.num_beams == imported.manifest["num_beams"] == 180
    assert imported.true_map is None and imported.explorer is None


def test_config_manifest_and_table_helpers(run):
    assert run.setting("laser.num_beams") == run.config["laser"]["num_beams"]
    with pytest.raises(KeyError, match="config.yaml: no laser.no_such_key"):
        run.setting("laser.no_such_key")
    assert run.manifest["status"] == "completed"
    first = run.trajectory.select(slice(0, 3))
    assert len(first) == 3 and list(first["t"]) == list(run.trajectory["t"][:3])
    assert list(first.lines) == [2, 3, 4]
    with pytest.raises(KeyError, match="trajectory.csv: missing column 'nothing'"):
        run.trajectory["nothing"]
    # pandas is optional: a DataFrame where it is installed, an ImportError where not.
    try:
        import pandas  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError):
            run.trajectory.to_frame()
    else:
        frame = run.trajectory.to_frame()
        assert list(frame.columns) == list(mjslam.TRAJECTORY_COLUMNS)
        assert frame["classical_x"].tolist() == run.trajectory["classical_x"].tolist()


def test_heading_errors_are_wrapped(run, tmp_path):
    assert mjslam.wrap_angle(3.5) == 3.5 - 2.0 * math.pi
    assert mjslam.wrap_angle(-math.pi) == math.pi
    assert list(mjslam.wrap_angle(np.array([-3.5, 0.25]))) == [2.0 * math.pi - 3.5, 0.25]
    # A filter heading a whole turn (and 0.001 rad) off the truth: an error of 0.001 rad.
    path = copy_run(run, tmp_path)
    trajectory = os.path.join(path, mjslam.TRAJECTORY_FILE)
    with open(trajectory) as f:
        lines = f.read().split("\n")
    fields = lines[5].split(",")
    true_th = float(fields[mjslam.TRAJECTORY_COLUMNS.index("true_th")])
    fields[mjslam.TRAJECTORY_COLUMNS.index("selective_th")] = repr(true_th + 2.0 * math.pi + 0.001)
    lines[5] = ",".join(fields)
    with open(trajectory, "w") as f:
        f.write("\n".join(lines))
    assert mjslam.read_run(path).errors("selective")[4, 2] == pytest.approx(0.001, abs=1e-12)


# ---------------------------------------------------------------------------------------------
# Bad files: errors name file, line, column and value.

def copy_run(run, tmp_path):
    path = str(tmp_path / "copy")
    shutil.copytree(run.path, path)
    return path


def edit(path, old, new, count=1):
    with open(path, newline="") as f:
        text = f.read()
    assert old in text
    with open(path, "w", newline="") as f:
        f.write(text.replace(old, new, count))


def test_a_renamed_column_is_an_error_naming_it(run, tmp_path):
    path = copy_run(run, tmp_path)
    trajectory = os.path.join(path, mjslam.TRAJECTORY_FILE)
    edit(trajectory, ",true_x,", ",truth_x,")
    with pytest.raises(mjslam.RunFormatError,
                       match="trajectory.csv: expected column 2 to be true_x \\(got 'truth_x'\\)"):
        mjslam.read_run(path).trajectory
    edit(trajectory, ",truth_x,", ",true_x,")
    edit(trajectory, ",selective_pxx,", ",selective_pXX,")
    with pytest.raises(KeyError, match="missing column 'selective_pxx'"):
        mjslam.read_run(path).covariances("selective")
    edit(os.path.join(path, mjslam.map_file("classical")), "c00,c01", "c01,c00")
    with pytest.raises(mjslam.RunFormatError, match="expected column 5 to be c00"):
        mjslam.read_run(path).maps


def test_bad_fields_name_file_line_column_and_value(run, tmp_path):
    path = copy_run(run, tmp_path)
    trajectory = os.path.join(path, mjslam.TRAJECTORY_FILE)
    with open(trajectory) as f:
        lines = f.read().split("\n")
    fields = lines[3].split(",")
    fields[4] = "1.5x"
    lines[3] = ",".join(fields)
    with open(trajectory, "w") as f:
        f.write("\n".join(lines))
    with pytest.raises(mjslam.RunFormatError) as error:
        mjslam.read_trajectory(trajectory)
    assert str(error.value) == "%s:4: column odom_x: expected a number (got '1.5x')" % trajectory
    # Fewer fields.
    lines[3] = ",".join(fields[:-1])
    with open(trajectory, "w") as f:
        f.write("\n".join(lines))
    with pytest.raises(mjslam.RunFormatError, match=":4: expected 44 fields \\(got 43\\)"):
        mjslam.read_trajectory(trajectory)
    # A file cut short inside its last row.
    with open(trajectory, "w") as f:
        f.write("\n".join(lines[:3])[:-3])
    with pytest.raises(mjslam.RunFormatError, match=":3: the last row has no line end"):
        mjslam.read_trajectory(trajectory)
    # Times going back.
    scans = os.path.join(path, mjslam.SCANS_FILE)
    edit(scans, "\n0.2,", "\n0.05,")
    with pytest.raises(mjslam.RunFormatError,
                       match=":4: column t: expected a time after the row before's \\(got 0.05\\)"):
        mjslam.read_scans(scans)
    # An unknown map feature type.
    map_path = os.path.join(path, mjslam.GROUND_TRUTH_MAP_FILE)
    edit(map_path, ",corner,", ",corners,")
    with pytest.raises(mjslam.RunFormatError,
                       match="column type: expected line or corner \\(got 'corners'\\)"):
        mjslam.read_map(map_path)


def test_empty_fields_are_nan_and_windows_line_ends_are_read(tmp_path):
    path = str(tmp_path / "nees.csv")
    with open(path, "w", newline="") as f:
        f.write("t,classical_anees,selective_anees,lower,upper,n_runs\r\n"
                "0,,3.5,2.2,3.9,2\r\n0.1,inf,nan,2.2,3.9,2\r\n")
    nees = mjslam.read_nees(path)
    assert np.isnan(nees["classical_anees"][0]) and np.isinf(nees["classical_anees"][1])
    assert np.isnan(nees["selective_anees"][1]) and nees["n_runs"].tolist() == [2.0, 2.0]
    with open(path, "w") as f:
        f.write("t,classical_anees,selective_anees,lower,upper,n_runs\n0,1e999,1,1,1,1\n")
    with pytest.raises(mjslam.RunFormatError, match="beyond the range of a double \\(got '1e999'\\)"):
        mjslam.read_nees(path)
