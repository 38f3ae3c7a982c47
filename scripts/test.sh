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
# Each step's wall time, printed as it ends and again in a table at the end.
suite_start=$SECONDS
timings=()
step() {
  local name=$1 start=$SECONDS
  shift
  "$@"
  timings+=("$(printf '%5d s  %s' $((SECONDS - start)) "$name")")
  echo "umbra tests: $name took $((SECONDS - start)) s"
}
step fmt cargo fmt --all -- --check
# The module graph: no import cycles (re-exports followed to where an item is defined), the engine
# never importing the lab or the CLI.
step "module graph" python3 scripts/imports.py
# The shape: no source file over 600 lines, no function over 80 (the figures printed).
step "shape gate" python3 scripts/sizes.py --gate 600 80
# The engine and the lab without their default features (checked, not built).
step "clippy, no default features" cargo clippy --no-default-features --all-targets --quiet -- -D warnings
# clippy -D warnings on every crate of the workspace while it is built for the tests: with
# clippy-driver wrapping rustc for the workspace's own crates (what `cargo clippy` does, through
# the same CLIPPY_ARGS), lints and code come from one compilation, and the dependencies are built
# once instead of checked and then built. The Python extension is linted when maturin builds it.
clippy_driver="$(rustc --print sysroot)/bin/clippy-driver"
if [ -x "$clippy_driver" ]; then
  export RUSTC_WORKSPACE_WRAPPER="$clippy_driver" CLIPPY_ARGS="-D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__"
else
  step clippy cargo clippy --workspace --all-targets --quiet -- -D warnings
fi
step "cargo test (and clippy)" cargo test --all-targets
step "doc tests" cargo test --doc
# umbra as a user's dev-dependency with default-features = false (shares this target dir).
step "dependent crate" cargo test --manifest-path examples/offscreen_user/Cargo.toml --target-dir target --test offscreen
# The Python package (its extension linked by maturin, not by cargo test).
step python bash scripts/python-test.sh
echo "umbra tests: wall time per step"
printf '  %s\n' "${timings[@]}"
echo "umbra tests: the whole suite took $((SECONDS - suite_start)) s"
