#!/usr/bin/env python3
"""The table of tools/excitation_comparison.sh: per trajectory (AG02, OF01) over the trials,
the excitation (kappa), the identified vectors' bias against the twin's truth and their spread
over the trials (per unit group, relative to the truth's norm in that group), the held-out
torque RMSE on V01-V03, the final PD audit and the physical consistency. Standard library only.

Usage: excitation_table.py <comparison folder> <trials>
"""
import math
import re
import sys


def run_record(path):
    """kappa, kappa_scaled and phi_clie of a run record (symoro-identification-run 1)."""
    out = {}
    for line in open(path):
        key, _, value = line.partition(":")
        value = value.strip()
        if key in ("kappa", "kappa_scaled", "clie_lambda_min"):
            out[key] = float(value)
        elif key == "phi_clie":
            out[key] = [float(v) for v in value.strip("[]").split(",")]
    return out


def accepted(path):
    """names, units and values of report/parameters.yaml."""
    names, units, values = [], [], []
    for m in re.finditer(r'\{name: "([^"]+)", unit: "([^"]+)", value: ([^}]+)\}', open(path).read()):
        names.append(m.group(1))
        units.append(m.group(2))
        values.append(float(m.group(3)))
    return names, units, values


def truth(path, names):
    """The Truth column of report.md's final parameter table (6 significant digits)."""
    rows = {}
    table = open(path).read().split("## Final parameters", 1)[1]
    for line in table.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 8 and cells[0] in names:
            rows[cells[0]] = float(cells[7])
    return [rows[n] for n in names]


def identify_text(path):
    text = open(path).read()
    rmse = [float(a) for a in re.findall(r"validation V0\d at 10 ms, [a-z-]+: RMSE [0-9.]+ / ([0-9.]+) N m", text)]
    rmse_final = [float(a) for a in re.findall(r"validation V0\d at 10 ms, [a-z-]+: RMSE ([0-9.]+) /", text)]
    audit = re.search(r"final audit lambda_min ([-0-9.e+]+) -> (accepted|NOT accepted)", text)
    consistent = "physical consistency of the accepted vector: consistent" in text
    return rmse_final, rmse, float(audit.group(1)), audit.group(2) == "accepted", consistent


def group(name, unit):
    if name.startswith("IA") or name.startswith("FV") or name.startswith("FS"):
        return "drives (IA, FV)"
    return {"kg*m^2": "inertia (kg m^2)", "kg*m": "first moments (kg m)"}.get(unit, unit)


def mean(v):
    return sum(v) / len(v)


def main():
    folder, trials = sys.argv[1], int(sys.argv[2])
    print("| | AG02 (structured) | OF01 (optimized) |")
    print("|:---|---:|---:|")
    rows = {}
    for t in ("AG02", "OF01"):
        kappa, kappa_s, rmse, rmse_final, lam, acc, cons, clie, acc_vecs = [], [], [], [], [], 0, 0, [], []
        names = units = tru = None
        for k in range(1, trials + 1):
            study = f"{folder}/study-{t}-t{k}"
            r = run_record(f"{study}/runs/{t}@10ms.yaml")
            kappa.append(r["kappa"])
            kappa_s.append(r["kappa_scaled"])
            clie.append(r["phi_clie"])
            names, units, values = accepted(f"{study}/report/parameters.yaml")
            acc_vecs.append(values)
            tru = truth(f"{study}/report/report.md", names)
            f, a, l, ok, c = identify_text(f"{folder}/identify-{t}-t{k}.txt")
            rmse_final.append(mean(f))
            rmse.append(mean(a))
            lam.append(l)
            acc += ok
            cons += c
        groups = sorted(set(group(n, u) for n, u in zip(names, units)))
        stats = {}
        for label, vecs in (("CLIE", clie), ("accepted", acc_vecs)):
            for g in groups:
                idx = [i for i, (n, u) in enumerate(zip(names, units)) if group(n, u) == g]
                scale = math.sqrt(sum(tru[i] ** 2 for i in idx))
                centre = [mean([v[i] for v in vecs]) for i in idx]
                bias = math.sqrt(sum((c - tru[i]) ** 2 for c, i in zip(centre, idx))) / scale
                spread = math.sqrt(mean([sum((v[i] - c) ** 2 for c, i in zip(centre, idx)) for v in vecs])) / scale
                stats[(label, g)] = (bias, spread)
        rows[t] = dict(kappa=mean(kappa), kappa_s=mean(kappa_s), rmse=mean(rmse), rmse_final=mean(rmse_final),
                       lam=min(lam), acc=acc, cons=cons, stats=stats, groups=groups)
    a, o = rows["AG02"], rows["OF01"]
    print(f"| kappa of W (mean over {trials} trials) | {a['kappa']:.1f} | {o['kappa']:.1f} |")
    print(f"| kappa with unit columns | {a['kappa_s']:.1f} | {o['kappa_s']:.1f} |")
    for label in ("CLIE", "accepted"):
        for g in a["groups"]:
            ba, sa = a["stats"][(label, g)]
            bo, so = o["stats"][(label, g)]
            print(f"| {label} {g}: bias / spread, % of the truth's norm | {100 * ba:.2f} / {100 * sa:.2f} | "
                  f"{100 * bo:.2f} / {100 * so:.2f} |")
    print(f"| held-out RMSE on V01-V03, N m (CLIE / accepted; mean) | {a['rmse_final']:.4f} / {a['rmse']:.4f} | "
          f"{o['rmse_final']:.4f} / {o['rmse']:.4f} |")
    print(f"| final PD audit: smallest lambda_min; trials accepted | {a['lam']:.3e}; {a['acc']}/{trials} | "
          f"{o['lam']:.3e}; {o['acc']}/{trials} |")
    print(f"| accepted vector physically consistent | {a['cons']}/{trials} | {o['cons']}/{trials} |")


if __name__ == "__main__":
    main()
