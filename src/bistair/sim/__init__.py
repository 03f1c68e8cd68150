"""A physically based virtual projector-camera rig, for ground truth.

A pinhole camera (the world frame) and a pinhole projector with OpenCV intrinsics,
distortion and pose (:mod:`~bistair.sim.rig`); 3-D surfaces ray-cast from the camera
with camera occlusion and projector shadows (:mod:`~bistair.sim.shapes`); image formation
with projector gamma and defocus, Lambertian shading, ambient light, camera defocus, shot and
read noise, saturation and quantisation (:mod:`~bistair.sim.render`); named scenes of the
paper's experiments (:mod:`~bistair.sim.presets`); board captures and views for calibration
(:mod:`~bistair.sim.boards`); things that move, a rigid motion per frame and a trace per
pose (:mod:`~bistair.sim.motion`); and a fast 2-D warp of the patterns without geometry for
tests (:mod:`~bistair.sim.warp`). Units are millimetres.

Examples
--------
>>> from bistair.codecs import encode
>>> from bistair.sim import Imaging, preset, preset_spec, render
>>> rig, scene = preset("sphere-on-plane", camera_size=(80, 64))
>>> spec = preset_spec("sphere-on-plane")
>>> images, truth = render(encode(spec), rig, scene, Imaging(seed=1))
>>> images.shape, images.dtype, truth.coord(spec).shape
((6, 64, 80), dtype('uint8'), (64, 80))
"""

from .presets import preset, preset_spec, scene_names
from .render import Imaging, Trace, expose, render, trace
from .rig import Camera, Pinhole, Projector, Rig, euler
from .shapes import Box, Ellipsoid, MaskRelief, Mesh, Plane, Prism, Scene, Sphere, Surface
from .truth import Truth

__all__ = ["Box", "Camera", "Ellipsoid", "Imaging", "MaskRelief", "Mesh", "Pinhole", "Plane",
           "Prism", "Projector", "Rig", "Scene", "Sphere", "Surface", "Trace", "Truth", "euler",
           "expose", "preset", "preset_spec", "render", "scene_names", "trace"]
