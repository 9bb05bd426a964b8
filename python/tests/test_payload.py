"""symoro.identify_payload on a robot the package was never built with (the Kinova Jaco2 from its
URDF, through its robot library): a controller's export of the arm carrying a body, synthesized
from the generated model with the body's standard parameters (derived here in NumPy) on the last
link, noise and a torque offset the code is not told of; the identified body is the one put in,
with the known-mass case beside it."""


import numpy as np
import pytest

import symoro
from synth_logs import MAPPING, RATE, ramp


@pytest.fixture(scope="module")
def jaco2(jaco2_standard):
    return jaco2_standard


def body_standard(m, c, I):
    """XX XY XZ YY YZ ZZ MX MY MZ M about the link frame's origin: I + m (|c|^2 1 - c c')."""
    J = I + m * (c @ c * np.eye(3) - np.outer(c, c))
    return np.array([J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2], *(m * c), m])


def export(path, arm, s, seed, seconds=20.0, noise_seed=None):
    rng = np.random.default_rng(seed)
    t = np.arange(0, seconds, 1 / RATE)
    w, dw, ddw = ramp(t, seconds - 1 / RATE)
    mid, half = (arm.lower + arm.upper) / 2, np.minimum((arm.upper - arm.lower) / 2, np.pi)
    q, qd, qdd = (np.zeros((t.size, arm.nq)) for _ in range(3))
    for j in range(arm.nq):
        for _ in range(3):
            a, f, p = 0.15 * half[j] * rng.uniform(0.5, 1), 2 * np.pi * rng.uniform(0.1, 0.6), rng.uniform(0, 6.3)
            sn, ds, dds = a * np.sin(f * t + p), a * f * np.cos(f * t + p), -a * f * f * np.sin(f * t + p)
            q[:, j] += w * sn
            qd[:, j] += dw * sn + w * ds
            qdd[:, j] += ddw * sn + 2 * dw * ds + w * dds
        q[:, j] += 0.2 * mid[j]
    tau = arm.inverse_dynamics(q, qd, qdd, arm.base_from_standard(s))
    tau[:, 1] += 0.03
    # The same motion with other noise when noise_seed is given (a tare run of the same motion).
    tau += (rng if noise_seed is None else np.random.default_rng(noise_seed)).normal(0, 0.01, tau.shape)
    cols = ["t_ms"] + [f"pos{j + 1}" for j in range(arm.nq)] + [f"vel{j + 1}" for j in range(arm.nq)] + \
           [f"eff{j + 1}" for j in range(arm.nq)]
    data = np.column_stack([t * 1000, np.degrees(q), np.degrees(qd), tau])
    np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.17g")


def test_the_body_on_the_last_link_is_found(jaco2, tmp_path):
    arm, s_arm = jaco2
    names = list(arm.standard_names)
    last = max(int(n[1:]) for n in names if n.rstrip("0123456789") == "M")
    idx = [names.index(f"{f}{last}") for f in ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M")]
    m, c = 0.8, np.array([0.015, -0.01, 0.07])
    R = np.array([[1, 0, 0], [0, np.cos(0.5), -np.sin(0.5)], [0, np.sin(0.5), np.cos(0.5)]])
    I = R @ np.diag([2e-3, 1.5e-3, 1e-3]) @ R.T
    s = s_arm.copy()
    s[idx] += body_standard(m, c, I)
    export(tmp_path / "tool.csv", arm, s, 3)
    symoro.import_logs(arm, tmp_path / "data", [tmp_path / "tool.csv"], **MAPPING)

    r = symoro.identify_payload(arm, arm.base_from_standard(s_arm), [tmp_path / "data"])
    assert r["link"] == last
    st = r["standard"]
    # The identified standard parameters give back the body in the link's frame.
    m_hat = st[9]
    c_hat = st[6:9] / m_hat
    J = np.array([[st[0], st[1], st[2]], [st[1], st[3], st[4]], [st[2], st[4], st[5]]])
    I_hat = J - m_hat * (c_hat @ c_hat * np.eye(3) - np.outer(c_hat, c_hat))
    assert abs(m_hat - m) / m < 0.02
    assert np.linalg.norm(c_hat - c) < 0.003
    assert np.linalg.norm(I_hat - I) / np.linalg.norm(I) < 0.15
    assert r["mass"] == pytest.approx(m_hat, rel=1e-12)
    assert r["margin"] > 0 and not r["projected"]
    assert np.all(r["rms_with"] < r["rms_without"])
    assert r["ur"].startswith("set_target_payload(") and "load_inertia" in r["franka"] and r["kuka"].startswith("{M ")

    k = symoro.identify_payload(arm, arm.base_from_standard(s_arm), [tmp_path / "data"], mass=m)
    assert k["mass"] == m and k["known_mass"] and k["mass_std"] == 0
    ck = k["standard"][6:9] / m
    assert np.linalg.norm(ck - c) < 0.003

    with pytest.raises(ValueError, match="mass"):
        symoro.identify_payload(arm, arm.base_from_standard(s_arm), [tmp_path / "data"], mass=-1.0)

    # A parameters file's timing (torque_delay_ms, the arm's identification's) is the default; given
    # 0, the file's values fit as the array did, bit for bit.
    phi = arm.base_from_standard(s_arm)
    params = tmp_path / "parameters.yaml"
    params.write_text(f"robot: \"{arm.robot}\"\nmodel: \"full\"\ntorque_delay_ms: 2\nparameters:\n" +
                      "".join(f"  - {{name: \"{n}\", value: {v!r}}}\n" for n, v in zip(arm.parameter_names, phi)))
    shifted = symoro.identify_payload(arm, params, [tmp_path / "data"])
    told = symoro.identify_payload(arm, params, [tmp_path / "data"], torque_delay_ms=0.0)
    assert shifted["torque_delay_ms"] == 2.0 and told["torque_delay_ms"] == 0.0 and r["torque_delay_ms"] == 0.0
    assert np.array_equal(told["standard"], r["standard"])
    assert not np.array_equal(shifted["standard"], r["standard"])

    # Arm parameters off along the body's link (a third of the body's second moments): without a
    # tare the body's inertia is far off; a run of the same motion without the body (other noise)
    # measures that error and takes it out.
    error = np.zeros(len(names))
    error[idx] = body_standard(m, c, I)[:10] * np.array([0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.05, 0.05, 0.05, 0.05])
    off = arm.base_from_standard(s_arm + error)
    export(tmp_path / "bare.csv", arm, s_arm, 3, noise_seed=11)
    symoro.import_logs(arm, tmp_path / "tare", [tmp_path / "bare.csv"], **MAPPING)

    def body(res):  # mass, CoM and inertia about it in the link's frame, from 'standard'
        st = res["standard"]
        cc = st[6:9] / st[9]
        J = np.array([[st[0], st[1], st[2]], [st[1], st[3], st[4]], [st[2], st[4], st[5]]])
        return st[9], cc, J - st[9] * (cc @ cc * np.eye(3) - np.outer(cc, cc))

    blind = symoro.identify_payload(arm, off, [tmp_path / "data"])
    tared = symoro.identify_payload(arm, off, [tmp_path / "data"], tare=[tmp_path / "tare"])
    assert np.linalg.norm(body(blind)[2] - I) / np.linalg.norm(I) > 0.15 and tared["tare_samples"] > 0
    m_t, c_t, I_t = body(tared)
    assert abs(m_t - m) / m < 0.02 and np.linalg.norm(c_t - c) < 0.003
    assert np.linalg.norm(I_t - I) / np.linalg.norm(I) < 0.15
    # The tare reads the error (less the noise): its second moments within 25 %.
    assert np.linalg.norm(tared["tare"][:6] + error[idx][:6]) < 0.25 * np.linalg.norm(error[idx][:6])
