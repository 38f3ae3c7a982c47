#!/usr/bin/env bash
# The size of each function llvmpipe compiled, from a dump that scripts/profile-llvmpipe.sh
# wrote with UMBRA_JITDUMP_DIR=DIR set: instructions up to the function's first return (a
# fragment function's block loop and its epilogue) and, of those, the per-lane ones (element
# inserts and extracts, scalar moves into vector registers: what llvmpipe emits where it cannot
# vectorise, such as a uniform read in a fragment shader or a format it converts lane by lane).
# Usage: scripts/jit-sizes.sh DIR
set -euo pipefail
dir=$1
for f in "$dir"/*.bin; do
  name=$(basename "$f" .bin)
  address=${name##*_}
  body=$(objdump -D -b binary -mi386:x86-64 --adjust-vma="0x$address" "$f" |
    awk -F'\t' 'NF >= 3 && !done { print $3 } $3 ~ /^ret/ { done = 1 }')
  total=$(grep -c . <<<"$body" || true)
  lanes=$(grep -cE '^(vpinsr|vpextr|vinsertps|vextractps|vmovd |vmovq |vmovss )' <<<"$body" || true)
  printf '%-40s %6d instructions %5d per-lane\n' "${name%_*}" "$total" "$lanes"
done
