#!/usr/bin/env python3
"""How a batch's time grows with its number of poses: a ring of N poses around a box on a ground
under a sun (built in code, no files), rendered tiny (32×24, so that planning shows) with the
shared map and fitted per pose. Prints one JSON line per N: milliseconds per pose, each the
median of ``--repeat`` runs of the whole batch.

  batch_scaling.py [--poses 100 400 1600 3200] [--repeat 3]
"""

import argparse
import json
import statistics
import time

import numpy as np

import umbra
from batch_bench import ring
from bench import box


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--poses", type=int, nargs="+", default=[100, 400, 1600, 3200])
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    scene = umbra.Scene()
    scene.add_mesh(*box((1.0, 1.0, 1.0)))
    scene.add_ground()
    scene.add_directional_light((0.3, -1.0, 0.2), intensity=3.0)
    camera = umbra.PerspectiveCamera(np.pi / 3.0, znear=0.05, zfar=100.0)
    r = umbra.OffscreenRenderer(32, 24)
    base = umbra.look_at((0.0, 1.5, 3.0), (0.0, 0.0, 0.0))
    r.render_batch(scene, camera, ring(scene, base, 2))  # pipelines compiled, scene uploaded
    for n in a.poses:
        poses = ring(scene, base, n)
        out = {"poses": n, "device": r.device, "ms_per_pose": {}}
        for name, share in (("shared", True), ("per pose", False)):
            runs = []
            for _ in range(a.repeat):
                t = time.perf_counter()
                r.render_batch(scene, camera, poses, share_shadows=share)
                runs.append((time.perf_counter() - t) * 1e3 / n)
            out["ms_per_pose"][name] = round(statistics.median(runs), 2)
        print(json.dumps(out), flush=True)
    r.close()


if __name__ == "__main__":
    main()
