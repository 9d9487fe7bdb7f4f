"""mjslam from Python: reading run and sweep directories (python/README.md).

    import mjslam
    run = mjslam.read_run("runs/demo")
    run.trajectory["classical_x"], run.errors("selective"), run.summary["run"]["duration_s"]

Everything is in mjslam.rundir, re-exported here.
"""

from mjslam.rundir import *  # noqa: F401,F403
from mjslam.rundir import __all__  # noqa: F401
