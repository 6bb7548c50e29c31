#!/usr/bin/env bash
# scripts/lcm-spy starts lcm-spy headless (Xvfb) with the project's types jar, and lcm-spy loads every
# type of lcm_types/ and decodes a published DYNAVINS_STATUS (no "??" unknown-type row is checked by
# the type count; the screenshot is for the README). Inside a private network namespace, ttl=0.
# Usage: test_lcm_spy.sh SOURCE_DIR TYPES_JAR [SCREENSHOT.png]
set -euo pipefail
src=$(readlink -f "$1") jar=$(readlink -f "$2") shot=${3:-}
command -v Xvfb > /dev/null || { echo "SKIP: Xvfb is not installed (scripts/install-deps.sh installs it)"; exit 77; }
[ -n "$shot" ] && shot=$(readlink -f "$(dirname "$shot")")/$(basename "$shot")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
want=$(ls "$src"/lcm_types/*.lcm | wc -l)
unshare -n bash -s "$src" "$jar" "$shot" <<'NS'
set -euo pipefail
src=$1 jar=$2 shot=$3
ip link set lo up
ip route add 224.0.0.0/4 dev lo
display=:$((90 + RANDOM % 9))
Xvfb $display -screen 0 1024x640x24 > xvfb.log 2>&1 & xvfb=$!
trap 'kill $xvfb 2>/dev/null || true' EXIT
sleep 1
DISPLAY=$display DYNAVINS_TYPES_JAR=$jar "$src/scripts/lcm-spy" --lcm-url='udpm://239.255.76.67:7667?ttl=0' > spy.log 2>&1 & spy=$!
for _ in $(seq 50); do grep -q 'LCM types' spy.log && break; sleep 0.2; done
if [ -n "$shot" ]; then  # something to show: the outputs of a short run
  sleep 2
  "${DYNAVINS:?set DYNAVINS to take a screenshot}" run --config "$CONFIG" --log "$LOG" --rate 1 \
      --lcm-url 'udpm://239.255.76.67:7667?ttl=0' --out run > /dev/null 2>&1
  DISPLAY=$display xwd -root -silent > shot.xwd
  "$src/scripts/xwd_to_png.py" shot.xwd "$shot" --crop 0 0 800 110
fi
kill $spy; wait $spy 2>/dev/null || true
NS
cat spy.log
found=$(sed -n 's/^Found \([0-9]*\) LCM types.*/\1/p' spy.log)
[ "${found:-0}" -eq "$want" ] || { echo "FAIL: lcm-spy found ${found:-no} LCM types, lcm_types/ has $want"; exit 1; }
grep -q 'Exception' spy.log && { echo "FAIL: lcm-spy threw"; exit 1; }
echo ok
