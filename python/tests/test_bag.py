"""ROS 2 bags from Python: symoro.import_logs reads a bag written by the MCAP project's own writer
(tests/bags/write_bag.mjs, installed by ctest's fixture bags.npm) of a motion synthesized here
from the RX-90's model, with a hand joint the robot has not and a current-controlled effort;
the dataset equals dynid import's, file for file, and the values arrive bit for bit. Then the
study's export as a MuJoCo model equals dynid export --mjcf's (test_workflow.py does the URDF)."""

import json
import os
import subprocess

import numpy as np
import pytest

import symoro

from synth_logs import ARM, true_phi, run


def write_bag(path, q, qd, tau, names, stamps_ns, compression="lz4"):
    node, writer = os.environ.get("SYMORO_NODE"), os.environ.get("SYMORO_BAG_WRITER")
    if not node or not writer:
        pytest.fail("SYMORO_NODE and SYMORO_BAG_WRITER are not set (run the tests through ctest)")
    msgs = []
    for k in range(q.shape[0]):
        stamp = int(stamps_ns[k])
        msgs.append({"topic": "/joint_states", "log_time_ns": str(stamp + 200000), "stamp_sec": stamp // 10**9,
                     "stamp_nanosec": stamp % 10**9, "name": ["hand"] + names,
                     "position": [0.0] + [float(x) for x in q[k]], "velocity": [0.0] + [float(x) for x in qd[k]],
                     "effort": [0.0] + [float(x) for x in tau[k]]})
    spec = path.with_suffix(".json")
    spec.write_text(json.dumps({"out": str(path), "compression": compression, "chunked": True, "messages": msgs}))
    subprocess.run([node, writer, str(spec)], check=True, capture_output=True)


@pytest.fixture(scope="module")
def bag(tmp_path_factory):
    d = tmp_path_factory.mktemp("bag")
    rng = np.random.default_rng(5)
    t = np.arange(0, 6.0, 0.001)
    q = np.column_stack([0.3 * np.sin((1.1 + 0.3 * j) * t + j) for j in range(ARM.nq)])
    qd = np.column_stack([0.3 * (1.1 + 0.3 * j) * np.cos((1.1 + 0.3 * j) * t + j) for j in range(ARM.nq)])
    qdd = np.column_stack([-0.3 * (1.1 + 0.3 * j) ** 2 * np.sin((1.1 + 0.3 * j) * t + j) for j in range(ARM.nq)])
    tau = ARM.inverse_dynamics(q, qd, qdd, true_phi()) + rng.normal(0, 0.01, q.shape)
    kt = np.linspace(1.5, 2.5, ARM.nq)
    stamps = 1764400000000000000 + np.arange(t.size) * 1000000
    path = d / "arm.mcap"
    write_bag(path, q, qd, tau / kt, list(ARM.joint_names), stamps)
    return path, q, qd, tau, kt, stamps


def test_import_logs_reads_a_bag_as_dynid_import_does(tmp_path, bag, dynid, source_dir):
    path, q, qd, tau, kt, stamps = bag
    r = symoro.import_logs(ARM, tmp_path / "py", [path], split=0.7, effort="current", torque_constants=list(kt))
    (log,) = r["logs"]
    assert log["samples"] == q.shape[0] and log["velocity"] == "measured"
    assert any("names the robot has not, ignored: hand" in x for x in log["remarks"])
    assert any(x.startswith("effort: motor current (A) times the torque constants") for x in log["remarks"])
    cli = run([dynid, "import", "--robot", "rx90", "--robots-dir", source_dir / "robots", "-o", tmp_path / "cli", path,
               "--split", "0.7", "--effort", "current", "--torque-constant", ",".join(repr(float(k)) for k in kt)])
    assert cli.returncode == 0, cli.stderr
    for name in ["arm.csv", "arm.meta.yaml", "dataset.yaml"]:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # The log's numbers: the positions and velocities as published, the torque as current x kt.
    data = np.genfromtxt(tmp_path / "py" / "arm.csv", delimiter=",", names=True)
    np.testing.assert_array_equal(data["time"], (stamps - stamps[0]) * 1e-9)
    np.testing.assert_array_equal(np.column_stack([data[f"q{j + 1}"] for j in range(ARM.nq)]), q)
    np.testing.assert_allclose(np.column_stack([data[f"tau{j + 1}"] for j in range(ARM.nq)]), tau, rtol=1e-14, atol=1e-14)
    with pytest.raises(ValueError, match="torque_constants"):
        symoro.import_logs(ARM, tmp_path / "x", [path], effort="current")


def test_export_urdf_writes_the_same_mjcf_as_dynid_export(tmp_path, bag, dynid, source_dir):
    path = bag[0]
    symoro.import_logs(ARM, tmp_path / "data", [path], split=0.7, effort="current", torque_constants=list(bag[4]))
    study = symoro.identify(ARM, tmp_path / "data", tmp_path / "study", intervals_ms=[10], jobs=1,
                            consistency="physical")
    assert study["accepted"]
    r = symoro.export_urdf(ARM, tmp_path / "study", tmp_path / "py" / "rx90.urdf", prior="zero",
                           mjcf=tmp_path / "py" / "rx90.xml")
    assert r["mjcf"] == tmp_path / "py" / "rx90.xml"
    cli = run([dynid, "export", "--robot", "rx90", "--robots-dir", source_dir / "robots", "--study", tmp_path / "study",
               "--urdf", tmp_path / "cli" / "rx90.urdf", "--mjcf", tmp_path / "cli" / "rx90.xml", "--prior", "zero"])
    assert cli.returncode == 0, cli.stderr
    for name in ["rx90.xml", "rx90.urdf", "rx90.standard.yaml"]:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    text = (tmp_path / "py" / "rx90.xml").read_text()
    assert text.count("<joint ") == ARM.nq and text.count("<motor ") == ARM.nq and "armature=" in text
