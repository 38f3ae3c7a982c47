#!/usr/bin/env python3
"""Per-frame time of umbra's Python renderer on the pyrender peer's scenes (the same triangles,
camera and sun as ../shared/peers/pyrender/bench_pyrender.py), for side-by-side runs in the
same minutes. Prints one JSON line.

  bench.py MODEL.gltf [--msaa 1|4] [--post-aa none|fxaa] [--supersample 1|2] [--width 1280 --height 720]
           [--frames 15] [--warmup 3]
  bench.py --gltf-scene EXPORTED.gltf ...   # bench_pyrender.py --synthetic 16 --export-gltf
  bench.py ... --batch 100                   # render_batch of N poses against N render calls

Each frame is ``render(scene, camera, pose)``: colour and depth read back into numpy arrays,
as pyrender's ``render`` returns them, with shadows.
"""

import argparse
import json
import statistics
import time

import numpy as np

import umbra


def box(extents):
    """A box's positions and indices (for the peer's ground)."""
    import trimesh

    b = trimesh.creation.box(extents=extents)
    return np.asarray(b.vertices, np.float32), np.asarray(b.faces, np.uint32)


def peer_scene(path):
    """The model with the peer's ground (a box 4× the model's extent, 1 % thick, under it), its
    camera (from centre + (0.5, 0.75, 1.9) × size) and sun (travelling (0.9, −1, −0.25))."""
    scene = umbra.load(path)
    lo, hi = (np.array(v) for v in scene.bounds)
    size = float((hi - lo).max())
    centre = (lo + hi) / 2
    side, thick = 4 * size, 0.01 * size
    pose = np.eye(4)
    pose[:3, 3] = [centre[0], lo[1] - thick / 2 - 1e-4 * size, centre[2]]
    p, i = box([side, thick, side])
    scene.add_mesh(p, i, base_color=(0.8, 0.8, 0.8, 1.0), roughness=0.9, pose=pose, name="ground")
    scene.add_directional_light((0.9, -1.0, -0.25), intensity=3.5, color=(1.0, 0.98, 0.95))
    camera = umbra.PerspectiveCamera(np.radians(45.0), znear=0.01 * size, zfar=100.0 * size)
    return scene, camera, umbra.look_at(centre + np.array([0.5, 0.75, 1.9]) * size, centre)


def timed(f, n):
    out = []
    for _ in range(n):
        t = time.perf_counter()
        f()
        out.append((time.perf_counter() - t) * 1e3)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("gltf", nargs="?")
    ap.add_argument("--gltf-scene", help="a glTF with its own camera and sun (the peer's export)")
    ap.add_argument("--width", type=int, default=1280)
    ap.add_argument("--height", type=int, default=720)
    ap.add_argument("--msaa", type=int, default=1)
    ap.add_argument("--post-aa", default="none", choices=["none", "fxaa"])
    ap.add_argument("--supersample", type=int, default=1, choices=[1, 2])
    ap.add_argument("--frames", type=int, default=15)
    ap.add_argument("--warmup", type=int, default=3)
    ap.add_argument("--batch", type=int, default=0)
    ap.add_argument("--png")
    a = ap.parse_args()
    if a.gltf_scene:
        scene = umbra.load(a.gltf_scene)
        (camera, pose), = scene.cameras[:1]
    else:
        scene, camera, pose = peer_scene(a.gltf)
    t = time.perf_counter()
    r = umbra.OffscreenRenderer(a.width, a.height, msaa=a.msaa)
    create_ms = (time.perf_counter() - t) * 1e3
    t = time.perf_counter()
    aa = {"post_aa": a.post_aa, "supersample": a.supersample}
    color, _ = r.render(scene, camera, pose, **aa)
    first_ms = (time.perf_counter() - t) * 1e3
    if a.png:
        from PIL import Image

        Image.fromarray(color).save(a.png)
    timed(lambda: r.render(scene, camera, pose, **aa), a.warmup)
    frames = timed(lambda: r.render(scene, camera, pose, **aa), a.frames)
    out = {
        "scene": scene.name,
        "triangles": scene.triangles,
        "device": r.device,
        "size": [a.width, a.height],
        "msaa": r.samples,
        "post_aa": a.post_aa,
        "supersample": a.supersample,
        "renderer_create_ms": round(create_ms, 1),
        "first_frame_ms": round(first_ms, 1),
        "frame_ms": {
            "min": round(min(frames), 2),
            "median": round(statistics.median(frames), 2),
            "max": round(max(frames), 2),
            "n": len(frames),
        },
    }
    if a.batch:
        # Poses around the first, the model staying in view.
        angles = np.linspace(-0.3, 0.3, a.batch)
        centre = np.append(np.mean(np.array(scene.bounds), axis=0), 1.0)
        poses = []
        for ang in angles:
            c, s = np.cos(ang), np.sin(ang)
            rot = np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1.0]])
            move = np.eye(4)
            move[:3, 3] = centre[:3]
            back = np.eye(4)
            back[:3, 3] = -centre[:3]
            poses.append(move @ rot @ back @ pose)
        poses = np.stack(poses)
        t = time.perf_counter()
        r.render_batch(scene, camera, poses)
        batch_ms = (time.perf_counter() - t) * 1e3
        t = time.perf_counter()
        for p in poses:
            r.render(scene, camera, p)
        calls_ms = (time.perf_counter() - t) * 1e3
        out["batch"] = {"poses": a.batch, "render_batch_ms": round(batch_ms, 1),
                        "render_calls_ms": round(calls_ms, 1)}
    r.close()
    print(json.dumps(out))


if __name__ == "__main__":
    main()
