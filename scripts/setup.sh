#!/usr/bin/env bash
# Installs the Debian 12 packages this package builds and tests against, then
# configures and builds it. Idempotent: re-running it only rebuilds.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$here/build}

pkgs=(
  build-essential cmake pkg-config
  ros-core-dev catkin python3-rostest python3-rosbag python3-nav-msgs python3-geometry-msgs
  libnav-msgs-dev libgeometry-msgs-dev libstd-msgs-dev librosbag-dev ros-message-generation ros-message-runtime
  libmap-msgs-dev libtf2-ros-dev
  libmrpt-dev libmrpt-ros1bridge-dev mrpt-apps mrpt-common
  libopencv-dev libeigen3-dev libgtest-dev libtclap-dev libyaml-cpp-dev nlohmann-json3-dev
)
"$here/scripts/ensure_packages.sh" "${pkgs[@]}"

# The pyenv python3 on PATH cannot import Debian's python3-* modules (catkin_pkg, genmsg).
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3
cmake --build "$build" -j2
