#!/usr/bin/env python3
"""Per-image time on pyrender's own example scene (its ``examples/example.py``: the fuze bottle,
drill, wood block and water bottle from its ``examples/models`` folder, and two 10 cm boxes with
vertex and face colours, all as trimesh meshes), the same scene built from the same trimesh
objects in both renderers, in a ring of N views around it. Prints one JSON line (milliseconds per
image, the median of ``--repeat`` runs of the whole ring).

  trimesh_bench.py MODELS_DIR [--views 64] [--width 640 --height 480] [--repeat 3]
  PYOPENGL_PLATFORM=egl PEER_PYTHON trimesh_bench.py MODELS_DIR --renderer pyrender

MODELS_DIR is pyrender's ``examples/models`` (github.com/mmatl/pyrender, MIT). Left out of the
example: its point cloud (umbra draws triangles only) and its spot and point lights; both
renderers get the example's directional light at its camera pose, with shadows, on a grey ground
under the models (pyrender draws no shadow without a receiver under them either).
"""

import argparse
import json
import os
import statistics
import time

import numpy as np
import trimesh


def example_scene(models):
    """pyrender's example meshes as one ``trimesh.Scene`` (its poses), its camera pose, and the
    example's model files missing from ``models`` (left out)."""
    s, missing = trimesh.Scene(), []

    def load(name):
        path = os.path.join(models, name)
        if os.path.exists(path) and os.path.getsize(path) > 0:
            return trimesh.load(path)
        missing.append(name)
        return None

    fuze = load("fuze.obj")
    if fuze is not None:
        s.add_geometry(fuze, transform=_at(0.1, 0.15, -fuze.vertices[:, 2].min()), geom_name="fuze")
    drill = load("drill.obj")
    if drill is not None:
        s.add_geometry(drill, transform=_at(0.1, 0.0, -drill.vertices[:, 2].min()), geom_name="drill")
    wood = load("wood.obj")
    if wood is not None:
        s.add_geometry(wood, geom_name="wood")
    bottle = load("WaterBottle.glb")
    if bottle is not None:
        bottle_pose = np.array(
            [[1.0, 0, 0, 0.1], [0, 0, -1.0, -0.16], [0, 1.0, 0, 0.13], [0, 0, 0, 1.0]]
        )
        s.add_geometry(list(bottle.geometry.values())[0], transform=bottle_pose, geom_name="bottle")
    rng = np.random.default_rng(0)
    boxv = trimesh.creation.box(extents=0.1 * np.ones(3))
    boxv.visual.vertex_colors = (rng.uniform(size=(len(boxv.vertices), 4)) * 255).astype(np.uint8)
    boxv.visual.vertex_colors[:, 3] = 255
    s.add_geometry(boxv, transform=_at(-0.1, 0.10, 0.05), geom_name="box_vertex_colours")
    boxf = trimesh.creation.box(extents=0.1 * np.ones(3))
    boxf.visual.face_colors = (rng.uniform(size=(len(boxf.faces), 4)) * 255).astype(np.uint8)
    boxf.visual.face_colors[:, 3] = 255
    s.add_geometry(boxf, transform=_at(-0.1, -0.10, 0.05), geom_name="box_face_colours")
    # A ground 1.2 m square under everything (z up, as in the example).
    ground = trimesh.creation.box(extents=[1.2, 1.2, 0.01])
    ground.visual.face_colors = [204, 204, 204, 255]
    s.add_geometry(ground, transform=_at(0.0, 0.0, -0.0051), geom_name="ground")
    s2 = np.sqrt(2) / 2
    cam_pose = np.array(
        [[0.0, -s2, s2, 0.5], [1.0, 0, 0, 0.0], [0.0, s2, s2, 0.4], [0.0, 0, 0, 1.0]]
    )
    return s, cam_pose, missing


def _at(x, y, z):
    m = np.eye(4)
    m[:3, 3] = [x, y, z]
    return m


def ring(pose, n):
    """``n`` poses turning ``pose`` around the vertical (z) axis through the origin."""
    out = []
    for ang in np.linspace(0.0, 2 * np.pi, n, endpoint=False):
        c, s = np.cos(ang), np.sin(ang)
        rot = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
        out.append(rot @ pose)
    return out


def median_ms(f, n_images, repeat):
    runs = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        runs.append((time.perf_counter() - t) * 1e3 / n_images)
    return round(statistics.median(runs), 1)


def bench_umbra(tscene, cam_pose, poses, a):
    import umbra

    scene = umbra.Scene.from_trimesh(tscene)
    # pyrender's DirectionalLight shines down its pose's -Z.
    scene.add_directional_light(tuple(-cam_pose[:3, 2]), intensity=3.0)
    camera = umbra.PerspectiveCamera(np.pi / 3.0, znear=0.05, zfar=100.0)
    r = umbra.OffscreenRenderer(a.width, a.height)
    stack = np.stack(poses)
    r.render_batch(scene, camera, stack[:2], outputs=["color", "depth", "segmentation"])
    n = len(poses)
    return {
        "single calls, color+depth": median_ms(
            lambda: [r.render(scene, camera, p) for p in poses], n, a.repeat
        ),
        "batch shared shadows, color+depth": median_ms(
            lambda: r.render_batch(scene, camera, stack), n, a.repeat
        ),
        "batch shared shadows, color+depth+segmentation": median_ms(
            lambda: r.render_batch(
                scene, camera, stack, outputs=["color", "depth", "segmentation"]
            ),
            n,
            a.repeat,
        ),
    }


def pyrender_scene(tscene, cam_pose):
    """The trimesh scene as pyrender's example builds it (``Mesh.from_trimesh`` per mesh, the
    coloured boxes flat-shaded) with the example's directional light."""
    import pyrender

    scene = pyrender.Scene(ambient_light=[0.02, 0.02, 0.02, 1.0])
    for node in tscene.graph.nodes_geometry:
        transform, name = tscene.graph[node]
        flat = name.startswith("box_") or name == "ground"
        scene.add(pyrender.Mesh.from_trimesh(tscene.geometry[name], smooth=not flat), pose=transform)
    scene.add(pyrender.DirectionalLight(color=np.ones(3), intensity=3.0), pose=cam_pose)
    return scene


def bench_pyrender(tscene, cam_pose, poses, a):
    import pyrender

    scene = pyrender_scene(tscene, cam_pose)
    cam = scene.add(pyrender.PerspectiveCamera(yfov=np.pi / 3.0, znear=0.05, zfar=100.0), pose=cam_pose)
    r = pyrender.OffscreenRenderer(a.width, a.height)
    flags = pyrender.RenderFlags.SHADOWS_DIRECTIONAL

    def run():
        for p in poses:
            scene.set_pose(cam, p)
            r.render(scene, flags)

    run()
    return {"pyrender, color+depth (4x MSAA, directional shadows)": median_ms(run, len(poses), a.repeat)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("models", help="pyrender's examples/models folder")
    ap.add_argument("--renderer", default="umbra", choices=["umbra", "pyrender"])
    ap.add_argument("--views", type=int, default=64)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--png", help="write the first view's colour here")
    a = ap.parse_args()
    tscene, cam_pose, missing = example_scene(a.models)
    poses = ring(cam_pose, a.views)
    bench = bench_umbra if a.renderer == "umbra" else bench_pyrender
    out = {
        "renderer": a.renderer,
        "views": a.views,
        "size": [a.width, a.height],
        "missing_models": missing,
        "triangles": int(sum(len(g.faces) for g in tscene.geometry.values())),
        "ms_per_image": bench(tscene, cam_pose, poses, a),
    }
    if a.png:
        _write_png(a, tscene, cam_pose)
    print(json.dumps(out))


def _write_png(a, tscene, cam_pose):
    from PIL import Image

    if a.renderer == "umbra":
        import umbra

        scene = umbra.Scene.from_trimesh(tscene)
        scene.add_directional_light(tuple(-cam_pose[:3, 2]), intensity=3.0)
        camera = umbra.PerspectiveCamera(np.pi / 3.0, znear=0.05, zfar=100.0)
        color, _ = umbra.OffscreenRenderer(a.width, a.height).render(scene, camera, cam_pose)
    else:
        import pyrender

        scene = pyrender_scene(tscene, cam_pose)
        scene.add(pyrender.PerspectiveCamera(yfov=np.pi / 3.0, znear=0.05, zfar=100.0), pose=cam_pose)
        r = pyrender.OffscreenRenderer(a.width, a.height)
        color, _ = r.render(scene, pyrender.RenderFlags.SHADOWS_DIRECTIONAL)
    Image.fromarray(np.ascontiguousarray(color)).save(a.png)


if __name__ == "__main__":
    main()
