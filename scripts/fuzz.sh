#!/usr/bin/env bash
# Fuzzes the map loaders and the aligner with libFuzzer under ASan + UBSan
# (clang from Debian, a separate build in build-fuzz/).
# Usage: bash scripts/fuzz.sh [SECONDS_PER_TARGET]   (default 50: what the test
# command runs; run longer, e.g. 3600, to search harder). A finding stops the
# run with the crashing input saved as build-fuzz/crash-* and a non-zero exit.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
secs=${1:-50}
build=${FUZZ_BUILD_DIR:-$here/build-fuzz}
pkgs=(clang-14 libclang-rt-14-dev libomp-14-dev)
"$here/scripts/ensure_packages.sh" "${pkgs[@]}"
CC=clang-14 CXX=clang++-14 cmake -S "$here" -B "$build" -DMMM_FUZZ=ON -DCATKIN_ENABLE_TESTING=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build "$build" -j2 --target fuzz_map_loader fuzz_aligner
bin="$build/devel/lib/multires_map_merge"
# Big allocations asked for by corrupt headers must fail as bad_alloc (which
# the loaders turn into errors), not abort the run.
export ASAN_OPTIONS=allocator_may_return_null=1:detect_leaks=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cd "$build"
for f in fuzz_map_loader fuzz_aligner; do
  mkdir -p "corpus/$f"
  echo "== $f for ${secs}s"
  if ! "$bin/$f" -max_total_time="$secs" -max_len=8192 -rss_limit_mb=4096 -timeout=30 \
      -print_final_stats=1 "corpus/$f" >"$f.log" 2>&1; then
    tail -n 60 "$f.log"
    echo "fuzz: $f found a problem (log: $build/$f.log; input saved as $build/crash-* or oom-*/timeout-*)" >&2
    exit 1
  fi
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$f.log" || true
done
echo "fuzz: no findings"
