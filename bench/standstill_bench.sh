#!/usr/bin/env bash
# A minute at rest (issue 22, estimator faults): the `standstill_minute` scene (a car stops 60 s at a
# corner, then drives on) in stereo and mono with both BA losses, rate 0. Per run: resets, frames held
# at rest by the zero-velocity factor, how far the estimate wandered while the car stood
# (bench/report/standstill_drift.py), the largest step between consecutive poses, ATE.
# Writes bench/results/standstill_minute.md. Usage: bench/standstill_bench.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(readlink -f "${DYNAVINS:-build/bin/dynavins}")
DYNAVINS=$bin scripts/cached-sim.sh standstill_minute --euroc > /dev/null
scene=bench/cache/standstill_minute
out=bench/results/standstill_minute.md
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
{
  echo "# A minute at rest: \`standstill_minute\`"
  echo
  echo "\`bench/standstill_bench.sh\`, $(date -u +%F), rate 0, loop closure off. Wander: how far the estimated"
  echo "position moved while the true one stood (max; and at the end of the stop). Largest step: between two"
  echo "consecutive estimated poses over the whole run (at 3 m/s a frame is 150 mm)."
  echo
  echo "| mode | BA | frames tracking | resets | frames held at rest | standstill | wander max | wander at end | largest step | ATE m |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
  for mode in stereo mono; do
    for ba in dynavins huber; do
      extra=(); [ $mode = mono ] && extra=(--mono)
      "$bin" run --euroc $scene/euroc --config $scene/euroc/vins_config.yaml --ba $ba --loop off "${extra[@]}" \
        --out "$tmp/$mode-$ba" > "$tmp/$mode-$ba.log" 2>&1 || { cat "$tmp/$mode-$ba.log"; exit 1; }
      s=$tmp/$mode-$ba/summary.json
      stats=$(python3 -c "import json,sys; s=json.load(open('$s')); print(f\"{s['frames_tracking']} / {s['frames_in']} | {s['resets']} | {s['standstill_frames']}\")")
      drift=$(/usr/bin/python3 bench/report/standstill_drift.py $scene/groundtruth.tum "$tmp/$mode-$ba/odometry.tum")
      ate=$(python3 -c "import json; print(f\"{json.load(open('$s'))['ate_se3_m']:.4f}\")")
      echo "| $mode | $ba | $stats | $drift | $ate |"
    done
  done
} | tee "$out"
