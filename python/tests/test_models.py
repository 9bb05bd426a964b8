"""The model bindings against the generated C++ called directly (python_model_reference), bit
for bit, on three models of three robots; a batch against its states one by one; the argument
checks; no copy of C-ordered float64 input; batches with the GIL released."""

import threading
import time
import tracemalloc

import numpy as np
import pytest

import symoro

N = 6  # states per model in the reference (model_reference.cpp)
MODELS = [("planar2r", "full"), ("crane_x7", "reduced"), ("rx90", "full")]


def model(robot, name):
    return getattr(getattr(symoro.models, robot), name)


def load(d, key, quantity, shape):
    return np.fromfile(d / f"{key}.{quantity}.bin", dtype="<f8").reshape(shape)


def same_bits(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def calls(m, x):
    """Every function's result for the inputs x (batch or one state), keyed by reference file."""
    idd = m.inverse_dynamics_derivatives(x["q"], x["qd"], x["qdd"], x["phi"])
    fdd = m.forward_dynamics_derivatives(x["q"], x["qd"], x["tau"], x["phi"])
    return {
        "regressor": m.regressor(x["q"], x["qd"], x["qdd"]),
        "inverse_dynamics": m.inverse_dynamics(x["q"], x["qd"], x["qdd"], x["phi"]),
        "inertia": m.inertia(x["q"], x["phi"]),
        "nonlinear_effects": m.nonlinear_effects(x["q"], x["qd"], x["phi"]),
        "forward_dynamics": m.forward_dynamics(x["q"], x["qd"], x["tau"], x["phi"]),
        "idd_tau": idd["tau"], "idd_dq": idd["dq"], "idd_dqd": idd["dqd"],
        "fdd_qdd": fdd["qdd"], "fdd_dq": fdd["dq"], "fdd_dqd": fdd["dqd"], "fdd_dtau": fdd["dtau"],
        "fdd_dphi": fdd["dphi"], "fdd_min_pivot": fdd["min_pivot"],
        "forward_kinematics": m.forward_kinematics(x["q"]),
        "jacobian": m.jacobian(x["q"]),
    }


def shapes(m):
    nq, np_ = m.nq, m.np
    return {"regressor": (nq, np_), "inverse_dynamics": (nq,), "inertia": (nq, nq), "nonlinear_effects": (nq,),
            "forward_dynamics": (nq,), "idd_tau": (nq,), "idd_dq": (nq, nq), "idd_dqd": (nq, nq), "fdd_qdd": (nq,),
            "fdd_dq": (nq, nq), "fdd_dqd": (nq, nq), "fdd_dtau": (nq, nq), "fdd_dphi": (nq, np_), "fdd_min_pivot": (),
            "forward_kinematics": (4, 4), "jacobian": (6, nq)}


@pytest.mark.parametrize("robot,name", MODELS)
def test_every_function_equals_the_cpp_call_bit_for_bit(reference, robot, name):
    m = model(robot, name)
    key = f"{robot}.{name}"
    x = {k: load(reference, key, k, (N, m.nq)) for k in ("q", "qd", "qdd")}
    x["tau"] = load(reference, key, "tau_in", (N, m.nq))
    x["phi"] = load(reference, key, "phi", (m.np,))
    s = load(reference, key, "s", (m.ns,))
    assert same_bits(m.base_from_standard(s), load(reference, key, "base_from_standard", (m.np,)))
    assert same_bits(m.inverse_dynamics(x["q"], x["qd"], x["qdd"], m.base_from_standard(s)),
                     load(reference, key, "inverse_dynamics", (N, m.nq)))
    batch = calls(m, x)
    for quantity, shape in shapes(m).items():
        expected = load(reference, key, quantity, (N,) + shape)
        assert same_bits(batch[quantity], expected), quantity
        # The batch against its states one by one: the same bits.
        for k in range(N):
            single = calls(m, {**{v: x[v][k] for v in ("q", "qd", "qdd", "tau")}, "phi": x["phi"]})
            assert same_bits(single[quantity], expected[k]), (quantity, k)
    # A phi per state: the same as one phi for all.
    phis = np.tile(x["phi"], (N, 1))
    assert same_bits(m.inverse_dynamics(x["q"], x["qd"], x["qdd"], phis), batch["inverse_dynamics"])


@pytest.mark.parametrize("robot,name", MODELS)
def test_the_regressor_times_phi_is_the_inverse_dynamics(reference, robot, name):
    # tau = W phi + the fixed parameters' torque; the models here have none fixed.
    m = model(robot, name)
    key = f"{robot}.{name}"
    q, qd, qdd = (load(reference, key, k, (N, m.nq)) for k in ("q", "qd", "qdd"))
    phi = load(reference, key, "phi", (m.np,))
    np.testing.assert_allclose(m.regressor(q, qd, qdd) @ phi, m.inverse_dynamics(q, qd, qdd, phi), rtol=1e-12, atol=1e-12)


def test_descriptions():
    arm = symoro.models.crane_x7.reduced
    assert arm.robot == "crane_x7" and arm.name == "reduced"
    assert arm.nq == 8 and len(arm.joint_names) == 8 and len(arm.parameter_names) == arm.np  # 7 arm joints and the hand
    assert len(arm.parameter_units) == arm.np and len(arm.parameter_families) == arm.np
    assert len(arm.standard_names) == arm.ns
    assert np.all(arm.lower < arm.upper) and arm.velocity_limits.shape == (8,) and arm.effort_limits.shape == (8,)
    assert set(symoro.models.crane_x7.models) >= {"full", "reduced"}
    assert symoro.models.planar2r.nq == 2  # a robot is its full model
    np.testing.assert_array_equal(symoro.models.planar2r.gravity, [0.0, -9.80665, 0.0])
    assert "planar2r" in symoro.models.names and "rx90" in symoro.models.names
    with pytest.raises(AttributeError, match="no compiled robot 'nope'"):
        symoro.models.nope
    with pytest.raises(AttributeError, match="has no model 'nope'"):
        symoro.models.crane_x7.nope


def test_wrong_arguments_name_themselves():
    m = symoro.models.rx90.full
    q = np.zeros(6)
    with pytest.raises(ValueError, match=r"q: expected shape \(6,\) or \(N, 6\), got \(7,\)"):
        m.regressor(np.zeros(7), q, q)
    with pytest.raises(ValueError, match=r"qdd: expected shape \(6,\) or \(N, 6\), got \(2, 3, 6\)"):
        m.regressor(q, q, np.zeros((2, 3, 6)))
    with pytest.raises(TypeError, match="qd: expected real numbers, got an array of dtype complex128"):
        m.regressor(q, np.zeros(6, dtype=complex), q)
    with pytest.raises(TypeError, match="q: expected real numbers, got an array of dtype <U1"):
        m.jacobian(["a"] * 6)
    with pytest.raises(TypeError, match="q: expected an array of 6 numbers, got None"):
        m.jacobian(None)
    bad = np.zeros((4, 6))
    bad[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"qd: nan at \[2, 1\]"):
        m.nonlinear_effects(np.zeros((4, 6)), bad, np.zeros(m.np))
    with pytest.raises(ValueError, match=r"phi: inf at \[3\]"):
        m.inertia(q, np.r_[0, 0, 0, np.inf, np.zeros(m.np - 4)])
    with pytest.raises(ValueError, match="qd: a batch of 3 where q is a batch of 4"):
        m.regressor(np.zeros((4, 6)), np.zeros((3, 6)), np.zeros((4, 6)))
    with pytest.raises(ValueError, match="qd: one state where q is a batch of 4"):
        m.regressor(np.zeros((4, 6)), q, np.zeros((4, 6)))
    with pytest.raises(ValueError, match="phi: a batch of 2 parameter vectors for 4 states"):
        m.inverse_dynamics(np.zeros((4, 6)), np.zeros((4, 6)), np.zeros((4, 6)), np.zeros((2, m.np)))
    with pytest.raises(ValueError, match=r"s: expected shape"):
        m.base_from_standard(np.zeros(m.np))


def test_other_layouts_and_integer_input_give_the_same_numbers():
    m = symoro.models.crane_x7.reduced
    rng = np.random.default_rng(5)
    q = rng.uniform(-1, 1, (5, m.nq))
    fortran = np.asfortranarray(q)
    strided = np.zeros((5, 2 * m.nq))
    strided[:, ::2] = q
    assert same_bits(m.jacobian(fortran), m.jacobian(q))
    assert same_bits(m.jacobian(strided[:, ::2]), m.jacobian(q))
    assert same_bits(m.jacobian(q.astype(np.float32)), m.jacobian(q.astype(np.float32).astype(np.float64)))
    assert same_bits(m.forward_kinematics([1] + [0] * (m.nq - 1)), m.forward_kinematics(np.r_[1.0, np.zeros(m.nq - 1)]))


def test_contiguous_float64_input_is_not_copied():
    m = symoro.models.crane_x7.reduced
    n = 50_000
    q = np.zeros((n, m.nq))
    q_f = np.asfortranarray(q)
    out_bytes = n * m.nq * 8
    m.inverse_dynamics(q, q, q, np.zeros(m.np))  # warm up (lazy initializations)
    tracemalloc.start()
    tracemalloc.reset_peak()
    m.inverse_dynamics(q, q, q, np.zeros(m.np))
    contiguous_peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.reset_peak()
    m.inverse_dynamics(q_f, q_f, q_f, np.zeros(m.np))
    fortran_peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    # The result alone, against the result and a C-ordered copy of each input.
    assert out_bytes <= contiguous_peak < 1.5 * out_bytes
    assert fortran_peak >= 3.5 * out_bytes


def test_a_batch_runs_with_the_gil_released():
    # While one thread is inside a long batch call, this one keeps running Python code: its
    # iterations must cover most of the call (with the GIL held they could not run at all,
    # beyond one switch interval at either end).
    m = symoro.models.crane_x7.reduced
    q = np.random.default_rng(1).uniform(-1, 1, (200_000, m.nq))
    span = {}

    def call():
        span["start"] = time.perf_counter()
        m.regressor(q, q, q)
        span["end"] = time.perf_counter()

    t = threading.Thread(target=call)
    stamps = []
    t.start()
    while t.is_alive():
        stamps.append(time.perf_counter())
    t.join()
    inside = [s for s in stamps if span["start"] <= s <= span["end"]]
    assert inside, "no Python ran during the batch"
    covered = (max(inside) - min(inside)) / (span["end"] - span["start"])
    assert covered > 0.8, covered
