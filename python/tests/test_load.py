"""symoro.load: a robot folder the package was not built with, through its robot library
(compiled on first use into $SYMORO_CACHE_DIR, ctest's build-tree cache). A copy of the RX-90's
folder loaded equals the compiled symoro.models.rx90 bit for bit, function by function, and its
study equals the compiled model's; a robot made here from a URDF (the Kinova Jaco2, which no
robots/ folder holds) passes checks between its own functions: the inverse dynamics against
regressor x phi, the forward dynamics against the inverse, the inertia against d tau / d qdd."""

import os
import shutil
import subprocess

import numpy as np
import pytest

import symoro
from synth_logs import MAPPING, make_exports

FUNCTIONS = ["regressor", "inverse_dynamics", "inertia", "nonlinear_effects", "forward_dynamics",
             "inverse_dynamics_derivatives", "forward_dynamics_derivatives", "forward_kinematics", "jacobian",
             "base_from_standard"]


@pytest.fixture(scope="module")
def rx90_copy(tmp_path_factory, source_dir):
    folder = tmp_path_factory.mktemp("robots") / "rx90"
    shutil.copytree(source_dir / "robots" / "rx90", folder)
    return folder


def arguments(arm, name, rng, n=7):
    q, qd, x = (rng.uniform(-1.5, 1.5, (n, arm.nq)) for _ in range(3))
    phi = rng.uniform(-1, 1, arm.np)
    return {"regressor": (q, qd, x), "inverse_dynamics": (q, qd, x, phi), "inertia": (q, phi),
            "nonlinear_effects": (q, qd, phi), "forward_dynamics": (q, qd, x, phi),
            "inverse_dynamics_derivatives": (q, qd, x, phi), "forward_dynamics_derivatives": (q, qd, x, phi),
            "forward_kinematics": (q,), "jacobian": (q,), "base_from_standard": (rng.uniform(-1, 1, (n, arm.ns)),)}[name]


def same(a, b):
    if isinstance(a, tuple) or isinstance(a, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


def test_a_loaded_folder_equals_the_compiled_robot_bit_for_bit(rx90_copy):
    robot = symoro.load(rx90_copy)
    assert sorted(robot.models) == ["full", "rigid"]
    assert robot.identified.name == "full"
    for name in ["full", "rigid"]:
        loaded, compiled = robot.models[name], getattr(symoro.models.rx90, name)
        assert (loaded.robot, loaded.nq, loaded.np, loaded.ns) == (compiled.robot, compiled.nq, compiled.np, compiled.ns)
        assert loaded.parameter_names == compiled.parameter_names
        assert loaded.joint_names == compiled.joint_names
        rng = np.random.default_rng(3)
        for f in FUNCTIONS:
            args = arguments(compiled, f, rng)
            assert same(getattr(loaded, f)(*args), getattr(compiled, f)(*args)), f
            one = [a[0] if a.ndim == 2 else a for a in args]  # one state, not a batch
            assert same(getattr(loaded, f)(*one), getattr(compiled, f)(*one)), f


def test_a_loaded_models_study_equals_the_compiled_ones(tmp_path, rx90_copy):
    loaded, compiled = symoro.load(rx90_copy).full, symoro.models.rx90.full
    exports = make_exports(tmp_path, compiled)
    symoro.import_logs(loaded, tmp_path / "data", exports, heldout=[exports[-1]], **MAPPING)
    a = symoro.identify(loaded, tmp_path / "data", tmp_path / "loaded", intervals_ms=[10], jobs=1)
    # The loaded model reads its folder (robot_dir's default); the compiled one is pointed at it.
    b = symoro.identify(compiled, tmp_path / "data", tmp_path / "compiled", intervals_ms=[10], jobs=1, robot_dir=rx90_copy)
    assert np.array_equal(a["phi"], b["phi"])
    assert (tmp_path / "loaded" / "validation.yaml").read_bytes() == (tmp_path / "compiled" / "validation.yaml").read_bytes()


def test_a_robot_from_a_urdf_loads_and_its_functions_agree(tmp_path, source_dir):
    symoroc = os.environ.get("SYMORO_SYMOROC")
    if not symoroc:
        pytest.fail("SYMORO_SYMOROC is not set (run the tests through ctest)")
    folder = tmp_path / "jaco2"
    subprocess.run([symoroc, "model", str(source_dir / "tests" / "urdf" / "kinova.urdf"), "-o", str(folder), "--name",
                    "jaco2"], check=True, capture_output=True)
    arm = symoro.load(folder).full
    assert arm.robot == "jaco2" and arm.nq >= 6
    rng = np.random.default_rng(5)
    # Physical standard parameters (positive masses, diagonal inertias): a positive definite M.
    s = np.array([rng.uniform(0.5, 2.0) if n.rstrip("0123456789") in ("M",) else
                  rng.uniform(0.01, 0.05) if n.rstrip("0123456789") in ("XX", "YY", "ZZ", "IA", "FV") else 0.0
                  for n in arm.standard_names])
    phi = arm.base_from_standard(s)
    q, qd, qdd = (rng.uniform(-1, 1, (5, arm.nq)) for _ in range(3))
    tau = arm.inverse_dynamics(q, qd, qdd, phi)
    W = arm.regressor(q, qd, qdd)
    np.testing.assert_allclose(tau, W @ phi, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(arm.forward_dynamics(q, qd, tau, phi), qdd, rtol=1e-8, atol=1e-8)
    M = arm.inertia(q, phi)
    # M = d tau / d qdd: tau is affine in qdd.
    e = np.eye(arm.nq)
    dtau = np.stack([arm.inverse_dynamics(q, qd, qdd + e[k], phi) - tau for k in range(arm.nq)], axis=-1)
    np.testing.assert_allclose(dtau, M, rtol=1e-9, atol=1e-9)


def test_a_loaded_model_reads_its_own_folder_as_dynid_does(tmp_path, source_dir, dynid):
    """No robot_dir needed: the physical path leans on the folder's nominal parameters (a URDF's
    inertials) and export_urdf takes them as its prior, as dynid does with --robot <folder>."""
    symoroc = os.environ["SYMORO_SYMOROC"]
    folder = tmp_path / "ur5"
    subprocess.run([symoroc, "model", str(source_dir / "tests" / "urdf" / "ur5_robot.urdf"), "-o", str(folder), "--name",
                    "ur5"], check=True, capture_output=True)
    arm = symoro.load(folder).full
    assert arm.folder == str(folder)
    exports = make_exports(tmp_path, arm)
    symoro.import_logs(arm, tmp_path / "data", exports, heldout=[exports[-1]], **MAPPING)
    symoro.identify(arm, tmp_path / "data", tmp_path / "study", intervals_ms=[10], jobs=1, consistency="physical")
    symoro.export_urdf(arm, tmp_path / "study", tmp_path / "py" / "ur5.urdf")
    cli = subprocess.run([dynid, "identify", "--robot", str(folder), "--data", str(tmp_path / "data"), "-o",
                          str(tmp_path / "cli-study"), "--interval", "10", "--jobs", "1", "--consistency", "physical"],
                         capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    strip = lambda p: [l for l in p.read_text().splitlines() if "study" not in l and "digest" not in l]
    assert strip(tmp_path / "study" / "report" / "parameters.yaml") == strip(tmp_path / "cli-study" / "report" / "parameters.yaml")
    cli = subprocess.run([dynid, "export", "--robot", str(folder), "--study", str(tmp_path / "study"), "--urdf",
                          str(tmp_path / "cli" / "ur5.urdf")], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    assert (tmp_path / "py" / "ur5.urdf").read_bytes() == (tmp_path / "cli" / "ur5.urdf").read_bytes()
