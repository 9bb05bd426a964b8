#!/usr/bin/env python3
"""From a robot controller's CSV export to an identified model, a plot and a URDF, in Python.

    PYTHONPATH=build/python python3 examples/python/identify_from_csv.py --robots-dir robots -o out/
    PYTHONPATH=build/python python3 examples/python/identify_from_csv.py --robots-dir robots -o out/ \\
        --export my_export.csv --time stamp_ms --time-unit ms --q '{name}_pos' --qd '{name}_vel' \\
        --tau '{name}_eff' --angle deg

The robot is the Staubli RX-90 (robots/rx90: OpenSYMORO files, no digital twin, no controller
description). Without --export, an export is made first from the RX-90's own model: smooth
motions starting and ending at rest, the model's torque with an offset on joint 2 it does not
have and 0.02 N m of noise, written as a controller would (ms, degrees). Then:
  1. import it (the last 30 % of the log held out by time),
  2. identify the physically consistent model (OLS, PD audit, SDP, physical rescue),
  3. predict the held-out torque and plot it beside the measured (matplotlib, when installed),
  4. export the identified arm as a URDF with consistent link inertials.
"""

import argparse
import pathlib
import sys

import numpy as np

import symoro


def synthesize_export(arm, path, seconds=30.0, rate=1000.0, seed=3):
    rng = np.random.default_rng(seed)
    t = np.arange(0, seconds, 1 / rate)
    x = np.clip(np.minimum(t, seconds - 1 / rate - t), 0, 1)  # 1 s quintic rise and fall
    w = 10 * x**3 - 15 * x**4 + 6 * x**5
    sign = np.where(t < seconds / 2, 1.0, -1.0)
    dw = sign * (30 * x**2 - 60 * x**3 + 30 * x**4) * ((x > 0) & (x < 1))
    ddw = (60 * x - 180 * x**2 + 120 * x**3) * ((x > 0) & (x < 1))
    half = (arm.upper - arm.lower) / 2
    q, qd, qdd = (np.zeros((t.size, arm.nq)) for _ in range(3))
    for j in range(arm.nq):
        for _ in range(4):
            a, f, p = 0.15 * half[j] * rng.uniform(0.5, 1), 2 * np.pi * rng.uniform(0.1, 0.5), rng.uniform(0, 2 * np.pi)
            s, ds, dds = a * np.sin(f * t + p), a * f * np.cos(f * t + p), -a * f * f * np.sin(f * t + p)
            q[:, j] += w * s
            qd[:, j] += dw * s + w * ds
            qdd[:, j] += ddw * s + 2 * dw * ds + w * dds
    # "True" parameters: plausible links (positive masses and inertias, small first moments).
    s = []
    for name in arm.standard_names:
        f, r = name.rstrip("0123456789"), rng.uniform(-1, 1)
        s.append({"XX": 0.6, "YY": 0.6, "ZZ": 0.6, "M": 1.5}.get(f, 0.05 if f in ("IA", "FV", "FS") else 0.0) +
                 (0.3 if f in ("XX", "YY", "ZZ") else 0.5 if f == "M" else 0.04 if f in ("IA", "FV", "FS")
                  else 0.1 if f in ("MX", "MY", "MZ") else 0.01) * r)
    tau = arm.inverse_dynamics(q, qd, qdd, arm.base_from_standard(np.array(s)))
    tau[:, 1] += 0.05
    tau += rng.normal(0, 0.02, tau.shape)
    names = arm.joint_names
    header = ["stamp_ms"] + [f"{n}_pos" for n in names] + [f"{n}_vel" for n in names] + [f"{n}_eff" for n in names]
    np.savetxt(path, np.column_stack([t * 1000, np.degrees(q), np.degrees(qd), tau]), delimiter=",",
               header=",".join(header), comments="", fmt="%.10g")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robots-dir", type=pathlib.Path, required=True, help="the project's robots/ folder")
    ap.add_argument("-o", "--out", type=pathlib.Path, required=True, help="a new folder for everything written")
    ap.add_argument("--export", type=pathlib.Path, help="your controller's CSV export (default: one made here)")
    ap.add_argument("--time", default="stamp_ms")
    ap.add_argument("--time-unit", default="ms")
    ap.add_argument("--q", default="{name}_pos")
    ap.add_argument("--qd", default="{name}_vel")
    ap.add_argument("--tau", default="{name}_eff")
    ap.add_argument("--angle", default="deg")
    a = ap.parse_args()

    arm = symoro.models.rx90.full
    a.out.mkdir(parents=True, exist_ok=True)
    export = a.export
    if export is None:
        export = a.out / "export.csv"
        synthesize_export(arm, export)
        print(f"export: {export} (made from the RX-90 model)")

    imported = symoro.import_logs(arm, a.out / "data", [export], time=a.time, time_unit=a.time_unit, q=a.q, qd=a.qd,
                                  tau=a.tau, angle=a.angle, split=0.7)
    for log in imported["logs"]:
        print(f"imported {log['input']}: {log['samples']} samples, {log['stale_rows']} stale rows")

    study = symoro.identify(arm, a.out / "data", a.out / "study", robot_dir=a.robots_dir / "rx90", intervals_ms=[10],
                            consistency="physical",
                            progress=lambda done, total, run: print(f"  run {done}/{total}: {run['id']}"))
    print(f"identified: {study['selection']['id']}, accepted {study['accepted']}; report {study['report']}")
    for name, value in list(study["parameters"].items())[:6]:
        print(f"  {name} = {value:.6g}")

    heldout = symoro.predict(arm, study["phi"], a.out / "data")[-1]
    print(f"held-out {heldout['name']}: torque RMSE per joint {np.round(heldout['rmse'], 4)} N m "
          f"(RMS of the torque {np.round(heldout['rms'], 2)})")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed (python3-matplotlib): no plot")
    else:
        fig, axes = plt.subplots(arm.nq, 1, sharex=True, figsize=(8, 2 * arm.nq))
        for j, ax in enumerate(axes):
            ax.plot(heldout["time"], heldout["tau"][:, j], label="measured")
            ax.plot(heldout["time"], heldout["tau_model"][:, j], "--", label="identified model")
            ax.set_ylabel(f"{arm.joint_names[j]} (N m)")
        axes[0].legend()
        axes[-1].set_xlabel("time (s)")
        fig.savefig(a.out / "heldout.png", dpi=80)
        print(f"plot: {a.out / 'heldout.png'}")

    urdf = symoro.export_urdf(arm, a.out / "study", a.out / "rx90_identified.urdf", prior="zero")
    print(f"urdf: {urdf['urdf']} (max |B s - phi| {urdf['residual']:.2g}, smallest pseudo-inertia eigenvalue "
          f"{urdf['lambda_min']:.3g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
