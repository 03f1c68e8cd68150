"""Calibration boards: description (``board.json``), model points, detection and a printable
albedo for simulated boards.

A board is a ``checkerboard`` (``columns x rows`` inner corners, ``spacing`` = square side),
a ``circles`` grid (``columns x rows`` dark circles on white, centres ``spacing`` apart) or an
``asymmetric-circles`` grid (OpenCV's layout: circle ``(i, j)`` of row ``i`` at
``((2 j + i % 2) * spacing, i * spacing)``). Units are millimetres. Model points lie in the
board plane ``z = 0``, row by row, in the order OpenCV's detectors return image points.

Examples
--------
>>> board = Board.from_dict({"type": "checkerboard", "columns": 4, "rows": 3, "spacing": 10})
>>> board.object_points()[[0, 1, 4]].tolist()
[[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 10.0, 0.0]]
>>> board.albedo(np.array([[5.0, 5.0], [15.0, 5.0]])).tolist()
[0.85, 0.25]
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ..errors import BistairError
from ..io.jsonfile import read_json

BOARD_TYPES = ("checkerboard", "circles", "asymmetric-circles")
ALIASES = {"chessboard": "checkerboard"}  # other names of the board types


@dataclass(frozen=True)
class Board:
    """A planar calibration target; see the module docstring for the layouts."""

    type: str = "checkerboard"
    columns: int = 9
    rows: int = 6
    spacing: float = 20.0

    def __post_init__(self) -> None:
        if self.type not in BOARD_TYPES:
            raise BistairError(f"board type must be one of {', '.join(BOARD_TYPES)}, "
                               f"got {self.type!r}")
        if min(self.columns, self.rows) < 2 or self.columns * self.rows < 6:
            raise BistairError(f"board of {self.columns}x{self.rows} features is too small")
        if not 0 < self.spacing < math.inf:  # (NaN too)
            raise BistairError(f"board spacing must be a positive number of mm, got "
                               f"{self.spacing}")

    # -- serialisation ---------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Board:
        """A board from its ``board.json`` dictionary (validated)."""
        if not isinstance(data, Mapping):
            raise BistairError("board description must be a JSON object")
        missing = [k for k in ("type", "columns", "rows", "spacing") if k not in data]
        if missing:
            raise BistairError(f"board description misses field(s): {', '.join(missing)}")
        try:
            kind = str(data["type"])
            return cls(ALIASES.get(kind, kind), _int(data["columns"]), _int(data["rows"]),
                       float(data["spacing"]))
        except (TypeError, ValueError) as exc:
            if isinstance(exc, BistairError):
                raise
            raise BistairError(f"bad board description: {exc}") from None

    @classmethod
    def load(cls, path: str | Path) -> Board:
        """Read ``board.json``."""
        return cls.from_dict(read_json(path, "board description"))

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    # -- geometry --------------------------------------------------------------------------
    @property
    def pattern_size(self) -> tuple[int, int]:
        """``(columns, rows)`` as OpenCV's detectors take it."""
        return self.columns, self.rows

    def object_points(self) -> np.ndarray:
        """Model points ``(columns * rows, 3)`` float32, row by row, in millimetres."""
        j, i = np.meshgrid(np.arange(self.columns), np.arange(self.rows))
        x = 2 * j + i % 2 if self.type == "asymmetric-circles" else j
        pts = np.stack([x.ravel(), i.ravel(), np.zeros(i.size)], axis=1) * self.spacing
        return pts.astype(np.float32)

    def extent(self, margin: float | None = None) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the printed board with a white ``margin`` (mm,
        default one spacing beyond the outermost squares or circles)."""
        pts = self.object_points()
        pad = (2.0 if self.type == "checkerboard" else 1.0) * self.spacing
        pad = pad if margin is None else pad - self.spacing + margin
        return (float(pts[:, 0].min() - pad), float(pts[:, 1].min() - pad),
                float(pts[:, 0].max() + pad), float(pts[:, 1].max() + pad))

    def albedo(self, xy: np.ndarray, dark: float = 0.25, light: float = 0.85) -> np.ndarray:
        """Albedo of the printed board at board coordinates ``xy`` ``(N, 2)`` (mm).

        Checkerboard squares (the one whose top-left corner is feature 0 is light) surrounded
        by a row of squares and then white; circles of radius ``spacing / 4`` (``0.35 *
        spacing`` for the asymmetric grid). For simulated boards (:mod:`bistair.sim`).
        """
        xy = np.asarray(xy, float)
        s = self.spacing
        if self.type == "checkerboard":
            ix, iy = np.floor(xy[:, 0] / s), np.floor(xy[:, 1] / s)
            inside = ((ix >= -1) & (ix <= self.columns - 1) & (iy >= -1)
                      & (iy <= self.rows - 1))
            return np.where(inside & ((ix + iy) % 2 == 1), dark, light)
        pts = self.object_points()[:, :2].astype(float)
        radius = (0.35 if self.type == "asymmetric-circles" else 0.25) * s
        # nearest circle centre on the grid, by rows then by position in the row
        row = np.clip(np.rint(xy[:, 1] / s), 0, self.rows - 1).astype(int)
        step = 2 if self.type == "asymmetric-circles" else 1
        shift = (row % 2) if self.type == "asymmetric-circles" else 0
        col = np.clip(np.rint((xy[:, 0] / s - shift) / step), 0, self.columns - 1).astype(int)
        centre = pts[row * self.columns + col]
        near = np.hypot(*(xy - centre).T) <= radius
        return np.where(near, dark, light)

    # -- detection -------------------------------------------------------------------------
    def detect(self, image: np.ndarray) -> np.ndarray | None:
        """Sub-pixel image points ``(columns * rows, 2)`` of the board in a grey image (any
        dtype; float images as fractions of full scale), or ``None`` if it is not found."""
        grey = _to_uint8(image)
        size = self.pattern_size
        if self.type == "checkerboard":
            flags = cv2.CALIB_CB_EXHAUSTIVE | cv2.CALIB_CB_ACCURACY
            found, pts = cv2.findChessboardCornersSB(grey, size, flags=flags)
            if not found:
                flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
                found, pts = cv2.findChessboardCorners(grey, size, flags=flags)
                if not found:
                    return None
                criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 50, 1e-3)
                pts = cv2.cornerSubPix(grey, pts, (5, 5), (-1, -1), criteria)
        else:
            params = cv2.SimpleBlobDetector_Params()
            params.minArea, params.maxArea = 8.0, 0.05 * grey.size
            detector = cv2.SimpleBlobDetector_create(params)
            flags = (cv2.CALIB_CB_ASYMMETRIC_GRID if self.type == "asymmetric-circles"
                     else cv2.CALIB_CB_SYMMETRIC_GRID)
            found, pts = cv2.findCirclesGrid(grey, size, flags=flags, blobDetector=detector)
            if not found:
                return None
        return np.asarray(pts, np.float64).reshape(-1, 2)


def parse_board(text: str) -> Board:
    """A board from its short description ``TYPE:COLUMNSxROWS:SPACING``.

    ``TYPE`` is ``chessboard`` (or ``checkerboard``), ``circles`` or
    ``asymmetric-circles``; ``COLUMNSxROWS`` the inner corners (circles) per row and column;
    ``SPACING`` the square side (centre distance) in millimetres.

    Parameters
    ----------
    text : str
        The description, e.g. ``"chessboard:9x7:75"``.

    Returns
    -------
    Board

    Raises
    ------
    BistairError
        If the text is not of that form or describes a board that cannot be.

    Examples
    --------
    >>> parse_board("chessboard:9x7:75")
    Board(type='checkerboard', columns=9, rows=7, spacing=75.0)
    >>> parse_board("chessboard:9x7")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: a board is TYPE:COLUMNSxROWS:SPACING (e.g. chessboard:9x7:25 \
for 9 x 7 inner corners of 25 mm squares), got 'chessboard:9x7'
    """
    parts = [part.strip() for part in text.strip().split(":")]
    size = parts[1].lower().split("x") if len(parts) == 3 else []
    try:
        if len(size) != 2 or not all(s.isdigit() for s in size):
            raise ValueError
        spacing = float(parts[2])
    except ValueError:
        raise BistairError(f"a board is TYPE:COLUMNSxROWS:SPACING (e.g. chessboard:9x7:25 for "
                           f"9 x 7 inner corners of 25 mm squares), got {text!r}") from None
    return Board.from_dict({"type": parts[0].lower(), "columns": int(size[0]),
                            "rows": int(size[1]), "spacing": spacing})


def is_board_text(text: str) -> bool:
    """Whether a ``--board`` value is a short description rather than a file name.

    Parameters
    ----------
    text : str
        The value.

    Returns
    -------
    bool
        True when it starts with a board type and a colon (``chessboard:``, ...).

    Examples
    --------
    >>> is_board_text("chessboard:9x7:75"), is_board_text("calib/board.json")
    (True, False)
    """
    kind = text.strip().split(":", 1)[0].lower()
    return ":" in text and (kind in BOARD_TYPES or kind in ALIASES)


def _int(value: Any) -> int:
    if isinstance(value, bool) or int(value) != value:
        raise BistairError(f"board columns and rows must be integers, got {value!r}")
    return int(value)


def _to_uint8(image: np.ndarray) -> np.ndarray:
    """A grey image stretched to uint8 (its 99.5th percentile to 255)."""
    img = np.asarray(image)
    if img.ndim != 2:
        raise BistairError(f"board image must be 2-D grey, got shape {img.shape}")
    img = np.nan_to_num(img.astype(np.float64))
    top = float(np.percentile(img, 99.5)) if img.size else 0.0
    if top <= 0:
        return np.zeros(img.shape, np.uint8)
    return np.clip(np.round(img * (255.0 / top)), 0, 255).astype(np.uint8)
