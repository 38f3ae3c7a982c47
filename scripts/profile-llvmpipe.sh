#!/usr/bin/env bash
# Where lavapipe's time goes in a benchmark: perf samples (2 kHz) of `umbra bench ARGS...`, with
# the functions llvmpipe compiles named (scripts/llvmpipe-jitmap.c: fragment shaders, vertex
# shaders, triangle setup, numbered in compile order: for a camera pass, the order of first
# draw). Prints the share of samples per function and per thread (llvmpipe-N: the rasterizer
# threads; the process's own name: recording, vertex processing and triangle setup).
# Needs perf, a C compiler and the release CLI (cargo build --release -p umbra-cli).
# Usage: scripts/profile-llvmpipe.sh [bench arguments...]
#   e.g. scripts/profile-llvmpipe.sh --synthetic close-up --maps 2048 --kernels 2x2 --repeat 40
# UMBRA_BIN=PATH (absolute, or from the repository root) profiles that umbra binary instead (a
# throwaway build kept aside).
# UMBRA_JITDUMP_DIR=DIR also saves each function's code (objdump -D -b binary -mi386:x86-64
# --adjust-vma=ADDRESS DIR/NN_name_ADDRESS.bin).
set -euo pipefail
cd "$(dirname "$0")/.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
llvm=$(ldd "$(ldconfig -p | awk '/libvulkan_lvp.so/ {print $NF; exit}')" | awk '/libLLVM/ {print $3; exit}')
cc -shared -fPIC -O2 -o "$work/jitmap.so" scripts/llvmpipe-jitmap.c "$llvm" -ldl -lpthread
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}"
LD_PRELOAD="$work/jitmap.so" perf record -q -F 2000 -o "$work/perf.data" "${UMBRA_BIN:-target/release/umbra}" bench "$@"
# Each function's size: the gap to the next one (at most 64 KiB).
map=$(ls -t /tmp/perf-*.map | head -1)
  python3 - "$map" <<'PY'
import sys
rows = sorted((int(a, 16), n) for a, _, n in (l.split() for l in open(sys.argv[1])))
with open(sys.argv[1], "w") as f:
    for i, (a, n) in enumerate(rows):
        gap = rows[i + 1][0] - a if i + 1 < len(rows) else 1 << 16
        f.write(f"{a:x} {min(gap, 1 << 16):x} {n}\n")
PY
perf report -i "$work/perf.data" --no-children --sort sym -g none 2>/dev/null | grep '%' | grep -v '^#' | head -16
perf report -i "$work/perf.data" --no-children --sort comm -g none 2>/dev/null | grep '%' | grep -v '^#' | head -4
rm -f "$map"
