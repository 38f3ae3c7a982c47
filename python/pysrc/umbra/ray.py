"""Batch rendering beyond one machine, on Ray (https://www.ray.io): a list of (scene, camera pose)
jobs rendered by a pool of Ray actors, one ``OffscreenRenderer`` per worker process, each scene
loaded once per worker, each shard's runs of jobs with the same scene, camera and settings
rendered as one ``render_batch`` (shadow maps drawn once per run), results written as compressed
``.npz`` shards (or PNGs) with a ``manifest.json`` saying which job is where and each worker's
images per second.

On one machine::

    import ray, umbra.ray
    ray.init(num_cpus=2)
    manifest = umbra.ray.render_jobs(jobs, "out", 640, 360, num_workers=2)

On a cluster, connect first (``ray.init(address="auto")`` on a node of it, or
``ray.init("ray://head:10001")``) and give an ``out_dir`` every node can write (a shared file
system); the code is the same. Each job is a dict::

    {"scene": "path/model.glb", "camera_pose": 4x4 pose,
     "camera": {"yfov": 0.785}            # or {"xmag": 2, "ymag": 1.5} for orthographic
     "settings": {"shadow_map": 4096}}    # optional, as OffscreenRenderer.render takes
"""

import json
import os
import time

import numpy as np

__all__ = ["render_jobs", "camera_of"]


def camera_of(spec):
    """The umbra camera of a job's ``camera`` dict (perspective by default: yfov pi/4)."""
    import umbra

    spec = dict(spec or {})
    if "xmag" in spec or "ymag" in spec:
        return umbra.OrthographicCamera(
            spec["xmag"], spec["ymag"], spec.get("znear", 0.05), spec.get("zfar", 100.0)
        )
    return umbra.PerspectiveCamera(
        spec.get("yfov", np.pi / 4), spec.get("znear", 0.05), spec.get("zfar")
    )


class _Worker:
    """One renderer in one worker process; scenes loaded once and kept."""

    def __init__(self, width, height, outputs, out_dir, png, device, settings):
        import umbra

        self.renderer = umbra.OffscreenRenderer(width, height, device=device)
        self.outputs = tuple(outputs)
        self.out_dir = out_dir
        self.png = png
        self.settings = dict(settings)
        self.scenes = {}

    def scene(self, path):
        import umbra

        if path not in self.scenes:
            self.scenes[path] = umbra.load(path)
        return self.scenes[path]

    def render(self, shard, jobs):
        """Renders ``jobs`` [(index, job)] into shard ``shard``, each run of jobs with the same
        scene, camera and settings as one ``render_batch`` (its shadow maps drawn once); returns
        its manifest entry (with the worker's process id and its rendering seconds)."""
        frames = {name: [] for name in self.outputs}
        start = time.time()
        for group in _runs(jobs):
            job = group[0]
            settings = dict(self.settings)
            settings.update(job.get("settings", {}))
            poses = np.stack([np.asarray(j["camera_pose"], dtype=np.float64) for j in group])
            out = self.renderer.render_batch(
                self.scene(job["scene"]),
                camera_of(job.get("camera")),
                poses,
                outputs=self.outputs,
                **settings,
            )
            for name in self.outputs:
                frames[name].extend(out[name])
        seconds = time.time() - start
        ids = [i for i, _ in jobs]
        if self.png:
            from PIL import Image

            files = []
            for k, i in enumerate(ids):
                name = f"job_{i:06d}.png"
                Image.fromarray(frames["color"][k]).save(os.path.join(self.out_dir, name))
                files.append(name)
            return {"shard": shard, "jobs": ids, "files": files, "worker": os.getpid(),
                    "seconds": seconds}
        name = f"shard_{shard:05d}.npz"
        arrays = {k: np.stack(v) for k, v in frames.items()}
        np.savez_compressed(os.path.join(self.out_dir, name), job=np.asarray(ids), **arrays)
        return {"shard": shard, "jobs": ids, "file": name, "worker": os.getpid(),
                "seconds": seconds}


def _runs(jobs):
    """``jobs`` [(index, job)] split into runs of consecutive jobs with the same scene, camera
    and settings (the jobs of one ``render_batch``)."""
    runs, key = [], None
    for _, job in jobs:
        k = (job["scene"], json.dumps(job.get("camera"), sort_keys=True, default=str),
             json.dumps(job.get("settings", {}), sort_keys=True, default=str))
        if k != key:
            runs.append([])
            key = k
        runs[-1].append(job)
    return runs


def render_jobs(
    jobs,
    out_dir,
    width,
    height,
    num_workers=2,
    outputs=("color", "depth"),
    shard_size=25,
    png=False,
    device=None,
    **settings,
):
    """Renders ``jobs`` (see the module's documentation) at ``width`` x ``height`` on
    ``num_workers`` Ray actors (one CPU each; Ray must be initialised, ``ray.init``), writing
    shards of ``shard_size`` jobs into ``out_dir``: ``shard_NNNNN.npz`` with one stacked array
    per output plus ``job`` (the job indices), or with ``png`` one ``job_NNNNNN.png`` colour
    image per job. ``settings`` apply to every job (a job's own ``settings`` win). Writes and
    returns the manifest (``out_dir/manifest.json``)."""
    import ray
    from ray.util import ActorPool

    if not ray.is_initialized():
        raise RuntimeError("call ray.init() first (ray.init(num_cpus=N) on one machine)")
    if png and "color" not in outputs:
        raise ValueError("png writes the color output: include it")
    os.makedirs(out_dir, exist_ok=True)
    start = time.time()
    worker = ray.remote(num_cpus=1)(_Worker)
    actors = [
        worker.remote(width, height, outputs, os.path.abspath(out_dir), png, device, settings)
        for _ in range(max(1, num_workers))
    ]
    indexed = list(enumerate(jobs))
    shards = [
        (k, indexed[s : s + shard_size])
        for k, s in enumerate(range(0, len(indexed), max(1, shard_size)))
    ]
    pool = ActorPool(actors)
    entries = sorted(
        pool.map_unordered(lambda a, shard: a.render.remote(*shard), shards),
        key=lambda e: e["shard"],
    )
    per_worker = {}
    for e in entries:
        w = per_worker.setdefault(e["worker"], {"jobs": 0, "seconds": 0.0})
        w["jobs"] += len(e["jobs"])
        w["seconds"] += e["seconds"]
    for w in per_worker.values():
        w["images_per_second"] = w["jobs"] / w["seconds"] if w["seconds"] > 0 else None
    manifest = {
        "width": width,
        "height": height,
        "outputs": list(outputs),
        "jobs": len(jobs),
        "workers": len(actors),
        "seconds": time.time() - start,
        "per_worker": {str(k): v for k, v in per_worker.items()},
        "shards": entries,
    }
    with open(os.path.join(out_dir, "manifest.json"), "w") as f:
        json.dump(manifest, f, indent=1)
    for a in actors:
        ray.kill(a)
    return manifest
