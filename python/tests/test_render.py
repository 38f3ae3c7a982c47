"""umbra from Python on lavapipe, validation on: shapes and dtypes, depth and segmentation read
what the geometry says, the Python render equals the command line's to the byte, poses move the
image, batches equal single renders (shared shadow maps: in any order), bad input raises, and the GIL is released while rendering."""

import json
import struct
import subprocess
import threading
import time

import numpy as np
import pytest
from PIL import Image

import umbra
from conftest import ROOT, quad, write_glb

W, H = 160, 120


def head_on(distance):
    """A 45° camera on the +Z axis at `distance`, looking at the origin."""
    return umbra.PerspectiveCamera(np.pi / 4, znear=0.1), umbra.look_at((0, 0, distance), (0, 0, 0))


def test_shapes_and_dtypes(renderer):
    scene = umbra.Scene()
    p, i = quad(2.0)
    scene.add_mesh(p, i, base_color=(0.8, 0.3, 0.2, 1.0))
    scene.add_directional_light((0.3, -1.0, -0.5))
    camera, pose = head_on(3.0)
    color, depth = renderer.render(scene, camera, pose)
    assert color.shape == (H, W, 3) and color.dtype == np.uint8
    assert depth.shape == (H, W) and depth.dtype == np.float32
    out = renderer.render(
        scene, camera, pose, outputs=("color", "depth", "segmentation", "normals", "shadow")
    )
    want = {
        "color": ((H, W, 3), np.uint8),
        "depth": ((H, W), np.float32),
        "segmentation": ((H, W), np.uint32),
        "normals": ((H, W, 3), np.float32),
        "shadow": ((H, W), np.float32),
    }
    assert {k: (v.shape, v.dtype) for k, v in out.items()} == want
    # The colour of both calls is the same frame.
    assert np.array_equal(out["color"], color)


def test_the_frame_depth_equals_the_aov_depth():
    # At one sample a pixel render() reads the lit frame's own depth buffer; it must equal the
    # AOV pass's bit for bit, sky, blended (no depth) and masked surfaces included.
    scene = umbra.Scene()
    p, i = quad(1.0)
    scene.add_mesh(p, i, base_color=(0.8, 0.8, 0.8, 1.0))
    scene.add_mesh(*quad(0.6, 0.4), base_color=(0.2, 0.4, 0.9, 0.5), alpha_mode="BLEND",
                   pose=np.array([[1, 0, 0, 0.5], [0, 1, 0, 0.3], [0, 0, 1, 0], [0, 0, 0, 1.0]]))
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    colors = np.array([[1, 1, 1, 0.0], [1, 1, 1, 1.0], [1, 1, 1, 1.0], [1, 1, 1, 0.0]], np.float32)
    scene.add_mesh(*quad(0.6, 0.2), uvs=uv, colors=colors, alpha_mode="MASK", alpha_cutoff=0.5,
                   pose=np.array([[1, 0, 0, -0.5], [0, 1, 0, -0.3], [0, 0, 1, 0], [0, 0, 0, 1.0]]))
    scene.add_ground()
    scene.add_directional_light((0.3, -1.0, -0.5))
    r = umbra.OffscreenRenderer(W, H, msaa=1, validation=True)
    camera, pose = umbra.PerspectiveCamera(np.pi / 4, 0.1), umbra.look_at((0.5, 1.5, 3), (0, 0, 0))
    _, depth = r.render(scene, camera, pose)
    aov = r.render(scene, camera, pose, outputs=("depth",))["depth"]
    assert np.array_equal(depth, aov), np.count_nonzero(depth != aov)
    assert np.count_nonzero(depth == 0) > 0 and np.count_nonzero(depth > 0) > W * H // 4
    assert r.validation_problems == 0
    r.close()


@pytest.mark.parametrize("orthographic", [False, True])
def test_depth_of_a_plane_is_its_distance(renderer, orthographic):
    scene = umbra.Scene()
    p, i = quad(1.0)
    scene.add_mesh(p, i)
    camera, pose = head_on(3.0)
    if orthographic:
        camera = umbra.OrthographicCamera(2.0, 1.5, 0.1, 10.0)
    depth = renderer.render(scene, camera, pose, outputs=("depth",))["depth"]
    centre = depth[H // 2, W // 2]
    assert abs(centre - 3.0) <= 3.0 * 1e-4, centre
    # Measured: the quad's pixels all read 3.0000 (perspective: largest deviation 1.2e-7
    # relative); the corners, off the quad, 0.
    on = depth[depth > 0]
    assert np.max(np.abs(on - 3.0)) <= 3.0 * 1e-4
    assert depth[0, 0] == 0.0 and depth[-1, -1] == 0.0


def test_segmentation_ids_of_two_instances(renderer):
    scene = umbra.Scene()
    p, i = quad(0.8)
    left = scene.add_mesh(p, i, pose=np.array([[1, 0, 0, -0.6], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]))
    right = scene.add_mesh(p, i, pose=np.array([[1, 0, 0, 0.6], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]))
    assert (left, right) == (0, 1)
    camera, pose = head_on(3.0)
    seg = renderer.render(scene, camera, pose, outputs=("segmentation",))["segmentation"]
    # 45° from 3 units, 120 rows: 48.3 pixels a unit; the quads' centres at x = 80 ∓ 29.
    assert seg[60, 80 - 29] == left + 1
    assert seg[60, 80 + 29] == right + 1
    assert seg[60, 80] == 0 and seg[5, 5] == 0
    assert set(np.unique(seg)) == {0, 1, 2}
    # Exact: each quad covers a solid block of its own id (no blend at their edges).
    assert np.count_nonzero(seg == 1) == np.count_nonzero(seg == 2)


def test_python_render_equals_the_command_line_to_the_byte(renderer, tmp_path, umbra_bin):
    p, i = quad(1.0)
    b = np.array([[-0.3, 0, -0.3], [0.3, 0, -0.3], [0.3, 0.6, -0.3], [-0.3, 0.6, -0.3]], np.float32)
    model = write_glb(
        tmp_path / "model.glb",
        [(p, i, (0.9, 0.5, 0.2, 1.0), (0, 0.5, 0)), (b, i, (0.2, 0.5, 0.9, 1.0), (0.2, 0, 0.4))],
        lights=[((-0.3826834, 0.0, 0.0, 0.9238795), 2.0)],
    )
    png = tmp_path / "cli.png"
    subprocess.run(
        [umbra_bin, "render", model, "--size", f"{W}x{H}", "-o", str(png)],
        check=True,
        capture_output=True,
        env={"UMBRA_DEVICE": "llvmpipe", "PATH": "/usr/bin:/bin"},
    )
    cli = np.asarray(Image.open(png).convert("RGB"))
    scene = umbra.load(model)
    camera, pose = scene.default_view(W, H)
    color, _ = renderer.render(scene, camera, pose)
    assert np.array_equal(color, cli), f"{np.count_nonzero(color != cli)} values differ"


def test_a_pose_change_moves_the_image(renderer):
    scene = umbra.Scene()
    p, i = quad(0.6)
    k = scene.add_mesh(p, i)
    camera, pose = head_on(3.0)
    a = renderer.render(scene, camera, pose, outputs=("color", "segmentation"))
    moved = np.eye(4)
    moved[0, 3] = 0.5
    scene.set_pose(k, moved)
    b = renderer.render(scene, camera, pose, outputs=("color", "segmentation"))
    assert not np.array_equal(a["color"], b["color"])
    # The quad's pixels moved right by 0.5 units: 24 pixels at 48.3 a unit.
    xa = np.nonzero(a["segmentation"][60])[0]
    xb = np.nonzero(b["segmentation"][60])[0]
    assert abs((xb.mean() - xa.mean()) - 0.5 * 48.3) < 1.0, (xa.mean(), xb.mean())


def test_time_poses_an_animated_file(renderer, tmp_path):
    # A quad that slides from x = 0 at 0 s to x = 1 at 2 s (linear): at 0.5 s it is at 0.25,
    # at 1.5 s at 0.75, and past the end it holds at 1.
    p, i = quad(0.6)
    model = write_glb(
        tmp_path / "slide.glb",
        [(p, i, (0.8, 0.8, 0.8, 1.0), (0, 0, 0))],
        animation=("Slide", 0, [0.0, 2.0], [[0, 0, 0], [1, 0, 0]]),
    )
    scene = umbra.load(model)
    assert scene.animations == ["Slide"]
    camera, pose = head_on(3.0)

    def centre_x(**settings):
        seg = renderer.render(scene, camera, pose, outputs=("segmentation",), **settings)
        return np.nonzero(seg["segmentation"][60])[0].mean()

    rest = centre_x()
    # 48.3 pixels a unit (45° from 3 units, 120 rows); measured offsets within 0.5 px.
    for t, x in [(0.5, 0.25), (1.5, 0.75), (9.0, 1.0)]:
        got = centre_x(time=t, animation="Slide") - rest
        assert abs(got - x * 48.3) < 1.0, (t, got)
    assert abs(centre_x(time=0.5, animation=0) - rest - 0.25 * 48.3) < 1.0
    with pytest.raises(ValueError, match="animation"):
        renderer.render(scene, camera, pose, time=0.5, animation="Walk")


def test_a_batch_equals_single_renders(renderer):
    scene = umbra.Scene()
    p, i = quad(1.0)
    scene.add_mesh(p, i, base_color=(0.2, 0.7, 0.3, 1.0))
    scene.add_ground()
    camera = umbra.PerspectiveCamera(np.pi / 4, znear=0.1)
    poses = np.stack([umbra.look_at((x, 1.0, 3.0), (0, 0, 0)) for x in (-1.0, 0.0, 1.0)])
    every = ("color", "depth", "segmentation", "normals")
    own = renderer.render_batch(scene, camera, poses, outputs=every, share_shadows=False)
    assert own["color"].shape == (3, H, W, 3) and own["depth"].shape == (3, H, W)
    assert own["segmentation"].shape == (3, H, W) and own["normals"].shape == (3, H, W, 3)
    for k in range(3):
        # Each output of a batch (frames in flight, ids from the camera pass) is a single call's.
        one = renderer.render(scene, camera, poses[k], outputs=every)
        for name in every:
            assert np.array_equal(own[name][k], one[name]), (k, name)
        # And the ids and normals are the extra pass's (asked for without the image).
        alone = renderer.render(scene, camera, poses[k], outputs=("segmentation", "normals"))
        assert np.array_equal(alone["segmentation"], one["segmentation"]), k
        assert np.array_equal(alone["normals"], one["normals"]), k
        assert set(np.unique(one["segmentation"])) == {0, 1, 2}, k
    # The shared map is fitted to all the poses, whatever their order: the same pixels
    # reversed; the same depth as each pose's own fit, and colour within the shadows' outlines.
    shared = renderer.render_batch(scene, camera, poses, outputs=("color", "depth"))
    back = renderer.render_batch(scene, camera, poses[::-1], outputs=("color", "depth"))
    assert np.array_equal(shared["color"], back["color"][::-1])
    assert np.array_equal(shared["depth"], own["depth"])
    changed = np.any(shared["color"] != own["color"], axis=-1).mean()
    # Measured: 13 of 57,600 pixels (2.3e-4), on the outlines of the quad's shadow.
    assert changed < 1e-3, changed


def test_bad_input_raises(tmp_path):
    with pytest.raises(umbra.LoadError, match="cannot read"):
        umbra.load(tmp_path / "missing.glb")
    broken = tmp_path / "broken.glb"
    broken.write_bytes(b"glTF not really")
    with pytest.raises(umbra.LoadError):
        umbra.load(broken)
    s = umbra.Scene()
    with pytest.raises(ValueError, match="add_ground: the scene has no geometry"):
        s.add_ground()
    with pytest.raises(ValueError, match="index 7 is past the 4 positions"):
        s.add_mesh(quad(1.0)[0], [[0, 1, 7]])
    with pytest.raises(ValueError, match="expected \\(n, 3\\)"):
        s.add_mesh(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="expected \\(4, 4\\)"):
        s.add_mesh(*quad(1.0), pose=np.eye(3))
    with pytest.raises(ValueError, match="yfov"):
        umbra.PerspectiveCamera(0.0)
    r = umbra.OffscreenRenderer(16, 16)
    s.add_mesh(*quad(1.0))
    cam, pose = head_on(2.0)
    with pytest.raises(TypeError, match="unknown setting 'shadowmap'"):
        r.render(s, cam, pose, shadowmap=512)
    with pytest.raises(ValueError, match="unknown output"):
        r.render(s, cam, pose, outputs=("colour",))
    with pytest.raises(ValueError, match="expected \\(n, 4, 4\\)"):
        r.render_batch(s, cam, np.zeros((0, 4, 4)))
    # Matrices that place no camera: each refused in words, in a batch by its index.
    flat, far = pose.copy(), pose.copy()
    flat[:3, 1] = 0.0
    far[2, 3] = 1e30
    with pytest.raises(ValueError, match="camera_pose: its last row is 0 0 0 0"):
        r.render(s, cam, np.zeros((4, 4)))
    with pytest.raises(ValueError, match="camera_pose: its axes are degenerate"):
        r.render(s, cam, flat)
    with pytest.raises(ValueError, match="poses\\[1\\]: its position is 1e30 from the origin"):
        r.render_batch(s, cam, np.stack([pose, far]))
    with pytest.raises(ValueError, match="poses\\[0\\]: holds a NaN"):
        r.render_batch(s, cam, np.full((1, 4, 4), np.nan))
    # Stacked arrays no machine holds (100,000 frames of 16384², 188 TB): an exception before
    # any rendering, not an aborted interpreter.
    huge = umbra.OffscreenRenderer(16384, 16384)
    with pytest.raises(MemoryError, match="100000 frames of color, depth at 16384x16384 take"):
        huge.render_batch(s, cam, np.broadcast_to(pose, (100_000, 4, 4)))
    huge.close()
    with pytest.raises(ValueError, match="alpha_mode 'GLASS'"):
        s.add_mesh(*quad(1.0), alpha_mode="glass")
    with pytest.raises(ValueError, match="texture: needs uvs"):
        s.add_mesh(*quad(1.0), texture=np.zeros((2, 2, 3), np.uint8))
    with pytest.raises(ValueError, match="aspect"):
        r.render(s, umbra.PerspectiveCamera(1.0, aspect=2.0), pose)
    r.close()
    with pytest.raises(umbra.UmbraError, match="closed"):
        r.render(s, cam, pose)
    with pytest.raises(ValueError):
        umbra.OffscreenRenderer(0, 10)


def test_settings_act_like_the_command_line_options(renderer):
    scene = umbra.Scene()
    scene.add_mesh(*quad(0.5, 0.3))
    scene.add_ground()
    scene.add_directional_light((0.4, -1.0, -0.3))
    camera, pose = umbra.PerspectiveCamera(np.pi / 4, 0.1), umbra.look_at((0, 2, 3), (0, 0, 0))
    base = renderer.render(scene, camera, pose, outputs=("color", "shadow"))
    none = renderer.render(scene, camera, pose, outputs=("shadow",), shadows=False)["shadow"]
    assert base["shadow"].min() == 0.0 and none.min() > 0.0  # facing-only without the map
    dark = renderer.render(scene, camera, pose, exposure="x0.1")[0]
    assert dark.mean() < base["color"].mean() * 0.5
    white = renderer.render(scene, camera, pose, background="#ffffff")[0]
    assert tuple(white[0, 0]) == (255, 255, 255)
    # FXAA moves only pixels on or beside an edge (measured: 2.1 % of this frame).
    smooth = renderer.render(scene, camera, pose, post_aa="fxaa")[0]
    moved = np.any(smooth != base["color"], axis=2).mean()
    assert 0.01 < moved < 0.04, moved
    with pytest.raises(ValueError, match="post_aa: post anti-aliasing 'smaa'"):
        renderer.render(scene, camera, pose, post_aa="smaa")
    # 2×2 supersampling: each pixel the mean, in linear light, of the render at twice the size
    # (measured: at most 1 level off, rounding), and the depth still at the image's size.
    ss = renderer.render(scene, camera, pose, supersample=2)
    twice = umbra.OffscreenRenderer(2 * W, 2 * H, validation=True)
    big = twice.render(scene, camera, pose)
    problems = twice.validation_problems
    twice.close()
    assert problems == 0, f"{problems} validation message(s) at twice the size"
    assert ss[0].shape == (H, W, 3)
    assert np.array_equal(ss[1], renderer.render(scene, camera, pose)[1]), "depth moved"
    lin = np.where(big[0] <= 10, big[0] / 255 / 12.92, ((big[0] / 255 + 0.055) / 1.055) ** 2.4)
    mean = lin.reshape(H, 2, W, 2, 3).mean(axis=(1, 3))
    enc = np.where(mean <= 0.0031308, mean * 12.92, 1.055 * mean ** (1 / 2.4) - 0.055)
    assert np.abs(np.round(enc * 255) - ss[0]).max() <= 1
    with pytest.raises(ValueError, match=r"supersample: 3 is not one of \[1, 2\]"):
        renderer.render(scene, camera, pose, supersample=3)
    # Exact shadows: hard (0 or 1 only, where the map's filter leaves greys on edges), and the
    # same verdict as the map away from its edges (measured: no pixel differs at 0.5).
    out = renderer.render(scene, camera, pose, outputs=("shadow", "depth"), shadow_method="exact")
    exact, surface = out["shadow"], out["depth"] > 0.0
    assert set(np.unique(exact[surface])) <= {0.0, 1.0}, np.unique(exact[surface])
    assert len(np.unique(base["shadow"][surface])) > 2
    differ = ((exact > 0.5) != (base["shadow"] > 0.5)).mean()
    assert differ < 0.01, differ
    shadowed = ((exact == 0.0) & surface).sum(), ((base["shadow"] < 0.5) & surface).sum()
    # Measured: 11 pixels in shadow in both (the card's thin shadow at this distance).
    assert shadowed[0] >= 8 and abs(shadowed[0] - shadowed[1]) <= 2, shadowed
    # Hybrid shadows: the exact verdicts (measured: identical at every pixel).
    hybrid = renderer.render(scene, camera, pose, outputs=("shadow",), shadow_method="hybrid")
    assert np.array_equal(hybrid["shadow"], exact)
    # Contact shadows only darken (measured: no pixel of this frame changes at 0.5).
    contact = renderer.render(scene, camera, pose, outputs=("shadow",), contact_shadows=True)
    assert ((contact["shadow"] > 0.5) & (base["shadow"] <= 0.5)).sum() == 0
    with pytest.raises(ValueError, match="shadow_method: shadow method 'rays'"):
        renderer.render(scene, camera, pose, shadow_method="rays")


def test_the_gil_is_released_while_rendering():
    scene = umbra.load(umbra_fixture_model())
    camera, pose = scene.default_view(320, 240)
    r = umbra.OffscreenRenderer(320, 240)
    r.render(scene, camera, pose)  # compile the pipelines first
    ticks, done = [0], threading.Event()

    def count():
        while not done.is_set():
            ticks[0] += 1
            time.sleep(0.0005)

    t = threading.Thread(target=count)
    t.start()
    start = time.perf_counter()
    for _ in range(5):
        r.render(scene, camera, pose)
    spent = time.perf_counter() - start
    done.set()
    t.join()
    r.close()
    # Another Python thread ran throughout (a held GIL would leave it at a handful of ticks).
    assert ticks[0] > spent * 200, (ticks[0], spent)


def umbra_fixture_model():
    """A small model for timing: the demo-like boxes written once."""
    import tempfile

    path = f"{tempfile.gettempdir()}/umbra-gil-model.glb"
    p, i = quad(1.0)
    write_glb(path, [(p, i, (0.7, 0.7, 0.7, 1.0), (0, 0, 0))])
    return path


def test_trimesh_meshes_and_scenes():
    import trimesh
    box = trimesh.creation.box((1.0, 1.0, 1.0))
    box.visual.vertex_colors = [200, 30, 30, 255]
    s = umbra.Scene.from_trimesh(box)
    assert s.instances == 1 and s.triangles == 12
    ts = trimesh.Scene()
    ts.add_geometry(box, transform=trimesh.transformations.translation_matrix((2, 0, 0)))
    ts.add_geometry(trimesh.creation.icosphere())
    s2 = umbra.Scene.from_trimesh(ts)
    assert s2.instances == 2
    lo, hi = s2.bounds
    assert hi[0] == pytest.approx(2.5) and lo[0] == pytest.approx(-1.0, abs=1e-3)
    r = umbra.OffscreenRenderer(64, 48)
    camera, pose = s.default_view(64, 48)
    color, _ = r.render(s, camera, pose)
    # The red box fills the middle of the frame.
    mid = color[24, 32].astype(int)
    assert mid[0] > mid[1] + 40, mid
    r.close()


def test_trimesh_face_colours_stay_on_their_faces():
    import trimesh

    # A square of two triangles, the lower right red and the upper left blue (trimesh's face
    # colours): each half keeps its own colour, unblended at the shared corners.
    p, i = quad(2.0)
    mesh = trimesh.Trimesh(p, i, process=False)
    mesh.visual.face_colors = [[255, 0, 0, 255], [0, 0, 255, 255]]
    scene = umbra.Scene.from_trimesh(mesh)
    assert scene.triangles == 2
    r = umbra.OffscreenRenderer(W, H, validation=True)
    camera, pose = head_on(3.0)
    color = r.render(scene, camera, pose, background="#000000", ambient=1.0)[0].astype(int)
    # The square spans 48.3 px a unit around (80, 60): the middles of the two halves.
    lower_right, upper_left = color[60 + 24, 80 + 24], color[60 - 24, 80 - 24]
    assert lower_right[0] > 200 and max(lower_right[1], lower_right[2]) < 10, lower_right
    assert upper_left[2] > 200 and max(upper_left[0], upper_left[1]) < 10, upper_left
    # What the conversion hands over: each face its own corners and colour; one colour on
    # every face stays the material's, the corners shared.
    from umbra._trimesh import to_arrays

    two = to_arrays(mesh)[0]
    assert two["positions"].shape == (6, 3) and (two["positions"] == p[i.reshape(-1)]).all()
    assert (two["colors"] == [[255, 0, 0, 255]] * 3 + [[0, 0, 255, 255]] * 3).all()
    mesh.visual.face_colors = [[0, 200, 0, 255], [0, 200, 0, 255]]
    one = to_arrays(mesh)[0]
    assert one["positions"].shape == (4, 3) and one["colors"] is None
    assert one["base_color"] == pytest.approx([0.0, 200 / 255, 0.0, 1.0])
    assert r.validation_problems == 0
    r.close()


def test_trimesh_textures_keep_their_orientation():
    import trimesh
    from PIL import Image as PILImage

    # A 2x2 image: red top-left, green top-right, blue bottom-left, white bottom-right, on a
    # quad whose UVs follow trimesh's convention (v = 0 at the image's bottom).
    img = PILImage.fromarray(
        np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]], np.uint8)
    )
    p, i = quad(2.0)
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)
    mesh = trimesh.Trimesh(p, i, process=False)
    mesh.visual = trimesh.visual.TextureVisuals(uv=uv, image=img)
    scene = umbra.Scene.from_trimesh(mesh)
    r = umbra.OffscreenRenderer(W, H, validation=True)
    camera, pose = head_on(3.0)
    color = r.render(scene, camera, pose, background="#000000", ambient=1.0)[0].astype(int)
    # The quad spans 48.3 px a unit around (80, 60): sample each quarter's middle.
    tl, tr = color[60 - 24, 80 - 24], color[60 - 24, 80 + 24]
    bl, br = color[60 + 24, 80 - 24], color[60 + 24, 80 + 24]
    assert tl[0] > 2 * max(tl[1], tl[2]), tl
    assert tr[1] > 2 * max(tr[0], tr[2]), tr
    assert bl[2] > 2 * max(bl[0], bl[1]), bl
    assert min(br) > 100, br
    assert r.validation_problems == 0
    r.close()



def test_compressed_files_load_and_render_alike(renderer, tmp_path):
    # The same generated model as gltf-pipeline wrote it with Draco and as gltfpack wrote it with
    # meshopt (-cc) and quantized attributes (tests/data/compressed, tools in its README): both
    # load, and at the same view their images agree within the loader's 35 dB bound.
    data = ROOT / "tests/data/compressed"
    draco = umbra.load(data / "normal_mapped.draco.glb")
    meshopt = umbra.load(data / "normal_mapped.meshopt-cc.glb")
    camera, pose = draco.default_view(W, H)
    a, _ = renderer.render(draco, camera, pose)
    b, _ = renderer.render(meshopt, camera, pose)
    mse = np.mean((a.astype(float) - b.astype(float)) ** 2)
    psnr = 10 * np.log10(255**2 / mse) if mse > 0 else np.inf
    assert psnr >= 35.0, f"{psnr:.1f} dB"
    # The model covers the view's middle (not the sky's colour everywhere).
    assert len(np.unique(a[H // 3 : 2 * H // 3, W // 3 : 2 * W // 3].reshape(-1, 3), axis=0)) > 20
    # A Draco stream cut short is one line, as a LoadError.
    raw = bytearray((data / "normal_mapped.draco.glb").read_bytes())
    n = struct.unpack_from("<I", raw, 12)[0]
    doc = json.loads(raw[20 : 20 + n])
    view = doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"]
    doc["bufferViews"][view]["byteLength"] = 16
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    cut = bytes(raw[:12]) + struct.pack("<I4s", len(js), b"JSON") + js + bytes(raw[20 + n :])
    cut = cut[:8] + struct.pack("<I", len(cut)) + cut[12:]
    (tmp_path / "cut.glb").write_bytes(cut)
    with pytest.raises(umbra.LoadError, match="KHR_draco_mesh_compression.*does not decode"):
        umbra.load(tmp_path / "cut.glb")
