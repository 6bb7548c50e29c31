#!/usr/bin/env bash
# Every loop mode (off, all, switchable, dynavins) on one cached scene: ATE of odometry.tum and of
# trajectory.tum, verified loops true/false against ground truth, optimisations, loop ms per keyframe.
# Usage: bench/loop_modes.sh SCENE [OUT_DIR]   (the scene from scripts/cached-sim.sh SCENE --euroc)
set -euo pipefail
cd "$(dirname "$0")/.."
scene=$1 out=${2:-runs/loop-modes}
bin=${DYNAVINS:-build/bin/dynavins}
[ -f "bench/cache/$scene/euroc/vins_config.yaml" ] || DYNAVINS=$bin scripts/cached-sim.sh "$scene" --euroc
printf '%-16s %-10s %8s %8s %6s %5s %5s %5s %8s %7s\n' scene mode odo_ate traj_ate loops true false opt kf_ms wall_s
for m in off all switchable dynavins; do
  d=$out/$scene-$m
  "$bin" run --config "bench/cache/$scene/euroc/vins_config.yaml" --log "bench/cache/$scene/sensors.lcmlog" \
      --loop $m --out "$d" > "$d.log" 2>&1 || { tail -3 "$d.log"; exit 1; }
  /usr/bin/python3 - "$d/summary.json" "$scene" "$m" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); l = s.get("loop", {})
g = lambda k: l.get(k, "-")
print(f"{sys.argv[2]:16s} {sys.argv[3]:10s} {s.get('ate_se3_m', float('nan')):8.3f} "
      f"{s.get('trajectory_ate_se3_m', s.get('ate_se3_m', float('nan'))):8.3f} {g('loops')!s:>6} {g('true_loops')!s:>5} "
      f"{g('false_loops')!s:>5} {g('optimizations')!s:>5} {l.get('keyframe_ms_mean', 0):8.1f} {s['wall_s']:7.1f}")
PY
done
