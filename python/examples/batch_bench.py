#!/usr/bin/env python3
"""Per-image time of a dataset batch: N views in a ring around a model on the pyrender peer's
ground and sun (bench.py's ``peer_scene``), rendered as single ``render`` calls and as
``render_batch`` with each pose's own shadow fit and with the shared map, with and without
segmentation. Prints one JSON line (milliseconds per image, each the median of ``--repeat``
runs of the whole ring).

  batch_bench.py MODEL.gltf [--views 64] [--width 640 --height 480] [--repeat 3]
  batch_bench.py --gltf-scene EXPORTED.gltf ...   # bench_pyrender.py --synthetic 16 --export-gltf
"""

import argparse
import json
import statistics
import time

import numpy as np

import umbra
from bench import peer_scene


def ring(scene, pose, n):
    """``n`` poses turning ``pose`` around the vertical axis through the scene's centre."""
    centre = np.mean(np.array(scene.bounds), axis=0)
    out = []
    for ang in np.linspace(0.0, 2 * np.pi, n, endpoint=False):
        c, s = np.cos(ang), np.sin(ang)
        rot = np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1.0]])
        move, back = np.eye(4), np.eye(4)
        move[:3, 3], back[:3, 3] = centre, -centre
        out.append(move @ rot @ back @ pose)
    return np.stack(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("gltf", nargs="?")
    ap.add_argument("--gltf-scene", help="a glTF with its own camera and sun (the peer's export)")
    ap.add_argument("--views", type=int, default=64)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    if a.gltf_scene:
        scene = umbra.load(a.gltf_scene)
        ((camera, pose),) = scene.cameras[:1]
    else:
        scene, camera, pose = peer_scene(a.gltf)
    poses = ring(scene, pose, a.views)
    r = umbra.OffscreenRenderer(a.width, a.height)
    # Pipelines compiled and the scene uploaded before any timing.
    r.render_batch(scene, camera, poses[:2], outputs=["color", "depth", "segmentation"])
    cases = {
        "single calls, color+depth": lambda: [r.render(scene, camera, p) for p in poses],
        "batch per-view shadows, color+depth": lambda: r.render_batch(
            scene, camera, poses, share_shadows=False
        ),
        "batch shared shadows, color+depth": lambda: r.render_batch(scene, camera, poses),
        "batch shared shadows, color+depth+segmentation": lambda: r.render_batch(
            scene, camera, poses, outputs=["color", "depth", "segmentation"]
        ),
    }
    out = {"scene": scene.name, "device": r.device, "size": [a.width, a.height],
           "views": a.views, "ms_per_image": {}}
    for name, f in cases.items():
        runs = []
        for _ in range(a.repeat):
            t = time.perf_counter()
            f()
            runs.append((time.perf_counter() - t) * 1e3 / a.views)
        out["ms_per_image"][name] = round(statistics.median(runs), 2)
    r.close()
    print(json.dumps(out))


if __name__ == "__main__":
    main()
