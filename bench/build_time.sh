#!/usr/bin/env bash
# Clean release build of the whole workspace into an empty target folder
# (docs/benchmarks.md, "Build time"; target, issue #2: under 8 minutes).
# Crates must already be downloaded (`cargo fetch`); the folder is removed
# afterwards (it holds several GB). Prints the wall and CPU time.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=target/build-time
rm -rf "$dir"
mkdir -p "$dir"
TIMEFORMAT='%R %U %S'
if ! { time cargo build --release --workspace --offline --target-dir "$dir" -q 2>"$dir.log"; } 2>"$dir.times"; then
    tail -n 20 "$dir.log" >&2
    rm -rf "$dir"
    exit 1
fi
read -r wall user sys <"$dir.times"
rm -rf "$dir" "$dir.log" "$dir.times"
awk -v w="$wall" -v u="$user" -v s="$sys" 'BEGIN {
    printf "clean release build (cargo build --release --workspace, empty target folder): %d min %02d s wall, %d min %02d s CPU\n",
        w / 60, w % 60, (u + s) / 60, (u + s) % 60
}'
