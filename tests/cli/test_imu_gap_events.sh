#!/usr/bin/env bash
# A 2 s IMU outage in the real EuRoC clip (rows removed from imu0/data.csv) is one reset: one
# "reset:" row in estimator_events.csv, `resets: 1` in summary.json, the 40 frames inside the gap
# counted as intervals with a gap but not each written as another reset (they were: 41 rows, summary 1).
# The run then re-initialises and ends ok.
# Usage: test_imu_gap_events.sh DYNAVINS SHARED_DIR
set -euo pipefail
bin=$1 shared=$2
clip=$shared/data/euroc_v1_01_micro/mav0
config=$shared/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/clip/mav0/imu0"
ln -s "$clip/cam0" "$tmp/clip/mav0/cam0"
ln -s "$clip/cam1" "$tmp/clip/mav0/cam1"
# The first image time, without a pipe into head: under pipefail, grep's second write after head had
# exited (the file is 4.2 kB, grep writes 4 kB at a time) was a SIGPIPE that failed the test at random.
t0=$(awk -F, '!/^#/ { print $1; exit }' "$clip/cam0/data.csv")
# The outage: [t0 + 2 s, t0 + 4 s) of the clip's first image time (the clip holds 4.75 s of images).
awk -F, -v a=$((t0 + 2000000000)) -v b=$((t0 + 4000000000)) '/^#/ { print; next } { if ($1 + 0 < a || $1 + 0 >= b) print }' \
  "$clip/imu0/data.csv" > "$tmp/clip/mav0/imu0/data.csv"
rc=0
"$bin" run --config "$config" --euroc "$tmp/clip" --loop off --out "$tmp/out" > "$tmp/log" 2>&1 || rc=$?
fail() { cat "$tmp/log"; echo "--- estimator_events.csv"; cat "$tmp/out/estimator_events.csv" || true; echo "FAIL: $*"; exit 1; }
[ "$rc" -eq 0 ] || fail "exit $rc"
resets_csv=$(grep -c '"reset: ' "$tmp/out/estimator_events.csv" || true)
resets_json=$(sed -nE 's/^  "resets": ([0-9]+),/\1/p' "$tmp/out/summary.json")
gaps=$(sed -nE 's/^  "imu_intervals_with_gap": ([0-9]+),/\1/p' "$tmp/out/summary.json")
echo "reset rows $resets_csv, summary resets $resets_json, intervals with a gap $gaps"
[ "$resets_csv" -eq 1 ] || fail "estimator_events.csv has $resets_csv reset rows, expected 1"
[ "$resets_json" -eq 1 ] || fail "summary.json says $resets_json resets, expected 1"
grep -q '"reset: IMU gap of 20[0-9][0-9] ms"' "$tmp/out/estimator_events.csv" || fail "the reset row does not name the 2 s IMU gap"
# The frames inside the gap had no IMU: counted, one interval each (40 frames at 20 Hz, +1 across the edge).
[ "$gaps" -ge 39 ] && [ "$gaps" -le 42 ] || fail "imu_intervals_with_gap $gaps, expected about 41"
# It tracks again after the gap: a second "initialized" after the reset.
[ "$(grep -c '"initialized"' "$tmp/out/estimator_events.csv")" -eq 2 ] || fail "no re-initialisation after the gap"
# The event count of the summary is the CSV's row count.
events_json=$(sed -nE 's/^  "estimator_events": ([0-9]+),/\1/p' "$tmp/out/summary.json")
[ "$events_json" -eq $(($(wc -l < "$tmp/out/estimator_events.csv") - 1)) ] || fail "estimator_events $events_json differs from the CSV"
echo "ok"
