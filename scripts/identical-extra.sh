#!/usr/bin/env bash
# Beside scripts/identical.sh: the settings its four modes leave out (contact shadows, MSAA,
# FXAA, supersampling, soft shadows, debug views, PCF kernels, fixed cascades), on the demo, a
# few --synthetic scenes and the compressed fixtures, compared byte for byte between two builds.
# Usage: scripts/identical-extra.sh OLD_UMBRA NEW_UMBRA [OUT_DIR]
set -euo pipefail
old=$1
new=$2
out=${3:-$(mktemp -d)}
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}"
mkdir -p "$out/old" "$out/new"
root="$(cd "$(dirname "$0")/.." && pwd)"
scenes=(demo --synthetic=sun-and-spot --synthetic=room --synthetic=foliage --synthetic=close-up)
while IFS= read -r f; do scenes+=("$f"); done < <(find "$root/tests/data/compressed" -name '*.glb' | sort | head -12)
settings=("--contact-shadows" "--msaa 4" "--post-aa fxaa" "--ssaa 2" "--light-size 2" "--view normals"
  "--view cascades" "--view texel-density" "--view overdraw" "--pcf 5x5" "--cascades 3" "--shadow-method exact --view shadow")
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
  for k in "${!settings[@]}"; do
    # shellcheck disable=SC2206
    extra=(${settings[$k]})
    for side in old new; do
      bin=$old
      [ "$side" = new ] && bin=$new
      "$bin" render "${args[@]}" --size 320x180 "${extra[@]}" -o "$out/$side/${tag}_$k.png" >/dev/null 2>&1 || true
    done
    if [ -f "$out/old/${tag}_$k.png" ] && cmp -s "$out/old/${tag}_$k.png" "$out/new/${tag}_$k.png"; then
      same=$((same + 1))
    else
      differ=$((differ + 1))
      echo "differs (or failed): $s ${settings[$k]}"
    fi
  done
done
echo "identical: $same images, differing: $differ (renders in $out)"
