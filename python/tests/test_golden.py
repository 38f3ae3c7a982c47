"""Golden-image tests from Python: the ``umbra_golden`` fixture of the ``umbra.testing`` pytest
plugin, in process (missing, blessed, matched; a moved sun named as shadow verdicts, a brighter
ambient as shading) and end to end through pytest's own runner (the entry point, --umbra-bless,
the refusal under CI)."""

import numpy as np
import pytest

import umbra
from umbra.testing import Golden, Tolerance
from conftest import quad

pytest_plugins = ["pytester"]


def yard():
    scene = umbra.Scene()
    scene.add_mesh(*quad(0.5, 0.3))
    scene.add_ground()
    scene.add_directional_light((0.4, -1.0, -0.3))
    camera, pose = umbra.PerspectiveCamera(np.pi / 4, 0.1), umbra.look_at((0, 2, 3), (0, 0, 0))
    return scene, camera, pose


def test_missing_blessed_matched_and_the_verdict_split(renderer, tmp_path):
    scene, camera, pose = yard()
    out = renderer.render(scene, camera, pose, outputs=("color", "shadow"))
    g = Golden(tmp_path, "yard", bless=False, ci=False)
    with pytest.raises(umbra.GoldenMismatch, match="UMBRA_BLESS=1"):
        g.check(out, renderer=renderer)
    blessed = Golden(tmp_path, "yard", bless=True, ci=False).check(out, renderer=renderer)
    assert blessed["outcome"] == "blessed"
    assert (tmp_path / "lavapipe" / "yard.png").is_file()
    assert (tmp_path / "lavapipe" / "yard.shadow.png").is_file()
    again = renderer.render(scene, camera, pose, outputs=("color", "shadow"))
    assert g.check(again, renderer=renderer) == {
        "outcome": "matched", "differing": 0, "mean_flip": 0.0, "pixels_over": 0, "shadow_changes": 0,
    }
    # The sun turned: shadow verdicts change, counted here against the stored shadow view.
    moved = renderer.render(scene, camera, pose, outputs=("color", "shadow"), sun_direction=(-0.4, -1.0, -0.3))
    with pytest.raises(umbra.GoldenMismatch, match="changed their shadow verdict") as e:
        g.check(moved, renderer=renderer, tolerance=Tolerance.close(160 * 120))
    counted = int(np.sum((again["shadow"] >= 0.5) != (moved["shadow"] >= 0.5)))
    assert f"{counted} pixels changed their shadow verdict" in str(e.value), (counted, str(e.value))
    for name in ("yard.actual.png", "yard.diff.png", "yard.actual.shadow.png", "yard.shadow-diff.png"):
        assert (tmp_path / "lavapipe" / name).is_file(), name
    # A brighter ambient: shading only.
    bright = renderer.render(scene, camera, pose, outputs=("color", "shadow"), ambient=0.6)
    with pytest.raises(umbra.GoldenMismatch, match="shadows within tolerance .0 verdicts changed.; shading changed"):
        g.check(bright, renderer=renderer, tolerance=Tolerance.close(160 * 120))
    # A batch is checked frame by frame, and a frame without a colour output is refused.
    batch = Golden(tmp_path, "ring", bless=True, ci=False).check([again, again["color"]], renderer=renderer)
    assert [b["outcome"] for b in batch] == ["blessed", "blessed"]
    assert (tmp_path / "lavapipe" / "ring_1.png").is_file()
    with pytest.raises(ValueError, match="no 'color' output"):
        g.check({"depth": np.zeros((2, 2), np.float32)})


PLUGIN_TEST = """
import numpy as np
import umbra

def test_yard(umbra_golden):
    r = umbra.OffscreenRenderer(64, 48, validation=True)
    scene = umbra.Scene()
    scene.add_mesh(np.array([[-0.5, 0.3, -0.5], [0.5, 0.3, -0.5], [0.5, 0.3, 0.5], [-0.5, 0.3, 0.5]]), np.array([[0, 2, 1], [0, 3, 2]]))
    scene.add_ground()
    scene.add_directional_light((0.4, -1.0, -0.3))
    camera, pose = umbra.PerspectiveCamera(np.pi / 4, 0.1), umbra.look_at((0, 2, 3), (0, 0, 0))
    umbra_golden.check(r.render(scene, camera, pose, outputs=("color", "shadow")), renderer=r)
    r.close()
"""


def test_the_plugin_end_to_end(pytester, monkeypatch):
    monkeypatch.delenv("UMBRA_BLESS", raising=False)
    monkeypatch.delenv("CI", raising=False)
    pytester.makepyfile(test_yard=PLUGIN_TEST)
    first = pytester.runpytest_subprocess()
    first.assert_outcomes(failed=1)
    first.stdout.fnmatch_lines(["*GoldenMismatch: no golden at*UMBRA_BLESS=1*"])
    monkeypatch.setenv("CI", "true")
    refused = pytester.runpytest_subprocess("--umbra-bless")
    refused.assert_outcomes(failed=1)
    refused.stdout.fnmatch_lines(["*refused under CI*"])
    monkeypatch.delenv("CI")
    pytester.runpytest_subprocess("--umbra-bless").assert_outcomes(passed=1)
    assert (pytester.path / "golden" / "lavapipe" / "test_yard.png").is_file()
    pytester.runpytest_subprocess().assert_outcomes(passed=1)
    # A deliberate change (the sun moved): the test fails, and --umbra-report writes the page
    # over the failed golden and names it.
    pytester.makepyfile(test_yard=PLUGIN_TEST.replace("(0.4, -1.0, -0.3)", "(-0.4, -1.0, -0.3)"))
    changed = pytester.runpytest_subprocess("--umbra-report", "report.html")
    changed.assert_outcomes(failed=1)
    changed.stdout.fnmatch_lines(["umbra report: *report.html (1 failed golden(s))", "*GoldenMismatch*shading changed*"])
    page = (pytester.path / "report.html").read_text()
    assert "lavapipe/test_yard.png" in page and page.count("data:image/png;base64,") == 6
    # Blessing accepts the change; a passing session writes no page.
    pytester.runpytest_subprocess("--umbra-bless").assert_outcomes(passed=1)
    (pytester.path / "report.html").unlink()
    pytester.runpytest_subprocess("--umbra-report", "report.html").assert_outcomes(passed=1)
    assert not (pytester.path / "report.html").exists()
