#!/usr/bin/env python3
"""The table of docs/compressed-gltf.md: each model re-encoded with each setting by the real tools
(scripts/gltf-recompress.py), then against its original at the same camera (framed on the
original's bounds, on a ground plane): loaded or not, PSNR of the lit image, `umbra compare`'s
misclassified shadow pixels against the original's, load time (median of 3 `umbra inspect` runs,
which load the file and plan a frame) against the original's, and file size.

Usage: scripts/compressed-table.py UMBRA_BIN TOOLS_DIR OUT_DIR MODEL...
  (PATH gets TOOLS_DIR; Python needs numpy and Pillow)
"""
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np
from PIL import Image

SETTINGS = ["quantized", "meshopt", "meshopt-cc", "draco", "etc1s", "uastc", "webp"]
SIZE = "480x270"


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def camera(umbra, model):
    b = json.loads(run([umbra, "inspect", model, "--json"]).stdout)["scale"]["bounds"]
    lo, hi = np.array(b["min"]), np.array(b["max"])
    c, d = (lo + hi) / 2, np.linalg.norm(hi - lo)
    eye = c + d * np.array([0.55, 0.45, 0.85])
    f = lambda v: ",".join(f"{x:.6g}" for x in v)
    return ["--eye", f(eye), "--target", f(c)]


def psnr(a, b):
    x = np.asarray(Image.open(a).convert("RGB"), dtype=float)
    y = np.asarray(Image.open(b).convert("RGB"), dtype=float)
    mse = ((x - y) ** 2).mean()
    return float("inf") if mse == 0 else 10 * np.log10(255 ** 2 / mse)


def measure(umbra, model, cam, out):
    """Rendered PNG, misclassified % from compare, median load seconds; None if it failed."""
    png = out + ".png"
    r = run([umbra, "render", model, "--ground", "--size", SIZE, *cam, "-o", png])
    if r.returncode != 0:
        return None, r.stderr.strip().splitlines()[-1]
    os.makedirs(out + "_compare", exist_ok=True)
    c = run([umbra, "compare", model, "--ground", "--size", SIZE, *cam, "--out", out + "_compare"])
    line = [l for l in c.stdout.splitlines() if l.startswith("{")]
    mis = "%.3f" % (100 * json.loads(line[-1])["misclassified"]) if line else None
    times = []
    for _ in range(3):
        t = time.perf_counter()
        run([umbra, "inspect", model, "--json"])
        times.append(time.perf_counter() - t)
    return (png, mis, statistics.median(times)), None


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    umbra, tools, out = sys.argv[1:4]
    env = dict(os.environ, PATH=tools + ":" + os.environ["PATH"])
    here = os.path.dirname(os.path.abspath(__file__))
    os.makedirs(out, exist_ok=True)
    print("| model | setting | loads | PSNR dB | misclassified % (original) | load s (original) | bytes (original) |")
    print("|---|---|---|---|---|---|---|")
    for model in sys.argv[4:]:
        stem = os.path.splitext(os.path.basename(model))[0]
        cam = camera(umbra, model)
        base, _ = measure(umbra, model, cam, os.path.join(out, stem))
        size0 = os.path.getsize(model)
        doc = json.loads(run([umbra, "inspect", model, "--json"]).stdout)
        if model.endswith(".gltf"):
            # The .gltf and the external files it names.
            folder = os.path.dirname(model)
            for r in doc["resources"]["buffers"] + doc["resources"]["images"]:
                if r.get("uri") and not r["uri"].startswith("data:"):
                    size0 += os.path.getsize(os.path.join(folder, r["uri"]))
        textured = len(doc["resources"]["images"]) > 0
        for s in SETTINGS:
            if s in ("etc1s", "uastc", "webp") and not textured:
                continue
            dst = os.path.join(out, f"{stem}.{s}.glb")
            enc = run(["python3", os.path.join(here, "gltf-recompress.py"), s, model, dst], env=env)
            if enc.returncode != 0:
                print(f"| {stem} | {s} | the tool refused it | | | | |")
                continue
            got, why = measure(umbra, dst, cam, os.path.join(out, f"{stem}.{s}"))
            if got is None:
                print(f"| {stem} | {s} | **no**: {why} | | | | |")
                continue
            png, mis, secs = got
            print(f"| {stem} | {s} | yes | {psnr(base[0], png):.1f} | {mis} ({base[1]}) | "
                  f"{secs:.3f} ({base[2]:.3f}) | {os.path.getsize(dst)} ({size0}) |", flush=True)


if __name__ == "__main__":
    main()
