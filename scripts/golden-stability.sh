#!/usr/bin/env bash
# How stable goldens are: renders each case N times (default 10), each in its own process, and
# counts distinct PNGs by SHA-256 (1 = identical to the byte every time). Cases: the demo, and
# with a corpus (UMBRA_GLTF_CORPUS or ../shared/gltf) FlightHelmet over a ground and Fox at
# three times of its animation. Device: UMBRA_DEVICE (default llvmpipe).
# Usage: scripts/golden-stability.sh [N] [BINARY]
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-10}
bin=${2:-target/release/umbra}
corpus=${UMBRA_GLTF_CORPUS:-../shared/gltf}
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cases=("demo|")
if [ -d "$corpus" ]; then
  cases+=("flighthelmet|$corpus/FlightHelmet/FlightHelmet.gltf --ground")
  for t in 0.5 1.5 3.0; do
    cases+=("fox_t$t|$corpus/Fox.glb --ground --time $t")
  done
fi
printf '| case | renders | distinct images |\n|---|---|---|\n'
for c in "${cases[@]}"; do
  name=${c%%|*}
  args=${c#*|}
  for i in $(seq 1 "$n"); do
    # shellcheck disable=SC2086
    "$bin" render $args --size 640x480 -o "$out/$name.$i.png" >/dev/null 2>&1
  done
  distinct=$(sha256sum "$out/$name".*.png | awk '{print $1}' | sort -u | wc -l)
  printf '| %s | %d | %d |\n' "$name" "$n" "$distinct"
done
