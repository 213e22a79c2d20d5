#!/usr/bin/env bash
# README command (1): set up and build, render two real maps at 5 and 8 cm
# from Debian's malaga dataset (the second rotated), merge them with
# gridmap-merge without their metadata, and print the result beside the truth.
# Usage: bash scripts/demo.sh [OUTPUT_DIR]   (default: ./demo_output)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bin="${BUILD_DIR:-$here/build}/devel/lib/multires_map_merge"
out=$(realpath -m "${1:-$PWD/demo_output}")
log="${TMPDIR:-/tmp}/multires_map_merge_setup.log"
echo "Setting up and building (log: $log) ..."
"$here/scripts/setup.sh" >"$log" 2>&1 || { tail -n 40 "$log"; exit 1; }
"$bin/multires_demo" --write "$out"
"$bin/gridmap-merge" "$out/ref.gridmap.gz" "$out/other.gridmap.gz" \
  --out "$out/merged.gridmap.gz" --png "$out/merged.png" --json "$out/result.json"
echo
echo "The same two maps as a robot would record them, merged from the bag:"
"$bin/gridmap-merge" --bag "$out/two_robots.bag" --topics /robot1/map /robot2/map | grep -A1 "^merged"
echo
echo "Wrote the merged map, an overlay PNG and the JSON result into $out"
