#!/usr/bin/env bash
# `dynavins run` (stereo) on an EuRoC folder without cam1 must fail naming the folder, not run mono.
# Usage: test_stereo_without_cam1.sh DYNAVINS SHARED_DIR
set -euo pipefail
bin=$1 shared=$2
clip=$shared/data/euroc_v1_01_micro/mav0
config=$shared/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/clip/mav0"
for d in cam0 imu0 state_groundtruth_estimate0; do
  [ -e "$clip/$d" ] && ln -s "$clip/$d" "$tmp/clip/mav0/$d"
done
set +e
"$bin" run --config "$config" --euroc "$tmp/clip" --out "$tmp/out" > "$tmp/log" 2>&1
rc=$?
set -e
cat "$tmp/log"
[ "$rc" -eq 2 ] || { echo "FAIL: exit $rc, expected 2"; exit 1; }
grep -q "no mav0/cam1 folder" "$tmp/log" || { echo "FAIL: the error does not name cam1"; exit 1; }
[ ! -e "$tmp/out/odometry.tum" ] || { echo "FAIL: a run was written"; exit 1; }
# --mono on the same folder runs through every frame. (The clip stands still, so mono never initialises:
# the run then ends with "no pose was estimated", exit 1, which is not a failure to open the folder.)
rc=0; "$bin" run --config "$config" --euroc "$tmp/clip" --mono --out "$tmp/out-mono" > "$tmp/log" 2>&1 || rc=$?
grep -q '"frames_estimated": 95' "$tmp/out-mono/summary.json" 2>/dev/null ||
  { cat "$tmp/log"; echo "FAIL: --mono did not run (exit $rc)"; exit 1; }
echo "ok"
