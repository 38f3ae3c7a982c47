#!/usr/bin/env bash
# Writes tests/data/compressed: the project's generated glTF models (tests/common/corpus.rs)
# re-encoded by the real tools (scripts/gltf-tools.sh installs them; scripts/gltf-recompress.py
# applies each setting), every setting a tool accepts for each model.
# Usage: scripts/compressed-fixtures.sh
set -euo pipefail
cd "$(dirname "$0")/.."
tools=$(bash scripts/gltf-tools.sh)
live=target/tmp/umbra-test-output/compressed_live
rm -rf "$live"
# The test writes the generated models and their re-encodings (UMBRA_GLTF_TOOLS) before it judges
# them; its verdict is read below, once the fixtures are in place.
UMBRA_GLTF_TOOLS="$tools" cargo test --test engine compressed::recompressed -- --nocapture >/dev/null 2>&1 || true
mkdir -p tests/data/compressed
rm -f tests/data/compressed/*.glb
cp "$live"/*.glb tests/data/compressed/
ls tests/data/compressed/*.glb | wc -l | xargs echo "fixtures written:"
cargo test --test engine compressed::recompressed -- --nocapture
