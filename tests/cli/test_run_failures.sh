#!/usr/bin/env bash
# `dynavins run` never passes off an incomplete run as a good one:
#  - an empty log estimates no pose: exit 1, summary.json ok: false, the error says why;
#  - SIGINT mid-run: exit 130, summary.json interrupted: true, and `compare` lists the run as interrupted.
# Usage: test_run_failures.sh DYNAVINS SHARED_DIR
set -euo pipefail
bin=$1 shared=$2
config=$shared/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

: > "$tmp/empty.lcmlog"
rc=0; "$bin" run --config "$config" --log "$tmp/empty.lcmlog" --out "$tmp/empty" > "$tmp/log" 2>&1 || rc=$?
cat "$tmp/log" | tail -3
[ "$rc" -eq 1 ] || { echo "FAIL: empty log exited $rc, expected 1"; exit 1; }
grep -q 'no pose was estimated' "$tmp/log" || { echo "FAIL: the error does not say no pose was estimated"; exit 1; }
grep -q '"ok": false' "$tmp/empty/summary.json" || { echo "FAIL: summary.json of the empty run says ok"; exit 1; }

"$bin" run --config "$config" --euroc "$shared/data/euroc_v1_01_micro" --rate 1 --out "$tmp/cut" > "$tmp/log" 2>&1 & pid=$!
sleep 2.5
kill -INT $pid
rc=0; wait $pid || rc=$?
tail -3 "$tmp/log"
[ "$rc" -eq 130 ] || { echo "FAIL: SIGINT exited $rc, expected 130"; exit 1; }
grep -q '"interrupted": true' "$tmp/cut/summary.json" || { echo "FAIL: summary.json does not say interrupted"; exit 1; }
"$bin" compare "$tmp/cut" --gt "$tmp/cut/odometry.tum" > "$tmp/compare" 2>&1 || true
grep -q 'cut (interrupted)' "$tmp/compare" || { cat "$tmp/compare"; echo "FAIL: compare does not list the run as interrupted"; exit 1; }
echo ok
