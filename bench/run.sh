#!/usr/bin/env bash
# The benchmark, one command:  bash bench/run.sh [--quick] [OUT_DIR]
# Sets up and builds (scripts/setup.sh), then runs multires_bench on the real
# logs in ../shared/data and writes OUT_DIR/REPORT.md with its PNGs and
# pairs.csv (default OUT_DIR: bench/results, or build/bench_quick with --quick).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
quick=()
if [ "${1:-}" = "--quick" ]; then quick=(--quick); shift; fi
default_out="$here/bench/results"
[ ${#quick[@]} -eq 0 ] || default_out="$here/build/bench_quick"
out=$(realpath -m "${1:-$default_out}")
data=$(realpath -m "$here/../shared/data")
[ -d "$data/carmen_corrected" ] || { echo "bench: $data/carmen_corrected not found" >&2; exit 1; }
log="${TMPDIR:-/tmp}/multires_map_merge_setup.log"
"$here/scripts/setup.sh" >"$log" 2>&1 || { tail -n 40 "$log"; exit 1; }
"${BUILD_DIR:-$here/build}/devel/lib/multires_map_merge/multires_bench" "${quick[@]}" --out "$out" --data "$data"
