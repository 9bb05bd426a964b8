"""Shared fixtures: the C++ reference results (python_model_reference) and the source tree."""

import os
import pathlib
import subprocess

import pytest


@pytest.fixture(scope="session")
def reference(tmp_path_factory):
    exe = os.environ.get("SYMORO_MODEL_REFERENCE")
    if not exe:
        pytest.fail("SYMORO_MODEL_REFERENCE is not set (run the tests through ctest)")
    d = tmp_path_factory.mktemp("reference")
    subprocess.run([exe, str(d)], check=True, capture_output=True)
    return d


@pytest.fixture(scope="session")
def source_dir():
    return pathlib.Path(os.environ.get("SYMORO_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture(scope="session")
def dynid():
    exe = os.environ.get("SYMORO_DYNID")
    if not exe:
        pytest.fail("SYMORO_DYNID is not set (run the tests through ctest)")
    return exe


@pytest.fixture(scope="module")
def jaco2_standard(tmp_path_factory, source_dir):
    """The Kinova Jaco2 from its URDF (a robot the package was never built with), loaded through
    its robot library, and physical standard parameters for it (positive masses, diagonal
    inertias: a positive definite M)."""
    symoroc = os.environ.get("SYMORO_SYMOROC")
    if not symoroc:
        pytest.fail("SYMORO_SYMOROC is not set (run the tests through ctest)")
    folder = tmp_path_factory.mktemp("robots") / "jaco2"
    subprocess.run([symoroc, "model", str(source_dir / "tests" / "urdf" / "kinova.urdf"), "-o", str(folder), "--name",
                    "jaco2"], check=True, capture_output=True)
    import numpy as np
    import symoro
    arm = symoro.load(folder).full
    rng = np.random.default_rng(5)
    s = np.array([rng.uniform(0.5, 2.0) if n.rstrip("0123456789") == "M" else
                  rng.uniform(0.01, 0.05) if n.rstrip("0123456789") in ("XX", "YY", "ZZ", "IA", "FV") else 0.0
                  for n in arm.standard_names])
    return arm, s
