"""The workflow from Python on logs synthesized here from a generated model (the RX-90, which
has no twin), with an effect the study is not told about (a torque offset) and noise:
import_logs as dynid import, identify as dynid identify (the same files, bit for bit), the
project's errors with dynid's text, and a study stopped by Ctrl-C that a rerun resumes."""

import os
import pathlib
import signal
import time

import numpy as np
import pytest

import symoro

from synth_logs import ARM, CLI_MAPPING, MAPPING, make_exports, run


@pytest.fixture(scope="module")
def exports(tmp_path_factory):
    return make_exports(tmp_path_factory.mktemp("exports"))


def records(study):
    """A study's records without their wall times."""
    out = {}
    for f in sorted((study / "runs").glob("*.yaml")):
        out[f.name] = [l for l in f.read_text().splitlines() if not l.lstrip().startswith("t_")]
    return out


@pytest.mark.parametrize("robot", ["rx90", "stanford_rrp"])  # six revolute joints; two and a prismatic one
def test_import_and_identify_equal_the_command_line(tmp_path, robot, dynid, source_dir):
    arm = getattr(symoro.models, robot).full
    exports = make_exports(tmp_path, arm)
    robot_dir = source_dir / "robots" / robot
    r = symoro.import_logs(arm, tmp_path / "py-data", exports, heldout=[exports[-1]], **MAPPING)
    assert [l["name"] for l in r["logs"]] == ["r1", "r2", "r3", "check"]
    assert [x["family"] for x in r["runs"]] == ["F", "F", "F", "V"]
    assert r["logs"][0]["samples"] == 8000 and r["logs"][0]["velocity"] == "measured"
    cli = run([dynid, "import", "--robot", robot, "--robots-dir", source_dir / "robots", "-o", tmp_path / "cli-data",
               *exports, "--heldout", exports[-1], *CLI_MAPPING])
    assert cli.returncode == 0, cli.stderr
    for f in ["r1.csv", "check.csv", "r1.meta.yaml", "dataset.yaml", "import.yaml"]:
        assert (tmp_path / "py-data" / f).read_bytes() == (tmp_path / "cli-data" / f).read_bytes(), f

    seen = []
    study = symoro.identify(arm, tmp_path / "py-data", tmp_path / "py-study", robot_dir=robot_dir, intervals_ms=[10],
                            jobs=1, progress=lambda done, total, run: seen.append((done, total, run["id"])))
    assert [s[:2] for s in seen] == [(1, 3), (2, 3), (3, 3)]
    cli = run([dynid, "identify", "--robot", robot, "--robots-dir", source_dir / "robots", "--data", tmp_path / "py-data",
               "-o", tmp_path / "cli-study", "--interval", "10", "--jobs", "1"])
    assert cli.returncode == 0, cli.stderr
    assert records(tmp_path / "py-study") == records(tmp_path / "cli-study")
    assert (tmp_path / "py-study" / "validation.yaml").read_bytes() == (tmp_path / "cli-study" / "validation.yaml").read_bytes()
    assert pathlib.Path(study["report"]).exists()

    # The results as Python objects, and the physics: the identified model predicts the
    # held-out torque to near its noise, and tau = W phi holds with the accepted parameters.
    assert study["robot"] == robot and study["model"] == "full"
    assert len(study["runs"]) == 3 and study["selection"]["id"] in [r["id"] for r in study["runs"]]
    assert list(study["parameters"]) == arm.parameter_names
    np.testing.assert_array_equal(study["phi"], [study["parameters"][n] for n in arm.parameter_names])
    [v] = study["validation"]
    # 0.02 N m of noise on every joint, and the unmodelled 0.05 N m offset on one of nq: against
    # the raw torque, about their sum (the study's own, filtered torque has less of the noise).
    bound = 1.3 * np.sqrt(0.02**2 + 0.05**2 / arm.nq)
    assert v["trajectory"] == "check" and v["rmse_rescue"] < bound and 0.018 < v["raw_rmse_rescue"] < bound
    assert study["validation"][0]["tau_rescue"].shape[1] == arm.nq


def read_csv_columns(path):
    header = path.read_text().splitlines()[0].split(",")
    return header, np.loadtxt(path, delimiter=",", skiprows=1)


@pytest.mark.parametrize("robot", ["rx90", "stanford_rrp"])
def test_predict_and_compare_equal_the_command_line(tmp_path, robot, dynid, source_dir):
    robots = source_dir / "robots"
    arm = getattr(symoro.models, robot).full
    exports = make_exports(tmp_path, arm)
    symoro.import_logs(arm, tmp_path / "data", exports, heldout=[exports[-1]], **MAPPING)
    full = symoro.identify(arm, tmp_path / "data", tmp_path / "full", intervals_ms=[10], jobs=1)
    rigid = getattr(symoro.models, robot).rigid  # without Coulomb friction, which the logs have
    symoro.identify(rigid, tmp_path / "data", tmp_path / "rigid", intervals_ms=[10], jobs=1)

    # predict: the accepted parameters on every run, against dynid predict's CSVs, and the physics
    # (the fitting runs' torque to the noise: 0.02 N m, the unmodelled offset 0.05 N m on joint 2).
    params = tmp_path / "full" / "report" / "parameters.yaml"
    runs = symoro.predict(arm, params, tmp_path / "data", interval_ms=10)
    assert [r["name"] for r in runs] == ["r1", "r2", "r3", "check"]
    again = symoro.predict(arm, full["phi"], tmp_path / "data" / "r1.csv", interval_ms=10)
    assert np.array_equal(again[0]["tau_model"], runs[0]["tau_model"])
    cli = run([dynid, "predict", "--robot", robot, "--robots-dir", robots, "--params", params, tmp_path / "data",
               "-o", tmp_path / "predicted", "--interval", "10"])
    assert cli.returncode == 0, cli.stderr
    for r in runs:
        header, table = read_csv_columns(tmp_path / "predicted" / f"{r['name']}.predicted.csv")
        n = arm.nq
        assert np.array_equal(table[:, 0], r["time"])
        for k, what in enumerate(["q", "qd", "qdd", "tau", "tau_model", "tau_band"]):
            assert np.array_equal(table[:, 1 + k * n:1 + (k + 1) * n], r[what]), what
        assert np.all(r["rmse"] < 0.06) and np.all(r["rms"] > 1), (r["rmse"], r["rms"])
    # The 95 % prediction band (the study's report/uncertainty.yaml beside the parameters): the
    # held-out run's torque inside it about 95 % of the time, as counted here.
    check = runs[-1]
    inside = np.abs(check["tau"] - check["tau_model"]) <= check["tau_band"]
    assert check["band_coverage"] == pytest.approx(inside.mean(), rel=1e-12)
    assert 0.90 <= check["band_coverage"] <= 0.98, check["band_coverage_joint"]

    # compare: gap.md as dynid compare writes it; the rigid model lacks the friction the logs have.
    gap = symoro.compare(tmp_path / "full", tmp_path / "rigid", tmp_path / "gap")
    cli = run([dynid, "compare", "--robot", robot, "--before", tmp_path / "full", "--after", tmp_path / "rigid", "-o",
               tmp_path / "gap-cli"])
    assert cli.returncode == 0, cli.stderr
    assert (tmp_path / "gap" / "gap.md").read_text() == (tmp_path / "gap-cli" / "gap.md").read_text()
    assert gap["before_model"] == "full" and gap["after_model"] == "rigid"
    assert [t["trajectory"] for t in gap["trajectories"]] == ["check"]
    assert gap["rmse_after"] > gap["rmse_before"]  # friction the rigid model cannot fit
    with pytest.raises(ValueError, match=f"joints: joint 9 is not in 1..{arm.nq}"):
        symoro.compare(tmp_path / "full", tmp_path / "rigid", tmp_path / "gap2", joints=[9])


def pseudo_inertia_eigenvalues(names, s, nq):
    """Per link, the smallest eigenvalue of its 4 x 4 pseudo-inertia [[tr(I)/2 E - I, h], [h', m]] (I
    about the frame origin, h the first moments): >= 0 for a physically consistent body."""
    v = dict(zip(names, s))
    out = []
    for j in range(1, nq + 1):
        g = lambda f: v.get(f"{f}{j}", 0.0)
        inertia = np.array([[g("XX"), g("XY"), g("XZ")], [g("XY"), g("YY"), g("YZ")], [g("XZ"), g("YZ"), g("ZZ")]])
        h = np.array([g("MX"), g("MY"), g("MZ")])
        J = np.zeros((4, 4))
        J[:3, :3] = np.trace(inertia) / 2 * np.eye(3) - inertia
        J[:3, 3] = J[3, :3] = h
        J[3, 3] = g("M")
        out.append(np.linalg.eigvalsh(J).min())
    return np.array(out)


@pytest.mark.parametrize("robot", ["rx90", "stanford_rrp"])
def test_export_urdf_equals_the_command_line(tmp_path, robot, dynid, source_dir):
    arm = getattr(symoro.models, robot).full
    exports = make_exports(tmp_path, arm)
    symoro.import_logs(arm, tmp_path / "data", exports, heldout=[exports[-1]], **MAPPING)
    study = symoro.identify(arm, tmp_path / "data", tmp_path / "physical", intervals_ms=[10], jobs=1, consistency="physical")
    assert study["accepted"]
    r = symoro.export_urdf(arm, tmp_path / "physical", tmp_path / "py" / f"{robot}.urdf", prior="zero")
    cli = run([dynid, "export", "--robot", robot, "--robots-dir", source_dir / "robots", "--study", tmp_path / "physical",
               "--urdf", tmp_path / "cli" / f"{robot}.urdf", "--prior", "zero"])
    assert cli.returncode == 0, cli.stderr
    # The same files, bit for bit: the module carries dynid's reference BLAS/LAPACK (the SDP
    # solve's last digits depend on which one runs; python/CMakeLists.txt).
    for name in sorted(p.name for p in (tmp_path / "cli").iterdir()):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert sorted(p.name for p in (tmp_path / "py").iterdir()) == sorted(p.name for p in (tmp_path / "cli").iterdir())
    cli_s = {row.split(",")[0]: float(row.split(",")[4])
             for row in (tmp_path / "cli" / f"{robot}.standard.csv").read_text().splitlines()[1:]}
    np.testing.assert_array_equal(r["s"], [cli_s[n] for n in r["standard_names"]])
    # The inertials reproduce the accepted parameters and are physically consistent bodies.
    np.testing.assert_allclose(arm.base_from_standard(r["s"]), study["phi"], rtol=0, atol=1e-7)
    assert r["residual"] < 1e-7
    assert np.all(pseudo_inertia_eigenvalues(r["standard_names"], r["s"], arm.nq) > 0)
    with pytest.raises(ValueError, match="robot.yaml's nominal parameters are needed"):
        symoro.export_urdf(arm, tmp_path / "physical", tmp_path / "x.urdf")


def test_errors_carry_the_project_text(tmp_path, exports, dynid, source_dir):
    bad = tmp_path / "bad.csv"
    text = exports[0].read_text().splitlines()
    text[5] = text[5].replace(",", ",x", 1)
    bad.write_text("\n".join(text) + "\n")
    with pytest.raises(symoro.DataError) as e:
        symoro.import_logs(ARM, tmp_path / "data", [bad], **MAPPING)
    assert e.value.file == str(bad) and e.value.line == 6
    assert isinstance(e.value, ValueError)
    cli = run([dynid, "import", "--robot", "rx90", "--robots-dir", source_dir / "robots", "-o", tmp_path / "cli", bad,
               *CLI_MAPPING])
    assert cli.returncode == 1 and cli.stderr.strip() == str(e.value)
    assert not (tmp_path / "data").exists()  # nothing written: every input is checked first
    with pytest.raises(ValueError, match="time_unit: 'min' is not one of s, ms, us, ns"):
        symoro.import_logs(ARM, tmp_path / "data", exports[:1], **{**MAPPING, "time_unit": "min"})
    with pytest.raises(symoro.DataError, match="dataset.yaml: error: not found"):
        symoro.identify(ARM, tmp_path, tmp_path / "study")
    # What dynid identify's options refuse, symoro.identify refuses (intervals_ms=[nan] aborted
    # Python with "double free or corruption"; jobs=0 and -3 were taken), before any work.
    for kwargs, pattern in [(dict(intervals_ms=[float("nan")]), "--interval nan: must be from 1 to 10000 ms"),
                            (dict(intervals_ms=[0.5]), "--interval 0.5"), (dict(jobs=0), "--jobs 0"),
                            (dict(jobs=-3), "--jobs -3"), (dict(trial=0), "--trial 0"),
                            (dict(torque_delay_ms=float("inf")), "--torque-delay inf"),
                            (dict(validation_ms=float("nan")), "--validation-interval nan")]:
        with pytest.raises(ValueError, match=pattern):
            symoro.identify(ARM, tmp_path, tmp_path / "refused", **kwargs)
    assert not (tmp_path / "refused").exists()
    for kwargs, pattern in [(dict(interval_ms=float("nan")), "interval_ms nan"), (dict(torque_delay_ms=float("inf")), "torque_delay_ms inf"),
                            (dict(trial=0), "trial 0")]:
        with pytest.raises(ValueError, match=pattern):
            symoro.predict(ARM, "nominal", exports[0], **kwargs)


def test_ctrl_c_stops_a_study_and_a_rerun_resumes(tmp_path, exports, source_dir):
    symoro.import_logs(ARM, tmp_path / "data", exports, heldout=[exports[-1]], **MAPPING)
    calls = []

    def interrupt_after_first(done, total, run):
        calls.append(run["id"])
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)  # as Ctrl-C would
            time.sleep(0.5)  # the waiting thread sees it before the next run is handed out

    with pytest.raises(KeyboardInterrupt):
        symoro.identify(ARM, tmp_path / "data", tmp_path / "study", intervals_ms=[10], jobs=1,
                        progress=interrupt_after_first)
    assert len(calls) == 1
    assert len(list((tmp_path / "study" / "runs").glob("*.yaml"))) == 1  # the finished run is kept
    seen = []
    symoro.identify(ARM, tmp_path / "data", tmp_path / "study", intervals_ms=[10], jobs=1,
                    progress=lambda done, total, run: seen.append((done, total)))
    assert seen == [(2, 3), (3, 3)]  # the saved run is not done again
    symoro.identify(ARM, tmp_path / "data", tmp_path / "fresh", intervals_ms=[10], jobs=1)
    assert records(tmp_path / "study") == records(tmp_path / "fresh")
    # A callback's own exception stops the study the same way, and arrives as itself.
    with pytest.raises(ZeroDivisionError):
        symoro.identify(ARM, tmp_path / "data", tmp_path / "other", intervals_ms=[10], jobs=1,
                        progress=lambda done, total, run: 1 / 0)
    assert len(list((tmp_path / "other" / "runs").glob("*.yaml"))) == 1


def test_logged_velocity_fits_on_the_exports_velocity_column(tmp_path, exports):
    """logged_velocity=True (dynid identify --logged-velocity) fits on the export's own velocity
    column. Put through a 5 Hz first-order filter here (a controller's causal estimate, 32 ms
    late; the study is not told), it costs the held-out run's error against its raw torque,
    which predict scores from q alone; the study's own fit does not read that column."""
    n = ARM.nq
    lagged = []
    for f in exports:
        header = f.read_text().splitlines()[0]
        data = np.loadtxt(f, delimiter=",", skiprows=1)
        a = 1 - np.exp(-2 * np.pi * 5 * np.diff(data[:, 0] / 1000))
        v = data[:, 1 + n:1 + 2 * n].copy()
        for k in range(1, len(v)):
            v[k] = v[k - 1] + a[k - 1] * (data[k, 1 + n:1 + 2 * n] - v[k - 1])
        data[:, 1 + n:1 + 2 * n] = v
        lagged.append(tmp_path / f.name)
        np.savetxt(lagged[-1], data, delimiter=",", header=header, comments="", fmt="%.17g")
    symoro.import_logs(ARM, tmp_path / "data", lagged, heldout=[lagged[-1]], **MAPPING)
    error = {}
    for logged in (False, True):
        study = symoro.identify(ARM, tmp_path / "data", tmp_path / f"study-{logged}", intervals_ms=[10], jobs=1,
                                logged_velocity=logged)
        error[logged] = symoro.predict(ARM, study["phi"], tmp_path / "data" / "check.csv", interval_ms=10)[0]["raw_rmse_overall"]
    # The study's own: the 0.02 N m of noise and the unmodelled 0.05 N m offset on one joint.
    assert error[False] < 0.05
    assert error[True] > 1.5 * error[False]
