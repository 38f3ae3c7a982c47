"""Golden-image tests with pytest: the ``umbra_golden`` fixture (a pytest plugin, registered as
the ``pytest11`` entry point ``umbra``, so installing the package is enough).

>>> def test_helmet(umbra_golden, renderer, scene, camera, pose):
...     out = renderer.render(scene, camera, pose, outputs=["color", "shadow"])
...     umbra_golden.check(out, renderer=renderer)

Goldens live in ``golden/`` beside the test file, as ``NAME.png`` with the shadow view beside it
(``NAME.shadow.png``); ``NAME`` defaults to the test's name. With ``renderer=`` a golden is looked
for first in the renderer's device-class folder (``golden/lavapipe/NAME.png``), then shared
(``golden/NAME.png``). The comparison is ``umbra::golden``'s: FLIP per pixel, a count allowed
over a threshold, a mean, and a count of pixels allowed to change their shadow verdict. A
failure raises ``umbra.GoldenMismatch`` with one line that says apart what changed in the
shadows and in the shading, and writes ``NAME.actual.png`` and ``NAME.diff.png`` (with
``NAME.actual.shadow.png`` and ``NAME.shadow-diff.png``) beside the golden.

``pytest --umbra-bless`` (or ``UMBRA_BLESS=1``) writes missing and failing goldens; without it a
missing golden fails. Under CI (``CI`` set, not ``0``/``false``) blessing is refused and every
check fails, so CI never blesses.

``pytest --umbra-report PAGE.html`` writes, after a pytest run in which a golden failed, the page
``umbra report`` writes (golden, actual and diff side by side, a slider, a blink, zoom) over the
golden folders that failed, and names it in the summary.
"""

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Dict, Optional, Sequence, Union

import pytest

from . import _umbra


@dataclass(frozen=True)
class Tolerance:
    """How close counts as equal (``umbra::golden::Tolerance``)."""

    pixel_flip: float = 0.0
    pixels_over: int = 0
    mean_flip: float = 0.0
    shadow_changes: int = 0

    @staticmethod
    def exact() -> "Tolerance":
        """The same bytes: a frame on the device class that wrote the golden."""
        return Tolerance()

    @staticmethod
    def close(pixels: int) -> "Tolerance":
        """What a driver update may move unseen (``Tolerance::close`` in Rust)."""
        return Tolerance(0.1, max(pixels // 1000, 4), 0.005, max(pixels // 2000, 2))


def _on(value: Optional[str]) -> bool:
    return value is not None and value not in ("", "0", "false")


_FAILED_FOLDERS = set()


class Golden:
    """What the ``umbra_golden`` fixture gives a test."""

    def __init__(self, folder: Path, test_name: str, bless: bool, ci: Optional[bool] = None):
        self.folder = folder
        self.test_name = re.sub(r"[^A-Za-z0-9_.-]+", "_", test_name)
        self.bless = bless
        self.ci = _on(os.environ.get("CI")) if ci is None else ci

    def check(
        self,
        frame: Union[Any, Dict[str, Any], Sequence[Any]],
        name: Optional[str] = None,
        renderer: Any = None,
        tolerance: Optional[Tolerance] = None,
    ) -> Dict[str, Any]:
        """Compares ``frame`` with its golden: a colour array, ``render``'s tuple or dict (its
        ``shadow`` output is compared as the shadow view), or ``render_batch``'s list (each
        frame against ``NAME_0``, ``NAME_1``, …). Returns the figures (a list for a batch)."""
        name = name or self.test_name
        if isinstance(frame, list):
            return [self.check(f, f"{name}_{i}", renderer, tolerance) for i, f in enumerate(frame)]
        if isinstance(frame, tuple):
            frame = frame[0]
        color, shadow = (frame.get("color"), frame.get("shadow")) if isinstance(frame, dict) else (frame, None)
        if color is None:
            raise ValueError("umbra_golden: the frame has no 'color' output")
        t = tolerance or Tolerance.exact()
        try:
            return self._check(color, shadow, name, renderer, t)
        except _umbra.GoldenMismatch:
            _FAILED_FOLDERS.add(self.folder.resolve())
            raise

    def _check(self, color, shadow, name, renderer, t):
        return _umbra.golden_check(
            color,
            str(self.folder / f"{name}.png"),
            shadow=shadow,
            device_class=renderer.device_class if renderer is not None else "",
            pixel_flip=t.pixel_flip,
            pixels_over=t.pixels_over,
            mean_flip=t.mean_flip,
            shadow_changes=t.shadow_changes,
            bless=self.bless,
            ci=self.ci,
        )


def pytest_addoption(parser):
    parser.addoption(
        "--umbra-bless",
        action="store_true",
        default=False,
        help="umbra golden images: write missing and failing goldens (refused under CI)",
    )
    parser.addoption(
        "--umbra-report",
        metavar="PAGE",
        default=None,
        help="umbra golden images: after a failure, write one HTML page of the failed goldens",
    )


def pytest_sessionfinish(session):
    page = session.config.getoption("--umbra-report")
    if not page or not _FAILED_FOLDERS:
        return
    root = Path(os.path.commonpath([str(f) for f in _FAILED_FOLDERS]))
    s = _umbra.write_report(str(root), str(page))
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if reporter is not None:
        reporter.write_line(f"umbra report: {s['path']} ({s['goldens']} failed golden(s))")


@pytest.fixture
def umbra_golden(request) -> Golden:
    """Golden-image checks for this test (see ``umbra.testing``)."""
    bless = request.config.getoption("--umbra-bless") or _on(os.environ.get("UMBRA_BLESS"))
    folder = Path(str(request.node.fspath)).parent / "golden"
    return Golden(folder, request.node.name, bless)
