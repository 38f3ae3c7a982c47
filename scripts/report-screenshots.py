#!/usr/bin/env python3
"""Screenshots of a report page for the docs (docs/images/report-*.png), through the test's
headless Chromium driver: the first failed golden side by side, then its slider at zoom 2, and
the first sweep chart with a point clicked.

Usage: scripts/report-screenshots.py REPORT.html OUTDIR"""

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python" / "tests"))
from browser import Browser, find_chromium  # noqa: E402


def main():
    page_path, out = Path(sys.argv[1]), Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    b = Browser(find_chromium() or sys.exit("no Chromium"), width=1200, height=900)
    try:
        b.open(page_path)
        if b.eval("!!document.querySelector('#goldens article')"):
            b.screenshot(str(out / "report-golden.png"), "#goldens article")
            cmp = "#goldens .cmp"
            b.click(f"{cmp} button[data-mode=slider]")
            b.key(f"{cmp} .zoom", "ArrowDown", "ArrowDown")
            b.click(f"{cmp} .slide", fraction=(0.4, 0.5))
            time.sleep(0.2)
            b.screenshot(str(out / "report-slider.png"), cmp)
        if b.eval("!!document.querySelector('#sweep svg.pareto circle')"):
            b.click("#sweep svg.pareto circle[data-point$='-p5']")
            b.screenshot(str(out / "report-sweep.png"), "#sweep article")
    finally:
        b.close()


if __name__ == "__main__":
    main()
