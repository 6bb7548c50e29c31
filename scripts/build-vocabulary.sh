#!/usr/bin/env bash
# Builds the default loop-closure vocabulary (data/vocabulary/default_vocabulary.bin) from real and
# synthetic images, reproducibly: the real EuRoC clip of ../shared (V1_01 micro, 95 frames, all used) and the
# first 10 s of two simulator scenes rendered afresh (bench/scenarios/none.yaml: the street on a drone flight;
# data/vocabulary/training_e_shape_board.yaml: the same street from a slower E-shaped path, with a board;
# bench/scenarios/e_shape.yaml as it was when the vocabulary was built, kept so that the bytes do not depend
# on the bench scene): every EuRoC image, every 2nd
# simulator image (the simulator's images give 400 corners each, the clip's about 260).
# The tree: branching 10, depth 5, seed 42 (`dynavins vocab` defaults). The same binary gives the same bytes.
# Usage: scripts/build-vocabulary.sh [OUT]   (default data/vocabulary/default_vocabulary.bin)
# DYNAVINS=path/to/dynavins picks the binary (default build/bin/dynavins); SHARED=... the shared data folder.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${DYNAVINS:-build/bin/dynavins}
shared=${SHARED:-../shared}
out=${1:-data/vocabulary/default_vocabulary.bin}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" --log-level warn sim --scenario none --duration 10 --euroc --out "$tmp/none"
"$bin" --log-level warn sim --scenario data/vocabulary/training_e_shape_board.yaml --duration 10 --euroc \
  --out "$tmp/e_shape"
"$bin" vocab --euroc "$shared/data/euroc_v1_01_micro" --euroc "$tmp/none/euroc" --euroc "$tmp/e_shape/euroc" \
  --every 1 --every 2 --every 2 --branching 10 --depth 5 --seed 42 --out "$out"
