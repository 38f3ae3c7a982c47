#!/usr/bin/env bash
# Renders the demo, every --synthetic scene and every model of a glTF corpus with two umbra
# binaries and compares the PNGs byte for byte (lit image, shadow view and shadow map, and the
# lit image with exact shadows). For refactors and changes that must not move a pixel.
# Usage: scripts/identical.sh OLD_UMBRA NEW_UMBRA [CORPUS_DIR] [OUT_DIR]
set -euo pipefail
old=$1
new=$2
corpus=${3:-${UMBRA_GLTF_CORPUS:-}}
out=${4:-$(mktemp -d)}
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}"
mkdir -p "$out/old" "$out/new"
scenes=(demo)
for s in double-sided close-up foliage foliage-masked town town-mover grazing stability room sun-and-spot two-suns lux-yard spheres:4; do
  scenes+=("--synthetic=$s")
done
if [ -n "$corpus" ]; then
  while IFS= read -r f; do scenes+=("$f"); done < <(find "$corpus" -name '*.gltf' -o -name '*.glb' | sort)
fi
same=0
differ=0
for s in "${scenes[@]}"; do
  case "$s" in
    demo) args=() ;;
    --synthetic=*) args=("$s") ;;
    *) args=("$s" --ground) ;;
  esac
  tag=$(basename -- "$s")
  tag=${tag//[^A-Za-z0-9._-]/_}
  for mode in lit shadow shadow-map exact; do
    for side in old new; do
      bin=$old
      [ "$side" = new ] && bin=$new
      view=(--view "$mode")
      [ "$mode" = exact ] && view=(--shadow-method exact)
      "$bin" render "${args[@]}" --size 640x360 "${view[@]}" -o "$out/$side/${tag}_$mode.png" >/dev/null 2>&1
    done
    if cmp -s "$out/old/${tag}_$mode.png" "$out/new/${tag}_$mode.png"; then
      same=$((same + 1))
    else
      differ=$((differ + 1))
      echo "differs: $s ($mode)"
    fi
  done
done
echo "identical: $same images, differing: $differ (renders in $out)"
