"""Things that move: a rigid motion per frame, and every frame traced at its own pose.

A :class:`Motion` is a constant velocity: a translation (mm per frame) and a rotation (a
rotation vector, degrees per frame, about the moving body's centre), or a velocity in
camera pixels per frame that :meth:`Motion.at_depth` turns into millimetres at the depth of
the moving surfaces. At time ``t`` (frames, real-valued) a body with centre ``c`` is at
``X' = c + R(t) (X - c) + t * translation`` with ``R(t)`` the rotation of ``t`` times the
rotation vector. The moving bodies are the scene's objects (every surface but its planes,
which are walls and floors; a scene of planes alone moves its planes), each about its own
centre, or the whole scene about the scene centre (``whole=True``).

:func:`scene_at` gives the scene at time ``t`` (each moving surface wrapped in
:class:`Moved`), :func:`trace_frames` traces one pose per frame, :func:`render_moving`
exposes frame ``k`` of a pattern set at pose ``k`` (with the noise frame ``k`` of a still
render would take) and returns each frame's truth.

Examples
--------
>>> import numpy as np
>>> from bistair.sim import Imaging, Plane, Rig, Scene, Sphere
>>> rig = Rig.default(camera_size=(48, 40))
>>> scene = Scene([Sphere(center=(0, 0, 560), radius=40), Plane(center=(0, 0, 640))])
>>> m = parse_motion("2,0,0mm")
>>> moved = scene_at(scene, m, 3.0)
>>> moved.surfaces[0].bound()[0].round(3).tolist(), moved.surfaces[1] is scene.surfaces[1]
([6.0, 0.0, 560.0], True)
>>> m = parse_motion("1px").at_depth(rig, scene)
>>> m.translation[0] == moving_depth(rig, scene) / rig.camera.fx  # 1 px at its depth
True
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import cv2
import numpy as np

from ..errors import BistairError
from .render import Imaging, Trace, expose, trace
from .rig import Rig, apply
from .shapes import Plane, Scene, Surface
from .truth import Truth

_SYNTAX = ("VALUEpx (along the coded axis), X,Ypx, X,Y,Zmm, X,Y,Zmm,RX,RY,RZdeg or "
           "RX,RY,RZdeg (per frame)")


@dataclass(frozen=True)
class Motion:
    """A constant rigid velocity per frame.

    Attributes
    ----------
    translation : (3,) mm per frame, camera frame (x right, y down, z away).
    rotation : (3,) rotation vector in degrees per frame (about the body's centre).
    pixels : ``(vx, vy)`` camera pixels per frame, or None; :meth:`at_depth` converts it
        into ``translation`` (a velocity in pixels has no translation of its own yet).
    whole : the whole scene moves (about the scene centre) instead of its objects.
    """

    translation: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotation: tuple[float, float, float] = (0.0, 0.0, 0.0)
    pixels: tuple[float, float] | None = None
    whole: bool = False
    text: str = field(default="", compare=False)

    @property
    def still(self) -> bool:
        """Whether nothing moves."""
        return (not any(self.translation) and not any(self.rotation)
                and not (self.pixels and any(self.pixels)))

    def pose(self, t: float, centre: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
        """``(R, shift)`` with ``X' = R @ X + shift`` for a body of ``centre`` at time ``t``.

        Examples
        --------
        >>> r, s = Motion(rotation=(0.0, 0.0, 90.0)).pose(1.0, (10.0, 0.0, 0.0))
        >>> (r @ [11.0, 0.0, 0.0] + s).round(6).tolist()
        [10.0, 1.0, 0.0]
        """
        if self.pixels is not None and any(self.pixels):
            raise BistairError("a motion in camera pixels needs a depth first (at_depth)")
        c = np.asarray(centre, float).reshape(3)
        rvec = np.deg2rad(np.asarray(self.rotation, float)) * float(t)
        rot = cv2.Rodrigues(rvec.reshape(3, 1))[0] if np.any(rvec) else np.eye(3)
        return rot, c - rot @ c + float(t) * np.asarray(self.translation, float)

    def at_depth(self, rig: Rig, scene: Scene) -> Motion:
        """The motion with a velocity in pixels turned into mm per frame at the median depth
        of the moving surfaces (seen by ``rig``'s camera at time 0); itself otherwise.

        Raises
        ------
        BistairError
            The camera sees none of the moving surfaces.
        """
        if self.pixels is None:
            return self
        depth = moving_depth(rig, scene, self.whole)
        cam = rig.camera
        vx, vy = self.pixels
        return dataclasses.replace(self, translation=(vx * depth / cam.fx, vy * depth / cam.fy,
                                                      0.0), pixels=None)

    def to_dict(self) -> dict[str, Any]:
        """The motion as written in ``scene.json``."""
        out: dict[str, Any] = {"text": self.text, "translation_mm": list(self.translation),
                               "rotation_deg": list(self.rotation),
                               "moves": "scene" if self.whole else "objects"}
        if self.pixels is not None:
            out["pixels"] = list(self.pixels)
        return out


def parse_motion(text: str, orientation: str = "columns", whole: bool = False) -> Motion:
    """A :class:`Motion` from its option syntax (per frame): ``1px`` (camera pixels along
    the coded axis: x for ``columns``, y for ``rows``), ``1,0.5px`` (x, y pixels),
    ``0.4,0,0mm`` (translation), ``0.4,0,0mm,0,0.2,0deg`` (translation and a rotation
    vector in degrees) or ``0,0.2,0deg`` (rotation alone).

    Raises
    ------
    BistairError
        One line naming the value and the syntax.

    Examples
    --------
    >>> parse_motion("0.5px").pixels, parse_motion("1,2px", "rows").pixels
    ((0.5, 0.0), (1.0, 2.0))
    >>> m = parse_motion("0.4,0,0mm,0,0.2,0deg")
    >>> m.translation, m.rotation
    ((0.4, 0.0, 0.0), (0.0, 0.2, 0.0))
    >>> parse_motion("3 px")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: --motion '3 px' is not a motion: give VALUEpx ...
    """
    bad = BistairError(f"--motion {text!r} is not a motion: give {_SYNTAX}")
    groups = re.fullmatch(r"([-+0-9.eE,]+?)(px|mm|deg)(?:,([-+0-9.eE,]+?)(deg))?",
                          text if isinstance(text, str) else "")
    if groups is None:
        raise bad
    first, unit, second, unit2 = groups.groups()
    parts = {unit: first}
    if second is not None:
        if unit != "mm":
            raise bad
        parts["deg"] = second
    values = {}
    for key, chunk in parts.items():
        try:
            numbers = tuple(float(v) for v in chunk.split(","))
        except ValueError:
            raise bad from None
        if not all(math.isfinite(v) for v in numbers):
            raise bad
        values[key] = numbers
    if "px" in values:
        px = values["px"]
        if len(px) == 1:
            px = (px[0], 0.0) if orientation != "rows" else (0.0, px[0])
        if len(px) != 2:
            raise bad
        return Motion(pixels=(px[0], px[1]), whole=whole, text=text)
    for key in values:
        if len(values[key]) != 3:
            raise bad
    zero = (0.0, 0.0, 0.0)
    return Motion(translation=values.get("mm", zero), rotation=values.get("deg", zero),
                  whole=whole, text=text)


@dataclass(frozen=True, eq=False, kw_only=True)
class Moved(Surface):
    """A surface moved rigidly: ``X' = rotation @ X + shift`` (its albedo moves with it)."""

    inner: Surface
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    shift: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def albedo_at(self, points: np.ndarray) -> np.ndarray:
        return self.inner.albedo_at(apply(self.rotation.T, points - self.shift))

    def bound(self) -> tuple[np.ndarray, float]:
        centre, radius = self.inner.bound()
        return self.rotation @ centre + self.shift, radius

    def intersect(self, origin, dirs, tmin=0.0, normals=True):
        o = self.rotation.T @ (origin - self.shift)
        t, n = self.inner.intersect(o, apply(self.rotation.T, dirs), tmin, normals)
        return t, None if n is None else apply(self.rotation, n)


def moving(scene: Scene, whole: bool = False) -> list[int]:
    """Indices of the surfaces that move: all with ``whole``, else every surface but the
    planes (all of them in a scene of planes alone)."""
    if whole:
        return list(range(len(scene.surfaces)))
    objects = [i for i, s in enumerate(scene.surfaces) if not isinstance(s, Plane)]
    return objects or list(range(len(scene.surfaces)))


def scene_at(scene: Scene, motion: Motion, t: float, centre: Sequence[float] | None = None
             ) -> Scene:
    """The scene at time ``t`` (frames): each moving surface wrapped in :class:`Moved`.

    Objects turn about their own bounding centre; the whole scene (``motion.whole``) about
    ``centre`` (default: the origin's ``(0, 0, 600)``, the default rig's scene centre).
    """
    surfaces = list(scene.surfaces)
    if t == 0 or motion.still:
        return scene
    for i in moving(scene, motion.whole):
        s = surfaces[i]
        c = (centre if centre is not None else (0.0, 0.0, 600.0)) if motion.whole \
            else s.bound()[0]
        rot, shift = motion.pose(t, c)
        surfaces[i] = Moved(inner=s, object_id=s.object_id, albedo=s.albedo, rotation=rot,
                            shift=shift)
    return Scene(surfaces)


def moving_depth(rig: Rig, scene: Scene, whole: bool = False) -> float:
    """Median depth (mm) of the moving surfaces' pixels seen by ``rig``'s camera at rest.

    Raises
    ------
    BistairError
        The camera sees none of them.
    """
    truth = trace(rig, scene, Imaging(supersample=1, edge_margin=0), workers=1).truth
    ids = [scene.ids[i] for i in moving(scene, whole)]
    seen = np.isin(truth.object_id, ids) & np.isfinite(truth.depth)
    if not seen.any():
        raise BistairError("the camera sees none of the moving surfaces, so a motion in "
                           "pixels has no depth to be converted at")
    return float(np.median(truth.depth[seen]))


def trace_frames(rig: Rig, scene: Scene, motion: Motion, times: Sequence[float],
                 imaging: Imaging | None = None, workers: int | None = None) -> list[Trace]:
    """One :func:`~bistair.sim.trace` per time (frames), the scene at its pose there.

    ``motion`` in pixels is converted at the depth of the moving surfaces first
    (:meth:`Motion.at_depth`); the rig's scene centre is the whole scene's pivot.
    """
    motion = motion.at_depth(rig, scene)
    return [trace(rig, scene_at(scene, motion, t, rig.scene_center), imaging, workers)
            for t in times]


def render_moving(patterns: np.ndarray, rig: Rig, scene: Scene, motion: Motion,
                  imaging: Imaging | None = None, workers: int | None = None
                  ) -> tuple[np.ndarray, list[Truth]]:
    """Frame ``k`` of ``patterns`` exposed with the scene at its pose of time ``k``, and
    the truth of every frame.

    A still motion gives the images of :func:`~bistair.sim.render` (frame ``k`` takes the
    noise of frame ``k``, ``expose(..., first_frame=k)``).

    Examples
    --------
    >>> from bistair.sim import Plane, Rig, Scene, Sphere, render
    >>> rig = Rig.default(camera_size=(32, 24), projector_size=(64, 48), projector_focal=100)
    >>> scene = Scene([Sphere(center=(0, 0, 560), radius=60)])
    >>> pats = np.random.default_rng(0).uniform(0, 1, (3, 48, 64))
    >>> still, _ = render(pats, rig, scene)
    >>> frames, truths = render_moving(pats, rig, scene, Motion())
    >>> bool((frames == still).all()), len(truths)
    (True, 3)
    """
    imaging = imaging or Imaging()
    pats = np.asarray(patterns)
    traces = trace_frames(rig, scene, motion, range(len(pats)), imaging, workers)
    frames = [expose(tr, pats[k:k + 1], imaging, workers, first_frame=k)[0]
              for k, tr in enumerate(traces)]
    return np.stack(frames), [tr.truth for tr in traces]
