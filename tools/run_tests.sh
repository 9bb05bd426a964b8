#!/usr/bin/env bash
# Every test: install what is missing, build, run the GoogleTest suite through ctest, check
# generated/ against a fresh compilation, drop an unseen robot folder in and run its generic
# tests, and fuzz the grammar for a bounded time (FUZZ_SECONDS, default 60) and the DYNAMIXEL
# decoder (FUZZ_DYNAMIXEL_SECONDS, default 20) and the file readers (FUZZ_IO_SECONDS each,
# default 20).
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

# Grammar fuzzing with clang's libFuzzer, bounded in time.
cmake -S . -B build/fuzz -G Ninja -DSYMORO_BUILD_FUZZER=ON -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build/fuzz -j"$jobs" --target fuzz_grammar
mkdir -p build/fuzz/corpus
cp tests/fuzz/corpus/* build/fuzz/corpus/
build/fuzz/tests/fuzz/fuzz_grammar -max_total_time="${FUZZ_SECONDS:-60}" -max_len=4096 -timeout=10 \
  -dict=tests/fuzz/grammar.dict build/fuzz/corpus 2>build/fuzz/fuzz.log || { tail -40 build/fuzz/fuzz.log; exit 1; }
grep -E "^Done|#[0-9]+.*DONE" build/fuzz/fuzz.log | tail -1

# DYNAMIXEL Protocol 2.0 decoder fuzzing, bounded in time (FUZZ_DYNAMIXEL_SECONDS, default 20).
cmake --build build/fuzz -j"$jobs" --target fuzz_dynamixel
mkdir -p build/fuzz/corpus_dynamixel
cp tests/fuzz/corpus_dynamixel/* build/fuzz/corpus_dynamixel/
build/fuzz/tests/fuzz/fuzz_dynamixel -max_total_time="${FUZZ_DYNAMIXEL_SECONDS:-20}" -max_len=2048 -timeout=10 \
  build/fuzz/corpus_dynamixel 2>build/fuzz/fuzz_dynamixel.log || { tail -40 build/fuzz/fuzz_dynamixel.log; exit 1; }
grep -E "^Done|#[0-9]+.*DONE" build/fuzz/fuzz_dynamixel.log | tail -1

# The file readers' fuzzing, bounded in time (FUZZ_IO_SECONDS each, default 20): the log reader,
# the importer's reader and dataset.yaml.
cmake --build build/fuzz -j"$jobs" --target fuzz_log fuzz_import fuzz_dataset
for t in log import dataset; do
  mkdir -p build/fuzz/corpus_$t
  cp tests/fuzz/corpus_$t/* build/fuzz/corpus_$t/
  build/fuzz/tests/fuzz/fuzz_$t -max_total_time="${FUZZ_IO_SECONDS:-20}" -max_len=4096 -timeout=10 \
    -artifact_prefix=build/fuzz/ build/fuzz/corpus_$t 2>build/fuzz/fuzz_$t.log || { tail -40 build/fuzz/fuzz_$t.log; exit 1; }
  grep -E "^Done|#[0-9]+.*DONE" build/fuzz/fuzz_$t.log | tail -1
done

# The whole suite last, so its summary closes the output.
ctest --test-dir build --output-on-failure -j"$jobs"
