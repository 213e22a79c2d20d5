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
# The decision validated leave one site out (issue 35): decision-fit on the
# calibration samples the benchmark made (multires_bench --calibration-data;
# bench/results/calibration_candidates*.csv), appended to the report.
samples=("$here"/bench/results/calibration_candidates*.csv)
table=$(mktemp)
trap 'rm -f "$table"' EXIT
"${BUILD_DIR:-$here/build}/devel/lib/multires_map_merge/decision-fit" --markdown "$table" "${samples[@]}" >/dev/null
{
  echo
  echo "## The decision, validated leave one site out"
  echo
  echo "\`decision-fit\` on the calibration samples (${#samples[@]} files: $(for s in "${samples[@]}"; do printf '`%s` ' "$(basename "$s")"; done)). The calibration pairs are grouped by the calibration site they touch (E5, HIH, the CARMEN negatives, the live fleet's growing maps, the independent ROS maps); each group is left out in turn. *Refit*: the whole fit made again without the group, judged on it. *This model*: the defaults' model with only its threshold set again without the group (its highest wrong value plus the least margin): how far a new site's wrong values rise above what the others showed, which sets the margin (docs/decision.md, Calibration). F5 and KPT4A stay out of every fit."
  echo
  cat "$table"
} >>"$out/REPORT.md"
