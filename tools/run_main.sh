#!/usr/bin/env bash
# The main job, end to end on the bundled CRANE-X7 (no hardware): install what is missing,
# build, check that generated/ matches a fresh compilation of robots/, install the package and
# run the example application against it; then simulate the digital twin's whole dataset (the
# 43 designed trajectories, one trial, seed 1; resumable) and run the whole identification
# study on it (40 trajectories x 4 intervals: OLS, all-pose PD audit, conditional SDP, CLIE,
# PCA selection, rescue onto the physically consistent vectors, final audit, validation on
# V01-V03) with its report in build/study/report/report.md, and the identified arm as a URDF that
# reproduces the accepted parameters (build/crane_x7_identified.urdf).
# Both steps are resumable: a rerun skips what is finished.
# Then the model-gap workflow on twin data with hidden effects (build/diagnosis/, build/gap/),
# 5 s of the 1 kHz controller against virtual servos (build/control-virtual.csv), and a robot
# with only its robots/ folder (the RX-90) from a CSV its controller could have exported:
# import, identify, diagnose, compare (build/rx90-*).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
# Only what this script runs and installs: symoroc, dynid, every library and the Python module
# the install step copies (symoro_installable), and the RX-90 export writer; tools/run_tests.sh
# builds everything.
cmake --build build -j"$(nproc)" --target symoro_installable write_export
build/codegen/symoroc check
build/codegen/symoroc info robots/crane_x7
prefix="$PWD/build/install"
cmake --install build --prefix "$prefix" >/dev/null
cmake -S tests/package -B build/example -G Ninja -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build build/example
build/example/crane_x7_example
build/example/identify_example

dynid=build/runtime/tools/dynid
$dynid trajectories --robot crane_x7
$dynid twin dataset --robot crane_x7 -o build/twin-data --trials 1 --seed 1
$dynid preprocess --robot crane_x7 build/twin-data/AG02_t1.csv
$dynid twin bench --robot crane_x7 --seconds 3
# --consistency physical: the paper's 160 runs as they are (each also checked for a physically
# consistent set of link inertials), and the representative rescued onto the vectors that have
# one, so that the accepted model is a physical robot (docs/identification.md).
$dynid identify --robot crane_x7 --data build/twin-data -o build/study --consistency physical
# The identified arm as a URDF (modified-DH link frames, consistent inertials nearest the CAD
# prior) that reproduces the accepted base parameters exactly.
$dynid export --robot crane_x7 --study build/study --urdf build/crane_x7_identified.urdf --force

# The model-gap workflow: a twin dataset with hidden Coulomb friction (joints 2 and 4) and a
# torque offset (joint 5), which dynid diagnose is not told about; it names them, writes
# build/diagnosis/diagnosis.md (before/after on V01-V03, figures) and the robot.yaml variant
# build/diagnosis/variant.yaml. `dynid diagnose --apply` added that variant to robots/crane_x7
# (reduced_diagnosed, compiled into generated/); both models are identified on the same data
# (OLS, PD audit, SDP, CLIE on AG02 at 10 ms) and compared on the held-out V01-V03 in
# build/gap/gap.md.
cat > build/hidden-effects.yaml <<'YAML'
effects:
  coulomb: {enabled: true, torque: [0, 0.10, 0, 0.06, 0, 0, 0, 0]}
  torque_offset: {enabled: true, torque: [0, 0, 0, 0, 0.02, 0, 0, 0]}
YAML
$dynid twin dataset --robot crane_x7 -o build/gap-data --trials 1 --seed 2 --only AG02 V01 V02 V03 \
  --config build/hidden-effects.yaml
$dynid diagnose --robot crane_x7 --data build/gap-data -o build/diagnosis
for model in reduced reduced_diagnosed; do
  $dynid identify --robot crane_x7 --model $model --data build/gap-data -o build/gap-study-$model \
    --only AG02 --interval 10 --validation V01,V02,V03
done
$dynid compare --robot crane_x7 --before build/gap-study-reduced --after build/gap-study-reduced_diagnosed -o build/gap
# A payload mounted after the identification (0.2 kg, 8 cm out on the flange axis): diagnose
# the clean study's parameters as they stand (--params holds them); it names the payload.
cat > build/payload.yaml <<'YAML'
effects:
  payload: {enabled: true, mass: 0.2, com: [0, 0, 0.08]}
YAML
$dynid twin dataset --robot crane_x7 -o build/payload-data --trials 1 --seed 3 --only AG02 V01 V02 V03 \
  --config build/payload.yaml
$dynid diagnose --robot crane_x7 --data build/payload-data -o build/payload-diagnosis \
  --params build/study/report/parameters.yaml

# The hardware controller without hardware: 5 s of AG02 at 1 kHz through the real DYNAMIXEL
# driver over a pseudo-terminal, against virtual servos that drive the digital twin.
rm -f build/control-virtual.csv build/control-virtual.meta.yaml  # a run never overwrites a log
$dynid control --robot crane_x7 --virtual --trajectory AG02 --seconds 5 -o build/control-virtual.csv

# Your robot, your logs: the RX-90 has no twin, trajectory design or controller description.
# Its export (synthesized from its model: degrees, ms, its own column names, stale rows, Coulomb
# friction and an offset that its `rigid` model lacks) goes through the README's commands.
build/tests/runtime/write_export rx90 build/rx90-export.csv 60 5
rm -rf build/rx90-data  # import never replaces files
$dynid import --robot rx90 -o build/rx90-data build/rx90-export.csv --name arm --time stamp_ms --time-unit ms \
  --q '{name}_pos' --qd '{name}_vel' --tau '{name}_eff' --angle deg --split 0.7
for model in rigid full; do
  $dynid identify --robot rx90 --model $model --data build/rx90-data -o build/rx90-study-$model --interval 10
done
$dynid diagnose --robot rx90 --model rigid --data build/rx90-data -o build/rx90-diagnosis
$dynid compare --robot rx90 --before build/rx90-study-rigid --after build/rx90-study-full -o build/rx90-gap
$dynid export --robot rx90 --model full --study build/rx90-study-full --urdf build/rx90_identified.urdf --prior zero --force

# The same from Python (docs/python.md), when the build made the package: the example goes from
# a CSV export of the RX-90 to an identified model, a plot and a URDF (build/python-example/).
if [ -f build/python/symoro/__init__.py ]; then
  rm -rf build/python-example
  PYTHONPATH=build/python /usr/bin/python3 examples/python/identify_from_csv.py --robots-dir robots -o build/python-example
fi
