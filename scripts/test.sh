#!/usr/bin/env bash
# README command (2): set up, build everything including the tests, run them all.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$here/build}
"$here/scripts/setup.sh"
cmake --build "$build" -j2 --target tests
# ROS tools write here; keep them out of $HOME.
export ROS_HOME="$build/ros_home" ROS_LOG_DIR="$build/ros_home/log"
# rostest's master and nodes talk over loopback only.
export ROS_IP=127.0.0.1
unset ROS_HOSTNAME ROS_MASTER_URI
mkdir -p "$ROS_LOG_DIR"
(cd "$build" && ctest --output-on-failure)
# Fuzz the loaders and the aligner briefly (ASan + UBSan, clang build).
"$here/scripts/fuzz.sh" 50
# The whole suite again under ASan + UBSan (gcc build in build-asan/).
"$here/scripts/sanitize.sh"
