"""symoro.MomentumObserver on a robot the package was never built with (the Kinova Jaco2 from its
URDF, through its robot library): on a motion whose torque is the model's inverse dynamics minus
an external torque pulse the log does not show, the residual equals the pulse through a
first-order lag integrated here by hand; stepping sample by sample equals observing the log;
thresholds from a log without contact raise no alarm on another, and the contact is found on
its joint within 10 ms."""


import numpy as np
import pytest

import symoro


@pytest.fixture(scope="module")
def jaco2(jaco2_standard):
    arm, s = jaco2_standard
    return arm, arm.base_from_standard(s)


def pulse(t, joint, start, duration, torque, nq):
    """tau_ext (N, nq): `torque` on `joint` from `start` for `duration` s, with 2 ms ramps."""
    shape = np.clip(np.minimum.reduce([np.ones_like(t), (t - start) / 0.002, (start + duration - t) / 0.002]), 0, 1)
    out = np.zeros((len(t), nq))
    out[:, joint] = torque * shape
    return out


def log(arm, phi, seconds, contact, seed, noise=0.0):
    """1 kHz samples of smooth cosines; the motor's torque gives way to the contact."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, seconds, 0.001)
    mid = 0.5 * (arm.lower + arm.upper)
    amp = np.minimum(0.3, 0.1 * (arm.upper - arm.lower))
    w = 2 * np.pi * rng.uniform(0.2, 0.5, arm.nq)
    q = mid + amp * (1 - np.cos(np.outer(t, w)))
    qd = amp * w * np.sin(np.outer(t, w))
    qdd = amp * w**2 * np.cos(np.outer(t, w))
    tau = arm.inverse_dynamics(q, qd, qdd, phi) - pulse(t, *contact, arm.nq)
    return t, q, qd, tau + noise * rng.standard_normal(tau.shape)


def lag(t, tau_ext, gain):
    """dr/dt = gain (tau_ext - r), r(0) = 0: exact exponential steps of 1 us over the pulse."""
    fine = np.arange(0, t[-1] + 1e-9, 1e-6)
    f = np.interp(fine + 0.5e-6, t, tau_ext)
    a = np.exp(-gain * 1e-6)
    r = np.empty_like(fine)
    acc = 0.0
    for i, x in enumerate(f):  # 1e6 steps per second of log: kept short
        acc = a * acc + (1 - a) * x
        r[i] = acc
    return np.interp(t, fine + 1e-6, r)


def test_the_residual_is_the_lagged_external_torque(jaco2):
    arm, phi = jaco2
    contact = (2, 0.5, 0.3, 1.5)
    t, q, qd, tau = log(arm, phi, 1.2, contact, 1)
    for rate in ("difference", "derivatives"):
        obs = symoro.MomentumObserver(arm, phi, gain=60.0, inertia_rate=rate)
        r = obs.observe(t, q, qd, tau)
        expected = lag(t, pulse(t, *contact, arm.nq)[:, 2], 60.0)
        assert np.max(np.abs(r[:, 2] - expected)) < 5e-3 * 1.5, rate
        others = np.delete(r, 2, axis=1)
        assert np.max(np.abs(others)) < 2e-4 * 1.5, rate
        assert np.max(np.abs(r[:, 2])) > 0.9 * 1.5
    # Sample by sample, as an application steps it, the same numbers.
    obs = symoro.MomentumObserver(arm, phi, gain=60.0)
    stepped = [np.zeros(arm.nq)]
    obs.reset(q[0], qd[0], tau[0])
    for k in range(1, len(t)):
        stepped.append(obs.update(q[k], qd[k], tau[k], t[k] - t[k - 1]))
    np.testing.assert_array_equal(np.array(stepped), symoro.MomentumObserver(arm, phi, gain=60.0).observe(t, q, qd, tau))


def test_a_contact_is_found_on_its_joint_within_10ms(jaco2):
    arm, phi = jaco2
    obs = symoro.MomentumObserver(arm, phi)
    quiet = [log(arm, phi, 6.0, (0, 0, 0, 0), seed, noise=0.02) for seed in (2, 3)]
    residuals = [obs.observe(*x) for x in quiet]
    bands = symoro.observer_thresholds(residuals[:1], [quiet[0][0]], obs.gain)
    assert bands["threshold"].shape == (arm.nq,) and np.all(bands["threshold"] > 0)
    assert symoro.collision_events(quiet[1][0], residuals[1], bands) == []
    contact = (1, 3.0, 0.2, -1.0)
    t, q, qd, tau = log(arm, phi, 6.0, contact, 4, noise=0.02)
    events = symoro.collision_events(t, obs.observe(t, q, qd, tau), bands)
    assert [e["joint"] for e in events] == [1]
    assert 3.0 <= events[0]["start"] <= 3.010
    assert events[0]["peak"] == pytest.approx(-1.0, rel=0.1)


def test_bad_arguments_are_refused(jaco2):
    arm, phi = jaco2
    with pytest.raises(ValueError, match="phi"):
        symoro.MomentumObserver(arm, phi[:-1])
    with pytest.raises(ValueError, match="inertia_rate"):
        symoro.MomentumObserver(arm, phi, inertia_rate="exact")
    with pytest.raises(ValueError, match="gain"):
        symoro.MomentumObserver(arm, phi, gain=-1.0)
    obs = symoro.MomentumObserver(arm, phi)
    t = np.array([0.0, 0.001, 0.001])
    x = np.zeros((3, arm.nq))
    with pytest.raises(ValueError, match="time must increase"):
        obs.observe(t, x, x, x)
