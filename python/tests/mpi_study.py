"""symoro.identify under mpirun (docs/scaling.md), run by ctest as python.mpi in MPI builds:
    python3 mpi_study.py prepare DIR        # logs (synth_logs.py), a dataset, a one-process study
    mpirun -n 2 python3 mpi_study.py ranks DIR
Every rank calls identify; rank 0 gathers and reports, the others return None. A progress
callback that raises on rank 0 stops the study on every rank (the runs in flight are saved, no
other starts); the same call again resumes, and the records equal the one-process study's."""

import os
import pathlib
import sys

import symoro

from synth_logs import ARM, MAPPING, make_exports


def records(study):
    return {f.name: [l for l in f.read_text().splitlines() if not l.lstrip().startswith("t_")]
            for f in sorted((study / "runs").glob("*.yaml"))}


def prepare(d):
    exports = make_exports(d, ARM)
    symoro.import_logs(ARM, d / "data", exports, heldout=[exports[-1]], **MAPPING)
    symoro.identify(ARM, d / "data", d / "single", intervals_ms=[10], jobs=1)


def ranks(d):
    rank = int(os.environ.get("OMPI_COMM_WORLD_RANK", os.environ.get("PMI_RANK", "0")))

    def stop_here(done, total, run):
        raise RuntimeError("stop here")

    try:
        r = symoro.identify(ARM, d / "data", d / "mpi", intervals_ms=[10], jobs=1, progress=stop_here)
        assert rank != 0 and r is None, (rank, r)
    except RuntimeError as e:
        assert rank == 0 and str(e) == "stop here", (rank, e)
        saved = len(list((d / "mpi" / "runs").glob("*.yaml")))
        assert 1 <= saved <= 2, saved  # the first run and at most the other rank's in flight; not the third
    r = symoro.identify(ARM, d / "data", d / "mpi", intervals_ms=[10], jobs=1)
    if rank != 0:
        assert r is None
        return
    assert len(r["runs"]) == 3 and r["accepted"]
    assert records(d / "mpi") == records(d / "single")
    assert (d / "mpi" / "validation.yaml").read_bytes() == (d / "single" / "validation.yaml").read_bytes()
    print("rank 0: stopped, resumed, the same records as one process")


if __name__ == "__main__":
    what, folder = sys.argv[1], pathlib.Path(sys.argv[2]).resolve()
    {"prepare": prepare, "ranks": ranks}[what](folder)
