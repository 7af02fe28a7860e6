#!/usr/bin/env bash
# CI subset of the MuJoCo grasp-hold benchmark (bench/physics/README.md).
# Exports the paper's five scenes (seed 1) and the first object of a few families
# (first placement) with the DEBUG build of the exporter -- `cargo test --workspace`
# has already built it, so this adds no compilation --, runs the harness's controls
# and the subset. Fails only when a control misbehaves or something errors; the
# subset's hold rate is printed, not asserted.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=target/physics-cases/ci
mkdir -p "$out"
if ! python3 -c "import mujoco, trimesh, coacd, numpy" 2>/dev/null; then
    echo "bench/physics/ci.sh: python packages missing (pip install -r bench/physics/requirements.txt)" >&2
    exit 1
fi
# PHYSICS_CI_PROFILE=release to reuse a release build instead (local runs).
cargo run -q --profile "${PHYSICS_CI_PROFILE:-dev}" -p tsukami-grasp-planner --example physics_cases -- \
    --seed 1 --quick --limit "${PHYSICS_CI_CASES:-9}" --out "$out/humanoid.jsonl"
python3 bench/physics/hold.py --cases "$out/humanoid.jsonl" --noise \
    --json "$out/results.json" --md "$out/results.md"
# The controls as a closing count (hold.py has already exited non-zero if one
# misbehaved; this line counts them from its results).
python3 - "$out/results.json" <<'PY'
import json, sys
controls = json.load(open(sys.argv[1]))["controls"]
ok = sum(1 for c in controls if c["ok"])
print(f"physics: {ok} passed, {len(controls) - ok} failed")
sys.exit(0 if ok == len(controls) else 1)
PY
