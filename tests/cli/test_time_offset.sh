#!/usr/bin/env bash
# VINS-Fusion's td through the command line: the EuRoC clip with every image stamped 3.7 ms early, run
# with `--set td=0.0037`, writes the same odometry.tum as the clip itself (outputs are in the IMU clock),
# and `overlay` finds that run's frames with `--td 0.0037` and, without it, says to pass it.
# Usage: test_time_offset.sh DYNAVINS SHARED_DIR
set -euo pipefail
bin=$1 shared=$2
config=$shared/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml
clip=$(cd "$shared/data/euroc_v1_01_micro/mav0" && pwd)  # absolute: the links below point at it
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

mkdir -p "$tmp/lagged/mav0"
for d in "$clip"/*; do
  name=$(basename "$d")
  if [ "$name" = cam0 ] || [ "$name" = cam1 ]; then
    mkdir "$tmp/lagged/mav0/$name"
    ln -s "$d/data" "$tmp/lagged/mav0/$name/data"
    # timestamps are 19 digits: subtract in two parts to stay exact in awk's doubles
    awk -F, 'BEGIN { OFS = "," } /^#/ { print; next } {
      hi = substr($1, 1, length($1) - 9); lo = substr($1, length($1) - 8) - 3700000
      if (lo < 0) { lo += 1000000000; hi -= 1 }
      $1 = sprintf("%s%09d", hi, lo); print }' "$d/data.csv" > "$tmp/lagged/mav0/$name/data.csv"
  else
    ln -s "$d" "$tmp/lagged/mav0/$name"
  fi
done
head -2 "$tmp/lagged/mav0/cam0/data.csv" | tail -1

"$bin" run --config "$config" --euroc "$clip" --out "$tmp/original" > "$tmp/log" 2>&1 || { tail -5 "$tmp/log"; exit 1; }
"$bin" run --config "$config" --euroc "$tmp/lagged" --set td=0.0037 --out "$tmp/td" > "$tmp/log" 2>&1 ||
  { tail -5 "$tmp/log"; exit 1; }
[ "$(wc -l < "$tmp/td/odometry.tum")" -gt 50 ] || { echo "FAIL: the td run tracked too little"; exit 1; }
cmp "$tmp/original/odometry.tum" "$tmp/td/odometry.tum" ||
  { diff "$tmp/original/odometry.tum" "$tmp/td/odometry.tum" | head -4; echo "FAIL: td did not restore the run"; exit 1; }

rc=0; "$bin" overlay --euroc "$tmp/lagged" --features "$tmp/td/features.csv" --out "$tmp/o.png" > "$tmp/log" 2>&1 || rc=$?
[ "$rc" -eq 1 ] || { cat "$tmp/log"; echo "FAIL: overlay without --td exited $rc, expected 1"; exit 1; }
grep -q 'pass --td' "$tmp/log" || { cat "$tmp/log"; echo "FAIL: the error does not suggest --td"; exit 1; }
"$bin" overlay --euroc "$tmp/lagged" --features "$tmp/td/features.csv" --td 0.0037 --out "$tmp/o.png" > "$tmp/log" 2>&1 ||
  { cat "$tmp/log"; echo "FAIL: overlay with --td failed"; exit 1; }
[ -s "$tmp/o.png" ] || { echo "FAIL: no overlay written"; exit 1; }
echo ok
