#!/usr/bin/env bash
# Generates a scenario once and reuses it: bench/cache/NAME/ is regenerated only when the scenario
# file or the simulator's code changed (keyed by their content), so demos and benchmarks start fast.
# Usage: scripts/cached-sim.sh NAME [extra dynavins sim options...]
# --euroc (also write NAME/euroc/, an EuRoC folder with vins_config.yaml) is not part of the key:
# a cache made with it serves requests without it; a request with it regenerates a cache without it.
# The scene is written to NAME.partial and swapped in only when complete.
# DYNAVINS=path/to/dynavins picks the binary (default build/bin/dynavins).
# CACHE_AS=DIRNAME caches under bench/cache/DIRNAME instead of bench/cache/NAME, so variants of one
# scenario (e.g. CACHE_AS=high-20s with --duration 20, as `make bench-quick` does) do not evict each other.
set -euo pipefail
cd "$(dirname "$0")/.."
name=$1; shift
bin=${DYNAVINS:-build/bin/dynavins}
out=bench/cache/${CACHE_AS:-$name}
want_euroc=0
args=()
for a in "$@"; do
  if [ "$a" = --euroc ]; then want_euroc=1; else args+=("$a"); fi
done
key=$( { cat "bench/scenarios/$name.yaml"; echo "${args[*]}"; find sim io/euroc_writer.cpp bin/cmd_sim.cpp -type f \( -name '*.cpp' -o -name '*.hpp' \) -print0 | sort -z | xargs -0 cat; } | sha256sum | cut -c1-16)
if [ -f "$out/sensors.lcmlog" ] && [ "$(cat "$out/.key" 2>/dev/null)" = "$key" ] &&
   { [ "$want_euroc" = 0 ] || [ -f "$out/euroc/vins_config.yaml" ]; }; then
  echo "cached-sim: $out is up to date"
  exit 0
fi
rm -rf "$out.partial"
extra=()
[ "$want_euroc" = 1 ] && extra=(--euroc)
"$bin" sim --scenario "$name" --out "$out.partial" "${args[@]}" "${extra[@]}"
echo "$key" > "$out.partial/.key"
rm -rf "$out"
mv "$out.partial" "$out"
