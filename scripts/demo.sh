#!/usr/bin/env bash
# Quick start, command 1: renders the built-in demo scene to demo.png (extra arguments are passed
# to `umbra render`, e.g. --size 1920x1080 or --view shadow).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-vulkan.sh
cargo run --release --quiet -- render -o demo.png "$@"
