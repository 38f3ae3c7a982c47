#!/usr/bin/env bash
# The README's gallery: each scene at the defaults and with 4× MSAA (the GPU default); with
# OLD_UMBRA, also at an older binary's defaults (`_previous.png`, the column that shows what a
# release changed). Real models come from UMBRA_GLTF_CORPUS (default ../shared/gltf); those
# missing are skipped. Prints each scene's share of pixels clipped at 255.
# Usage: scripts/gallery.sh [OLD_UMBRA]
set -euo pipefail
cd "$(dirname "$0")/.."
old=${1:-}
corpus="${UMBRA_GLTF_CORPUS:-../shared/gltf}"
out=docs/gallery
mkdir -p "$out"
cargo build --release --quiet
umbra=target/release/umbra
size=480x270
render() { # NAME ARGS...
  local name=$1
  shift
  if [ -n "$old" ]; then
    "$old" render "$@" --size "$size" -o "$out/${name}_previous.png" | tail -n 1
  fi
  "$umbra" render "$@" --size "$size" -o "$out/${name}.png" | tail -n 1
  "$umbra" render "$@" --size "$size" --msaa 4 -o "$out/${name}_msaa4.png" | tail -n 1
}
render demo
[ -f "$corpus/FlightHelmet/FlightHelmet.gltf" ] && render flighthelmet "$corpus/FlightHelmet/FlightHelmet.gltf" --ground
[ -f "$corpus/Cubes.glb" ] && render bevy_cubes "$corpus/Cubes.glb" --ground
[ -f "$corpus/alien.glb" ] && render alien "$corpus/alien.glb" --ground
render lux_yard --synthetic lux-yard
python3 - "$out" <<'PY' 2>/dev/null || true
import sys, glob, os
from PIL import Image
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.png"))):
    im = Image.open(f).convert("RGB")
    px = im.tobytes()
    n = len(px) // 3
    clipped = sum(1 for i in range(n) if 255 in px[3 * i:3 * i + 3])
    print(f"{os.path.basename(f)}: {100 * clipped / n:.2f} % of pixels clipped at 255")
PY
