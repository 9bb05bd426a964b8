#!/usr/bin/env bash
# Every test: install what is missing, build, run the GoogleTest suite through ctest, check
# generated/ against a fresh compilation, drop an unseen robot folder in and run its generic
# tests, and fuzz the grammar, the DYNAMIXEL decoder and the file readers for a bounded time.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
jobs=$(nproc)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"
build/codegen/symoroc check

# A robot folder the suite has never seen, written by symoroc model from a URDF that is not a
# robot of robots/ (the Kinova Jaco2, continuous joints, rpy offsets), through the generic tests
# compiled once, with no rebuild: its robot library is built on first use (tests/robot/
# robot_folders.hpp: SYMORO_TEST_ROBOT_DIRS).
scratch=build/unseen
rm -rf "$scratch" && mkdir -p "$scratch"
build/codegen/symoroc model tests/urdf/kinova.urdf -o "$scratch/unseen_arm" --name unseen_arm
for t in test_robot_values test_excite; do
  SYMORO_TEST_ROBOT_DIRS="$PWD/$scratch/unseen_arm" "build/tests/$t" --gtest_filter='*/unseen_arm' --gtest_brief=1
done

# Fuzzing with clang's libFuzzer, each target bounded in time: the grammar (FUZZ_SECONDS, default
# 60), the DYNAMIXEL Protocol 2.0 decoder (FUZZ_DYNAMIXEL_SECONDS, default 20) and the file readers:
# the URDF reader, the log reader, the importer's reader, the ROS 2 bag (MCAP) reader, dataset.yaml and the other YAML readers
# (FUZZ_IO_SECONDS each, default 20). A fuzzer is one process on one core: two lanes of 80-100 s
# when there are two cores (the grammar, then the YAML readers; the others one after another), so
# that each keeps its whole time.
cmake -S . -B build/fuzz -G Ninja -DSYMORO_BUILD_FUZZER=ON -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build/fuzz -j"$jobs" --target fuzz_grammar fuzz_dynamixel fuzz_log fuzz_import fuzz_dataset fuzz_yaml fuzz_urdf \
  fuzz_mcap
fuzz() {  # fuzz <target> <corpus folder under tests/fuzz> <seconds> [libFuzzer options...]
  local target=$1 corpus=$2 seconds=$3
  shift 3
  mkdir -p "build/fuzz/$corpus"
  cp "tests/fuzz/$corpus"/* "build/fuzz/$corpus/"
  if ! "build/fuzz/tests/fuzz/$target" -max_total_time="$seconds" -timeout=10 -artifact_prefix=build/fuzz/ "$@" \
      "build/fuzz/$corpus" 2>"build/fuzz/$target.log"; then
    echo "$target failed:"; tail -40 "build/fuzz/$target.log"; return 1
  fi
  echo "$target: $(grep -E "^Done|#[0-9]+.*DONE" "build/fuzz/$target.log" | tail -1)"
}
fuzz_first_lane() {
  fuzz fuzz_grammar corpus "${FUZZ_SECONDS:-60}" -max_len=4096 -dict=tests/fuzz/grammar.dict &&
    fuzz fuzz_yaml corpus_yaml "${FUZZ_IO_SECONDS:-20}" -max_len=16384 &&
    fuzz fuzz_mcap corpus_mcap "${FUZZ_IO_SECONDS:-20}" -max_len=16384
}
fuzz_second_lane() {
  # urdfdom leaks what it parsed of a URDF with a joint cycle: suppressed for it alone.
  (export LSAN_OPTIONS=suppressions=tests/fuzz/urdfdom.supp
   fuzz fuzz_urdf corpus_urdf "${FUZZ_IO_SECONDS:-20}" -max_len=16384) &&
    fuzz fuzz_dynamixel corpus_dynamixel "${FUZZ_DYNAMIXEL_SECONDS:-20}" -max_len=2048 &&
    fuzz fuzz_log corpus_log "${FUZZ_IO_SECONDS:-20}" -max_len=4096 &&
    fuzz fuzz_import corpus_import "${FUZZ_IO_SECONDS:-20}" -max_len=4096 &&
    fuzz fuzz_dataset corpus_dataset "${FUZZ_IO_SECONDS:-20}" -max_len=4096
}
if [ "$jobs" -ge 2 ]; then
  fuzz_first_lane &
  first=$! first_rc=0 second_rc=0
  fuzz_second_lane || second_rc=$?
  wait "$first" || first_rc=$?
  if [ "$first_rc" -ne 0 ] || [ "$second_rc" -ne 0 ]; then exit 1; fi
else
  fuzz_first_lane
  fuzz_second_lane
fi

# The whole suite last, so its summary closes the output.
ctest --test-dir build --output-on-failure -j"$jobs"
