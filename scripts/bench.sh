#!/usr/bin/env bash
# The benchmark suite (issue 6): generates the scenarios once (scripts/cached-sim.sh), runs the
# estimator on each in every mode that matters, then writes the report (bench/report/make_report.py).
# Usage: scripts/bench.sh [--quick | --loop-only] [--out DIR]
#   full  (make bench):       every scenario of bench/scenarios at full length (40-85 s), and `none`
#                             and `high` again at noise seeds 12 to 17 -> bench/results/
#   quick (make bench-quick): `none` and `high` cut to 20 s (cached as NAME-20s) -> bench/results/quick/
#   loop-only:                only the loop-closure scenes, DynaVINS BA, their loop-mode runs, mono on
#                             the scenes with genuine revisits only, no --loop off run (18 runs)
#                             -> bench/results/loop/
# Loop scenes (loop_scenes below) also run with --loop all and --loop switchable (DynaVINS BA; stereo
# and mono), beside the plain runs, which are
# --loop dynavins and whose odometry.tum is --loop off's; and one --loop off run (e_shape stereo) for
# the estimator's speed without the loop thread.
# Every run: `dynavins run --rate 0` (lossless replay; at rate 0 the solves are bounded by iterations
# only), so accuracy does not depend on machine load. A failed run is recorded as failed
# (manifest + report) and the bench goes on; it exits 1 at the end when a scene or run crashed.
# Only the full bench rewrites the README headline.
# DYNAVINS=path/to/dynavins (default build/bin/dynavins); BENCH_TRACKER=path/to/bench_tracker
# (default build/bin/bench_tracker; skipped when missing; bench_track_accuracy is taken from beside it);
# PYTHON (default /usr/bin/python3).
set -euo pipefail
cd "$(dirname "$0")/.."

quick=0
out=""
while [ $# -gt 0 ]; do
  case $1 in
    --quick) quick=1 ;;
    --out) out=$2; shift ;;
    --loop-only) quick=2 ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) echo "bench: unknown argument $1" >&2; exit 2 ;;
  esac
  shift
done

bin=${DYNAVINS:-build/bin/dynavins}
tracker_bin=${BENCH_TRACKER:-build/bin/bench_tracker}
accuracy_bin=$(dirname "$tracker_bin")/bench_track_accuracy
accuracy_scenes=(none high street_none street_crowd_night street_follow)  # at their own seeds, first 12 s
python=${PYTHON:-/usr/bin/python3}
[ -x "$bin" ] || { echo "bench: $bin not found (make build first)" >&2; exit 1; }

loop_scenes=(temporal_static e_shape revisit temporal_revisit)
bas=(huber dynavins)
if [ "$quick" = 1 ]; then
  scenarios=(none high)
  sim_args=(--duration 20)
  suffix=-20s
  out=${out:-bench/results/quick}
  extra_seeds=()
elif [ "$quick" = 2 ]; then
  scenarios=(e_shape revisit temporal_static temporal_revisit)
  bas=(dynavins)  # the loop table compares loop modes over the DynaVINS odometry
  sim_args=()
  suffix=""
  out=${out:-bench/results/loop}
  extra_seeds=()
else
  scenarios=(none low mid high night mav_none mav_high standstill_none standstill_high dynamic_follow temporal_static e_shape revisit temporal_revisit
             street_none street_crowd street_crowd_night street_jam street_rush street_follow_none street_follow
             street_turns_none street_turns)
  sim_args=()
  suffix=""
  out=${out:-bench/results}
  extra_seeds=(12 13 14 15 16 17)  # besides each scenario file's own seed (11)
fi
ablation_scene=high
overlay_scene=high

mkdir -p "$out"
rm -rf "$out/runs"
mkdir -p "$out/runs"
manifest=$out/manifest.tsv
meta=$out/meta.tsv

# --- what was run, where, on what -------------------------------------------------------------
commit=$(git rev-parse HEAD 2>/dev/null || echo unknown)
dirty=clean
[ -n "$(git status --porcelain --untracked-files=no 2>/dev/null)" ] && dirty=dirty
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
ram_gb=$(awk '/MemTotal/ {printf "%.1f", $2/1048576}' /proc/meminfo)
{
  printf 'mode\t%s\n' "$(case $quick in 1) echo quick ;; 2) echo loop ;; *) echo full ;; esac)"
  printf 'commit\t%s\n' "$commit"
  printf 'dirty\t%s\n' "$dirty"
  printf 'date\t%s\n' "$(date -u +%Y-%m-%dT%H:%M:%SZ)"
  printf 'nproc\t%s\n' "$(nproc)"
  printf 'cpu\t%s\n' "$cpu"
  printf 'ram_gb\t%s\n' "$ram_gb"
  printf 'binary\t%s\n' "$bin"
  printf 'bench_command\t%s\n' "scripts/bench.sh$(case $quick in 1) echo ' --quick' ;; 2) echo ' --loop-only' ;; esac) --out $out"
  printf 'sim_args\t%s\n' "${sim_args[*]:-}"
} > "$meta"
printf 'kind\tscenario\tmode\tba\tvariant\tstatus\twall_s\tdir\tcommand\n' > "$manifest"

# --- progress ---------------------------------------------------------------------------------
runs_per_scene=$((2 * ${#bas[@]}))
loop_sensors=(stereo mono)
# --loop-only keeps to the runs the loop table needs most: mono (odometry that drifts) only where
# there are genuine revisits to correct it
loop_sensors_of() {
  if [ "$quick" = 2 ] && [ "$1" != revisit ] && [ "$1" != temporal_revisit ]; then echo stereo; else echo "${loop_sensors[@]}"; fi
}
is_loop_scene() { local s; for s in "${loop_scenes[@]}"; do [ "$s" = "$1" ] && return 0; done; return 1; }
n_loop=0
for sc in "${scenarios[@]}"; do
  if is_loop_scene "$sc"; then for m in $(loop_sensors_of "$sc"); do n_loop=$((n_loop + 2)); done; fi
done
total=$(( (${#scenarios[@]} + 2 * ${#extra_seeds[@]}) * (1 + runs_per_scene) + n_loop ))  # scenes x (generate + runs), loop modes
[ "$quick" = 2 ] && total=$(( ${#scenarios[@]} + n_loop / 2 + n_loop ))  # generate, one plain run per sensor, loop modes
[ "$quick" != 2 ] && for sc in "${scenarios[@]}"; do [ "$sc" = e_shape ] && total=$((total + 1)); done  # --loop off
[ "$quick" != 2 ] && total=$((total + 2))  # ablation, overlay
[ -x "$tracker_bin" ] && [ "$quick" != 2 ] && total=$((total + 1))
[ -x "$accuracy_bin" ] && [ "$quick" != 2 ] && total=$((total + ${#accuracy_scenes[@]}))
step=0
bench_start=$(date +%s)

# record KIND SCENARIO MODE BA VARIANT STATUS WALL DIR COMMAND
record() { local IFS=$'\t'; echo "$*" >> "$manifest"; }

# timed LABEL LOGFILE CMD...: runs CMD with output to LOGFILE, prints a progress line, sets $status
# (ok, cached: a scene reused by cached-sim.sh, exitN) and $wall
timed() {
  local label=$1 log=$2; shift 2
  step=$((step + 1))
  printf '[%d/%d] %s ... ' "$step" "$total" "$label"
  local t0; t0=$(date +%s.%N)
  if "$@" > "$log" 2>&1; then status=ok; else status="exit$?"; fi
  [ "$status" = ok ] && grep -q 'cached-sim: .* is up to date' "$log" && status=cached
  wall=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN {printf "%.1f", b - a}')
  printf '%s s (%s)\n' "$wall" "$status"
}

# run_one SCENARIO MODE BA [VARIANT --set k=v ...]; the scene comes from bench/cache/$scene_cache
run_one() {
  local sc=$1 mode=$2 ba=$3; shift 3
  local variant=${1:-}; [ $# -gt 0 ] && shift
  local data=bench/cache/$scene_cache/euroc
  local dir=$out/runs/$sc/$mode-$ba${variant:+-$variant}
  local cmd=("$bin" run --config "$data/vins_config.yaml" --euroc "$data" --ba "$ba" --rate 0
             "$@" --out "$dir")
  [ "$mode" = mono ] && cmd+=(--mono)
  mkdir -p "$dir"
  timed "$sc $mode $ba${variant:+ ($variant)}" "$dir/run.log" timeout 1800 "${cmd[@]}"
  record run "$sc" "$mode" "$ba" "${variant:--}" "$status" "$wall" "$dir" "${cmd[*]}"
}

# not_run SCENARIO MODE BA VARIANT: a run whose scene could not be generated (recorded, never dropped)
not_run() {
  step=$((step + 1))
  record run "$1" "$2" "$3" "${4:--}" "no-data" 0 "$out/runs/$1/$2-$3${4:+-$4}" "(scene not generated)"
}

# scene_runs SCENARIO VARIANT [SIM_ARGS...]: generates the scene into bench/cache/$scene_cache (once),
# then runs it in the four configurations (as VARIANT); returns 1, with the runs recorded as not run,
# when the scene could not be generated.
scene_runs() {
  local sc=$1 variant=$2 mode ba generated=1; shift 2
  local log=$out/runs/generate-$sc${variant:+-$variant}.log
  local gen=(env CACHE_AS="$scene_cache" DYNAVINS="$bin" scripts/cached-sim.sh "$sc" "$@" --euroc)
  timed "generate $scene_cache" "$log" "${gen[@]}"
  record generate "$sc" - - "${variant:--}" "$status" "$wall" "bench/cache/$scene_cache" "${gen[*]}"
  if [ "$status" != ok ] && [ "$status" != cached ]; then
    echo "bench: generating $scene_cache failed (see $log); its runs are recorded as failed" >&2
    generated=0
  fi
  for mode in $([ "$quick" = 2 ] && loop_sensors_of "$sc" || echo stereo mono); do
    for ba in "${bas[@]}"; do
      if [ "$generated" = 1 ]; then run_one "$sc" "$mode" "$ba" "$variant"; else not_run "$sc" "$mode" "$ba" "$variant"; fi
    done
  done
  [ "$generated" = 1 ]
}

loop_speed_scene=e_shape
for sc in "${scenarios[@]}"; do
  scene_cache=$sc$suffix
  if scene_runs "$sc" "" "${sim_args[@]}"; then
    # Table I: regularisation only (the paper's λm = 0 ablation)
    [ "$sc" = "$ablation_scene" ] && run_one "$sc" stereo dynavins nomomentum --set momentum_on=0
    # Loop closure (paper IV): the baselines' trajectory.tum beside the plain run's (--loop dynavins)
    if is_loop_scene "$sc"; then
      for mode in $(loop_sensors_of "$sc"); do
        for lm in all switchable; do run_one "$sc" "$mode" dynavins "loop$lm" --loop "$lm"; done
      done
      [ "$sc" = "$loop_speed_scene" ] && [ "$quick" != 2 ] && run_one "$sc" stereo dynavins loopoff --loop off
    fi
  else
    [ "$sc" = "$ablation_scene" ] && not_run "$sc" stereo dynavins nomomentum
    if is_loop_scene "$sc"; then
      for mode in $(loop_sensors_of "$sc"); do
        for lm in all switchable; do not_run "$sc" "$mode" dynavins "loop$lm"; done
      done
      [ "$sc" = "$loop_speed_scene" ] && [ "$quick" != 2 ] && not_run "$sc" stereo dynavins loopoff
    fi
  fi
done

# --- the degradation pair at other noise seeds -----------------------------------------------
# One seed's ATE moves by tens of percent with any small change (IMU and image noise draw, a
# parameter nudged), so Table III is also given over the scenario seed and these extra draws.
for seed in "${extra_seeds[@]}"; do
  for sc in none high; do
    scene_cache=$sc$suffix-s$seed
    scene_runs "$sc" "seed$seed" "${sim_args[@]}" --seed "$seed" || true
  done
done
unset scene_cache

# --- a feature-weight overlay from the DynaVINS stereo run on `high` ---------------------------
if [ "$quick" != 2 ]; then
ov=("$bin" overlay --euroc "bench/cache/$overlay_scene$suffix/euroc"
    --features "$out/runs/$overlay_scene/stereo-dynavins/features.csv" --frames 2 --scale 0.6
    --out "$out/overlay_$overlay_scene.png")
timed "overlay $overlay_scene" "$out/runs/overlay.log" "${ov[@]}"
record overlay "$overlay_scene" stereo dynavins - "$status" "$wall" "$out/overlay_$overlay_scene.png" "${ov[*]}"

# --- tracker alone on one core (sim + the real EuRoC clip) -------------------------------------
if [ -x "$tracker_bin" ]; then
  timed "bench_tracker" "$out/bench_tracker.txt" "$tracker_bin"
  record bench_tracker - - - - "$status" "$wall" "$out/bench_tracker.txt" "$tracker_bin"
fi
# --- the tracker's pixels against the truth (deterministic) ------------------------------------
if [ -x "$accuracy_bin" ]; then
  : > "$out/track_accuracy.txt"
  for sc in "${accuracy_scenes[@]}"; do
    timed "bench_track_accuracy $sc" "$out/runs/track_accuracy-$sc.log" "$accuracy_bin" --scenario "$sc" --duration 12
    record bench_track_accuracy "$sc" stereo - - "$status" "$wall" "$out/track_accuracy.txt" "$accuracy_bin --scenario $sc --duration 12"
    cat "$out/runs/track_accuracy-$sc.log" >> "$out/track_accuracy.txt"
  done
fi
fi  # not --loop-only

printf 'bench_wall_s\t%s\n' "$(( $(date +%s) - bench_start ))" >> "$meta"

report=("$python" bench/report/make_report.py --results "$out")
[ "$quick" = 0 ] && report+=(--readme README.md)
printf 'report_command\t%s\n' "${report[*]}" >> "$meta"
"${report[@]}"

# Crashes (a scene not generated, a run or the overlay exiting non-zero) fail the bench once the
# report is written; lost or diverged estimates are results, not errors.
crashed=$(awk -F'\t' 'NR > 1 && $6 != "ok" && $6 != "cached"' "$manifest" | wc -l)
if [ "$crashed" -gt 0 ]; then
  echo "bench: $crashed step(s) failed (status column of $manifest); the report shows them" >&2
  exit 1
fi
echo "bench: report in $out/REPORT.md"
