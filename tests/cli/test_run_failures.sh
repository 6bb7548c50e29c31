#!/usr/bin/env bash
# `dynavins run` never passes off an incomplete run as a good one:
#  - an empty log estimates no pose: exit 1, summary.json ok: false, the error says why;
#  - SIGINT mid-run: exit 130, summary.json interrupted: true, and `compare` lists the run as interrupted;
#  - `convert --out EXISTING_DIR` fails before writing; a non-yaml config is an error naming the file.
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

# Rate 0.2: the 4.7 s clip lasts 23 s, so a slow build (ASan, a loaded machine) is still running when
# the SIGINT comes (at rate 0.5 an ASan build had ended before its first pose was written).
"$bin" run --config "$config" --euroc "$shared/data/euroc_v1_01_micro" --rate 0.2 --out "$tmp/cut" > "$tmp/log" 2>&1 & pid=$!
# SIGINT once the run is under way (its first poses are written), never before its handler is installed.
for _ in $(seq 200); do [ -s "$tmp/cut/odometry.tum.partial" ] && break; sleep 0.1; done
sleep 0.5
kill -0 $pid 2> /dev/null || { tail -5 "$tmp/log"; echo "FAIL: the run ended before the SIGINT"; exit 1; }
kill -INT $pid
rc=0; wait $pid || rc=$?
tail -3 "$tmp/log"
[ "$rc" -eq 130 ] || { echo "FAIL: SIGINT exited $rc, expected 130"; exit 1; }
grep -q '"interrupted": true' "$tmp/cut/summary.json" || { echo "FAIL: summary.json does not say interrupted"; exit 1; }
"$bin" compare "$tmp/cut" --gt "$tmp/cut/odometry.tum" > "$tmp/compare" 2>&1 || true
grep -q 'cut (interrupted)' "$tmp/compare" || { cat "$tmp/compare"; echo "FAIL: compare does not list the run as interrupted"; exit 1; }
# convert --out an existing directory fails before writing anything.
mkdir -p "$tmp/existing"
rc=0; "$bin" convert --euroc "$shared/data/euroc_v1_01_micro" --out "$tmp/existing" > "$tmp/log" 2>&1 || rc=$?
[ "$rc" -eq 2 ] || { cat "$tmp/log"; echo "FAIL: convert --out DIR exited $rc, expected 2"; exit 1; }
grep -q 'is a directory' "$tmp/log" || { cat "$tmp/log"; echo "FAIL: the error does not say --out is a directory"; exit 1; }
[ -z "$(ls -A "$tmp/existing")" ] && [ ! -e "$tmp/existing.partial" ] || { echo "FAIL: convert wrote something"; exit 1; }

# A config that is not yaml names the file and says what a config looks like, without OpenCV's internals.
printf 'this is: [not yaml\n' > "$tmp/bad.yaml"
rc=0; "$bin" run --config "$tmp/bad.yaml" --euroc "$shared/data/euroc_v1_01_micro" --out "$tmp/bad" > "$tmp/log" 2>&1 || rc=$?
cat "$tmp/log" | tail -2
[ "$rc" -eq 2 ] || { echo "FAIL: a non-yaml config exited $rc, expected 2"; exit 1; }
grep -q "$tmp/bad.yaml" "$tmp/log" && grep -q '%YAML:1.0' "$tmp/log" || { echo "FAIL: the error does not name the file"; exit 1; }
grep -q 'in function' "$tmp/log" && { echo "FAIL: OpenCV's raw message leaks"; exit 1; }
echo ok
