"""symoro: fast robot dynamics compiled from OpenSYMORO models, and the identification workflow.

    import numpy as np, symoro
    arm = symoro.models.crane_x7.reduced          # a compiled robot model
    my_arm = symoro.load("robots/my_arm")         # any robot folder, through its robot library
    W = arm.regressor(q, qd, qdd)                 # (nq, np), or (N, nq, np) for a batch
    symoro.import_logs(arm, "data", ["log.csv"], time="t", q="pos_*", tau="eff_*")
    study = symoro.identify(arm, "data", "study", robot_dir="robots/crane_x7")
    fits = symoro.predict(arm, study["phi"], "data")          # the model's torque on every run
    found = symoro.diagnose(arm, "data", "diagnosis", robot_dir="robots/crane_x7")  # missing effects
    gap = symoro.compare("study", "study-diagnosed", "gap")   # two studies on their held-out runs
    symoro.export_urdf(arm, "study-physical", "arm.urdf", prior="zero")  # consistent inertials
    obs = symoro.MomentumObserver(arm, study["phi"])          # collision detection (docs/observer.md)
    tool = symoro.identify_payload(arm, study["phi"], ["tool-data"], full=symoro.models.crane_x7.full)

See docs/python.md.
"""

from ._symoro import (DataError, Model, MomentumObserver, StudyStopped, collision_events, compare, diagnose, export_urdf,
                      identify, identify_payload, import_logs, observer_thresholds, predict)
from . import models
from .models import load

__all__ = ["DataError", "Model", "MomentumObserver", "StudyStopped", "collision_events", "compare", "diagnose",
           "export_urdf", "identify", "identify_payload", "import_logs", "load", "models", "observer_thresholds", "predict"]
