#!/usr/bin/env bash
# The live fleet demo: records a three-robot session from Debian's malaga
# dataset (5 / 3 / 8 cm, different frames, the third joining late; with
# ../shared/data, a fourth robot in another building) and plays it through
# the map_merge node with rviz. Needs a display for rviz; HEADLESS=1 runs
# without it for a minute and prints what the node says of each robot.
# Usage: bash scripts/fleet_demo.sh [OUTPUT_DIR]   (after scripts/setup.sh)
set -eo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$here/build}
out=$(realpath -m "${1:-$PWD/demo_output}")
mkdir -p "$out"
intel="$here/../shared/data/carmen_corrected/intel-corrected.log.gz"
other=(); [ -f "$intel" ] && other=(--other-log "$intel")
"$build/devel/lib/multires_map_merge/fleet-bag" --out "$out/fleet.bag" "${other[@]}"
export ROS_HOME=${ROS_HOME:-$out/ros_home} ROS_LOG_DIR=${ROS_LOG_DIR:-$out/ros_home/log}
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
if [ -n "${HEADLESS:-}" ]; then
  timeout -s INT 60 roslaunch multires_map_merge fleet_demo.launch bag:="$out/fleet.bag" rviz:=false 2>&1 |
    grep --line-buffered -E 'map_merge: /robot' || true
else
  roslaunch multires_map_merge fleet_demo.launch bag:="$out/fleet.bag"
fi
