#!/usr/bin/env bash
# Renders with two umbra binaries and compares the PNGs byte for byte. For refactors and changes
# that must not move a pixel.
#   1. The demo, every --synthetic scene and every model of a glTF corpus at 640x360: the lit
#      image, the shadow view, the shadow map and the lit image with exact shadows.
#   2. The settings those four leave out (contact shadows, MSAA, FXAA, supersampling, soft
#      shadows, debug views, a PCF kernel, fixed cascades, exact shadows' shadow view) at 320x180
#      on the demo, four --synthetic scenes and the first twelve compressed fixtures.
# Usage: scripts/identical.sh OLD_UMBRA NEW_UMBRA [CORPUS_DIR] [OUT_DIR]
set -euo pipefail
old=$1
new=$2
corpus=${3:-${UMBRA_GLTF_CORPUS:-}}
out=${4:-$(mktemp -d)}
root="$(cd "$(dirname "$0")/.." && pwd)"
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}"
mkdir -p "$out/old" "$out/new"
same=0
differ=0

# compare SIZE SCENE SETTINGS...: renders SCENE with both binaries and compares the two PNGs.
compare() {
  local size=$1 s=$2 args tag side bin name
  shift 2
  case "$s" in
    demo) args=() ;;
    --synthetic=*) args=("$s") ;;
    *) args=("$s" --ground) ;;
  esac
  tag=$(basename -- "$s")
  name="${tag//[^A-Za-z0-9._-]/_}_${size}_$(printf '%s' "$*" | tr -c 'A-Za-z0-9' '_')"
  for side in old new; do
    bin=$old
    [ "$side" = new ] && bin=$new
    "$bin" render "${args[@]}" --size "$size" "$@" -o "$out/$side/$name.png" >/dev/null 2>&1 || true
  done
  if [ -f "$out/old/$name.png" ] && cmp -s "$out/old/$name.png" "$out/new/$name.png"; then
    same=$((same + 1))
  else
    differ=$((differ + 1))
    echo "differs (or did not render): $s $*"
  fi
}

scenes=(demo)
for s in double-sided close-up foliage foliage-masked town town-mover grazing stability room sun-and-spot two-suns lux-yard spheres:4; do
  scenes+=("--synthetic=$s")
done
if [ -n "$corpus" ]; then
  while IFS= read -r f; do scenes+=("$f"); done < <(find "$corpus" -name '*.gltf' -o -name '*.glb' | sort)
fi
for s in "${scenes[@]}"; do
  for mode in "--view lit" "--view shadow" "--view shadow-map" "--shadow-method exact"; do
    # shellcheck disable=SC2086
    compare 640x360 "$s" $mode
  done
done
echo "identical: $same images at 640x360, differing: $differ"

extra=(demo --synthetic=sun-and-spot --synthetic=room --synthetic=foliage --synthetic=close-up)
while IFS= read -r f; do extra+=("$f"); done < <(find "$root/tests/data/compressed" -name '*.glb' | sort | head -12)
settings=("--contact-shadows" "--msaa 4" "--post-aa fxaa" "--ssaa 2" "--light-size 2" "--view normals"
  "--view cascades" "--view texel-density" "--view overdraw" "--pcf 5x5" "--cascades 3"
  "--shadow-method exact --view shadow")
for s in "${extra[@]}"; do
  for setting in "${settings[@]}"; do
    # shellcheck disable=SC2086
    compare 320x180 "$s" $setting
  done
done
echo "identical: $same images in all, differing: $differ (renders in $out)"
