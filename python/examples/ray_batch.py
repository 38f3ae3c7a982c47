"""Render a turntable of a glTF on a Ray cluster: N camera poses as jobs, shards of .npz with a
manifest. On one machine it starts a local cluster; on a real one, run it on a node of the
cluster with RAY_ADDRESS set (or `ray.init(address="auto")`) and an out folder every node can
write.

    python python/examples/ray_batch.py MODEL.glb OUT_DIR [JOBS] [WORKERS]
"""
import os
import sys
import time

import numpy as np
import ray

import umbra
import umbra.ray

model, out = sys.argv[1], sys.argv[2]
jobs_n = int(sys.argv[3]) if len(sys.argv) > 3 else 200
workers = int(sys.argv[4]) if len(sys.argv) > 4 else 2

scene = umbra.load(model)
lo, hi = (np.array(v) for v in scene.bounds)
centre, radius = (lo + hi) / 2, float(np.linalg.norm(hi - lo))
jobs = []
for k in range(jobs_n):
    a = 2 * np.pi * k / jobs_n
    eye = centre + radius * np.array([np.sin(a), 0.5, np.cos(a)])
    jobs.append({"scene": os.path.abspath(model),
                 "camera_pose": umbra.look_at(eye, centre).tolist(),
                 "camera": {"yfov": np.pi / 4}})

if os.environ.get("RAY_ADDRESS"):
    ray.init()
else:
    ray.init(num_cpus=workers, include_dashboard=False)
t = time.time()
manifest = umbra.ray.render_jobs(jobs, out, 320, 240, num_workers=workers)
print(f"{jobs_n} jobs on {workers} workers: {time.time() - t:.1f} s "
      f"({manifest['seconds']:.1f} s in render_jobs), {len(manifest['shards'])} shards in {out}")
ray.shutdown()
