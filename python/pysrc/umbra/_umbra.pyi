"""Type stubs of umbra's native module (re-exported by ``umbra``)."""

from os import PathLike
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

Output = Literal["color", "depth", "segmentation", "normals", "shadow"]
ArrayLike = npt.ArrayLike
Camera = Union["PerspectiveCamera", "OrthographicCamera"]

class UmbraError(Exception):
    """Any error umbra reports (its message is the command line's one line)."""

class LoadError(UmbraError):
    """A scene that cannot be loaded: missing, unreadable, corrupt or unsupported glTF."""

class GpuError(UmbraError):
    """No usable Vulkan device, or a device error while rendering."""

def load(path: Union[str, PathLike]) -> "Scene":
    """Loads a glTF 2.0 file (.gltf or .glb); raises LoadError when it cannot."""

class PerspectiveCamera:
    """A perspective camera; it looks down its -Z, Y up."""

    yfov: float
    znear: float
    zfar: Optional[float]
    aspect: Optional[float]
    def __init__(
        self,
        yfov: float,
        znear: float = 0.05,
        zfar: Optional[float] = None,
        aspect: Optional[float] = None,
    ) -> None:
        """Vertical field of view ``yfov`` in radians; ``zfar`` None is an infinite (reversed-z)
        far plane; ``aspect`` None uses the image's (umbra draws square pixels, so a given
        aspect must equal width / height)."""

class OrthographicCamera:
    """An orthographic camera: +/-ymag vertically, +/-ymag x the image's aspect horizontally."""

    xmag: float
    ymag: float
    znear: float
    zfar: float
    def __init__(
        self, xmag: float, ymag: float, znear: float = 0.05, zfar: float = 100.0
    ) -> None: ...

class Scene:
    """Meshes, materials, textures, lights and cameras: a glTF file or arrays you add."""

    name: str
    instances: int
    lights: int
    triangles: int
    bounds: Tuple[Tuple[float, float, float], Tuple[float, float, float]]
    warnings: List[str]
    animations: List[str]
    cameras: List[Tuple[Camera, np.ndarray]]
    def __init__(self) -> None:
        """An empty scene."""
    @staticmethod
    def load(path: Union[str, PathLike]) -> "Scene":
        """Loads a glTF 2.0 file; raises LoadError when it cannot."""
    @staticmethod
    def from_trimesh(obj: Any) -> "Scene":
        """A scene of a trimesh.Trimesh or trimesh.Scene (meshes, vertex colours, transforms)."""
    def add_mesh(
        self,
        positions: ArrayLike,
        indices: Optional[ArrayLike] = None,
        normals: Optional[ArrayLike] = None,
        uvs: Optional[ArrayLike] = None,
        colors: Optional[ArrayLike] = None,
        base_color: Sequence[float] = (1.0, 1.0, 1.0, 1.0),
        pose: Optional[ArrayLike] = None,
        name: Optional[str] = None,
        metallic: float = 0.0,
        roughness: float = 0.6,
        double_sided: bool = False,
        unlit: bool = False,
        alpha_mode: Literal["OPAQUE", "MASK", "BLEND"] = "OPAQUE",
        alpha_cutoff: float = 0.5,
    ) -> int:
        """Adds a triangle mesh and one instance of it; returns the instance index
        (segmentation reports it plus 1). positions (N, 3); indices (M, 3) or None (every three
        positions a triangle); normals (N, 3) (computed when absent); uvs (N, 2); colors
        (N, 3|4) linear 0..1 (uint8: /255); base_color linear RGB(A); pose 4x4
        world-from-model; alpha_mode as glTF's (MASK cuts out below alpha_cutoff)."""
    def add_directional_light(
        self,
        direction: Sequence[float],
        intensity: float = 1.0,
        color: Sequence[float] = (1.0, 1.0, 1.0),
        shadows: bool = True,
    ) -> int:
        """A sun travelling along ``direction`` (a glTF light shines down its -Z)."""
    def add_point_light(
        self,
        position: Sequence[float],
        intensity: float = 1.0,
        color: Sequence[float] = (1.0, 1.0, 1.0),
        range: Optional[float] = None,
        shadows: bool = True,
    ) -> int:
        """A point light (cube shadows) at ``position``."""
    def add_spot_light(
        self,
        position: Sequence[float],
        direction: Sequence[float],
        inner_cone: float = 0.0,
        outer_cone: float = 0.7853981633974483,
        intensity: float = 1.0,
        color: Sequence[float] = (1.0, 1.0, 1.0),
        range: Optional[float] = None,
        shadows: bool = True,
    ) -> int:
        """A spot light: full inside ``inner_cone``, dark outside ``outer_cone`` (radians)."""
    def set_pose(self, instance: int, pose: ArrayLike) -> None:
        """Moves an instance (4x4 world-from-model); a renderer redraws it without a new upload."""
    def add_ground(self) -> int:
        """A grey ground under the scene (the command line's --ground); its instance index.
        ValueError on a scene without geometry (nothing to size the ground by)."""
    def default_view(self, width: int, height: int) -> Tuple[Camera, np.ndarray]:
        """The camera and 4x4 pose umbra frames the scene with at width x height."""

class OffscreenRenderer:
    """Renders scenes offscreen into numpy arrays (pyrender's OffscreenRenderer, shaped alike)."""

    width: int
    height: int
    device: str
    device_class: str
    samples: int
    validation_problems: int
    def __init__(
        self,
        width: int,
        height: int,
        device: Optional[str] = None,
        msaa: Optional[int] = None,
        validation: bool = False,
    ) -> None:
        """``device``: a substring of the Vulkan device's name (None: UMBRA_DEVICE, else a GPU
        before a CPU device); ``msaa`` samples per pixel (None: 4 on GPUs, 1 on CPU devices)."""
    @overload
    def render(
        self,
        scene: Scene,
        camera: Camera,
        camera_pose: ArrayLike,
        outputs: None = None,
        **settings: Any,
    ) -> Tuple[np.ndarray, np.ndarray]: ...
    @overload
    def render(
        self,
        scene: Scene,
        camera: Camera,
        camera_pose: ArrayLike,
        outputs: Sequence[Output],
        **settings: Any,
    ) -> Dict[str, np.ndarray]: ...
    def render(self, scene, camera, camera_pose, outputs=None, **settings):
        """Renders ``scene`` through ``camera`` at ``camera_pose`` (4x4 world-from-camera; the
        camera looks down its -Z). Without outputs: (color uint8 (H, W, 3) sRGB, depth float32
        (H, W) distance along the view axis, 0 where nothing is hit). With outputs: a dict of
        color, depth, segmentation (uint32 (H, W): instance + 1, 0 background), normals
        (float32 (H, W, 3), world) and shadow (float32 (H, W): the first shadowed light's
        visibility, or shadow_light's). Settings: shadows, shadow_map, shadow_format ('auto',
        'd32', 'd16'), shadow_method ('map', 'exact': each pixel's shadow ray tested against
        the caster triangles, 'hybrid': the same verdicts, tracing only what the map cannot
        prove), contact_shadows (bool: creases finer than a texel), pcf ('none', '2x2', '3x3', '5x5'), cascades (0 = automatic), depth_fit, fit
        ('camera', 'sphere', 'scene'), bias_constant, bias_slope, normal_offset, shadow_budget
        (misclassified pixels, %), shadow_light, light_size, exposure ('auto', an EV100, or
        'x1.5'), tonemap ('neutral', 'aces', 'none'), post_aa ('none', 'fxaa'), supersample (1, 2), ambient, background ('sky', '#rrggbb' or an
        RGB triple within 0..1), sun_direction, sun_intensity, time (seconds), animation (a
        name, an index or 'all'). The GIL is released while the GPU works."""
    def render_batch(
        self,
        scene: Scene,
        camera: Camera,
        poses: ArrayLike,
        outputs: Optional[Sequence[Output]] = None,
        share_shadows: bool = True,
        **settings: Any,
    ) -> Dict[str, np.ndarray]:
        """Renders ``scene`` from each of ``poses`` (N, 4, 4) without uploading it again; each
        output stacked (N, H, W[, C]) (default: color and depth). ``share_shadows``: one map
        per directional light fitted to all the poses and drawn once (False: per pose)."""
    def close(self) -> None:
        """Frees the device's resources."""
    def __enter__(self) -> "OffscreenRenderer": ...
    def __exit__(self, *args: Any) -> None: ...


class GoldenMismatch(UmbraError):
    """A frame that does not match its golden image (the message is one line of figures)."""

def golden_check(
    color: np.ndarray,
    path: Union[str, "PathLike[str]"],
    shadow: Optional[np.ndarray] = None,
    device_class: str = "",
    pixel_flip: float = 0.0,
    pixels_over: int = 0,
    mean_flip: float = 0.0,
    shadow_changes: int = 0,
    bless: bool = False,
    ci: bool = False,
) -> Dict[str, Any]:
    """Compares a frame with its golden (``umbra.testing`` wraps it); raises GoldenMismatch."""
