#!/usr/bin/env bash
# End to end over real UDP multicast, inside a private network namespace (nothing leaves the machine):
#  1. `dynavins live` on a simulated scene that lcm-logplayer plays onto udpm, ended by SIGINT;
#  2. `dynavins run --rate 1 --lcm-url` on the same scene.
# lcm-logger records the outputs each time; `dynavins decode` checks that every message decodes, poses
# are finite, weights lie in [0, 1]; the window poses are scored against the simulator's ground truth;
# the IMU-rate pose must arrive at IMU rate (200 Hz) and stats and status must be present.
# Usage: test_lcm_live.sh DYNAVINS SCENARIO.yaml
set -euo pipefail
bin=$(readlink -f "$1") scenario=$(readlink -f "$2")
if [ "$(id -u)" -ne 0 ] && ! unshare -rn true 2>/dev/null; then
  echo "SKIP: needs root or unprivileged user namespaces for unshare -n"; exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
"$bin" sim --scenario "$scenario" --duration 9 --euroc --out scene > sim.log 2>&1 || { cat sim.log; exit 1; }

# ATE bound: the same 0.10 m as the estimator's truck-crossing test allows, on the first 9 s of that scene (the first 6 s are a straight line, where no alignment is defined).
ate_bound=0.10
check_outputs() {  # recording, label
  "$bin" decode --log "$1" --out "dec-$2" | tee "decode-$2.txt"
  # log-info names the type of every DynaVINS channel (status_t was missing once); LCM_SELF_TEST is
  # the udpm provider's own message.
  "$bin" log-info "$1" > "info-$2.txt" || { cat "info-$2.txt"; echo "FAIL ($2): log-info"; exit 1; }
  if grep -v '^LCM_SELF_TEST ' "info-$2.txt" | grep -q "not a dynavins_lcm type"; then
    cat "info-$2.txt"; echo "FAIL ($2): log-info: unknown type"; exit 1
  fi
  rate=$(awk '$2 == "pose_imu" {print $4}' "decode-$2.txt")
  python3 - "$rate" <<'PY' || { echo "FAIL ($2): IMU-rate pose at $rate Hz, expected 200"; exit 1; }
import sys; r = float(sys.argv[1]); sys.exit(0 if 190 <= r <= 210 else 1)
PY
  for key in pose features status stats; do
    n=$(awk -v k=$key '$2 == k {print $3}' "decode-$2.txt")
    [ "${n:-0}" -gt 0 ] || { echo "FAIL ($2): no $key messages"; exit 1; }
  done
  # decode --out writes the stats over time: one row per stage (and per queue) per report
  for f in stats queues; do
    [ "$(wc -l < "dec-$2/$f.csv")" -gt 2 ] || { echo "FAIL ($2): dec-$2/$f.csv has no rows"; exit 1; }
  done
  grep -q ',estimator,' "dec-$2/stats.csv" || { head -3 "dec-$2/stats.csv"; echo "FAIL ($2): no estimator row in stats.csv"; exit 1; }
  "$bin" eval --gt scene/groundtruth.tum --est "dec-$2/pose.tum" --json "ate-$2.json" > /dev/null
  python3 - "ate-$2.json" "$ate_bound" <<'PY' || { echo "FAIL ($2): ATE above bound"; exit 1; }
import json, sys
ate = json.load(open(sys.argv[1]))["ate"]["rmse"]
print(f"ATE of the published window poses: {ate:.4f} m (bound {sys.argv[2]} m)")
sys.exit(0 if ate < float(sys.argv[2]) else 1)
PY
}

# Inside the namespace: loopback up, multicast routed to it, ttl=0 on every URL.
unshare -n bash -s "$bin" <<'NS'
set -euo pipefail
bin=$1
ip link set lo up
ip route add 224.0.0.0/4 dev lo
url='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
config=scene/euroc/vins_config.yaml

lcm-logger --lcm-url="$url" -q out-live.lcm & logger=$!
"$bin" live --config "$config" --lcm-url "$url" --out live > live.log 2>&1 & live=$!
sleep 1.5  # both subscribed
lcm-logplayer --lcm-url="$url" scene/sensors.lcmlog > /dev/null
sleep 1.5  # the last frames drain
kill -INT $live
rc=0; wait $live || rc=$?
kill -INT $logger; wait $logger || true
cat live.log | tail -12
[ "$rc" -eq 0 ] || { echo "FAIL: live exited $rc"; exit 1; }

lcm-logger --lcm-url="$url" -q out-run.lcm & logger=$!
sleep 1
"$bin" run --config "$config" --log scene/sensors.lcmlog --rate 1 --lcm-url "$url" --out run > run.log 2>&1 ||
  { cat run.log; echo "FAIL: run --rate 1 --lcm-url"; exit 1; }
sleep 0.5
kill -INT $logger; wait $logger || true
tail -4 run.log
NS

grep -q '"lcm": {"url"' live/summary.json || { echo "FAIL: live/summary.json has no lcm section"; exit 1; }
# Every frame that arrived is either tracked or counted as dropped (real time drops the oldest when the
# tracker falls behind); at least 80 % are estimated on a machine that is not overloaded.
# DYNAVINS_LIVE_MIN_ESTIMATED lowers that floor for builds too slow for real time (AddressSanitizer: about
# 2-3x slower, so the real-time policy drops more; what that pass checks is memory, not throughput).
python3 - "${DYNAVINS_LIVE_MIN_ESTIMATED:-145}" <<'PY' || exit 1
import json, sys
min_estimated = int(sys.argv[1])
s = json.load(open("live/summary.json"))
print(f"live: {s['frames_in']} frames in, {s['frames_tracked']} tracked, {s['frames_dropped']} dropped, "
      f"{s['frames_estimated']} estimated, real-time threads {s.get('realtime_threads')}")
if s["frames_tracked"] + s["frames_dropped"] != s["frames_in"]:
    sys.exit("FAIL: frames in != tracked + dropped")
if s["frames_estimated"] < min_estimated:
    sys.exit(f"FAIL: live estimated {s['frames_estimated']} of 181 frames, need {min_estimated} "
             "(UDP loss? check net.core.rmem_max)")
PY
check_outputs out-live.lcm live
check_outputs out-run.lcm run
echo ok
