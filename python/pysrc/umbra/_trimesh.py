"""Meshes of trimesh objects as the arrays ``Scene.add_mesh`` takes (``Scene.from_trimesh``)."""

import numpy as np


def _mesh_arrays(mesh, pose, name):
    positions = np.asarray(mesh.vertices, dtype=np.float32)
    indices = np.asarray(mesh.faces, dtype=np.uint32)
    normals = None
    if hasattr(mesh, "vertex_normals") and len(mesh.vertex_normals) == len(positions):
        normals = np.asarray(mesh.vertex_normals, dtype=np.float32)
    colors, uvs, texture, base = None, None, None, [1.0, 1.0, 1.0, 1.0]
    visual = getattr(mesh, "visual", None)
    kind = getattr(visual, "kind", None)
    if kind == "vertex":
        colors = np.asarray(visual.vertex_colors, dtype=np.uint8)
    elif kind == "face":
        c = np.asarray(visual.face_colors, dtype=np.uint8)
        if len(c) and (c == c[0]).all():
            # One colour for every face: the material's.
            base = list(c[0] / 255.0)
        elif len(c) == len(indices):
            # Each face its own three corners, so that each keeps its own colour (the corners of
            # a shared vertex would blend its faces' colours); normals as they were.
            corners = indices.reshape(-1)
            positions = positions[corners]
            if normals is not None:
                normals = normals[corners]
            indices = np.arange(len(corners), dtype=np.uint32).reshape(-1, 3)
            colors = np.repeat(c, 3, axis=0)
        elif len(c):
            # Colours that do not match the faces one to one: the first, for the material.
            base = list(c[0] / 255.0)
    elif kind == "texture":
        uv = getattr(visual, "uv", None)
        if uv is not None and len(uv) == len(positions):
            uvs = np.asarray(uv, dtype=np.float32)
            # trimesh's UVs put v = 0 at the image's bottom (OpenGL); glTF's at its top.
            uvs[:, 1] = 1.0 - uvs[:, 1]
        material = getattr(visual, "material", None)
        image = getattr(material, "baseColorTexture", None) or getattr(material, "image", None)
        if image is not None and uvs is not None:
            texture = np.asarray(image.convert("RGBA"), dtype=np.uint8)
        factor = getattr(material, "baseColorFactor", None)
        if factor is not None:
            base = list(np.asarray(factor, dtype=np.float64) / 255.0)
    translucent = base[3] < 1.0 or (colors is not None and colors.shape[1] == 4 and colors[:, 3].min() < 255)
    return {
        "positions": positions,
        "indices": indices,
        "normals": normals,
        "uvs": uvs,
        "colors": colors,
        "base_color": [float(x) for x in base],
        "texture": texture,
        "alpha_mode": "BLEND" if translucent else "OPAQUE",
        "pose": np.asarray(pose, dtype=np.float64),
        "name": name,
    }


def to_arrays(obj):
    """The meshes of a ``trimesh.Trimesh`` or ``trimesh.Scene`` (with their world transforms)."""
    if hasattr(obj, "graph") and hasattr(obj, "geometry"):
        parts = []
        for node in obj.graph.nodes_geometry:
            transform, geometry = obj.graph[node]
            mesh = obj.geometry[geometry]
            if hasattr(mesh, "faces") and len(mesh.faces):
                parts.append(_mesh_arrays(mesh, transform, str(node)))
        return parts
    if hasattr(obj, "faces") and hasattr(obj, "vertices"):
        return [_mesh_arrays(obj, np.eye(4), getattr(obj, "metadata", {}).get("name", "mesh"))]
    raise TypeError(f"not a trimesh.Trimesh or trimesh.Scene: {type(obj).__name__}")
