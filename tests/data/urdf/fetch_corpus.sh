#!/usr/bin/env bash
# Fetches two public robot collections from PyPI (pybullet's pybullet_data and
# example-robot-data), runs the reference parser (yourdfpy, from PyPI) over
# every URDF, then Tsukami's corpus test, which prints the table of
# docs/robots.md. Nothing is committed; everything goes to $WORK.
#   tests/data/urdf/fetch_corpus.sh [WORK_DIR]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
work="${1:-${TMPDIR:-/tmp}/tsukami-urdf-corpus}"
mkdir -p "$work/dl" "$work/x"
pip download --no-deps -d "$work/dl" pybullet==3.2.7 example-robot-data==6.0.0
for w in "$work"/dl/*.whl; do (cd "$work/x" && unzip -q -o "$w"); done
[ -x "$work/venv/bin/python" ] || python3 -m venv "$work/venv"
"$work/venv/bin/pip" install -q yourdfpy==0.0.60
share="$work/x/cmeel.prefix/share"
"$work/venv/bin/python" "$here/reference_fk.py" "$work/x" "$work/reference.json" \
    "$share/example-robot-data/robots" "$share" 2>/dev/null
cd "$root"
TSUKAMI_URDF_CORPUS="$work/x" TSUKAMI_URDF_REFERENCE="$work/reference.json" \
TSUKAMI_URDF_PACKAGES="$share/example-robot-data/robots:$share" \
    cargo test -p tsukami-body --test corpus -- --ignored --nocapture
