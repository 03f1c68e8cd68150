"""Calibration boards on the virtual rig: a printed board as a textured plane in several poses,
rendered in both orientations and written in the layout ``bistair calibrate`` reads.

Examples
--------
>>> from bistair.board import Board
>>> plane = board_plane(Board("checkerboard", 9, 6, 20.0), 0, 0, 0, 0, 0, 600)
>>> [round(float(v), 6) for v in plane.center]
[0.0, 0.0, 600.0]
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..board import Board
from ..io import output_folder, write_image
from ..spec import BaseSpec
from .geometry import Rig, euler
from .render import Imaging, expose, trace
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
                         imaging: Imaging | None = None, suffix: str = ".png") -> Path:
    """Render ``board`` in every pose for the ``"columns"`` and ``"rows"`` specs (each with a
    white frame) and write ``board.json`` and ``pose-NN/{columns,rows}/`` into ``out``."""
    imaging = imaging or Imaging()
    patterns = {o: _encode(s) for o, s in specs.items()}
    with output_folder(out) as tmp:
        (tmp / "board.json").write_text(json.dumps(board.to_dict(), indent=2) + "\n")
        for i, pose in enumerate(poses):
            traced = trace(rig, Scene([board_plane(board, *pose)]),
                           dataclasses.replace(imaging, seed=imaging.seed + i))
            for orientation, spec in specs.items():
                folder = tmp / f"pose-{i:02d}" / orientation
                folder.mkdir(parents=True)
                for j, img in enumerate(expose(traced, patterns[orientation])):
                    write_image(folder / f"{j:02d}{suffix}", img)
                (folder / "spec.json").write_text(spec.to_json())
    return Path(out)


def _encode(spec: BaseSpec) -> np.ndarray:
    from .. import encode

    return encode(spec)
