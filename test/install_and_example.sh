#!/usr/bin/env bash
# Installs the package into an empty prefix and uses it as a user would:
# examples/align_two_maps built as a plain CMake project against it (only
# CMAKE_PREFIX_PATH set, nothing of the build tree or ROS in its environment)
# aligns two real map_server files; the installed programs find their
# libraries; roslaunch finds the installed nodes through the install space.
# Usage: install_and_example.sh BUILD_DIR SOURCE_DIR SHARED_DATA   (a ctest)
set -euo pipefail
build=$1 source=$2 data=$3
willow=$data/ros_maps/willow
if [ ! -f "$willow/navstage_willow_5cm.yaml" ]; then
  echo "missing $willow (../shared/data beside the repo)" >&2
  [ "${CI:-}" = "true" ] && exit 1 || exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
clean_env=(env -i PATH=/usr/bin:/bin HOME="$work" ROS_HOME="$work/ros")

cmake --install "$build" --prefix "$prefix" >"$work/install.log"
"${clean_env[@]}" cmake -S "$source/examples/align_two_maps" -B "$work/example" \
  -DCMAKE_PREFIX_PATH="$prefix" >"$work/configure.log"
"${clean_env[@]}" cmake --build "$work/example" -j2 >"$work/build.log"

out=$("${clean_env[@]}" "$work/example/align_two_maps" \
  "$willow/navstage_willow_5cm.yaml" "$willow/stageros_willow_10cm.yaml")
echo "align_two_maps: $out"
# The pair's reference (test_real_maps.cpp, WillowNavstage5cmAgainstStageros10cm):
# OTHER's frame in REF's at y 50.889 m, yaw -92.65 deg, scale 0.9996.
echo "$out" | awk '{ y = $5 + 0; yaw = $8 + 0; scale = $11 + 0
  ok = (y > 50.3 && y < 51.5) && (yaw > -93.2 && yaw < -92.1) && (scale > 0.99 && scale < 1.01)
  if (!ok) { print "not the Willow pair'"'"'s transform" > "/dev/stderr"; exit 1 } }'

for exe in "$prefix"/lib/multires_map_merge/* "$prefix"/bin/gridmap-merge "$prefix"/lib/*.so; do
  if ldd "$exe" | grep -q "not found"; then
    echo "$exe: $(ldd "$exe" | grep 'not found')" >&2
    exit 1
  fi
done
"${clean_env[@]}" "$prefix/bin/gridmap-merge" "$willow/navstage_willow_5cm.yaml" "$willow/stageros_willow_10cm.yaml" \
  --json "$work/r.json" >/dev/null
grep -q '"success": *true' "$work/r.json"
[ -s "$prefix/share/multires_map_merge/config/aligner.ini" ]

ros_env=("${clean_env[@]}" ROS_PACKAGE_PATH="$prefix/share:/usr/share" CMAKE_PREFIX_PATH="$prefix:/usr")
for launch in "/merge_maps merge_maps.launch" "/map_merge fleet_demo.launch bag:=none rviz:=false"; do
  read -r node file args <<<"$launch"
  line=$("${ros_env[@]}" roslaunch --args "$node" multires_map_merge "$file" $args)
  echo "roslaunch $file: $line"
  case $line in *"$prefix/lib/multires_map_merge/"*) ;; *) echo "not the installed node" >&2; exit 1 ;; esac
done
echo "installed, example built and run, nodes found"
