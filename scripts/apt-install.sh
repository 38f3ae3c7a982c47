#!/usr/bin/env bash
# Installs Debian/Ubuntu packages with apt, as root or with passwordless sudo; otherwise prints
# exactly what to run and exits 1. Used by ensure-vulkan.sh and ensure-browser.sh.
# Usage: scripts/apt-install.sh PACKAGE...
set -euo pipefail
echo "umbra: installing missing packages: $*" >&2
if [ "$(id -u)" = 0 ]; then
  SUDO=""
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
  SUDO="sudo"
else
  echo "umbra: cannot install as this user. Run: sudo apt-get update && sudo apt-get install -y $*" >&2
  exit 1
fi
if ! command -v apt-get >/dev/null 2>&1; then
  echo "umbra: no apt-get here. Install with your package manager: $*" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq "$@" >/dev/null
echo "umbra: installed $*" >&2
