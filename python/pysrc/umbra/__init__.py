"""umbra: a real-time shadow-mapping renderer on Vulkan, from Python.

An offscreen renderer shaped like pyrender's (``OffscreenRenderer(w, h).render(scene, camera,
camera_pose)`` returns colour and depth as numpy arrays), with exact instance segmentation,
world normals and shadow visibility besides, point-light shadows, and no EGL to set up: it runs
on any Vulkan 1.3 device, Mesa's lavapipe CPU driver included (``UMBRA_DEVICE`` or ``device=``
choose one).

>>> import umbra
>>> scene = umbra.load("model.glb")
>>> camera, pose = scene.default_view(640, 360)
>>> color, depth = umbra.OffscreenRenderer(640, 360).render(scene, camera, pose)

Scenes can also be built from arrays (``Scene().add_mesh(positions, indices, ...)``) or from
trimesh (``Scene.from_trimesh(mesh)``); ``umbra.ray`` renders many jobs on a Ray cluster.
"""

from ._umbra import (
    GoldenMismatch,
    GpuError,
    LoadError,
    OffscreenRenderer,
    OrthographicCamera,
    PerspectiveCamera,
    Scene,
    UmbraError,
    __version__,
    load,
    write_report,
)

__all__ = [
    "GoldenMismatch",
    "GpuError",
    "LoadError",
    "OffscreenRenderer",
    "OrthographicCamera",
    "PerspectiveCamera",
    "Scene",
    "UmbraError",
    "look_at",
    "write_report",
    "load",
    "__version__",
]


def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    """The 4x4 world-from-camera pose of a camera at ``eye`` looking at ``target`` (its -Z
    towards the target, its +Y as close to ``up`` as the view allows), as a float64 array."""
    import numpy as np

    eye = np.asarray(eye, dtype=np.float64)
    forward = np.asarray(target, dtype=np.float64) - eye
    n = np.linalg.norm(forward)
    if n == 0.0:
        raise ValueError("eye and target must differ")
    forward /= n
    up = np.asarray(up, dtype=np.float64)
    right = np.cross(forward, up)
    if np.linalg.norm(right) < 1e-9:
        right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = right, true_up, -forward, eye
    return pose
