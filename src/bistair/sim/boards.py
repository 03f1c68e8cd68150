"""Calibration boards on the virtual rig: a printed board as a textured plane in several poses,
rendered in both orientations and written in the layout ``bistair calibrate`` reads; and
board correspondences drawn straight from a calibration (:func:`synthetic_views`).

Examples
--------
>>> from bistair.geometry.board import Board
>>> plane = board_plane(Board("checkerboard", 9, 6, 20.0), 0, 0, 0, 0, 0, 600)
>>> [round(float(v), 6) for v in plane.center]
[0.0, 0.0, 600.0]
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Sequence
from pathlib import Path

import cv2
import numpy as np

from ..codecs import encode
from ..errors import BistairError
from ..geometry.board import Board
from ..geometry.calibration import Calibration
from ..io.atomic import output_folder, write_image
from ..spec import BaseSpec
from .render import Imaging, expose, trace
from .rig import Rig, euler
from .shapes import Plane, Scene

# Board poses: degrees about x, y, z, then the features' centre in mm. Tilted up to 25
# degrees and spread toward the image corners (distortion needs the corners), all inside
# both devices' views of the default rig.
POSES = ((0, 0, 0, 0, 0, 600), (20, 0, 0, -50, -35, 620), (-20, 0, 5, 50, 35, 580),
         (0, 25, 0, 50, -35, 600), (0, -25, -5, -50, 35, 640), (15, 15, 10, -50, 0, 560),
         (-15, -15, -10, 50, 0, 650), (10, -20, 0, 0, 40, 600))


def board_plane(board: Board, rx: float, ry: float, rz: float, *centre: float) -> Plane:
    """The printed board as a plane with its albedo, its features centred on ``centre``."""
    rot = euler(rx, ry, rz)
    x0, y0, x1, y1 = board.extent()
    t = np.array(centre, float) - rot @ board.object_points().mean(axis=0)
    return Plane(center=rot @ [(x0 + x1) / 2, (y0 + y1) / 2, 0] + t, normal=rot[:, 2],
                 x_axis=rot[:, 0], size=(x1 - x0, y1 - y0),
                 albedo=lambda p: board.albedo((p - t) @ rot[:, :2]))


def write_board_captures(rig: Rig, board: Board, specs: dict[str, BaseSpec], out: str | Path,
                         poses: Sequence[Sequence[float]] = POSES,
                         imaging: Imaging | None = None, suffix: str = ".png",
                         progress: Callable[[str], None] | None = None) -> Path:
    """Render ``board`` in every pose for the ``"columns"`` and ``"rows"`` specs and write
    ``board.json`` and ``pose-NN/{columns,rows}/`` into ``out``; or for one ``"both"`` spec
    (both axes in one capture set), ``pose-NN/`` with the captures and their ``spec.json``.
    The board is found in the white frame of specs that have one, else in the mean image
    (``bistair calibrate``). ``progress`` is called as each pose starts."""
    return write_board_sets(rig, board, {"": specs}, out, poses, imaging, suffix, progress)


def write_board_sets(rig: Rig, board: Board, sets: dict[str, dict[str, BaseSpec]],
                     out: str | Path, poses: Sequence[Sequence[float]] = POSES,
                     imaging: Imaging | None = None, suffix: str = ".png",
                     progress: Callable[[str], None] | None = None) -> Path:
    """:func:`write_board_captures` for several pattern sets at once, each pose ray-cast
    once: ``sets`` maps a sub-folder of ``out`` (``""`` for ``out`` itself) to its specs by
    orientation, and each sub-folder gets its own ``board.json`` and ``pose-NN/``.
    ``progress`` is called with ``"rendering board pose N of M"`` as each pose starts."""
    imaging = imaging or Imaging()
    patterns = {(name, o): encode(s) for name, specs in sets.items() for o, s in specs.items()}
    with output_folder(out) as tmp:
        for name in sets:
            (tmp / name).mkdir(parents=True, exist_ok=True)
            (tmp / name / "board.json").write_text(json.dumps(board.to_dict(), indent=2) + "\n")
        for i, pose in enumerate(poses):
            if progress is not None:
                progress(f"rendering board pose {i + 1} of {len(poses)}")
            traced = trace(rig, Scene([board_plane(board, *pose)]),
                           dataclasses.replace(imaging, seed=imaging.seed + i))
            for (name, orientation), pats in patterns.items():
                folder = tmp / name / f"pose-{i:02d}"
                folder = folder if orientation == "both" else folder / orientation
                folder.mkdir(parents=True)
                for j, img in enumerate(expose(traced, pats)):
                    write_image(folder / f"{j:02d}{suffix}", img)
                (folder / "spec.json").write_text(sets[name][orientation].to_json())
    return Path(out)


def synthetic_views(calibration: Calibration, board: Board, poses: int,
                    rng: np.random.Generator, noise: float = 0.0, distance: float = 600.0
                    ) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
    """Random board poses seen by both devices of ``calibration``: object points and the
    camera and projector pixels of each pose (``cv2.projectPoints``, Gaussian ``noise`` px).

    The board is tilted by up to 25 degrees about x and y and turned about its normal, near
    ``(0, 0, distance)``; every point falls inside both images.
    """
    obj = board.object_points().astype(float)
    centre = obj.mean(axis=0)
    views: tuple[list, list, list] = ([], [], [])
    for _ in range(100 * poses):
        if len(views[0]) == poses:
            return views
        rvec = np.deg2rad([rng.uniform(-25, 25), rng.uniform(-25, 25), rng.uniform(-20, 20)])
        rot = cv2.Rodrigues(rvec)[0]
        tvec = np.array([rng.uniform(-30, 30), rng.uniform(-30, 30),
                         distance + rng.uniform(-60, 60)]) - rot @ centre
        world = obj @ rot.T + tvec
        pix = [cv2.projectPoints(world @ r.T + t, np.zeros(3), np.zeros(3), d.K, d.dist)[0]
               .reshape(-1, 2) + (rng.normal(0, noise, (len(obj), 2)) if noise else 0.0)
               for d, r, t in ((calibration.camera, np.eye(3), np.zeros(3)),
                               (calibration.projector, calibration.R, calibration.T))]
        if all(((p >= 0) & (p <= np.array(d.size) - 1)).all()
               for p, d in zip(pix, (calibration.camera, calibration.projector), strict=True)):
            for out, value in zip(views, (obj.astype(np.float32), *pix), strict=True):
                out.append(value)
    raise BistairError("the board rarely falls inside both images; check the geometry")
