#!/usr/bin/env bash
# Generates a scenario once and reuses it: bench/cache/NAME/ is regenerated only when the scenario
# file or the simulator's code changed (keyed by their content), so demos and benchmarks start fast.
# Usage: scripts/cached-sim.sh NAME [extra dynavins sim options...]
set -euo pipefail
cd "$(dirname "$0")/.."
name=$1; shift
out=bench/cache/$name
key=$( { cat "bench/scenarios/$name.yaml"; echo "$*"; find sim io/euroc_writer.cpp bin/cmd_sim.cpp -type f \( -name '*.cpp' -o -name '*.hpp' \) -print0 | sort -z | xargs -0 cat; } | sha256sum | cut -c1-16)
if [ -f "$out/sensors.lcmlog" ] && [ "$(cat "$out/.key" 2>/dev/null)" = "$key" ]; then
  echo "cached-sim: $out is up to date"
  exit 0
fi
rm -rf "$out"
build/bin/dynavins sim --scenario "$name" --out "$out" "$@"
echo "$key" > "$out/.key"
