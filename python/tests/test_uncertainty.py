"""Prediction bands from Python on a robot the package was never built with (the Kinova Jaco2 from
its URDF, through its robot library): a study of a controller's export synthesized from the
generated model with noise and an offset the model does not hold writes report/uncertainty.yaml;
symoro.predict's 95 % band holds 90-98 % of the held-out torque, counted here."""

import numpy as np

import symoro
from synth_logs import MAPPING
from test_payload import export


def test_the_held_out_torque_is_inside_the_95_percent_band(jaco2_standard, tmp_path):
    arm, s = jaco2_standard
    export(tmp_path / "arm.csv", arm, s, 21, seconds=40.0)
    symoro.import_logs(arm, tmp_path / "data", [tmp_path / "arm.csv"], split=0.7, **MAPPING)
    symoro.identify(arm, tmp_path / "data", tmp_path / "study", intervals_ms=[10], jobs=1)
    assert (tmp_path / "study" / "report" / "uncertainty.yaml").exists()
    runs = symoro.predict(arm, tmp_path / "study" / "report" / "parameters.yaml", tmp_path / "data")
    held = [r for r in runs if r["name"].endswith("_heldout")][0]
    inside = np.abs(held["tau"] - held["tau_model"]) <= held["tau_band"]
    assert held["band_coverage"] == inside.mean()
    assert 0.90 <= held["band_coverage"] <= 0.98, held["band_coverage_joint"]
    # Without the band: no band keys.
    plain = symoro.predict(arm, tmp_path / "study" / "report" / "parameters.yaml", tmp_path / "data", band=0)
    assert "tau_band" not in plain[0]
