#!/usr/bin/env bash
# Quick start, command 2: the whole test suite. Lint gate (rustfmt, the module graph, clippy -D
# warnings), then unit, GPU (lavapipe, Khronos validation with synchronization validation), CLI
# and viewer tests, the library without its default features, a dependent crate using it that
# way, and the Python package (built into a virtual environment, pytest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-vulkan.sh --validation --xvfb --python
# The suite writes its own glTF corpus; UMBRA_GLTF_CORPUS adds real models (CI sets it).
if [ -n "${UMBRA_GLTF_CORPUS:-}" ]; then
  echo "umbra tests: corpus = generated models + $UMBRA_GLTF_CORPUS"
else
  echo "umbra tests: corpus = generated models only (set UMBRA_GLTF_CORPUS to add real ones)"
fi
# lavapipe is the reference device for tests; a machine with a GPU can override UMBRA_DEVICE.
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}"
cargo fmt --all -- --check
# The module graph: no import cycles, the engine never importing the lab or the CLI.
python3 scripts/imports.py
cargo clippy --all-targets --quiet -- -D warnings
cargo clippy --no-default-features --all-targets --quiet -- -D warnings
cargo clippy -p umbra-python --all-targets --quiet -- -D warnings
cargo test --all-targets
cargo test --doc
# umbra as a user's dev-dependency with default-features = false (shares this target dir).
cargo test --manifest-path examples/offscreen_user/Cargo.toml --target-dir target --test offscreen
# The Python package (its extension linked by maturin, not by cargo test).
bash scripts/python-test.sh
