#!/usr/bin/env bash
# umbra's Python renderer against pyrender, side by side in the same minutes: per-frame time of
# `render(scene, camera, pose)` (colour and depth into numpy, shadows on) on FlightHelmet + the
# peer's ground and on the peer's 16×16 sphere grid, umbra at msaa 1, msaa 1 with FXAA, msaa 4
# and 2×2 supersampling (pyrender always 4×),
# the runs alternating ROUNDS times; then render_batch of 100 poses against 100 render calls.
# Needs the package in the active Python (scripts/python-test.sh's target/pyenv will do) and the
# pyrender peer's environment (../shared/peers/pyrender/setup.sh).
# Usage: scripts/python-vs-pyrender.sh FLIGHTHELMET.gltf [ROUNDS] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
model=$1
rounds=${2:-3}
out=${3:-out/python-vs-pyrender}
peer=${PYRENDER_PEER:-../shared/peers/pyrender}
peer_py=${PYRENDER_PYTHON:-$HOME/.cache/umbra-peers/pyrender/bin/python}
mkdir -p "$out"
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}"
# The peer's grid, exported with its camera and sun, for umbra to load.
PYOPENGL_PLATFORM=egl "$peer_py" "$peer/bench_pyrender.py" --synthetic 16 --frames 1 --warmup 0 \
  --export-gltf "$out/spheres16.gltf" >/dev/null
for r in $(seq "$rounds"); do
  for scene in helmet spheres; do
    if [ "$scene" = helmet ]; then
      umbra_args=("$model"); peer_args=("$model")
    else
      umbra_args=(--gltf-scene "$out/spheres16.gltf"); peer_args=(--synthetic 16)
    fi
    for aa in msaa1 fxaa msaa4 ssaa2; do
      case $aa in
        msaa1) aa_args=(--msaa 1) ;;
        fxaa) aa_args=(--msaa 1 --post-aa fxaa) ;;
        msaa4) aa_args=(--msaa 4) ;;
        ssaa2) aa_args=(--msaa 1 --supersample 2) ;;
      esac
      python python/examples/bench.py "${umbra_args[@]}" "${aa_args[@]}" \
        | sed "s/^/{\"run\": \"umbra $aa $scene r$r\", \"r\": /; s/\$/}/" >>"$out/runs.jsonl"
    done
    PYOPENGL_PLATFORM=egl "$peer_py" "$peer/bench_pyrender.py" "${peer_args[@]}" --frames 15 \
      | sed "s/^/{\"run\": \"pyrender $scene r$r\", \"r\": /; s/\$/}/" >>"$out/runs.jsonl"
  done
done
python python/examples/bench.py "$model" --batch 100 \
  | sed "s/^/{\"run\": \"umbra batch helmet\", \"r\": /; s/\$/}/" >>"$out/runs.jsonl"
python - "$out/runs.jsonl" <<'EOF'
import json, sys
for line in open(sys.argv[1]):
    d = json.loads(line)
    r = d["r"]
    fm = r.get("frame_ms") or r.get("shadows_on_ms") or {}
    extra = f" batch {r['batch']}" if "batch" in r else ""
    print(f"{d['run']:28s} median {fm.get('median')} ms (min {fm.get('min')}, max {fm.get('max')}){extra}")
EOF
