#!/usr/bin/env bash
# Makes sure a headless Chromium is installed for the report's browser test
# (python/tests/test_report.py): Debian's `chromium` package, with apt when root or with
# passwordless sudo. Exits 1 with what to install otherwise; the test then skips, or fails under
# CI. UMBRA_CHROMIUM names another binary.
set -euo pipefail
for b in "${UMBRA_CHROMIUM:-}" chromium chromium-browser google-chrome google-chrome-stable; do
  if [ -n "$b" ] && command -v "$b" >/dev/null 2>&1; then
    exit 0
  fi
done
if [ "$(id -u)" = 0 ]; then
  SUDO=""
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
  SUDO="sudo"
else
  echo "umbra: no Chromium for the report's browser test. Run: sudo apt-get install -y chromium" >&2
  exit 1
fi
if ! command -v apt-get >/dev/null 2>&1; then
  echo "umbra: no Chromium and no apt-get: install Chromium, or set UMBRA_CHROMIUM" >&2
  exit 1
fi
echo "umbra: installing chromium (the report's browser test)" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq chromium >/dev/null
