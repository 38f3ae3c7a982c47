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
echo "umbra: no Chromium for the report's browser test" >&2
bash "$(dirname "$0")/apt-install.sh" chromium
