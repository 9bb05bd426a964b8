"""Logs synthesized from a generated model for the workflow tests: a controller's CSV export of
smooth multisine motion, with an effect the code under test is not told about (a torque offset
on joint 2) and noise."""

import subprocess

import numpy as np

import symoro

ARM = symoro.models.rx90.full
RATE = 1000.0  # Hz


def true_phi(arm=ARM):
    rng = np.random.default_rng(11)
    s = []
    for name in arm.standard_names:
        f = name.rstrip("0123456789")
        r = rng.uniform(-1, 1)
        s.append(0.6 + 0.3 * r if f in ("XX", "YY", "ZZ") else 1.5 + 0.5 * r if f == "M"
                 else 0.05 + 0.04 * r if f in ("IA", "FV", "FS") else 0.1 * r if f in ("MX", "MY", "MZ") else 0.01 * r)
    return arm.base_from_standard(np.array(s))


def ramp(t, seconds, rise=1.0):
    """A smooth window 0 -> 1 -> 0 (quintic rise and fall over `rise` s) and its two derivatives:
    the logs start and end at rest, as a recording does (a log cut in mid-motion loses the
    zero-phase filter's settling time at its ends; these keep every sample)."""
    def up(x):
        x = np.clip(x, 0, 1)
        inside = (x > 0) & (x < 1)
        return (10 * x**3 - 15 * x**4 + 6 * x**5, inside * (30 * x**2 - 60 * x**3 + 30 * x**4) / rise,
                inside * (60 * x - 180 * x**2 + 120 * x**3) / rise**2)
    a, da, dda = up(t / rise)
    b, db, ddb = up((seconds - t) / rise)
    return a * b, da * b - a * db, dda * b - 2 * da * db + a * ddb


def write_export(path, seed, seconds=8.0, arm=ARM):
    """A controller's CSV export: time in ms, angles in degrees (prismatic joints in m), with a
    0.05 N m offset on joint 2 (not modelled) and 0.02 N m of noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, seconds, 1 / RATE)
    w, dw, ddw = ramp(t, seconds - 1 / RATE)
    mid, half = (arm.lower + arm.upper) / 2, (arm.upper - arm.lower) / 2
    q, qd, qdd = (np.zeros((t.size, arm.nq)) for _ in range(3))
    for j in range(arm.nq):
        for _ in range(3):
            a, f, p = 0.12 * half[j] * rng.uniform(0.5, 1), 2 * np.pi * rng.uniform(0.1, 0.6), rng.uniform(0, 2 * np.pi)
            s, ds, dds = a * np.sin(f * t + p), a * f * np.cos(f * t + p), -a * f * f * np.sin(f * t + p)
            q[:, j] += w * s
            qd[:, j] += dw * s + w * ds
            qdd[:, j] += ddw * s + 2 * dw * ds + w * dds
        q[:, j] += mid[j] if arm.joint_types[j] == "prismatic" else 0.2 * mid[j]
    tau = arm.inverse_dynamics(q, qd, qdd, true_phi(arm))
    tau[:, 1] += 0.05
    tau += rng.normal(0, 0.02, tau.shape)
    cols = ["t_ms"] + [f"pos{j + 1}" for j in range(arm.nq)] + [f"vel{j + 1}" for j in range(arm.nq)] + \
           [f"eff{j + 1}" for j in range(arm.nq)]
    unit = np.array([1.0 if kind == "prismatic" else 180 / np.pi for kind in arm.joint_types])
    data = np.column_stack([t * 1000, q * unit, qd * unit, tau])
    np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.17g")


MAPPING = dict(time="t_ms", q="pos*", qd="vel*", tau="eff*", time_unit="ms", angle="deg")
CLI_MAPPING = ["--time", "t_ms", "--q", "pos*", "--qd", "vel*", "--tau", "eff*", "--time-unit", "ms", "--angle", "deg"]


def make_exports(d, arm=ARM):
    files = []
    for k, name in enumerate(["r1", "r2", "r3", "check"]):
        f = d / f"{name}.csv"
        write_export(f, 100 + k, arm=arm)
        files.append(f)
    return files




def run(cmd):
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
