#!/usr/bin/env bash
# The whole test suite built with AddressSanitizer + UndefinedBehaviorSanitizer
# (gcc, a separate build in build-asan/). Any report fails the test it is in.
# Usage: bash scripts/sanitize.sh   (run by scripts/test.sh; needs setup.sh's packages)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${ASAN_BUILD_DIR:-$here/build-asan}
san="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS="$san" -DCMAKE_C_FLAGS="$san" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build "$build" -j2
cmake --build "$build" -j2 --target tests
export ROS_HOME="$build/ros_home" ROS_LOG_DIR="$build/ros_home/log" ROS_IP=127.0.0.1
unset ROS_HOSTNAME ROS_MASTER_URI
mkdir -p "$ROS_LOG_DIR"
# Leaks: MRPT's and roscpp's process-lifetime singletons are reported as
# leaks at exit; those are suppressed by library, ours are not.
export LSAN_OPTIONS="suppressions=$here/test/lsan.supp:print_suppressions=0"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd "$build"
# The benchmark's runs, the memory soak (ASan's allocator is not the node's) and
# the install test (an uninstrumented example cannot load instrumented
# libraries) run un-instrumented in the main suite.
ctest --output-on-failure -E 'bench_|soak|install_'
