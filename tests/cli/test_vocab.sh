#!/usr/bin/env bash
# `dynavins vocab` is reproducible (two builds on the real EuRoC clip give the same bytes) and refuses a
# folder that is not an EuRoC one with exit 2, naming it.
# Usage: test_vocab.sh DYNAVINS SHARED_DIR
set -euo pipefail
bin=$1 shared=$2
clip=$shared/data/euroc_v1_01_micro
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" vocab --euroc "$clip" --every 2 --out "$tmp/a.bin" > "$tmp/log" 2>&1 || { cat "$tmp/log"; echo "FAIL: vocab"; exit 1; }
cat "$tmp/log"
grep -q "words" "$tmp/log" || { echo "FAIL: no summary printed"; exit 1; }
"$bin" vocab --euroc "$clip" --every 2 --out "$tmp/b.bin" > /dev/null 2>&1
cmp "$tmp/a.bin" "$tmp/b.bin" || { echo "FAIL: two builds differ"; exit 1; }
mkdir -p "$tmp/empty"
set +e
"$bin" vocab --euroc "$tmp/empty" --out "$tmp/c.bin" > "$tmp/log" 2>&1
rc=$?
set -e
cat "$tmp/log"
[ "$rc" -eq 2 ] || { echo "FAIL: exit $rc, expected 2"; exit 1; }
grep -q "$tmp/empty: no mav0/cam0/data folder" "$tmp/log" || { echo "FAIL: the error does not name the folder"; exit 1; }
[ ! -e "$tmp/c.bin" ] || { echo "FAIL: a file was written"; exit 1; }
echo "ok"
