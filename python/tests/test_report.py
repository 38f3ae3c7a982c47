"""`umbra report` in a real browser (headless Chromium from the distribution, loading the page
from disk; no server, no network): a failed golden (from the pytest plugin's Golden), a
`compare` folder and a quick `sweep` folder, made here by the code under test, then the page's
images must all decode and its controls must work under real mouse clicks and key presses:
blink alternates golden and actual, the slider shows the golden left of its position and the
actual right of it (checked against the PNGs pixel by pixel in a screenshot), zoom doubles the
images, a click on a Pareto point shows its settings and image. UMBRA_REPORT_SHOTS=DIR keeps the
screenshots (docs/images has them)."""

import io
import os
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import umbra
from browser import Browser, find_chromium
from umbra.testing import Golden, Tolerance
from test_golden import yard


def chromium_or_skip():
    binary = find_chromium()
    if binary is None:
        if os.environ.get("CI", "") not in ("", "0", "false"):
            pytest.fail("no Chromium under CI: scripts/ensure-browser.sh installs it")
        pytest.skip("no Chromium: apt-get install chromium, or set UMBRA_CHROMIUM")
    return binary


def run(umbra_bin, *args):
    p = subprocess.run([umbra_bin, *args], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stdout + p.stderr
    return p.stdout + p.stderr


def pixels(png_bytes_or_path):
    src = io.BytesIO(png_bytes_or_path) if isinstance(png_bytes_or_path, bytes) else png_bytes_or_path
    return np.asarray(Image.open(src).convert("RGB")).astype(np.int16)


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory, umbra_bin):
    """A failed golden, a compare folder and a quick sweep folder, and the page over them."""
    root = tmp_path_factory.mktemp("report")
    r = umbra.OffscreenRenderer(160, 120, validation=True)
    scene, camera, pose = yard()
    out = r.render(scene, camera, pose, outputs=("color", "shadow"))
    Golden(root / "golden", "yard", bless=True, ci=False).check(out, renderer=r)
    # The sun moved (shadow verdicts change) and the ambient raised (the ground's shading
    # changes across the whole width, which the slider test needs on both sides of its cut).
    moved = r.render(scene, camera, pose, outputs=("color", "shadow"), sun_direction=(-0.4, -1.0, -0.3),
                     ambient=0.5)
    with pytest.raises(umbra.GoldenMismatch) as failure:
        Golden(root / "golden", "yard", bless=False, ci=False).check(
            moved, renderer=r, tolerance=Tolerance.close(160 * 120))
    assert r.validation_problems == 0
    r.close()
    run(umbra_bin, "compare", "--size", "160x120", "--validation", "--out", str(root / "compare"))
    run(umbra_bin, "sweep", "demo", "--quick", "--formats", "d16", "--size", "96x54", "--repeat", "1",
        "--views", "1", "--images", "--validation", "--out", str(root / "sweep"))
    log = run(umbra_bin, "report", str(root))
    assert "1 failed golden(s), 1 compare, 1 sweep, 0 stability" in log, log
    return root, str(failure.value)


@pytest.fixture(scope="module")
def page(report_dir):
    browser = Browser(chromium_or_skip())
    try:
        browser.open(report_dir[0] / "report.html")
        yield browser
    finally:
        browser.close()


def shots():
    d = os.environ.get("UMBRA_REPORT_SHOTS")
    if d:
        Path(d).mkdir(parents=True, exist_ok=True)
    return Path(d) if d else None


def test_every_image_decodes_and_the_failure_reads(page, report_dir):
    page.wait_for("[...document.images].every(i => i.complete)")
    images = page.eval("[...document.images].filter(i => i.getAttribute('src'))"
                       ".map(i => [i.alt, i.naturalWidth, i.naturalHeight])")
    # golden: 3 lit + 3 shadow views; compare: 3 + its extra figures; sweep: 48 points' images.
    assert len(images) >= 6 + 3 + 48, images
    assert all(w > 0 and h > 0 for _, w, h in images), [i for i in images if i[1] == 0]
    reason = page.eval("document.querySelector('#goldens .reason').textContent")
    assert reason == report_dir[1], (reason, report_dir[1])
    assert page.eval("document.querySelectorAll('.cmp').length") == 3  # lit, shadow views, compare


def test_blink_alternates_golden_and_actual(page):
    cmp = "#goldens .cmp"
    d = shots()
    before = page.screenshot(str(d / "report-golden.png") if d else os.devnull, "#goldens article")
    page.click(f"{cmp} button[data-mode=blink]")
    assert page.eval(f"document.querySelector('{cmp}').dataset.mode") == "blink"
    shown = "getComputedStyle(document.querySelector('{}')).display !== 'none'"
    assert page.eval(shown.format(f"{cmp} .stack")) is True
    assert page.eval(shown.format(f"{cmp} .panes")) is False
    seen = set()
    for _ in range(30):
        seen.add(page.eval(f"document.querySelector('{cmp}').dataset.showing"))
        time.sleep(0.1)
    assert seen == {"a", "b"}, seen
    after = page.screenshot(os.devnull, "#goldens article")
    assert before != after


def test_the_slider_shows_the_golden_left_and_the_actual_right(page, report_dir):
    cmp = "#goldens .cmp"
    page.click(f"{cmp} button[data-mode=slider]")
    page.click(f"{cmp} .slide", fraction=(0.25, 0.5))
    value = int(page.eval(f"document.querySelector('{cmp} .slide').value"))
    assert 15 <= value <= 35, value
    d = shots()
    shot = pixels(page.screenshot(str(d / "report-slider.png") if d else os.devnull, f"{cmp} .stack"))
    golden = pixels(report_dir[0] / "golden" / "lavapipe" / "yard.png")
    actual = pixels(report_dir[0] / "golden" / "lavapipe" / "yard.actual.png")
    h, w = golden.shape[:2]
    # The rows inside: headless Chromium may blend an edge row of a layer with what is beside it.
    rows = slice(2, h - 2)
    shot, golden, actual = shot[:h, :w][rows], golden[rows], actual[rows]
    cut = w * value // 100
    # Each column where the two images differ is shown from one of them: the golden's left of
    # the cut, the actual's right of it (a column on the cut may be either).
    differ = np.abs(golden - actual).max(axis=(0, 2)) > 20
    from_golden = np.abs(shot - golden).max(axis=(0, 2)) <= 2
    from_actual = np.abs(shot - actual).max(axis=(0, 2)) <= 2
    cols = np.arange(w)
    left, right = differ & (cols < cut - 1), differ & (cols > cut + 1)
    assert left.sum() > 10 and right.sum() > 10, (left.sum(), right.sum())
    assert from_golden[left].all() and not from_actual[left].any()
    assert from_actual[right].all() and not from_golden[right].any()


def test_zoom_scales_the_images_by_whole_pixels(page):
    cmp = "#goldens .cmp"
    page.click(f"{cmp} button[data-mode=side]")
    page.key(f"{cmp} .zoom", "ArrowDown", "ArrowDown")
    assert page.eval(f"document.querySelector('{cmp} .zoom').value") == "2"
    sizes = page.eval("[...document.querySelectorAll('.cmp')].map(c => [...c.querySelectorAll('.panes img')]"
                      ".map(i => i.getBoundingClientRect().width / i.naturalWidth))")
    # This comparator's three images doubled, the other comparators' left alone.
    assert sizes[0] == [2, 2, 2] and all(z == 1 for c in sizes[1:] for z in c), sizes


def test_a_pareto_point_shows_its_settings_and_image(page):
    assert page.eval("document.querySelectorAll('#sweep svg.pareto circle').length") == 48
    assert page.eval("[...document.querySelectorAll('#sweep .point')].every(p => p.hidden)")
    page.click("#sweep svg.pareto circle[data-point$='-p5']")
    shown = page.eval("[...document.querySelectorAll('#sweep .point')].filter(p => !p.hidden)"
                      ".map(p => [p.id, p.querySelector('td').textContent, p.querySelectorAll('img').length,"
                      " p.querySelector('img') && p.querySelector('img').naturalWidth])")
    assert len(shown) == 1 and shown[0][0].endswith("-p5"), shown
    assert shown[0][2] == 1 and shown[0][3] == 96, shown
    d = shots()
    if d:
        page.screenshot(str(d / "report-sweep.png"), "#sweep article")


def test_write_report_from_python(report_dir, tmp_path):
    s = umbra.write_report(str(report_dir[0]), str(tmp_path / "page.html"))
    assert (s["goldens"], s["compares"], s["sweeps"], s["stabilities"]) == (1, 1, 1, 0)
    assert (tmp_path / "page.html").read_text().count("<article") == 3
    with pytest.raises(OSError, match="missing: not a folder"):
        umbra.write_report(str(tmp_path / "missing"))
