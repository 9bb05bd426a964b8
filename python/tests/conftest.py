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
