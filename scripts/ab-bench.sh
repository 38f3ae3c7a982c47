#!/usr/bin/env bash
# Two umbra builds' `umbra bench` in alternating rounds, in the same minutes: the fair way to
# compare them on a shared machine whose speed drifts by up to 2× between hours. Prints each
# round's row and the CPU seconds (user + system, all threads) of its whole run, each build's
# medians, and the paired ratios (new / old, round by round) of GPU camera, GPU total, wall time
# and CPU seconds, with how many rounds the new build was faster in. CPU seconds drift less than
# wall time where other tenants take the cores (a run includes loading the scene: use a large
# --repeat to weigh the frames).
# The bench arguments must give one row (one map size, one kernel).
# Usage: scripts/ab-bench.sh ROUNDS OLD_UMBRA NEW_UMBRA [bench arguments...]
#   e.g. scripts/ab-bench.sh 8 /tmp/umbra-old target/release/umbra --synthetic close-up \
#          --maps 2048 --kernels 2x2 --repeat 9
set -euo pipefail
rounds=$1
old=$2
new=$3
shift 3
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}"
rows=$(mktemp)
out=$(mktemp)
trap 'rm -f "$rows" "$out"' EXIT
TIMEFORMAT='%U %S'
for _ in $(seq "$rounds"); do
  for side in old new; do
    bin=$old
    [ "$side" = new ] && bin=$new
    cpu=$({ time "$bin" bench "$@" >"$out" 2>/dev/null; } 2>&1)
    row=$(grep '^|' "$out" | tail -1)
    echo "$side $row $(awk '{ printf "%.2f", $1 + $2 }' <<<"$cpu") CPU s" | tee -a "$rows"
  done
done
python3 - "$rows" <<'PY'
import statistics as st
import sys

# SIDE | map | PCF | shadow | camera | total | wall | [casters |] CPU CPU s
rows = [line.split("|") for line in open(sys.argv[1])]
runs = {"old": [], "new": []}
for r in rows:
    runs[r[0].strip()].append([float(r[i]) for i in (3, 4, 5, 6)] + [float(r[-1].split()[0])])
names = ("GPU shadow ms", "GPU camera ms", "GPU total ms", "wall ms", "CPU s")
for side in ("old", "new"):
    meds = [st.median(x[i] for x in runs[side]) for i in range(5)]
    print(f"{side} medians: " + ", ".join(f"{n} {m:.2f}" for n, m in zip(names, meds)))
for i in (1, 2, 3, 4):
    ratios = [n[i] / o[i] for o, n in zip(runs["old"], runs["new"])]
    faster = sum(r < 1 for r in ratios)
    print(
        f"{names[i]}: paired ratio new/old median {st.median(ratios):.3f} "
        f"({min(ratios):.2f}-{max(ratios):.2f}), new faster in {faster} of {len(ratios)} rounds"
    )
PY
