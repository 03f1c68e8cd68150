"""Random variations of scenes for data sets: optics, objects and pose, drawn from seeds.

:func:`draw` turns a random generator into the parameters of one scene, plain numbers and
lists that a JSON file holds; :func:`build` turns those parameters into the rig, the
scene and the imaging. The parameters say everything, so a scene is rebuilt from its JSON.

What varies (the ``vary`` names):

- ``optics``: camera read noise 0.3-2% of full scale, camera defocus 0.5-1.5 px, projector
  gamma 1.8-2.6, ambient light 0-0.25 (uniform);
- ``objects``: a preset scene (:func:`~bistair.sim.presets.scene_names`, one in three) or
  one to four objects from :mod:`~bistair.sim.shapes` (spheres, ellipsoids, boxes, prisms,
  face-like masks) of random size, place, rotation and albedo in the field of view at
  560-650 mm, in front of a tilted background plane (three in five) or a dark background;
- ``pose``: the scene turned by up to 8 degrees about x and y and 5 about z around the
  rig's scene centre and moved by up to 15 mm across and 30 mm along the view; the
  projector's baseline 200 +/- 20 mm, its aim +/- 1.5 degrees and roll +/- 2 degrees.

Each aspect draws from a stream of its own (:func:`streams`), so adding ``pose`` to a data
set leaves its objects and optics as they were.

Examples
--------
>>> import numpy as np
>>> params = draw(streams(np.random.SeedSequence(7)), ("objects", "pose"), base="plane",
...               camera_size=(64, 48))
>>> sorted(params), params["imaging"]["seed"] > 0
(['camera_size', 'imaging', 'objects', 'pose', 'preset', 'rig'], True)
>>> rig, scene, imaging = build(params)
>>> rig.camera.size, len(scene.surfaces) >= 1
((64, 48), True)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from ..errors import BistairError
from .presets import preset, scene_names
from .render import Imaging
from .rig import Rig, euler
from .shapes import Box, Ellipsoid, MaskRelief, Plane, Prism, Scene, Sphere, Surface

ASPECTS = ("optics", "objects", "pose")
OPTICS = {"read_noise": (0.003, 0.02), "camera_blur": (0.5, 1.5), "gamma": (1.8, 2.6),
          "ambient": (0.0, 0.25)}
_KINDS = {"sphere": Sphere, "ellipsoid": Ellipsoid, "box": Box, "prism": Prism,
          "mask": MaskRelief, "plane": Plane}


def check_vary(vary: Iterable[str]) -> tuple[str, ...]:
    """The aspects named (a comma-separated string or names), checked.

    Raises
    ------
    BistairError
        An unknown name.

    Examples
    --------
    >>> check_vary("pose,optics")
    ('optics', 'pose')
    >>> check_vary(["colour"])
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: --vary takes optics, objects, pose (joined by commas), got 'colour'
    """
    names = [v.strip() for v in (vary.split(",") if isinstance(vary, str) else vary)]
    names = [v for v in names if v]
    for name in names:
        if name not in ASPECTS:
            raise BistairError(f"--vary takes {', '.join(ASPECTS)} (joined by commas), got "
                               f"{name!r}")
    return tuple(a for a in ASPECTS if a in names)


def streams(seed: np.random.SeedSequence) -> dict[str, np.random.Generator]:
    """One generator per aspect and one for the camera noise, from one scene's seed
    sequence (``noise``, ``optics``, ``objects``, ``pose``)."""
    return {name: np.random.default_rng(child)
            for name, child in zip(("noise", *ASPECTS), seed.spawn(1 + len(ASPECTS)),
                                   strict=True)}


def draw(rngs: Mapping[str, np.random.Generator], vary: Iterable[str] = (),
         base: str | None = None, camera_size: tuple[int, int] | None = None,
         imaging: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The parameters of one scene: ``base`` (a preset name) unless ``objects`` varies,
    ``imaging`` (keyword arguments of :class:`~bistair.sim.Imaging`) with the optics drawn
    if they vary and the noise seed drawn always; ``rngs`` from :func:`streams`."""
    vary = check_vary(vary)
    params: dict[str, Any] = {"camera_size": None if camera_size is None
                              else [int(v) for v in camera_size]}
    im = dict(imaging or {})
    im["seed"] = int(rngs["noise"].integers(1, 2**31))
    if "optics" in vary:
        rng = rngs["optics"]
        im.update({k: round(float(rng.uniform(*span)), 5) for k, span in OPTICS.items()})
    params["imaging"] = im
    if "objects" in vary:
        rng = rngs["objects"]
        names = scene_names()
        if rng.random() < 1 / 3:
            params["preset"], params["objects"] = names[int(rng.integers(len(names)))], None
        else:
            params["preset"], params["objects"] = None, random_objects(rng)
    else:
        if base is None:
            raise BistairError("name a --scene, or let the objects vary (--vary objects)")
        params["preset"], params["objects"] = base, None
    params["pose"], params["rig"] = (_pose(rngs["pose"]) if "pose" in vary
                                     else (None, {}))
    return params


def random_objects(rng: np.random.Generator) -> list[dict[str, Any]]:
    """One to four objects (and maybe a background plane) as dictionaries of
    :func:`surface` (``kind`` and the shape's fields; rotations as Euler degrees)."""
    def u(lo: float, hi: float) -> float:
        return round(float(rng.uniform(lo, hi)), 3)

    def place() -> list[float]:
        return [u(-95, 95), u(-70, 70), u(560, 650)]

    objects = []
    for _ in range(int(rng.integers(1, 5))):
        kind = ("sphere", "ellipsoid", "box", "prism", "mask")[int(rng.integers(5))]
        obj: dict[str, Any] = {"kind": kind, "center": place(), "albedo": u(0.35, 0.85)}
        if kind == "sphere":
            obj["radius"] = u(12, 45)
        elif kind == "ellipsoid":
            obj.update(radii=[u(8, 40), u(8, 40), u(8, 30)],
                       rotation_deg=[u(-30, 30), u(-30, 30), u(-90, 90)])
        elif kind == "box":
            obj.update(size=[u(15, 60), u(15, 60), u(10, 40)],
                       rotation_deg=[u(-25, 25), u(-40, 40), u(-30, 30)])
        elif kind == "prism":
            obj.update(width=u(15, 50), depth=u(8, 20), length=u(30, 90),
                       rotation_deg=[0.0, u(-15, 15), u(-90, 90)])
        else:
            width = u(70, 140)
            obj.update(width=width, height=round(width * u(1.2, 1.35), 3),
                       depth=round(width * u(0.3, 0.4), 3),
                       rotation_deg=[u(-8, 8), u(-15, 15), u(-5, 5)])
        objects.append(obj)
    if rng.random() < 0.6:
        tilt_x, tilt_y = np.deg2rad([u(-10, 10), u(-10, 10)])
        normal = [round(float(np.sin(tilt_y)), 6), round(float(np.sin(tilt_x)), 6), -1.0]
        objects.append({"kind": "plane", "center": [0.0, 0.0, u(680, 760)], "normal": normal,
                        "size": [900.0, 800.0], "albedo": u(0.5, 0.85)})
    return objects


def _pose(rng: np.random.Generator) -> tuple[dict[str, Any], dict[str, Any]]:
    def u(lo: float, hi: float) -> float:
        return round(float(rng.uniform(lo, hi)), 4)

    pose = {"rotation_deg": [u(-8, 8), u(-8, 8), u(-5, 5)],
            "shift_mm": [u(-15, 15), u(-15, 15), u(-30, 30)]}
    baseline = u(180, 220)
    aim = float(np.rad2deg(np.arctan2(baseline, 600.0)))
    rig = {"baseline": baseline, "convergence_deg": round(aim + u(-1.5, 1.5), 4),
           "roll_deg": u(-2, 2)}
    return pose, rig


def surface(description: Mapping[str, Any]) -> Surface:
    """A surface of :mod:`~bistair.sim.shapes` from a dictionary: ``kind`` (sphere,
    ellipsoid, box, prism, mask, plane), the shape's fields and ``rotation_deg`` (Euler
    angles about x, y, z, see :func:`~bistair.sim.rig.euler`).

    Examples
    --------
    >>> surface({"kind": "sphere", "center": [0, 0, 600], "radius": 20.0}).radius
    20.0
    """
    fields = dict(description)
    kind = fields.pop("kind", None)
    if kind not in _KINDS:
        raise BistairError(f"unknown object kind {kind!r} (known: {', '.join(_KINDS)})")
    if "rotation_deg" in fields:
        fields["rotation"] = euler(*fields.pop("rotation_deg"))
    if "size" in fields and kind == "plane":
        fields["size"] = tuple(fields["size"])
    return _KINDS[kind](**fields)


def move_scene(scene: Scene, rotation: np.ndarray, shift: Iterable[float],
               pivot: Iterable[float]) -> Scene:
    """The scene turned by ``rotation`` about ``pivot`` and moved by ``shift`` (mm), as one
    rigid body (albedo functions of the world point stay where they are)."""
    rot = np.asarray(rotation, float)
    shift, pivot = np.asarray(list(shift), float), np.asarray(list(pivot), float)
    moved = []
    for s in scene.surfaces:
        change: dict[str, Any] = {}
        if hasattr(s, "center"):
            change["center"] = rot @ (np.asarray(s.center, float) - pivot) + pivot + shift
        if isinstance(s, Plane):
            change.update(normal=rot @ s.normal, x_axis=rot @ s.x_axis)
        elif hasattr(s, "rotation"):
            own = np.eye(3) if s.rotation is None else np.asarray(s.rotation, float)
            change["rotation"] = rot @ own
        moved.append(dataclasses.replace(s, **change))
    return Scene(moved)


def build(params: Mapping[str, Any]) -> tuple[Rig, Scene, Imaging]:
    """The rig, scene and imaging of parameters from :func:`draw`."""
    rig_args = dict(params.get("rig") or {})
    if params.get("camera_size") is not None:
        rig_args["camera_size"] = tuple(params["camera_size"])
    if params.get("objects"):
        rig, scene = Rig.default(**rig_args), Scene([surface(o) for o in params["objects"]])
    else:
        rig, scene = preset(params["preset"], **rig_args)
    pose = params.get("pose")
    if pose:
        scene = move_scene(scene, euler(*pose["rotation_deg"]), pose["shift_mm"],
                           rig.scene_center)
    return rig, scene, Imaging(**params.get("imaging", {}))
