"""Shared fixtures: a renderer with the Khronos validation layer on (every test that uses it
fails on any validation message), small glTF files written here, and the command line binary."""

import json
import os
import struct
from pathlib import Path

import numpy as np
import pytest

import umbra

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def renderer():
    r = umbra.OffscreenRenderer(160, 120, validation=True)
    yield r
    problems = r.validation_problems
    r.close()
    assert problems == 0, f"{problems} validation message(s)"


@pytest.fixture(scope="session")
def umbra_bin():
    """The command line binary the test command built (UMBRA_BIN overrides)."""
    for p in [os.environ.get("UMBRA_BIN"), ROOT / "target/debug/umbra", ROOT / "target/release/umbra"]:
        if p and Path(p).is_file():
            return str(p)
    pytest.fail("no umbra binary: build it (cargo build) or set UMBRA_BIN")


def quad(size, z=0.0):
    """Positions and indices of a square of side `size` in the XY plane at depth z, facing +Z."""
    h = size / 2
    p = np.array([[-h, -h, z], [h, -h, z], [h, h, z], [-h, h, z]], dtype=np.float32)
    return p, np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)


def write_glb(path, meshes, lights=(), animation=None):
    """A GLB of `meshes` [(positions (N, 3), indices (M, 3), rgba, translation)], KHR lights
    [(direction as the node's -Z rotation quaternion, intensity)] and optionally one animation
    (name, node, key times (K,), translations (K, 3)), linear."""
    binary = bytearray()
    views, accessors, gltf_meshes, nodes, materials = [], [], [], [], []

    def add(data, target, ctype, typ, count, bounds=None):
        while len(binary) % 4:
            binary.append(0)
        view = {"buffer": 0, "byteOffset": len(binary), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        views.append(view)
        binary.extend(data)
        a = {"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": typ}
        if bounds is not None:
            a["min"], a["max"] = bounds
        accessors.append(a)
        return len(accessors) - 1

    for k, (pos, idx, rgba, at) in enumerate(meshes):
        pos = np.asarray(pos, np.float32)
        idx = np.asarray(idx, np.uint32).reshape(-1)
        p = add(pos.tobytes(), 34962, 5126, "VEC3", len(pos),
                (pos.min(0).tolist(), pos.max(0).tolist()))
        i = add(idx.tobytes(), 34963, 5125, "SCALAR", len(idx))
        materials.append({"pbrMetallicRoughness": {"baseColorFactor": list(rgba), "roughnessFactor": 0.7}})
        gltf_meshes.append({"name": f"mesh {k}", "primitives": [{"attributes": {"POSITION": p}, "indices": i, "material": k}]})
        nodes.append({"name": f"node {k}", "mesh": k, "translation": list(at)})
    doc = {"asset": {"version": "2.0"}, "scene": 0, "buffers": [{"byteLength": 0}],
           "bufferViews": views, "accessors": accessors, "meshes": gltf_meshes,
           "materials": materials, "nodes": nodes}
    if lights:
        doc["extensionsUsed"] = ["KHR_lights_punctual"]
        doc["extensions"] = {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "intensity": i} for _, i in lights]}}
        for k, (q, _) in enumerate(lights):
            nodes.append({"rotation": list(q), "extensions": {"KHR_lights_punctual": {"light": k}}})
    if animation is not None:
        name, node, times, moves = animation
        times = np.asarray(times, np.float32)
        moves = np.asarray(moves, np.float32)
        t = add(times.tobytes(), None, 5126, "SCALAR", len(times), ([float(times.min())], [float(times.max())]))
        m = add(moves.tobytes(), None, 5126, "VEC3", len(moves))
        doc["animations"] = [{"name": name,
                              "samplers": [{"input": t, "output": m, "interpolation": "LINEAR"}],
                              "channels": [{"sampler": 0, "target": {"node": node, "path": "translation"}}]}]
    doc["scenes"] = [{"nodes": list(range(len(nodes)))}]
    while len(binary) % 4:
        binary.append(0)
    doc["buffers"][0]["byteLength"] = len(binary)
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(binary))
    out += struct.pack("<II", len(js), 0x4E4F534A) + js
    out += struct.pack("<II", len(binary), 0x004E4942) + bytes(binary)
    Path(path).write_bytes(out)
    return str(path)
