#!/usr/bin/env bash
# Hybrid shadows against maps and exact shadows (docs/exact-shadows.md, "Hybrid"): for each scene,
# misclassified pixels against the CPU reference (`umbra compare`, 640x360), the fraction of
# pixels hybrid traced (its cascade view: traced verdicts green), the caster triangles its culling
# kept for the grid (`render`'s line, from FrameStats::grid_triangles), and the frame (`umbra bench`,
# 1280x720, 2048² map, PCF 2x2, median of REPEAT), one markdown row per scene, all in the same
# minutes. Usage: scripts/hybrid-table.sh [REPEAT] [CORPUS] [OAKTREE]   (CORPUS: ../shared/gltf;
# OAKTREE: SaschaWillems/Vulkan-Assets' models/oaktree.gltf, adding scripts/oak-grove.py's grove
# near and far)
set -euo pipefail
cd "$(dirname "$0")/.."
repeat=${1:-5}
corpus=${2:-../shared/gltf}
umbra=target/release/umbra
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}"
scenes=("" "--synthetic foliage" "--synthetic foliage-masked" "--synthetic close-up" "--synthetic town")
names=(demo foliage foliage-masked close-up "town (eye height)")
if [ -f "$corpus/FlightHelmet/FlightHelmet.gltf" ]; then
  scenes+=("$corpus/FlightHelmet/FlightHelmet.gltf --ground")
  names+=("FlightHelmet + ground")
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if [ -n "${3:-}" ]; then
  for at in near far; do
    python3 scripts/oak-grove.py "$3" "$tmp/grove-$at.gltf" "$at" >/dev/null
    scenes+=("$tmp/grove-$at.gltf")
    names+=("oak grove, $at")
  done
fi
misclassified() { # scene args..., method -> "pixels (percent)"
  local method=${*: -1}
  # shellcheck disable=SC2086
  $umbra compare ${@:1:$#-1} --size 640x360 --shadow-method "$method" --out "$tmp/c" 2>/dev/null |
    tail -1 | python3 -c '
import json, sys
d = json.loads(sys.stdin.read())
m = d["misclassified"]
print("%d (%.3f %%)" % (round(m * d["judged_pixels"]), 100 * m))'
}
traced() { # -> "traced % | kept of all caster triangles"
  # shellcheck disable=SC2086
  $umbra render "$@" --size 640x360 --shadow-method hybrid --view cascades -o "$tmp/v.png" \
    >"$tmp/v.txt" 2>&1
  python3 - "$tmp/v.png" "$tmp/v.txt" <<'EOF'
import re, sys
from PIL import Image
im = Image.open(sys.argv[1]).convert("RGB")
g = r = 0
for R, G, B in im.get_flattened_data() if hasattr(im, "get_flattened_data") else im.getdata():
    g += G > R and G > B
    r += R > G and R > B
m = re.search(r"hybrid: (\d+) of (\d+) caster triangles", open(sys.argv[2]).read())
kept = f"{int(m[1]):,} of {int(m[2]):,}" if m else "–"
print(f"{100 * g / max(g + r, 1):.1f} % | {kept}")
EOF
}
frame() { # -> median GPU ms of the frame
  local method=${*: -1}
  # shellcheck disable=SC2086
  $umbra bench ${@:1:$#-1} --size 1280x720 --maps 2048 --kernels 2x2 --repeat "$repeat" \
    --shadow-method "$method" 2>/dev/null | tail -1 | awk -F'|' '{gsub(/ /, "", $6); print $6}'
}
echo "| scene | misclassified: map / exact / hybrid | traced | casters kept (triangles) | frame, ms: map / exact / hybrid | hybrid / exact | hybrid / map |"
echo "|---|---|---|---|---|---|---|"
for i in "${!scenes[@]}"; do
  # shellcheck disable=SC2206
  s=(${scenes[$i]})
  m=() f=()
  for method in map exact hybrid; do
    m+=("$(misclassified "${s[@]}" "$method")")
    f+=("$(frame "${s[@]}" "$method")")
  done
  ratios=$(python3 -c "print('%.2f× | %.2f×' % (${f[2]} / ${f[1]}, ${f[2]} / ${f[0]}))")
  echo "| ${names[$i]} | ${m[0]} / ${m[1]} / ${m[2]} | $(traced "${s[@]}") | ${f[0]} / ${f[1]} / ${f[2]} | ${ratios} |"
done
