#!/usr/bin/env bash
# One draw is not a measurement (issue 23): an estimator change moves a single run's ATE by tens of
# percent either way. This runs scenes at several noise seeds (same world, path and traffic; other IMU
# and image noise and object textures) with huber and with dynavins under up to three settings, and prints
# each ATE and the mean over the seeds, so a change is judged by its mean, not by one draw.
# Usage: bench/seed_sweep.sh --seeds 21,22,23 [--mono] [--rig viode] [--a "--set k=v ..."] [--b "..."]
#                            [--c "..."] SCENARIO...
#   --a / --b / --c: dynavins run options of up to three settings compared (default: --a "" i.e. the
#              defaults, no --b or --c). Scenes are cached as bench/cache/NAME-seedS (scripts/cached-sim.sh).
#   --rig:     render with another stereo rig (`dynavins sim --rig`; cached as NAME-RIG-seedS).
# Every run is `dynavins run --rate 0 --loop off` (lossless, deterministic). Writes runs to
# bench/results/seed_sweep/ (not kept in git) and the table to stdout.
# Example (the README's "Street scenes" table, seeds 22-24; bench/results/seed_sweep.md has the others):
#   bench/seed_sweep.sh --seeds 22,23,24 --a "--set kept_full_weight=0" --b "--set kept_full_weight=1" \
#     street_none street_crowd street_follow_none street_follow
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(readlink -f "${DYNAVINS:-build/bin/dynavins}")
python=${PYTHON:-/usr/bin/python3}
seeds=""; mono=(); rig=""; a=""; b=""; c=""; have_b=0; have_c=0; scenes=()
while [ $# -gt 0 ]; do
  case $1 in
    --seeds) seeds=$2; shift ;;
    --mono) mono=(--mono) ;;
    --rig) rig=$2; shift ;;
    --a) a=$2; shift ;;
    --b) b=$2; have_b=1; shift ;;
    --c) c=$2; have_c=1; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    -*) echo "seed_sweep: unknown option $1" >&2; exit 2 ;;
    *) scenes+=("$1") ;;
  esac
  shift
done
[ ${#scenes[@]} -gt 0 ] || { echo "seed_sweep: name at least one scenario (bench/scenarios/NAME.yaml)" >&2; exit 2; }
[ -n "$seeds" ] || { echo "seed_sweep: --seeds is required, e.g. --seeds 21,22,23" >&2; exit 2; }
[ -x "$bin" ] || { echo "seed_sweep: $bin not found (make build first)" >&2; exit 1; }
out=bench/results/seed_sweep
mkdir -p "$out"

# run_one SCENE_DIR TAG ARGS...: one run; prints nothing, leaves $out/NAME-TAG/summary.json
run_one() {
  local dir=$1 tag=$2; shift 2
  local name; name=$(basename "$dir")
  local run=$out/$name${mono:+-mono}-$tag
  if ! "$bin" run --config "$dir/euroc/vins_config.yaml" --euroc "$dir/euroc" --rate 0 --loop off \
       --set max_solver_time=1000 "${mono[@]}" --out "$run" "$@" > "$run.log" 2>&1; then
    echo "seed_sweep: run failed, see $run.log" >&2
    return 1
  fi
}

rows=()
for sc in "${scenes[@]}"; do
  for s in ${seeds//,/ }; do
    cache=$sc${rig:+-$rig}-seed$s
    echo "seed_sweep: $sc seed $s${mono:+ (mono)}${rig:+ ($rig rig)}" >&2
    if ! CACHE_AS=$cache DYNAVINS=$bin scripts/cached-sim.sh "$sc" --seed "$s" ${rig:+--rig "$rig"} --euroc \
         > "$out/$cache.sim.log" 2>&1; then
      echo "seed_sweep: could not generate $sc at seed $s, see $out/$cache.sim.log" >&2
      exit 1
    fi
    dir=bench/cache/$cache
    run_one "$dir" huber --ba huber
    # shellcheck disable=SC2086  # the settings are option lists
    run_one "$dir" a --ba dynavins $a
    # shellcheck disable=SC2086
    [ "$have_b" = 1 ] && run_one "$dir" b --ba dynavins $b
    # shellcheck disable=SC2086
    [ "$have_c" = 1 ] && run_one "$dir" c --ba dynavins $c
    rows+=("$sc $s $out/$cache${mono:+-mono}")
  done
done

printf '%s\n' "${rows[@]}" | "$python" bench/report/seed_sweep_table.py "$a" "$b" "$have_b" "$c" "$have_c"
