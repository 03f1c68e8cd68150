"""Two cameras and a projector: the binocular virtual rig.

The left camera is the world frame (at the origin, looking along +z); the right camera sits
``baseline`` mm to its right (+x) and the projector on the line between them (``projector_at``
of the way from left to right), both turned toward the scene centre
``(0, 0, working_distance)``. Each camera with the projector is a :class:`~bistair.sim.Rig`
(:meth:`StereoRig.rig`), so every camera renders with the same tracer
(:func:`~bistair.sim.trace`, :func:`~bistair.sim.expose`) and its own ground truth: depth
in that camera's frame, points in the world (left camera) frame.

Examples
--------
>>> srig = StereoRig.default(camera_size=(64, 48), baseline=150)
>>> (srig.right.center.round(3) + 0).tolist(), (srig.projector.center.round(3) + 0).tolist()
([150.0, 0.0, 0.0], [75.0, 0.0, 0.0])
>>> point = np.array([[0.0, 0.0, 600.0]])
>>> srig.left.project(point).round(3).tolist(), srig.right.project(point).round(3).tolist()
([[31.5, 23.5]], [[31.5, 23.5]])
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..codecs import encode
from ..geometry.board import Board
from ..io.atomic import output_folder, write_image
from ..spec import BaseSpec
from .boards import POSES, board_plane
from .render import Imaging, expose, trace
from .rig import Camera, Projector, Rig, check_size, look_rotation
from .shapes import Scene
from .truth import Truth

_NO_DIST = (0.0, 0.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True, eq=False)
class StereoRig:
    """A left camera (the world frame), a right camera and a projector (mm)."""

    left: Camera
    right: Camera
    projector: Projector
    working_distance: float = 600.0

    @classmethod
    def default(cls, camera_size: tuple[int, int] = (1280, 1024),
                projector_size: tuple[int, int] = (1920, 1080), baseline: float = 200.0,
                projector_at: float = 0.5, working_distance: float = 600.0,
                camera_focal: float | None = None, projector_focal: float = 2000.0,
                camera_dist: Sequence[float] = _NO_DIST,
                right_dist: Sequence[float] | None = None,
                projector_dist: Sequence[float] = _NO_DIST, right_height: float = 0.0,
                right_roll_deg: float = 0.0) -> StereoRig:
        """Two equal cameras ``baseline`` mm apart along x, both aimed at the scene centre,
        and the projector on the baseline between them (``projector_at`` = 0: at the left
        camera, 1: at the right one), aimed there too.

        ``camera_focal`` defaults to ``1.875 * width`` (2400 px at 1280 wide, as
        :meth:`~bistair.sim.Rig.default`); ``right_dist`` to ``camera_dist``.
        ``right_height`` moves the right camera along y (mm) and ``right_roll_deg`` turns it
        about its axis: a pair that is not level, as real ones are not quite.
        """
        cw, ch = check_size(camera_size, "camera")
        pw, ph = check_size(projector_size, "projector")
        fc = 1.875 * cw if camera_focal is None else float(camera_focal)
        left = Camera(cw, ch, fc, fc, (cw - 1) / 2, (ch - 1) / 2, tuple(camera_dist))
        right = _aimed(Camera, (cw, ch, fc, fc, (cw - 1) / 2, (ch - 1) / 2,
                                tuple(camera_dist if right_dist is None else right_dist)),
                       baseline, working_distance, right_height, right_roll_deg)
        projector = _aimed(Projector, (pw, ph, projector_focal, projector_focal, (pw - 1) / 2,
                                       (ph - 1) / 2, tuple(projector_dist)),
                           projector_at * baseline, working_distance)
        return cls(left, right, projector, working_distance)

    def rig(self, side: str) -> Rig:
        """The camera ``side`` (``"left"`` or ``"right"``) with the projector."""
        return Rig(getattr(self, side), self.projector, self.working_distance)

    @property
    def baseline(self) -> float:
        """Distance between the camera centres (mm)."""
        return float(np.linalg.norm(self.right.center - self.left.center))


def _aimed(kind: type, intrinsics: tuple, x: float, distance: float, y: float = 0.0,
           roll: float = 0.0) -> Camera | Projector:
    """A device at ``(x, y, 0)`` turned about y toward ``(0, 0, distance)``, then rolled
    by ``roll`` degrees about its axis."""
    rot = look_rotation(float(np.rad2deg(np.arctan2(x, distance))), roll)
    return kind(*intrinsics, rot, -rot @ np.array([x, y, 0.0]))


def render_stereo(patterns: np.ndarray, srig: StereoRig, scene: Scene,
                  imaging: Imaging | None = None
                  ) -> tuple[np.ndarray, np.ndarray, Truth, Truth]:
    """Both cameras' images of ``patterns`` on ``scene`` and their ground truths.

    The right camera's noise is seeded with ``imaging.seed + 1``; each truth's depth is in
    its own camera's frame, its points in the left camera's.
    """
    imaging = imaging or Imaging()
    out = []
    for i, side in enumerate(("left", "right")):
        im = dataclasses.replace(imaging, seed=imaging.seed + i)
        traced = trace(srig.rig(side), scene, im)
        out.append((expose(traced, patterns, im), traced.truth))
    (li, lt), (ri, rt) = out
    return li, ri, lt, rt


def write_board_pairs(srig: StereoRig, board: Board, out: str | Path,
                      poses: Sequence[Sequence[float]] = POSES, spec: BaseSpec | None = None,
                      imaging: Imaging | None = None, layout: str = "poses") -> Path:
    """Render ``board`` in every pose under the projector's white light for both cameras and
    write them as ``bistair calibrate-stereo`` reads them.

    ``layout="poses"``: ``pose-NN/left.png`` and ``pose-NN/right.png``; ``"folders"``:
    ``left/NN.png`` and ``right/NN.png``. ``spec`` gives the projector size of the white
    frame (default: the rig's projector, lit fully). Also writes ``board.json``.
    """
    imaging = imaging or Imaging()
    white = np.ones((1, srig.projector.height, srig.projector.width), np.float32)
    if spec is not None:
        white = encode(spec.replace(white=1))[-1:]
    with output_folder(out) as tmp:
        (tmp / "board.json").write_text(json.dumps(board.to_dict(), indent=2) + "\n")
        for i, pose in enumerate(poses):
            scene = Scene([board_plane(board, *pose)])
            for k, side in enumerate(("left", "right")):
                im = dataclasses.replace(imaging, seed=imaging.seed + 2 * i + k)
                img = expose(trace(srig.rig(side), scene, im), white, im)[0]
                path = (tmp / f"pose-{i:02d}" / f"{side}.png" if layout == "poses"
                        else tmp / side / f"{i:02d}.png")
                path.parent.mkdir(parents=True, exist_ok=True)
                write_image(path, img)
    return Path(out)
