"""mjslam from Python (python/README.md).

Reading run and sweep directories (mjslam.rundir, pure Python):

    import mjslam
    run = mjslam.read_run("runs/demo")
    run.trajectory["classical_x"], run.errors("selective"), run.summary["run"]["duration_s"]

The closed loop, runs and filters written in Python (the extension mjslam._mjslam, which the
build puts beside this file in build/python/mjslam/):

    loop = mjslam.Loop("configs/default.yaml", ["run.duration_s=20"])
    for step in loop:
        step.t, step.true_pose, loop.pose("classical"), loop.covariance("classical")
    mjslam.register_filter("my_filter", MyFilter)    # then slam.filters can name kind my_filter
    mjslam.run("configs/default.yaml", ["slam.filters=[...]"], out="runs/mine")
"""

from mjslam.rundir import *  # noqa: F401,F403
from mjslam.rundir import __all__ as _rundir_all

try:
    from mjslam._mjslam import (ConfigError, Features, Loop, ParamError, Record,  # noqa: F401
                                SimError, SlamInputError, Step, filter_kinds, load_config,
                                register_filter, run)
    HAS_EXTENSION = True
except ImportError:  # the source tree's copy (python/), without the build's extension
    HAS_EXTENSION = False

__all__ = list(_rundir_all) + ["HAS_EXTENSION"] + (
    ["ConfigError", "Features", "Loop", "ParamError", "Record", "SimError", "SlamInputError",
     "Step", "filter_kinds", "load_config", "register_filter", "run"] if HAS_EXTENSION else [])
