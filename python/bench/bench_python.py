#!/usr/bin/env python3
"""The Python binding's cost against the C++ loop (bench_loop.cpp): per-call overhead on one
state (target: under 1 us) and the cost per state of a 10,000-state batch (target: within 1.3x of
the C++ loop). Run from the build tree:

    PYTHONPATH=build/python python3 python/bench/bench_python.py build/python/bench_python_loop
"""

import json
import subprocess
import sys
import timeit

import numpy as np

import symoro

BATCH = 10_000


def best_seconds(stmt, number, repeat=7):
    return min(timeit.repeat(stmt, number=number, repeat=repeat)) / number


def cxx_numbers(exe):
    out = subprocess.run([exe, "--benchmark_format=json", "--benchmark_min_time=0.5"], check=True, capture_output=True,
                         text=True).stdout
    res = {}
    for b in json.loads(out)["benchmarks"]:
        if "ns_per_state" in b:
            res[b["name"]] = b["ns_per_state"]  # s per state (an inverted rate)
        else:
            res[b["name"]] = b["real_time"] * {"ns": 1e-9, "us": 1e-6, "ms": 1e-3}[b["time_unit"]]
    return res


def main():
    cxx = cxx_numbers(sys.argv[1])
    rng = np.random.default_rng(7)
    rows = []
    for robot, name in [("planar2r", "full"), ("crane_x7", "reduced")]:
        m = getattr(getattr(symoro.models, robot), name)
        key = f"{robot}.{name}"
        q1, phi = rng.uniform(-1, 1, m.nq), rng.uniform(-1, 1, m.np)
        one = best_seconds(lambda: m.inverse_dynamics(q1, q1, q1, phi), 20000)
        c_one = cxx[f"inverse_dynamics_one/{key}"]
        rows.append((f"inverse_dynamics, one state, {key}", one * 1e6, c_one * 1e6, (one - c_one) * 1e6, "overhead < 1 us"))
        q = rng.uniform(-1, 1, (BATCH, m.nq))
        batch = best_seconds(lambda: m.inverse_dynamics(q, q, q, phi), 20) / BATCH
        c_batch = cxx[f"inverse_dynamics_batch/{key}"]
        rows.append((f"inverse_dynamics, {BATCH} states, {key}, per state", batch * 1e6, c_batch * 1e6, batch / c_batch,
                     "ratio <= 1.3"))
        if robot == "crane_x7":
            batch = best_seconds(lambda: m.regressor(q, q, q), 10) / BATCH
            c_batch = cxx[f"regressor_batch/{key}"]
            rows.append((f"regressor, {BATCH} states, {key}, per state", batch * 1e6, c_batch * 1e6, batch / c_batch,
                         "ratio <= 1.3"))
    print(f"{'measurement':58s} {'Python us':>10s} {'C++ us':>10s} {'overhead/ratio':>15s}  target")
    for what, py, c, x, target in rows:
        print(f"{what:58s} {py:10.3f} {c:10.3f} {x:15.3f}  {target}")


if __name__ == "__main__":
    main()
