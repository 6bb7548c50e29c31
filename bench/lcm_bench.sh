#!/usr/bin/env bash
# What publishing on LCM costs, and how fast poses come out (issue: LCM interface). Inside a private
# network namespace (udpm, ttl=0, nothing leaves the machine), on a cached scene (default high-20s):
#  1. rate 0, without and with --lcm-url (lcm-logger subscribed), alternated REPS times: wall time ratio;
#  2. latency from an input's arrival to its pose being published (IMU-rate and window pose), from
#     summary.json (mean, p99);
#  3. `live` at 1x, fed by lcm-logplayer, REPS times with the default real-time scheduling of the light
#     threads (--rt-priority 10) and without it (0), alternated: frames dropped, IMU samples received,
#     resets, IMU-pose latency.
# Writes bench/results/lcm.md. Usage: bench/lcm_bench.sh [SCENE_DIR] [REPS]
set -euo pipefail
cd "$(dirname "$0")/.."
scene=$(readlink -f "${1:-bench/cache/high-20s}") reps=${2:-3}
bin=$(readlink -f "${DYNAVINS:-build/bin/dynavins}")
out=$(readlink -f bench/results)/lcm.md
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
[ -f "$scene/sensors.lcmlog" ] || { echo "no $scene/sensors.lcmlog (scripts/cached-sim.sh high --euroc --duration 20 with CACHE_AS=high-20s)"; exit 2; }
cd "$tmp"
unshare -n bash -s "$bin" "$scene" "$reps" <<'NS'
set -euo pipefail
bin=$1 scene=$2 reps=$3
ip link set lo up
ip route add 224.0.0.0/4 dev lo
url='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
config=$scene/euroc/vins_config.yaml
for i in $(seq "$reps"); do
  "$bin" run --config "$config" --log "$scene/sensors.lcmlog" --out "plain-$i" > /dev/null 2>&1
  lcm-logger --lcm-url="$url" -q "rec-$i.lcm" & logger=$!
  sleep 0.5
  "$bin" run --config "$config" --log "$scene/sensors.lcmlog" --lcm-url "$url" --out "lcm-$i" > /dev/null 2>&1
  kill -INT $logger; wait $logger || true
done
for i in $(seq "$reps"); do
  for rt in 10 0; do
    "$bin" live --config "$config" --lcm-url "$url" --rt-priority $rt --out "live-rt$rt-$i" > "live-rt$rt-$i.log" 2>&1 & live=$!
    sleep 1.5
    lcm-logplayer --lcm-url="$url" "$scene/sensors.lcmlog" > /dev/null
    sleep 1.5
    kill -INT $live; wait $live
  done
done
NS
/usr/bin/python3 - "$reps" "$scene" "$out" <<'PY'
import json, os, statistics, sys
reps, scene, out = int(sys.argv[1]), sys.argv[2], sys.argv[3]
load = lambda p: json.load(open(p))
plain = [load(f"plain-{i}/summary.json") for i in range(1, reps + 1)]
lcm = [load(f"lcm-{i}/summary.json") for i in range(1, reps + 1)]
live = {rt: [load(f"live-rt{rt}-{i}/summary.json") for i in range(1, reps + 1)] for rt in (10, 0)}
wp, wl = [s["wall_s"] for s in plain], [s["wall_s"] for s in lcm]
ratio = statistics.median(wl) / statistics.median(wp)
lat = lambda s, k: s["lcm"][k]
rows = [
    "# Publishing on LCM: cost and latency",
    "",
    f"Scene `{scene}`, {reps} alternated runs each, rate 0 (as fast as possible), stereo, dynavins BA;",
    "udpm with ttl=0 in a private network namespace, lcm-logger subscribed. `bench/lcm_bench.sh`.",
    "",
    "| | wall time [s] (median) | real-time factor | ATE SE3 [m] |",
    "|---|---|---|---|",
    f"| no `--lcm-url` | {statistics.median(wp):.2f} ({', '.join(f'{x:.2f}' for x in wp)}) | {statistics.median(s['real_time_factor'] for s in plain):.2f} | {plain[0].get('ate_se3_m', float('nan')):.4f} |",
    f"| `--lcm-url` | {statistics.median(wl):.2f} ({', '.join(f'{x:.2f}' for x in wl)}) | {statistics.median(s['real_time_factor'] for s in lcm):.2f} | {lcm[0].get('ate_se3_m', float('nan')):.4f} |",
    "",
    f"Publishing costs {100 * (ratio - 1):+.1f} % of the rate-0 replay's wall time (ratio {ratio:.3f}; goal < 5 %).",
    "",
    "| latency, input arrival -> published [ms] | mean | p99 | max |",
    "|---|---|---|---|",
]
for k, label in [("imu_pose_latency_ms", "IMU-rate pose"), ("window_pose_latency_ms", "window pose (frame -> pose)")]:
    l = lcm[0]["lcm"][k]
    rows.append(f"| rate 0 run: {label} | {l['mean']:.3f} | {l['p99']:.3f} | {l['max']:.3f} |")
for rt, runs in live.items():
    for i, s in enumerate(runs, 1):
        for k, label in [("imu_pose_latency_ms", "IMU-rate pose"), ("window_pose_latency_ms", "window pose")]:
            l = s["lcm"][k]
            rows.append(f"| live at 1x, --rt-priority {rt}, run {i}: {label} | {l['mean']:.3f} | {l['p99']:.3f} | {l['max']:.3f} |")
rows += ["", "| `live` at 1x | frames in | dropped | IMU samples | resets | tracking | publish dropped | real-time threads | ATE SE3 [m] |",
         "|---|---|---|---|---|---|---|---|---|"]
for rt, runs in live.items():
    for i, s in enumerate(runs, 1):
        rows.append(f"| --rt-priority {rt}, run {i} | {s['frames_in']} | {s['frames_dropped']} | {s['imu_samples']} | {s['resets']} | "
                    f"{s['frames_tracking']} | {s['lcm']['dropped']} | {s.get('realtime_threads', 0)} | {s.get('ate_se3_m', float('nan')):.4f} |")
rows += [
    "",
    "The IMU-rate latency is measured from the moment the IMU stage takes the sample (its wait in the IMU",
    "queue is in the stage's wait statistics); the window-pose latency from the moment the tracker takes the frame.",
    f"Load on the machine while this ran (1-min load average at the end): {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores.",
]
open(out, "w").write("\n".join(rows) + "\n")
print("\n".join(rows))
PY
