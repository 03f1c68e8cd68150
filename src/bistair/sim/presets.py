"""Named rigs and scenes: the paper's experiments and simple ones for tests.

=================  ==========  ========================================================
name               projector   scene
=================  ==========  ========================================================
plane              1920x1080   a flat plane facing the camera at the working distance
sphere-on-plane    1920x1080   a sphere in front of a background plane (projector shadow)
paper-sim          1080x1080   one big mask and three small objects, 1-3 fringes wide
two-masks          1920x1080   two isolated face-like masks
mask-prism         1920x1080   one mask and one prism carrying about 3 fringes
two-sculptures     1920x1080   two isolated mesh sculptures (a bust and a vase)
objects-on-plane   1920x1080   a sphere, a box, a prism and two small ellipsoids on a plane
                               (sized for 11 x 11 = 121 fringes of 16 px)
mugs-on-wall       1920x1080   two mugs in front of a wall, one partly hiding the other:
                               occlusion edges without shadow gaps on their right sides
=================  ==========  ========================================================

Objects are isolated on a dark background unless a plane is named. :func:`preset_spec`
gives the pattern set the preset was sized for (period 30: 6 x 6 fringes on 1080 columns,
8 x 8 on 1920). Keyword overrides go to :meth:`Rig.default`, e.g. a smaller camera with the
same field of view: ``preset("paper-sim", camera_size=(640, 512))``.

Examples
--------
>>> rig, scene = preset("sphere-on-plane", camera_size=(64, 52))
>>> rig.camera.size, rig.projector.size, scene.ids
((64, 52), (1920, 1080), (1, 2))
>>> preset_spec("paper-sim").fringes
36
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import trimesh

from ..codecs import make_spec
from ..spec import BaseSpec
from .rig import Rig, euler
from .shapes import Box, Ellipsoid, MaskRelief, Mesh, Plane, Prism, Scene, Sphere


def _plane() -> Scene:
    return Scene([Plane(center=(0, 0, 600), size=(700, 600), albedo=0.8)])


def _sphere_on_plane() -> Scene:
    return Scene([Sphere(center=(0, 0, 520), radius=50, albedo=0.55),
                  Plane(center=(0, 0, 700), size=(900, 800), albedo=0.7)])


def _paper_sim() -> Scene:
    return Scene([
        MaskRelief(center=(-42, 0, 650), width=230, height=250, depth=70, albedo=0.75),
        Ellipsoid(center=(105, -80, 595), radii=(7, 13, 7), albedo=0.6),
        Box(center=(108, 0, 595), size=(18, 24, 10), rotation=euler(y=20), albedo=0.5),
        Prism(center=(108, 82, 600), width=26, depth=10, length=26, albedo=0.7),
    ])


def _two_masks() -> Scene:
    return Scene([
        MaskRelief(center=(-78, 0, 620), width=140, height=180, depth=55, albedo=0.7),
        MaskRelief(center=(82, 5, 630), width=135, height=175, depth=50,
                   rotation=euler(y=-12, z=4), albedo=0.6),
    ])


def _mask_prism() -> Scene:
    return Scene([
        MaskRelief(center=(-60, 0, 620), width=150, height=190, depth=55, albedo=0.7),
        Prism(center=(90, 0, 610), width=26, depth=12, length=150, rotation=euler(z=3),
              albedo=0.6),
    ])


def _bust():
    head = trimesh.creation.icosphere(subdivisions=4, radius=36)
    head.apply_scale((0.85, 1.0, 0.92))
    head.apply_translation((0, -62, 0))
    nose = trimesh.creation.cone(radius=7, height=16, sections=24)
    nose.apply_transform(_pose(euler(x=180), (0, -58, -30)))
    neck = trimesh.creation.cylinder(radius=15, height=40, sections=40)
    neck.apply_transform(_pose(euler(x=90), (0, -15, 0)))
    chest = trimesh.creation.capsule(height=70, radius=28, count=(24, 24))
    chest.apply_transform(_pose(euler(y=90), (0, 28, 4)))
    return trimesh.util.concatenate([head, nose, neck, chest])


def _vase():
    z = np.linspace(0, 165, 60)
    r = 26 + 16 * np.sin(np.pi * z / 165 * 1.25) ** 2 - 10 * (z / 165) ** 3
    profile = np.vstack([[0, 0], np.column_stack([r, z]), [0, 165]])
    vase = trimesh.creation.revolve(profile, sections=72)
    ring = trimesh.creation.torus(major_radius=24, minor_radius=5, major_sections=48,
                                  minor_sections=16)
    ring.apply_translation((0, 0, 120))
    body = trimesh.util.concatenate([vase, ring])
    body.apply_transform(_pose(euler(x=90), (0, 80, 0)))  # axis along -y, base down
    return body


def _pose(rotation: np.ndarray, translation) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = rotation
    m[:3, 3] = translation
    return m


def _two_sculptures() -> Scene:
    return Scene([
        Mesh(mesh=_bust(), center=(-80, 10, 650), rotation=euler(y=10), albedo=0.7),
        Mesh(mesh=_vase(), center=(85, -5, 640), albedo=0.6),
    ])


def _objects_on_plane() -> Scene:
    return Scene([
        Sphere(center=(-70, -40, 600), radius=42, albedo=0.6),
        Box(center=(60, -45, 615), size=(60, 50, 40), rotation=euler(y=25, z=8), albedo=0.5),
        Prism(center=(-40, 70, 620), width=40, depth=16, length=60, rotation=euler(z=80),
              albedo=0.7),
        Ellipsoid(center=(55, 55, 625), radii=(9, 14, 8), albedo=0.65),
        Ellipsoid(center=(95, 40, 625), radii=(5, 10, 5), albedo=0.55),
        Plane(center=(0, 0, 640), size=(800, 700), albedo=0.75),
    ])


def _mugs_on_wall() -> Scene:
    return Scene([
        Mesh(mesh=_mug(), center=(-55, 0, 600), albedo=0.7),
        Mesh(mesh=_mug(), center=(25, 10, 650), rotation=euler(y=30), albedo=0.55),
        Plane(center=(0, 0, 720), size=(900, 800), albedo=0.8),
    ])


def _mug():
    body = trimesh.creation.cylinder(radius=42, height=105, sections=96)
    body.apply_transform(_pose(euler(x=90), (0, 0, 0)))  # axis along y, upright
    handle = trimesh.creation.torus(major_radius=24, minor_radius=7, major_sections=48,
                                    minor_sections=16)
    handle.apply_transform(_pose(euler(x=90), (-50, 0, 0)))
    return trimesh.util.concatenate([body, handle])


_PRESETS: dict[str, tuple[Callable[[], Scene], dict[str, Any], dict[str, Any]]] = {
    "plane": (_plane, {}, dict(width=1920, height=1080, partitions=8, stairs=8)),
    "sphere-on-plane": (_sphere_on_plane, {},
                        dict(width=1920, height=1080, partitions=8, stairs=8)),
    "paper-sim": (_paper_sim, dict(projector_size=(1080, 1080)), dict(width=1080, height=1080)),
    "two-masks": (_two_masks, {}, dict(width=1920, height=1080, partitions=8, stairs=8)),
    "mask-prism": (_mask_prism, {}, dict(width=1920, height=1080, partitions=8, stairs=8)),
    "two-sculptures": (_two_sculptures, {},
                       dict(width=1920, height=1080, partitions=8, stairs=8)),
    "objects-on-plane": (_objects_on_plane, {},
                         dict(width=1920, height=1080, partitions=11, stairs=11, period=16)),
    "mugs-on-wall": (_mugs_on_wall, {}, dict(width=1920, height=1080, partitions=8, stairs=8)),
}


def scene_names() -> list[str]:
    """The preset names."""
    return list(_PRESETS)


def preset(name: str, **overrides: Any) -> tuple[Rig, Scene]:
    """The rig and scene of a preset; ``overrides`` go to :meth:`Rig.default`."""
    if name not in _PRESETS:
        raise ValueError(f"unknown preset {name!r} (known: {', '.join(_PRESETS)})")
    make_scene, rig_args, _ = _PRESETS[name]
    return Rig.default(**{**rig_args, **overrides}), make_scene()


def preset_spec(name: str, method: str = "bidirectional", **params: Any) -> BaseSpec:
    """The pattern set a preset was sized for (period 30 unless it says otherwise;
    ``params`` override it)."""
    if name not in _PRESETS:
        raise ValueError(f"unknown preset {name!r} (known: {', '.join(_PRESETS)})")
    return make_spec(method, **{"period": 30, **_PRESETS[name][2], **params})
