#!/usr/bin/env bash
# The main job, end to end on the bundled CRANE-X7 (no hardware): install what is missing,
# build, check that generated/ matches a fresh compilation of robots/, install the package and
# run the example application against it; then simulate the digital twin's whole dataset (the
# 43 designed trajectories, one trial, seed 1; resumable) and run the whole identification
# study on it (40 trajectories x 4 intervals: OLS, all-pose PD audit, conditional SDP, CLIE,
# PCA selection, rescue, final audit, validation on V01-V03) with its report in
# build/study/report/report.md. Both steps are resumable: a rerun skips what is finished.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
build/codegen/symoroc check
build/codegen/symoroc info robots/crane_x7
prefix="$PWD/build/install"
cmake --install build --prefix "$prefix" >/dev/null
cmake -S tests/package -B build/example -G Ninja -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build build/example
build/example/crane_x7_example

dynid=build/runtime/tools/dynid
$dynid trajectories --robot crane_x7
$dynid twin dataset --robot crane_x7 -o build/twin-data --trials 1 --seed 1
$dynid preprocess --robot crane_x7 build/twin-data/AG02_t1.csv
$dynid twin bench --robot crane_x7 --seconds 3
$dynid identify --robot crane_x7 --data build/twin-data -o build/study
