"""Reading mjslam run directories from Python: the Python side of rundir/.

The file names and column lists below mirror rundir/layout.h (docs/run_directory.md);
tests/python/rundir_test.py makes a run with the program and checks them against the headers it
writes, file by file, and the values read here against `mjslam evaluate`'s summary.json.

    import mjslam
    run = mjslam.read_run("runs/demo")
    run.trajectory["classical_x"]          # a column: numpy float64 array
    run.errors("selective")                # estimate - truth per step, (N, 3)
    run.scans.ranges                       # (scans, beams)
    run.summary["filters"]["classical"]    # summary.json as a dict

Readers of CSV files keep the C++ readers' rules (rundir/csv_reader.h): a header row, one field
per column in every row, empty fields read as NaN ("not finite"), "nan" and "inf" as written,
text only in the text columns (explorer.csv `kind`, the maps' `type`, divergence.csv `pair`), a
last row without a line end is a file cut short. Bad input raises RunFormatError (a ValueError)
naming the file, line, column and value; a missing file raises FileNotFoundError naming it.
Needs numpy; config.yaml needs PyYAML (Debian's python3-numpy, python3-yaml); pandas is optional
(Table.to_frame).
"""

import functools
import json
import math
import os

import numpy as np

__all__ = [
    "CONFIG_FILE", "MANIFEST_FILE", "SUMMARY_FILE", "TRAJECTORY_FILE", "SCANS_FILE",
    "EXPLORER_FILE", "GROUND_TRUTH_MAP_FILE", "DIVERGENCE_FILE", "VIDEO_FILE",
    "FINAL_IMAGE_FILE", "REFERENCE_FILE", "SWEEP_RUNS_FOLDER", "NEES_FILE", "FILTER_NAMES",
    "RECORDED_TRAJECTORY_COLUMNS", "FILTER_COLUMN_SUFFIXES", "TRAJECTORY_COLUMNS",
    "SCAN_POSE_COLUMNS", "EXPLORER_COLUMNS", "MAP_COLUMNS", "NEES_COLUMNS", "REFERENCE_COLUMNS",
    "DIVERGENCE_COLUMNS", "MEASURED_COLUMN_SUFFIX", "MANIFEST_VOLATILE_KEYS",
    "filter_columns", "scan_columns", "map_file", "is_measured_column",
    "RunFormatError", "Table", "Scans", "Map", "Run", "Sweep",
    "read_run", "read_sweep", "read_csv", "read_header", "read_trajectory", "read_scans",
    "read_explorer", "read_map", "read_reference", "read_divergence", "read_nees",
    "read_json_object", "read_config", "config_value", "check_columns",
    "check_increasing_times", "divergence_by_pair", "divergence_pair", "wrap_angle",
]

# ---------------------------------------------------------------------------------------------
# The layout (rundir/layout.h).

CONFIG_FILE = "config.yaml"
MANIFEST_FILE = "manifest.json"
SUMMARY_FILE = "summary.json"
TRAJECTORY_FILE = "trajectory.csv"
SCANS_FILE = "scans.csv"
EXPLORER_FILE = "explorer.csv"
GROUND_TRUTH_MAP_FILE = "ground_truth_map.csv"
DIVERGENCE_FILE = "divergence.csv"
VIDEO_FILE = "video.mp4"
FINAL_IMAGE_FILE = "final.png"
# An imported log's reference trajectory (mjslam import): the log's own poses, a SLAM
# estimate, not ground truth.
REFERENCE_FILE = "reference.csv"
# A sweep directory: its runs' folder and the average NEES per step.
SWEEP_RUNS_FOLDER = "runs"
NEES_FILE = "nees.csv"

# The default filters (slam.filters absent), classical then selective, as in file names and
# column prefixes; a run's own are Run.filter_names (its trajectory.csv's header).
FILTER_NAMES = ("classical", "selective")

# trajectory.csv: the recorded columns (what a replay reads), the explored fraction, then each
# filter's columns "<filter>_<suffix>" in the order of FILTER_NAMES.
RECORDED_TRAJECTORY_COLUMNS = ("t", "true_x", "true_y", "true_th", "odom_x", "odom_y", "odom_th",
                               "cmd_v", "cmd_w")
FILTER_COLUMN_SUFFIXES = ("x", "y", "th", "pxx", "pxy", "pxth", "pyy", "pyth", "pthth", "nfeat",
                          "nmatched", "nupdated", "us", "period", "open_loop", "nees", "processed")


def filter_columns(name):
    """One filter's columns of trajectory.csv: "<name>_<suffix>" per FILTER_COLUMN_SUFFIXES."""
    return tuple("%s_%s" % (name, suffix) for suffix in FILTER_COLUMN_SUFFIXES)


TRAJECTORY_COLUMNS = (RECORDED_TRAJECTORY_COLUMNS + ("explored",) +
                      tuple(c for name in FILTER_NAMES for c in filter_columns(name)))

# scans.csv: time, the true laser pose X_WS, then the ranges r0 .. r<n-1>.
SCAN_POSE_COLUMNS = ("t", "x", "y", "th")


def scan_columns(num_beams):
    """The columns of scans.csv for `num_beams` beams."""
    return SCAN_POSE_COLUMNS + tuple("r%d" % i for i in range(num_beams))


EXPLORER_COLUMNS = ("t", "kind", "index", "x", "y")
MAP_COLUMNS = ("id", "type", "p0", "p1", "c00", "c01", "c11", "ax", "ay", "bx", "by")
NEES_COLUMNS = (("t",) + tuple(name + "_anees" for name in FILTER_NAMES) +
                ("lower", "upper", "n_runs"))
REFERENCE_COLUMNS = ("t", "x", "y", "th")
DIVERGENCE_COLUMNS = ("num_points", "pair", "mean", "variance")


def map_file(name):
    """The map file of filter `name`: "map_<name>.csv"."""
    return "map_%s.csv" % name


# What differs between two runs with the same seed, binary and machine (docs/run_directory.md,
# "Determinism"): the measured processing times, and the manifest's times and command line
# (and the commit it was built at).
MEASURED_COLUMN_SUFFIX = "_us"
MANIFEST_VOLATILE_KEYS = ("start_time", "end_time", "command_line", "git_commit")


def is_measured_column(column):
    """Whether a CSV column holds measured processing times (f_us), which no rerun repeats."""
    return column.endswith(MEASURED_COLUMN_SUFFIX)


# ---------------------------------------------------------------------------------------------
# CSV files.

class RunFormatError(ValueError):
    """A run file that does not hold what its format says; the message names the file, and the
    line, column and value where there is one."""


class Table:
    """A CSV file read whole: each column a numpy array (float64; text columns an array of str),
    looked up by name like a dict (`table["t"]`, `"explored" in table`, `table.get(name)`).
    `len(table)` is the number of rows; `lines[i]` the file's line of row i (1 is the header)."""

    def __init__(self, path, columns, data, lines):
        self.path = path
        self.columns = tuple(columns)
        self._data = data
        self.lines = lines

    def __getitem__(self, column):
        try:
            return self._data[column]
        except KeyError:
            raise KeyError("%s: missing column '%s'" % (self.path, column)) from None

    def __contains__(self, column):
        return column in self._data

    def __iter__(self):
        return iter(self.columns)

    def __len__(self):
        return len(self.lines)

    def __repr__(self):
        return "<%s %s: %d rows, %d columns>" % (type(self).__name__, self.path, len(self),
                                                 len(self.columns))

    def get(self, column, default=None):
        return self._data.get(column, default)

    def keys(self):
        return self.columns

    def items(self):
        return [(c, self._data[c]) for c in self.columns]

    def select(self, rows):
        """A table of some rows (a slice, indices or a boolean mask), of the same class."""
        table = object.__new__(type(self))
        table.__dict__.update(self.__dict__)
        table._data = {c: v[rows] for c, v in self._data.items()}
        table.lines = self.lines[rows]
        return table

    def to_frame(self):
        """The table as a pandas DataFrame (pandas is optional: ImportError without it)."""
        import pandas  # noqa: PLC0415 (optional dependency)
        return pandas.DataFrame({c: self._data[c] for c in self.columns})


def _where(path, line, column=None):
    return "%s:%d: %s" % (path, line, "column %s: " % column if column else "")


def read_header(path):
    """The column names of a CSV file (its first line only)."""
    with open(path, newline="") as f:
        line = f.readline()
    if not line:
        raise RunFormatError("%s: empty file, expected a header" % path)
    return line.rstrip("\r\n").split(",")


def read_csv(path, text_columns=()):
    """Reads a CSV file with a header row into a Table (rundir/csv_reader.h's rules: empty fields
    are NaN, the columns named in `text_columns` hold text). Raises RunFormatError naming the
    file, line, column and value of the first bad field, of a row with the wrong number of
    fields, or of a last row without a line end (a file cut short)."""
    path = os.fspath(path)
    with open(path, newline="") as f:
        text = f.read()
    if not text:
        raise RunFormatError("%s: empty file, expected a header" % path)
    lines = text.split("\n")
    if len(lines) == 1:
        raise RunFormatError("%s:1: the header has no line end (the file was cut short)" % path)
    if lines[-1]:
        raise RunFormatError("%s:%d: the last row has no line end (the file was cut short)"
                             % (path, len(lines)))
    columns = lines[0].rstrip("\r").split(",")
    rows, numbers = [], []
    for number, line in enumerate(lines[1:-1], start=2):
        line = line.rstrip("\r")
        if not line:
            continue
        fields = line.split(",")
        if len(fields) != len(columns):
            raise RunFormatError("%sexpected %d fields (got %d)" % (
                _where(path, number), len(columns), len(fields)))
        rows.append(fields)
        numbers.append(number)
    fields_by_column = list(zip(*rows)) if rows else [()] * len(columns)
    data = {}
    for j, column in enumerate(columns):
        fields = fields_by_column[j]
        if column in text_columns:
            data[column] = np.array(fields, dtype=str)
        else:
            data[column] = _numbers(path, column, fields, numbers)
    return Table(path, columns, data, np.array(numbers, dtype=int))


def _number(field):
    # strtod's spellings: no digit separators.
    if "_" in field:
        raise ValueError(field)
    value = float(field)
    if math.isinf(value) and "inf" not in field.lower():
        raise OverflowError(field)
    return value


def _numbers(path, column, fields, lines):
    """The numbers of one column (empty fields NaN); the error names the first bad field."""
    values = np.empty(len(fields))
    for i, field in enumerate(fields):
        if not field:
            values[i] = math.nan
            continue
        try:
            values[i] = _number(field)
        except OverflowError:
            raise RunFormatError("%sa number beyond the range of a double (got '%s')" % (
                _where(path, lines[i], column), field)) from None
        except ValueError:
            raise RunFormatError("%sexpected a number (got '%s')" % (
                _where(path, lines[i], column), field)) from None
    return values


def check_columns(table, expected, exact=True):
    """Checks that the table's columns are `expected` (or, not exact, start with them), in order.
    Raises RunFormatError naming the file and the first column that differs."""
    for i, name in enumerate(expected):
        if i >= len(table.columns) or table.columns[i] != name:
            got = ("'%s'" % table.columns[i]) if i < len(table.columns) else "no more columns"
            raise RunFormatError("%s: expected column %d to be %s (got %s)" % (
                table.path, i + 1, name, got))
    if exact and len(table.columns) > len(expected):
        raise RunFormatError("%s: unexpected column %d '%s' (expected %d columns)" % (
            table.path, len(expected) + 1, table.columns[len(expected)], len(expected)))


def check_increasing_times(table, column="t"):
    """Checks that `column` holds finite times, each after the row before's. Raises
    RunFormatError naming the file, line, column and value."""
    t = table[column]
    bad = ~np.isfinite(t)
    bad[1:] |= ~(t[1:] > t[:-1])
    if bad.any():
        i = int(np.argmax(bad))
        problem = "expected a finite time" if not math.isfinite(t[i]) else \
            "expected a time after the row before's"
        raise RunFormatError("%s%s (got %r)" % (_where(table.path, int(table.lines[i]), column),
                                                problem, float(t[i])))


def read_trajectory(path):
    """trajectory.csv: at least one row, the recorded columns first (RECORDED_TRAJECTORY_COLUMNS;
    a run of an older program may lack the later optional ones), times finite and increasing."""
    table = read_csv(path)
    check_columns(table, RECORDED_TRAJECTORY_COLUMNS, exact=False)
    if len(table) == 0:
        raise RunFormatError("%s: no rows" % table.path)
    check_increasing_times(table)
    return table


class Scans(Table):
    """scans.csv: `t`, the true laser poses `poses` (N x 3: x, y, th of S in W; NaN for a log
    without truth) and the ranges `ranges` (N x num_beams, metres, no-return beams at the
    maximum range)."""

    @property
    def num_beams(self):
        return len(self.columns) - len(SCAN_POSE_COLUMNS)

    @property
    def t(self):
        return self["t"]

    @functools.cached_property
    def poses(self):
        return np.column_stack([self[c] for c in SCAN_POSE_COLUMNS[1:]]).reshape(len(self), 3)

    @functools.cached_property
    def ranges(self):
        columns = self.columns[len(SCAN_POSE_COLUMNS):]
        return np.column_stack([self[c] for c in columns]).reshape(len(self), len(columns))

    def select(self, rows):
        table = super().select(rows)
        table.__dict__.pop("poses", None)
        table.__dict__.pop("ranges", None)
        return table


def read_scans(path):
    """scans.csv: columns t, x, y, th, r0 .. r<n-1>; times finite and increasing. No rows is
    allowed (a run too short to scan)."""
    table = read_csv(path)
    num_beams = len(table.columns) - len(SCAN_POSE_COLUMNS)
    check_columns(table, scan_columns(max(num_beams, 0)))
    check_increasing_times(table)
    scans = object.__new__(Scans)
    scans.__dict__.update(table.__dict__)
    return scans


def read_explorer(path):
    """explorer.csv: t, kind (text: frontier, goal, path), index, x, y."""
    table = read_csv(path, text_columns=("kind",))
    check_columns(table, EXPLORER_COLUMNS)
    return table


class Map(Table):
    """A map CSV (map_<filter>.csv, ground_truth_map.csv): one row per feature, MAP_COLUMNS. A
    line's p0, p1 are rho, alpha (x cos(alpha) + y sin(alpha) = rho) and ax .. by the ends of its
    seen segment; a corner's p0, p1 its x, y."""

    @property
    def is_corner(self):
        return self["type"] == "corner"

    @property
    def corners(self):
        """(K, 2): the corners' x, y."""
        mask = self.is_corner
        return np.column_stack((self["p0"][mask], self["p1"][mask])).reshape(-1, 2)

    @property
    def segments(self):
        """(L, 2, 2): the seen segment of every line that has one, [[ax, ay], [bx, by]]."""
        mask = ~self.is_corner & ~np.isnan(self["ax"])
        ends = np.column_stack([self[c][mask] for c in ("ax", "ay", "bx", "by")])
        return ends.reshape(-1, 2, 2)


def read_map(path):
    """A map CSV: MAP_COLUMNS, `type` text (line or corner)."""
    table = read_csv(path, text_columns=("type",))
    check_columns(table, MAP_COLUMNS)
    unknown = ~np.isin(table["type"], ("line", "corner"))
    if unknown.any():
        i = int(np.argmax(unknown))
        raise RunFormatError("%sexpected line or corner (got '%s')" % (
            _where(table.path, int(table.lines[i]), "type"), table["type"][i]))
    result = object.__new__(Map)
    result.__dict__.update(table.__dict__)
    return result


def read_reference(path):
    """reference.csv of an imported log: t, x, y, th (the log's poses of R, not ground truth)."""
    table = read_csv(path)
    check_columns(table, REFERENCE_COLUMNS)
    return table


def read_divergence(path):
    """divergence.csv: num_points, pair (text: `<a>_<b>`, `<b>_<a>`, `<a>_truth`, `<b>_truth` of
    the two filters compared, classical_selective, ... by default), mean, variance."""
    table = read_csv(path, text_columns=("pair",))
    check_columns(table, DIVERGENCE_COLUMNS)
    return table


def read_nees(path):
    """nees.csv of a sweep: t, <filter>_anees of each filter, lower, upper, n_runs."""
    table = read_csv(path)
    names = [c[:-len("_anees")] for c in table.columns if c.endswith("_anees")]
    check_columns(table, ("t",) + tuple(n + "_anees" for n in names) + NEES_COLUMNS[-3:])
    return table


def divergence_pair(table):
    """The two filters (a, b) a divergence table compares, from its `<a>_truth`, `<b>_truth` rows
    in their order (filter names may hold '_': the other labels cannot say)."""
    pair = []
    for label in table["pair"].tolist():
        if label.endswith("_truth") and label[:-len("_truth")] not in pair:
            pair.append(label[:-len("_truth")])
    if len(pair) != 2:
        raise RunFormatError("%s: pair: expected the rows of two filters' <name>_truth (got %s)"
                             % (table.path, ", ".join(pair) or "none"))
    return tuple(pair)


def divergence_by_pair(table):
    """{pair: [(num_points, mean, variance), ...]} of a divergence table, sorted by num_points
    (Python int and float)."""
    out = {}
    for n, pair, m, v in zip(table["num_points"].tolist(), table["pair"].tolist(),
                             table["mean"].tolist(), table["variance"].tolist()):
        out.setdefault(pair, []).append((int(n), m, v))
    for rows in out.values():
        rows.sort()
    return out


# ---------------------------------------------------------------------------------------------
# JSON and YAML files.

def read_json_object(path):
    """A JSON file holding an object (manifest.json, summary.json), as a dict. Raises
    RunFormatError naming the file when it is not valid JSON or not an object."""
    path = os.fspath(path)
    with open(path) as f:
        try:
            value = json.load(f)
        except json.JSONDecodeError as error:
            raise RunFormatError("%s:%d: %s" % (path, error.lineno, error.msg)) from None
    if not isinstance(value, dict):
        raise RunFormatError("%s: expected a JSON object" % path)
    return value


def read_config(path):
    """A config.yaml as nested dicts (PyYAML, Debian's python3-yaml)."""
    import yaml  # noqa: PLC0415 (only config.yaml needs it)
    path = os.fspath(path)
    with open(path) as f:
        try:
            value = yaml.safe_load(f)
        except yaml.YAMLError as error:
            raise RunFormatError("%s: %s" % (path, error)) from None
    if not isinstance(value, dict):
        raise RunFormatError("%s: expected a mapping of sections" % path)
    return value


def config_value(config, key, path="config.yaml"):
    """The value at a dotted key ("laser.num_beams") of a config dict. Raises KeyError naming
    `path` and the key when it is missing."""
    value = config
    for part in key.split("."):
        if not isinstance(value, dict) or part not in value:
            raise KeyError("%s: no %s" % (path, key))
        value = value[part]
    return value


# ---------------------------------------------------------------------------------------------
# Run and sweep directories.

def wrap_angle(angle):
    """Angles wrapped to (-pi, pi] as common/angles.h's WrapAngle: the IEEE remainder by 2 pi
    (math.remainder, elementwise), -pi moved to pi."""
    values = np.asarray(angle, dtype=float)
    wrapped = np.array([math.remainder(a, 2.0 * math.pi) for a in values.ravel().tolist()])
    wrapped = np.where(wrapped <= -math.pi, wrapped + 2.0 * math.pi, wrapped).reshape(values.shape)
    return wrapped if wrapped.ndim else float(wrapped)


class Run:
    """A run directory (of mjslam run, replay or import). Nothing is read when it is made; each
    file on first use, then kept (a missing file raises FileNotFoundError naming it then):
    `trajectory`, `scans` (Scans), `explorer`, `reference`, `true_map`, `divergence` (Tables;
    None when the run has no such file), `maps` ({filter: Map}), `config`, `manifest`,
    `summary` (dicts). `filter_names` come from trajectory.csv's header."""

    def __init__(self, path):
        self.path = os.fspath(path)

    def __repr__(self):
        return "<Run %s>" % self.path

    def file(self, name):
        """The path of a file of the run."""
        return os.path.join(self.path, name)

    def has(self, name):
        """Whether the run has the file `name`."""
        return os.path.isfile(self.file(name))

    def _optional(self, name, reader):
        return reader(self.file(name)) if self.has(name) else None

    @functools.cached_property
    def config(self):
        return read_config(self.file(CONFIG_FILE))

    def setting(self, key):
        """A value of config.yaml by its dotted key ("laser.num_beams"); KeyError names the file
        and key when it is missing."""
        return config_value(self.config, key, self.file(CONFIG_FILE))

    @functools.cached_property
    def manifest(self):
        return read_json_object(self.file(MANIFEST_FILE))

    @functools.cached_property
    def summary(self):
        return read_json_object(self.file(SUMMARY_FILE))

    @functools.cached_property
    def trajectory(self):
        return read_trajectory(self.file(TRAJECTORY_FILE))

    @functools.cached_property
    def scans(self):
        return read_scans(self.file(SCANS_FILE))

    @functools.cached_property
    def explorer(self):
        return self._optional(EXPLORER_FILE, read_explorer)

    @functools.cached_property
    def reference(self):
        return self._optional(REFERENCE_FILE, read_reference)

    @functools.cached_property
    def true_map(self):
        """ground_truth_map.csv (written by mjslam evaluate), or None."""
        return self._optional(GROUND_TRUTH_MAP_FILE, read_map)

    @functools.cached_property
    def maps(self):
        return {name: read_map(self.file(map_file(name))) for name in self.filter_names}

    @functools.cached_property
    def divergence(self):
        return self._optional(DIVERGENCE_FILE, read_divergence)

    @functools.cached_property
    def filter_names(self):
        """The filters of trajectory.csv, in its order: the prefixes f of its f_x, f_y, f_th
        columns other than true and odom."""
        columns = self.trajectory.columns if "trajectory" in self.__dict__ else \
            read_header(self.file(TRAJECTORY_FILE))
        names = []
        for column in columns:
            name = column[:-2]
            if (column.endswith("_x") and name not in ("true", "odom") and
                    name + "_y" in columns and name + "_th" in columns):
                names.append(name)
        return tuple(names)

    # Per-step arrays of trajectory.csv.

    def poses(self, name):
        """(N, 3) poses x, y, th of R in W per step: `name` a filter, "true" or "odom"."""
        t = self.trajectory
        return np.column_stack([t["%s_%s" % (name, c)] for c in ("x", "y", "th")])

    def covariances(self, name):
        """(N, 3, 3) pose covariances of filter `name` per step (x, y, th)."""
        t = self.trajectory
        xx, xy, xth, yy, yth, thth = (t["%s_p%s" % (name, c)]
                                      for c in ("xx", "xy", "xth", "yy", "yth", "thth"))
        return np.stack([np.column_stack(r) for r in
                         ((xx, xy, xth), (xy, yy, yth), (xth, yth, thth))], axis=1)

    def variances(self, name):
        """(N, 3) the diagonal of covariances(name): pxx, pyy, pthth."""
        t = self.trajectory
        return np.column_stack([t["%s_p%s" % (name, c)] for c in ("xx", "yy", "thth")])

    def errors(self, name):
        """(N, 3) estimate - true pose of filter `name` per step (heading wrapped, wrap_angle),
        as mjslam evaluate compares them (app/jobs/evaluate.cc): on a step the filter skipped
        (slam.timing realtime) it holds the estimate of its last processed step, compared with
        that step's true pose; on every other step, with the step's own."""
        processed = self.processed(name)
        processed[0] = True
        steps = np.arange(len(processed))
        held = np.maximum.accumulate(np.where(processed, steps, 0))
        error = self.poses(name) - self.poses("true")[held]
        error[:, 2] = wrap_angle(error[:, 2])
        return error

    def nees(self, name):
        """Pose NEES of filter `name` per step (NaN where P is nearly singular)."""
        return self.trajectory[name + "_nees"]

    def processed(self, name):
        """Whether filter `name` processed each step's record: f_processed not 0 (all True for
        a run without the column)."""
        column = self.trajectory.get(name + "_processed")
        return np.ones(len(self.trajectory), bool) if column is None else column != 0.0


class Sweep:
    """A sweep directory (mjslam sweep): `config`, `summary`, `nees` (Table), `divergence`
    (Table or None) and `runs`, a Run per folder of runs/ in the order of their names (none
    without runs/). Files are read on first use."""

    def __init__(self, path):
        self.path = os.fspath(path)

    def __repr__(self):
        return "<Sweep %s>" % self.path

    def file(self, name):
        return os.path.join(self.path, name)

    def has(self, name):
        return os.path.isfile(self.file(name))

    @functools.cached_property
    def config(self):
        return read_config(self.file(CONFIG_FILE))

    @functools.cached_property
    def summary(self):
        return read_json_object(self.file(SUMMARY_FILE))

    @functools.cached_property
    def nees(self):
        return read_nees(self.file(NEES_FILE))

    @functools.cached_property
    def divergence(self):
        return read_divergence(self.file(DIVERGENCE_FILE)) if self.has(DIVERGENCE_FILE) else None

    @functools.cached_property
    def runs(self):
        root = self.file(SWEEP_RUNS_FOLDER)
        if not os.path.isdir(root):
            return []
        return [Run(os.path.join(root, name)) for name in sorted(os.listdir(root))
                if os.path.isdir(os.path.join(root, name))]


def read_run(path):
    """The run directory at `path` (files read on first use)."""
    return Run(path)


def read_sweep(path):
    """The sweep directory at `path` (files read on first use)."""
    return Sweep(path)
