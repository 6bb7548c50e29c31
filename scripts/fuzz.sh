#!/usr/bin/env bash
# Runs each libFuzzer harness of fuzz/ for FUZZ_SECONDS (default 600) on one core (a single fuzzing process, no -jobs or -fork: the
# machine is shared), one after the other, from a seed corpus made of real inputs (make_fuzz_seeds).
#   scripts/fuzz.sh <fuzz build dir> [harness ...]     (default: every harness)
# Per harness, in <build>/fuzz-runs/<name>/: corpus/ (seeds + what libFuzzer adds), crash-* files,
# log.txt, row.md. Each harness's latest row (finished at, executions, cov, ft, seconds, result) is kept in its
# row.md, and <build>/fuzz-runs/summary.md is rebuilt from every harness's row, so a call that runs only
# some harnesses keeps the others' last results. Exit status 1 if any harness found a crash.
# A crash input belongs in tests/data/fuzz_regressions/<name>/ once the bug is fixed.
set -uo pipefail
BUILD=${1:?usage: scripts/fuzz.sh <fuzz build dir> [harness ...]}
shift
HARNESSES=("$@")
ALL=(lcm_log lcm_decode euroc_csv config camera rosbag)
[ ${#HARNESSES[@]} -eq 0 ] && HARNESSES=("${ALL[@]}")
SECONDS_EACH=${FUZZ_SECONDS:-600}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SHARED=${DYNAVINS_SHARED:-$ROOT/../shared}/data
RUNS=$BUILD/fuzz-runs
SEEDS=$RUNS/seeds

mkdir -p "$RUNS"
rm -rf "$SEEDS"
"$BUILD/bin/make_fuzz_seeds" "$SHARED" "$SEEDS" || exit 1

# Per-input memory: a reader may hold a few decoded images; 1 GB RSS is far beyond any valid input here.
export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
summary=$RUNS/summary.md
for h in "${HARNESSES[@]}"; do
  dir=$RUNS/$h
  mkdir -p "$dir/corpus" "$dir/artifacts"
  cp -n "$SEEDS/$h"/* "$dir/corpus/" 2>/dev/null
  echo "fuzz: $h for ${SECONDS_EACH}s"
  start=$(date +%s)
  # max_len: the seeds (a few frames shrunk to 24x16) stay below 16 kB; larger inputs add no new paths.
  "$BUILD/bin/fuzz_$h" "$dir/corpus" -max_total_time="$SECONDS_EACH" -max_len=16384 \
    -rss_limit_mb=1024 -malloc_limit_mb=1024 -timeout=25 -print_final_stats=1 \
    -artifact_prefix="$dir/artifacts/" >"$dir/log.txt" 2>&1
  rc=$?
  secs=$(($(date +%s) - start))
  # libFuzzer's last status line: "#N DONE cov: C ft: F corp: K/.."; or the last pulse line on a crash.
  last=$(grep -E '^#[0-9]+' "$dir/log.txt" | tail -1)
  execs=$(grep -E '^stat::number_of_executed_units' "$dir/log.txt" | awk '{print $2}')
  [ -z "$execs" ] && execs=$(echo "$last" | sed -E 's/^#([0-9]+).*/\1/')
  cov=$(echo "$last" | sed -nE 's/.*cov: ([0-9]+).*/\1/p')
  ft=$(echo "$last" | sed -nE 's/.*ft: ([0-9]+).*/\1/p')
  corp=$(echo "$last" | sed -nE 's/.*corp: ([0-9]+\/[0-9a-zA-Z]+).*/\1/p')
  if [ $rc -eq 0 ]; then result=clean; else
    result="FOUND: $(ls "$dir/artifacts" | head -3 | tr '\n' ' ')(see $dir/log.txt)"
    status=1
  fi
  echo "| $h | $(date -u +%Y-%m-%dT%H:%MZ) | $secs | $execs | $cov | $ft | $corp | $result |" | tee "$dir/row.md"
done
{
  echo "| harness | finished (UTC) | seconds | executions | cov | ft | corpus | result |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
  for h in "${ALL[@]}"; do
    [ -f "$RUNS/$h/row.md" ] && cat "$RUNS/$h/row.md"
  done
} >"$summary"
echo "fuzz: summary in $summary"
exit $status
