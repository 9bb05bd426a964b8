#!/usr/bin/env bash
# Installs the Debian packages the project needs, only those that are missing.
set -euo pipefail
packages=(
  build-essential cmake ninja-build clang libclang-rt-14-dev
  clang-format-14  # the code's format (.clang-format), checked by the test format.clang_format
  libeigen3-dev libboost-dev libfmt-dev libcli11-dev libyaml-cpp-dev
  libceres-dev coinor-libipopt-dev libsdp-dev
  libblas3 liblapack3  # the reference BLAS/LAPACK every program links (CMakeLists.txt says why)
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenmpi-dev openmpi-bin  # optional: the MPI farm and its test (docs/scaling.md)
  procps  # pgrep/ps: the MPI test finds the rank it kills
  liblz4-dev libzstd-dev  # MCAP chunks: dynid import reads ROS 2 bags (io/mcap.hpp)
  libmujoco-dev  # dynid export --mjcf is checked against MuJoCo's own inverse dynamics (tests)
  libxxhash-dev  # content digests (io/digest.hpp): saved runs, parameters files, robot folders
  liburdfdom-dev liburdfdom-tools  # symoroc model reads URDFs (urdfdom); the export tests read them back (check_urdf)
  libtinyxml-dev  # symoroc model names the line of a malformed URDF (urdfdom's own XML parser)
  liborocos-kdl-dev  # the tests compare URDF models against KDL, an independent rigid-body library
  python3-dev pybind11-dev python3-numpy python3-pytest  # the Python package (python/) and its tests
  libblas-dev liblapack-dev  # their static archives: the Python module's reference BLAS/LAPACK (python/CMakeLists.txt)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Test-only: node and npm run the MCAP project's writer, which makes the bags the import tests read
# (tests/bags). Judged by the commands, not the packages: a Node.js from another source (e.g.
# NodeSource's, which bundles npm and conflicts with Debian's npm package) serves as well.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  missing+=(nodejs npm)
fi
if ((${#missing[@]})); then
  echo "Installing: ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
