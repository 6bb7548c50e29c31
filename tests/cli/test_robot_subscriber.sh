#!/usr/bin/env bash
# examples/robot_subscriber, built out of tree against `cmake --install` of this build, receives the
# window poses and feature weights of `dynavins run --lcm-url` (EuRoC clip, udpm in a private network
# namespace with ttl=0).
# Usage: test_robot_subscriber.sh SOURCE_DIR BUILD_DIR SHARED_DIR
set -euo pipefail
src=$(readlink -f "$1") build=$(readlink -f "$2") shared=$(readlink -f "$3")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" > "$tmp/install.log"
for f in include/dynavins_lcm/pose_t.hpp lib/cmake/dynavins/dynavinsConfig.cmake bin/dynavins bin/dynavins-lcm-spy; do
  [ -e "$tmp/prefix/$f" ] || { echo "FAIL: $f not installed"; exit 1; }
done
cmake -S "$src/examples/robot_subscriber" -B "$tmp/robot" -G Ninja -DCMAKE_PREFIX_PATH="$tmp/prefix" > "$tmp/cfg.log" ||
  { cat "$tmp/cfg.log"; exit 1; }
cmake --build "$tmp/robot" > "$tmp/build.log" || { cat "$tmp/build.log"; exit 1; }
cd "$tmp"
unshare -n bash -s "$tmp/prefix/bin/dynavins" "$tmp/robot/robot_subscriber" "$shared" <<'NS'
set -euo pipefail
bin=$1 robot=$2 shared=$3
ip link set lo up
ip route add 224.0.0.0/4 dev lo
url='udpm://239.255.76.67:7667?ttl=0'
"$robot" "$url" 20 > robot.log & r=$!
sleep 0.5
"$bin" run --config "$shared/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml" \
    --euroc "$shared/data/euroc_v1_01_micro" --rate 2 --lcm-url "$url" --out run > run.log 2>&1
wait $r
NS
cat robot.log
[ "$(grep -c '^pose ' robot.log)" -eq 20 ] || { echo "FAIL: the robot program did not receive 20 poses"; exit 1; }
grep -q 'rejected features' robot.log
echo ok
