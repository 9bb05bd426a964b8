"""symoro: fast robot dynamics compiled from OpenSYMORO models, and the identification workflow.

    import numpy as np, symoro
    arm = symoro.models.crane_x7.reduced          # a compiled robot model
    W = arm.regressor(q, qd, qdd)                 # (nq, np), or (N, nq, np) for a batch
    symoro.import_logs(arm, "data", ["log.csv"], time="t", q="pos_*", tau="eff_*")
    study = symoro.identify(arm, "data", "study", robot_dir="robots/crane_x7")

See docs/python.md.
"""

from ._symoro import DataError, Model, StudyStopped, identify, import_logs
from . import models

__all__ = ["DataError", "Model", "StudyStopped", "identify", "import_logs", "models"]
