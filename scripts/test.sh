#!/usr/bin/env bash
# Quick start, command 2: the whole test suite. Lint gate (rustfmt, clippy -D warnings), then unit,
# GPU (lavapipe, Khronos validation with synchronization validation) and CLI tests.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-vulkan.sh --validation --xvfb
if [ -z "${UMBRA_GLTF_CORPUS:-}" ] && [ -d ../shared/gltf ]; then
  export UMBRA_GLTF_CORPUS="$(cd ../shared/gltf && pwd)"
fi
# lavapipe is the reference device for tests; a machine with a GPU can override UMBRA_DEVICE.
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}"
cargo fmt --all -- --check
cargo clippy --all-targets --quiet -- -D warnings
cargo test --all-targets
cargo test --doc
