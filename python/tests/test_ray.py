"""The Ray helper on a local cluster of 2 CPUs (loopback only): jobs rendered by 2 worker
processes land in shards whose arrays equal a direct batch of the shard's poses, with a manifest
naming each job and each worker's images per second."""

import json
import os

import numpy as np
import ray

import umbra
import umbra.ray
from conftest import quad, write_glb


def test_jobs_render_on_two_local_workers(tmp_path):
    p, i = quad(1.0)
    model = write_glb(tmp_path / "m.glb", [(p, i, (0.8, 0.4, 0.2, 1.0), (0, 0.5, 0))])
    jobs = [
        {"scene": model, "camera_pose": umbra.look_at((x, 1.0, 3.0), (0, 0.5, 0)).tolist()}
        for x in np.linspace(-1.0, 1.0, 6)
    ]
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        m = umbra.ray.render_jobs(jobs, str(tmp_path / "out"), 64, 48, num_workers=2, shard_size=2)
    finally:
        ray.shutdown()
    assert m["jobs"] == 6 and m["workers"] == 2 and len(m["shards"]) == 3
    on_disk = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert on_disk["shards"] == m["shards"]
    # Two worker processes shared the shards, neither of them this one.
    workers = {e["worker"] for e in m["shards"]}
    assert len(workers) == 2 and os.getpid() not in workers, workers
    # Throughput per worker: every job counted once, at a rate above zero.
    per = m["per_worker"]
    assert sorted(int(k) for k in per) == sorted(workers)
    assert sum(w["jobs"] for w in per.values()) == 6
    assert all(w["images_per_second"] > 0 for w in per.values())
    r = umbra.OffscreenRenderer(64, 48)
    scene = umbra.load(model)
    seen = []
    for entry in m["shards"]:
        with np.load(tmp_path / "out" / entry["file"]) as z:
            assert list(z["job"]) == entry["jobs"]
            # A shard is one batch (its shadow map shared by its poses).
            poses = np.stack([np.asarray(jobs[j]["camera_pose"]) for j in entry["jobs"]])
            direct = r.render_batch(scene, umbra.ray.camera_of(None), poses)
            assert np.array_equal(z["color"], direct["color"])
            assert np.array_equal(z["depth"], direct["depth"])
            seen.extend(entry["jobs"])
    assert sorted(seen) == list(range(6))
    r.close()
