#!/usr/bin/env bash
# The Python package's tests: builds the extension once into a virtual environment
# (target/pyenv; maturin's dev profile, sharing the workspace's build), installs what the tests
# use (numpy, pytest, pillow, trimesh, Ray), and runs pytest on python/tests (validation on;
# the Ray test starts a local 2-CPU cluster on loopback; the report test drives a headless
# Chromium, installed by scripts/ensure-browser.sh). Run by scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ensure-vulkan.sh --validation --python
# The report's browser test needs Chromium; without it that test skips (and fails under CI).
bash scripts/ensure-browser.sh || true
venv=target/pyenv
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
# shellcheck disable=SC1091
. "$venv/bin/activate"
python -m pip install -q --disable-pip-version-check \
  "maturin>=1.5,<2" numpy pytest pillow trimesh "ray>=2.9"
maturin develop -q -m python/Cargo.toml --profile dev --features suite
export UMBRA_DEVICE="${UMBRA_DEVICE:-llvmpipe}" UMBRA_BIN="${UMBRA_BIN:-target/debug/umbra}"
python -m pytest -q python/tests
