#!/usr/bin/env bash
# README command (1): set up, build, and align two maps rendered at different
# resolutions from Debian's real malaga dataset.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
"$here/scripts/setup.sh" >"${TMPDIR:-/tmp}/multires_map_merge_setup.log" 2>&1 ||
  { tail -n 40 "${TMPDIR:-/tmp}/multires_map_merge_setup.log"; exit 1; }
exec "${BUILD_DIR:-$here/build}/devel/lib/multires_map_merge/multires_demo" "$@"
