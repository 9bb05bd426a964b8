"""symoro.diagnose on logs synthesized from a generated model with an effect the diagnosis is
not told about (a 0.05 N m torque offset on joint 2, synth_logs.py) and noise: the same
findings, report and variant as dynid diagnose (the same files, bit for bit), on two robots;
its errors with dynid's text; --apply's robot.yaml as dynid's; Ctrl-C stops it writing nothing."""

import os
import shutil
import signal
import time

import numpy as np
import pytest

import symoro

from synth_logs import MAPPING, make_exports, run


def imported(tmp_path, arm):
    exports = make_exports(tmp_path, arm)
    symoro.import_logs(arm, tmp_path / "data", exports, heldout=[exports[-1]], **MAPPING)
    return tmp_path / "data"


def files(folder):
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("robot", ["rx90", "stanford_rrp"])  # six revolute joints; two and a prismatic one
def test_diagnose_equals_the_command_line_and_names_the_offset(tmp_path, robot, dynid, source_dir):
    arm = getattr(symoro.models, robot).full
    data = imported(tmp_path, arm)
    robot_dir = source_dir / "robots" / robot
    lines = []
    d = symoro.diagnose(arm, data, tmp_path / "py", robot_dir=robot_dir, progress=lines.append)
    cli = run([dynid, "diagnose", "--robot", robot, "--robots-dir", source_dir / "robots", "--data", data,
               "-o", tmp_path / "cli"])
    assert cli.returncode == 0, cli.stderr
    # The same report, figures and variant; dynid's lines are the progress lines (its paths aside).
    py_files, cli_files = files(tmp_path / "py"), files(tmp_path / "cli")
    assert sorted(py_files) == sorted(cli_files) and "diagnosis.md" in py_files and "variant.yaml" in py_files
    for name in py_files:
        assert py_files[name] == cli_files[name], name
    assert [l.replace(str(tmp_path / "py"), "OUT") for l in lines] == \
        [l.replace(str(tmp_path / "cli"), "OUT") for l in cli.stdout.splitlines()]

    # The findings as Python objects, and the physics: the offset on joint 2 is named with its
    # size, and the held-out residual falls to about the noise (0.02 N m).
    assert d["robot"] == robot and d["model"] == robot and d["train"] == ["r1", "r2", "r3"] and d["heldout"] == ["check"]
    offsets = [e for e in d["effects"] if e["effect"] == "offset"]
    assert [e["joint"] for e in offsets] == [2]
    [std] = offsets[0]["std"]
    assert std < 0.01 and abs(offsets[0]["values"][0] - 0.05) < 3 * std, offsets[0]["magnitude"]
    # Refitting the model's parameters absorbs part of it elsewhere (gravity, friction); what is
    # left falls on joint 2 held out, and against the raw torque it is the noise.
    assert offsets[0]["heldout_gain"] > 0.2 and d["heldout_rmse_after"][1] < d["heldout_rmse_before"][1]
    assert d["heldout_total_after"] < d["heldout_total_before"]
    # (the raw-torque evaluation's low-pass at 0.4 of the rate keeps 0.8 of white noise's power:
    # 0.02 * sqrt(0.8) = 0.0179 N m)
    assert d["raw_total_after"] <= d["raw_total_before"] and 0.016 < d["raw_total_after"] < 0.024
    assert d["heldout_rmse_before"].shape == (arm.nq,)
    assert not d["backlash_judged"] and "has none" in d["backlash_note"]  # neither robot has a twin
    assert d["variant"] == "diagnosed" and d["variant_yaml"] in (tmp_path / "py" / "variant.yaml").read_text()
    assert str(d["report"]) == str(tmp_path / "py" / "diagnosis.md") and d["applied"] is None


def test_apply_and_errors_as_the_command_line(tmp_path, dynid, source_dir):
    arm = symoro.models.rx90.full
    data = imported(tmp_path, arm)
    # --apply: each on its own copy of the robot folder; the same robot.yaml after.
    for name in ["py", "cli"]:
        shutil.copytree(source_dir / "robots" / "rx90", tmp_path / name / "rx90")
    d = symoro.diagnose(arm, data, tmp_path / "py-diag", robot_dir=tmp_path / "py" / "rx90", only=["offset"],
                        variant="with_offset", apply=True, backlash=False)
    cli = run([dynid, "diagnose", "--robot", "rx90", "--robots-dir", tmp_path / "cli", "--data", data, "-o",
               tmp_path / "cli-diag", "--only", "offset", "--variant", "with_offset", "--apply", "--no-backlash"])
    assert cli.returncode == 0, cli.stderr
    yaml = (tmp_path / "py" / "rx90" / "robot.yaml").read_text()
    assert yaml == (tmp_path / "cli" / "rx90" / "robot.yaml").read_text()
    assert yaml.endswith(d["variant_yaml"]) and "with_offset:" in yaml and str(d["applied"]).endswith("robot.yaml")
    assert [e["effect"] for e in d["effects"]] == ["offset"] and d["backlash_note"] == "Not run (--no-backlash)."

    # Errors: the text dynid prints (after its "dynid: error: " prefix), as ValueError.
    def same_error(kwargs, args):
        with pytest.raises(ValueError) as e:
            symoro.diagnose(arm, data, tmp_path / "x", robot_dir=source_dir / "robots" / "rx90", **kwargs)
        cli = run([dynid, "diagnose", "--robot", "rx90", "--robots-dir", source_dir / "robots", "--data", data, "-o",
                   tmp_path / "y", *args])
        assert cli.returncode != 0 and str(e.value) in cli.stderr, (str(e.value), cli.stderr)
        return str(e.value)

    assert "no run nope of trial 1 to fit" in same_error(dict(train=["nope"]), ["--train", "nope"])
    assert "no fitting run for trial 2" in same_error(dict(trial=2), ["--trial", "2"])
    assert "no run nope of trial 1 to hold out" in same_error(dict(heldout=["nope"]), ["--heldout", "nope"])
    assert "unknown effect 'friction'" in same_error(dict(only=["friction"]), ["--only", "friction"])
    assert "lower-case identifier" in same_error(dict(variant="Upper"), ["--variant", "Upper"])
    assert "needs --params" in same_error(dict(only=["payload"]), ["--only", "payload"])
    with pytest.raises(ValueError, match="apply: needs robot_dir"):
        symoro.diagnose(arm, data, tmp_path / "x", apply=True)
    # Numbers dynid refuses are refused here too, before any work (alpha=nan was computed with).
    for kwargs, pattern in [(dict(alpha=float("nan")), "--alpha nan: must be > 0 and <= 0.5"),
                            (dict(alpha=0.9), "--alpha 0.9"), (dict(trial=0), "--trial 0"),
                            (dict(interval_ms=float("inf")), "--interval inf"), (dict(min_gain=-1), "--min-gain -1"),
                            (dict(cutoff=0), "--cutoff 0")]:
        with pytest.raises(ValueError, match=pattern.replace("+", "\\+")):
            symoro.diagnose(arm, data, tmp_path / "x", **kwargs)
    assert not (tmp_path / "x").exists() and not (tmp_path / "y").exists()


def test_ctrl_c_stops_a_diagnosis_writing_nothing(tmp_path):
    arm = symoro.models.rx90.full
    data = imported(tmp_path, arm)

    lines = []

    def interrupt(line):
        lines.append(line)
        if len(lines) == 1:
            os.kill(os.getpid(), signal.SIGINT)  # as Ctrl-C would
            time.sleep(0.5)  # the waiting thread sees it before the next stage

    with pytest.raises(KeyboardInterrupt):
        symoro.diagnose(arm, data, tmp_path / "stopped", progress=interrupt)
    assert not (tmp_path / "stopped" / "diagnosis.md").exists()
    # A callback's own exception stops it the same way, and arrives as itself.
    with pytest.raises(ZeroDivisionError):
        symoro.diagnose(arm, data, tmp_path / "stopped", progress=lambda line: 1 / 0)
    assert not (tmp_path / "stopped" / "diagnosis.md").exists()
    d = symoro.diagnose(arm, data, tmp_path / "stopped")
    assert (tmp_path / "stopped" / "diagnosis.md").exists() and np.isfinite(d["heldout_total_after"])
