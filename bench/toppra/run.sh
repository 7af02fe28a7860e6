#!/usr/bin/env bash
# Our motion timing against toppra's on the same paths and limits (bench/toppra/compare.py).
set -euo pipefail
cd "$(dirname "$0")/../.."
if ! python3 -c "import toppra" 2>/dev/null; then
    echo "bench/toppra/run.sh: toppra missing (pip install -r bench/toppra/requirements.txt)" >&2
    exit 1
fi
out=target/toppra
mkdir -p "$out"
cargo run -q --release -p tsukami-trajectory-planner --example timing_export -- "$out/motions.json" >/dev/null
python3 bench/toppra/compare.py "$out/motions.json"
