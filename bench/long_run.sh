#!/usr/bin/env bash
# Long run (issue 22; issue 21's scene "for scale"): the `long_run` scene (30 minutes of laps with a
# revisit every lap, a parked truck moved every 4 minutes, cars passing and crossing) replayed at rate 0
# with everything on: stereo, the dynavins BA, loop closure (--loop, default dynavins) and every LCM
# output, recorded to a file through LCM's file:// provider. While it runs, the process's resident memory is sampled every 2 s
# from /proc; afterwards `dynavins decode` turns the recorded stats reports (one a second) into per-stage
# latency over time, and bench/report/long_run_report.py plots memory and latency over time, fits the
# memory growth per keyframe and writes the report.
# Writes bench/results/long_run[-loopMODE][-Ss]/: REPORT.md, long_run.png, summary.json, rss.csv,
# stats.csv.gz, queues.csv.gz, loops.csv.gz, decode.txt.
# Usage: bench/long_run.sh [--duration S] [--loop MODE] [--max-wall-min M] [--without-ground-truth]
#   --duration S      a shorter cut of the same scene (rendered and cached apart), as a quick check
#   --loop MODE       loop closure mode (default dynavins; off: the odometry pipeline alone)
#   --max-wall-min M  stop the run with SIGINT after M minutes of wall time: the report then covers the
#                     data processed until then and says so (summary.json: interrupted: true)
#   --without-ground-truth  replay a copy of the log without its GROUND_TRUTH channel (written to a temporary
#                     folder: 15.5 GB for the whole scene), so the memory is the pipeline's alone (a run keeps
#                     every ground-truth state it reads, for its final ATE); the ATE is still computed after
#                     the run, from the cached groundtruth.tum. Results go to ...-nogt.
# Cost: rendering the scene takes 35-50 min of this 2-core machine (cached in bench/cache/long_run, 15.5 GB);
# the run with --loop off about 10 min, with loop closure about 15 min (README "Long run").
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(readlink -f "${DYNAVINS:-build/bin/dynavins}")
duration= loop=dynavins max_wall_min= without_gt=
while [ $# -gt 0 ]; do
  case $1 in
    --duration) duration=$2; shift 2 ;;
    --loop) loop=$2; shift 2 ;;
    --max-wall-min) max_wall_min=$2; shift 2 ;;
    --without-ground-truth) without_gt=1; shift ;;
    *) echo "usage: bench/long_run.sh [--duration S] [--loop MODE] [--max-wall-min M] [--without-ground-truth]" >&2; exit 2 ;;
  esac
done

name=long_run sim_args=()
if [ -n "$duration" ]; then name=long_run-${duration}s sim_args=(--duration "$duration"); fi
DYNAVINS=$bin CACHE_AS=$name scripts/cached-sim.sh long_run "${sim_args[@]}"
scene=bench/cache/$name
out=bench/results/long_run${loop:+-loop$loop}${duration:+-${duration}s}${without_gt:+-nogt}
[ "$loop" = dynavins ] && out=bench/results/long_run${duration:+-${duration}s}${without_gt:+-nogt}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The scene's calibration: the simulator writes its VINS-Fusion config with --euroc; half a second of the
# same scenario gives it without a second copy of 30 minutes of images.
"$bin" sim --scenario long_run --duration 0.5 --euroc --out "$tmp/calib" > "$tmp/calib.log" 2>&1 ||
  { cat "$tmp/calib.log"; exit 1; }

log=$scene/sensors.lcmlog
if [ -n "$without_gt" ]; then
  /usr/bin/python3 bench/report/drop_channel.py "$log" "$tmp/sensors.lcmlog" GROUND_TRUTH
  log=$tmp/sensors.lcmlog
fi
"$bin" run --config "$tmp/calib/euroc/vins_config.yaml" --log "$log" --rate 0 --ba dynavins \
  --loop "$loop" --lcm-url "file://$tmp/outputs.lcmlog?mode=w" --out "$tmp/run" > "$tmp/run.log" 2>&1 &
pid=$!
start=$(date +%s.%N)
echo "wall_s,rss_kb" > "$tmp/rss.csv"
while kill -0 $pid 2>/dev/null; do
  rss=$(awk '/^VmRSS:/ {print $2}' /proc/$pid/status 2>/dev/null || true)
  if [ -n "$max_wall_min" ] && [ ! -e "$tmp/stopped" ] &&
     awk -v s="$start" -v n="$(date +%s.%N)" -v m="$max_wall_min" 'BEGIN {exit !(n - s > 60 * m)}'; then
    kill -INT $pid; touch "$tmp/stopped"
  fi
  [ -n "$rss" ] && awk -v s="$start" -v n="$(date +%s.%N)" -v r="$rss" 'BEGIN {printf "%.1f,%s\n", n - s, r}' >> "$tmp/rss.csv"
  sleep 2
done
rc=0; wait $pid || rc=$?
tail -12 "$tmp/run.log"
if [ $rc -ne 0 ] && ! { [ -e "$tmp/stopped" ] && grep -q '"interrupted": true' "$tmp/run/summary.json"; }; then
  echo "long_run: dynavins run exited $rc" >&2; exit 1
fi

"$bin" decode --log "$tmp/outputs.lcmlog" --out "$tmp/decoded" > "$tmp/decode.txt" ||
  { cat "$tmp/decode.txt"; echo "long_run: decode found problems in the LCM outputs" >&2; exit 1; }
for est in odometry trajectory; do  # an ATE that cannot be computed (e.g. a straight-line cut) is reported as such
  "$bin" eval --gt "$scene/groundtruth.tum" --est "$tmp/run/$est.tum" --json "$tmp/ate_$est.json" > /dev/null 2>&1 ||
    echo '{"ate": {"rmse": null}}' > "$tmp/ate_$est.json"
done

mkdir -p "$out"
cp "$tmp/run/summary.json" "$tmp/rss.csv" "$tmp/decode.txt" "$out/"
gzip -9 -c "$tmp/decoded/stats.csv" > "$out/stats.csv.gz"
gzip -9 -c "$tmp/decoded/queues.csv" > "$out/queues.csv.gz"
[ ! -f "$tmp/run/loops.csv" ] || gzip -9 -c "$tmp/run/loops.csv" > "$out/loops.csv.gz"
/usr/bin/python3 bench/report/long_run_report.py --dir "$out" --ate-odometry "$tmp/ate_odometry.json" \
  --ate-trajectory "$tmp/ate_trajectory.json" --loop "$loop" \
  --command "bench/long_run.sh${duration:+ --duration $duration} --loop $loop${max_wall_min:+ --max-wall-min $max_wall_min}${without_gt:+ --without-ground-truth}"
echo "long_run: wrote $out/REPORT.md and $out/long_run.png"
