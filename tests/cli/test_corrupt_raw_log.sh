#!/usr/bin/env bash
# A log of raw (gray8) images with 3 kB overwritten inside a frame's pixels: every length field is
# intact, so only the checksum blocks that `convert` writes (pipeline/lcm_log.hpp) can tell.
# `log-info` must fail with exit 2 and `run --log` with a non-zero exit, both naming the checksum
# mismatch (log-info: with the events and the bytes); the run must not be reported ok. The untouched log passes log-info with its blocks verified.
# Usage: test_corrupt_raw_log.sh DYNAVINS SHARED_DIR
set -euo pipefail
bin=$1 shared=$2
config=$shared/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { cat "$tmp/log"; echo "FAIL: $*"; exit 1; }
"$bin" convert --euroc "$shared/data/euroc_v1_01_micro" --raw --out "$tmp/raw.lcmlog" > "$tmp/log" 2>&1 || fail "convert"
"$bin" log-info "$tmp/raw.lcmlog" > "$tmp/log" 2>&1 || fail "log-info on the intact log"
grep -qE 'checksums: [1-9][0-9]* blocks verified' "$tmp/log" || fail "log-info does not report verified checksum blocks"
# 3000 bytes of 0x5a at the middle of the file: inside some frame's pixels (a frame is 722 kB of them).
size=$(stat -c %s "$tmp/raw.lcmlog")
at=$((size / 2))
head -c 3000 /dev/zero | tr '\0' 'Z' | dd of="$tmp/raw.lcmlog" bs=1 seek="$at" conv=notrunc status=none
rc=0; "$bin" log-info "$tmp/raw.lcmlog" > "$tmp/log" 2>&1 || rc=$?
[ "$rc" -eq 2 ] || fail "log-info exited $rc on the overwritten log, expected 2"
grep -q 'checksum mismatch' "$tmp/log" || fail "log-info does not name the checksum mismatch"
grep -qE 'events #[0-9]+ to #[0-9]+ \(bytes [0-9]+ to [0-9]+\)' "$tmp/log" || fail "log-info does not name the events and bytes"
# The named byte range holds the overwritten bytes.
read -r first last < <(sed -nE 's/.*\(bytes ([0-9]+) to ([0-9]+)\).*/\1 \2/p' "$tmp/log" | head -1)
[ "$first" -le "$at" ] && [ $((at + 3000)) -le "$last" ] || fail "bytes $first..$last do not hold the overwritten $at..$((at + 3000))"
rc=0; "$bin" run --config "$config" --log "$tmp/raw.lcmlog" --loop off --out "$tmp/run" > "$tmp/log" 2>&1 || rc=$?
[ "$rc" -ne 0 ] || fail "run exited 0 on the overwritten log"
grep -q 'checksum mismatch' "$tmp/log" || fail "run does not name the checksum mismatch"
if [ -f "$tmp/run/summary.json" ]; then
  grep -q '"ok": true' "$tmp/run/summary.json" && fail "summary.json says ok"
fi
echo "ok (log-info and run: exit 2 / $rc, bytes $first..$last hold the overwrite at $at)"
