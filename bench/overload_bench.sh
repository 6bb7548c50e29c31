#!/usr/bin/env bash
# Overload (issue 22): replay a cached scene faster than the pipeline can follow, in the real-time policy
# (`run --rate R`: frames are dropped oldest first when the tracker falls behind, IMU never is), at each
# RATE, REPS times, and rate 0 (lossless) once as the reference. Reports, per rate, from summary.json:
# frames in / dropped / estimated, IMU samples received of those in the log and the IMU queue's drops,
# resets, tracking share, peak RSS and ATE. Writes bench/results/overload_<scene>.md.
# Usage: bench/overload_bench.sh [SCENE_DIR] [REPS] [RATE ...]   (default: bench/cache/high-20s 3 1 2 5 10)
set -euo pipefail
args="$*"
cd "$(dirname "$0")/.."
scene=$(readlink -f "${1:-bench/cache/high-20s}") reps=${2:-3}
shift $(( $# > 2 ? 2 : $# ))
rates=("$@")
[ ${#rates[@]} -eq 0 ] && rates=(1 2 5 10)
bin=$(readlink -f "${DYNAVINS:-build/bin/dynavins}")
out=$(readlink -f bench/results)/overload_$(basename "$scene").md
[ -d "$scene/euroc" ] || { echo "no $scene/euroc (scripts/cached-sim.sh high --euroc --duration 20 with CACHE_AS=high-20s)"; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
config=$scene/euroc/vins_config.yaml
imu_in=$(($(grep -vc '^#' "$scene/euroc/mav0/imu0/data.csv")))

run() {  # rate rep
  "$bin" run --config "$config" --euroc "$scene/euroc" --rate "$1" --loop off --out "$tmp/r$1-$2" > "$tmp/r$1-$2.log" 2>&1 \
    || { echo "run at rate $1 failed: $tmp/r$1-$2.log"; cat "$tmp/r$1-$2.log"; exit 1; }
}
row() {  # rate rep
  python3 - "$tmp/r$1-$2/summary.json" "$1" "$imu_in" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); rate = sys.argv[2]; imu_in = int(sys.argv[3])
q = {x["name"]: x for x in s["pipeline"]["queues"]}
track = 100.0 * s["frames_tracking"] / max(1, s["frames_estimated"])
ate = s.get("ate_se3_m")
print(f"| {rate} | {s['wall_s']:.1f} | {s['frames_in']} | {s['frames_dropped']} | {s['frames_estimated']} | "
      f"{s['imu_samples']} / {imu_in} | {q['imu']['dropped']} | {s['resets']} | {track:.0f} % | "
      f"{s['peak_rss_mb']:.0f} | {ate if ate is None else f'{ate:.3f}'} |")
PY
}

{
  echo "# Overload: replay faster than real time (real-time policy)"
  echo
  echo "\`bench/overload_bench.sh $args\` on \`$(basename "$scene")\` ($(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start), $(date -u +%F)."
  echo "Rate 0 is the lossless reference (every frame processed, as fast as possible). Loop closure off."
  echo
  echo "| rate | wall s | frames in | dropped | estimated | IMU samples in / in log | IMU queue drops | resets | tracking | peak RSS MB | ATE m |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
  run 0 1; row 0 1
  for r in "${rates[@]}"; do
    for i in $(seq "$reps"); do run "$r" "$i"; row "$r" "$i"; done
  done
} | tee "$out"
echo "overload: $out"
