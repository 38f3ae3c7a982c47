"""Render a glTF to a PNG and a depth array (the README's Python quick start).

    python python/examples/quickstart.py MODEL.glb out.png
"""
import sys

import numpy as np
from PIL import Image

import umbra

scene = umbra.load(sys.argv[1])                      # a .gltf or .glb; umbra.LoadError if bad
scene.add_ground()                                   # a floor to catch the shadow
camera, pose = scene.default_view(640, 360)          # front view, fitted; or your own 4x4 pose
renderer = umbra.OffscreenRenderer(640, 360)         # lavapipe or a GPU (UMBRA_DEVICE, device=)
color, depth = renderer.render(scene, camera, pose)  # uint8 (360, 640, 3), float32 (360, 640)
Image.fromarray(color).save(sys.argv[2])
np.save(sys.argv[2] + ".depth.npy", depth)           # distance along the view axis, 0: none
print(color.shape, depth[depth > 0].min(), depth.max())
