"""Row matching of two rectified cameras: both cameras' projector coordinates resampled
onto their rectified grids, kinks dropped and runs smoothed, equal phase found along each
row and checked back, confirmed by a neighbouring row, and triangulated on the left
camera's grid (steps 2-4 of :mod:`bistair.geometry.stereo`; the compiled passes in
:mod:`bistair.geometry.stereo_match_jit`). The thresholds grow with the measured noise.

Examples
--------
>>> round(_noise(np.tile(np.arange(40.0), (32, 1))), 6)  # a clean ramp: no noise
0.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import BistairError
from .stereo_jit import depth_counts, remap_valid
from .stereo_match_jit import (
    ALONE,
    AMBIGUOUS,
    INCONSISTENT,
    MATCHED,
    NOT_MONOTONIC,
    OTHER_AXIS,
    UNMATCHED,
    count_status,
    match_pair,
    smooth_runs,
    supported,
)

if TYPE_CHECKING:
    from .stereo import Rectification

KINK, KINK_REACH = 4.0, 1  # a row's kinks: second differences over 4 noise, dropped +-2 px


@dataclass
class Matched:
    """What :func:`match` gives: the matched axis, the disparity and status on the
    rectified left grid, the depth on the left camera's own grid, where it is found
    (``mask``, and how many per row), how many points fell outside the depth range, the
    left pixels decoded on that axis, and the thresholds used (noise, tolerance, wiggle,
    support: rectified pixels)."""

    axis: str
    disparity: np.ndarray
    status: np.ndarray
    depth: np.ndarray
    mask: np.ndarray
    per_row: np.ndarray
    outside: int
    decoded: int
    noise: float
    tolerance: float
    wiggle: float
    support: float

    @property
    def counts(self) -> dict[str, int]:
        """How many pixels of the rectified left grid have each outcome of the search."""
        counts = count_status(self.status)
        return {"unmatched": int(counts[UNMATCHED]), "ambiguous": int(counts[AMBIGUOUS]),
                "not_monotonic": int(counts[NOT_MONOTONIC]),
                "inconsistent": int(counts[INCONSISTENT]),
                "other_axis": int(counts[OTHER_AXIS]), "alone": int(counts[ALONE]),
                "rectified_matches": int(counts[MATCHED])}


def match(coords: dict[str, tuple[np.ndarray, np.ndarray]], rect: Rectification,
          min_depth: float, max_depth: float, tolerance: float, other_tolerance: float,
          gap: int, wiggle: float, support: float, smooth: float) -> Matched:
    """Resample both cameras' projector coordinates onto the rectified grids, match them
    along the rows and triangulate (steps 2-4 of :mod:`bistair.geometry.stereo`).

    Parameters
    ----------
    coords : dict
        ``{axis: (left, right)}``: each camera's projector coordinates per coded axis
        (``"columns"``, ``"rows"``), on its own image grid, NaN where not decoded.
    rect : Rectification
        The pair's rectified grids (:func:`~bistair.geometry.stereo.rectify`).
    min_depth, max_depth, tolerance, other_tolerance, gap, wiggle, support, smooth
        The matching's settings, as for
        :func:`~bistair.geometry.stereo.reconstruct_stereo` (checked there).

    Returns
    -------
    Matched
        The matched axis, disparity and status (rectified left grid), depth and mask (the
        left camera's grid), the counts and the thresholds used.

    Raises
    ------
    BistairError
        Too few decoded pixels shared on the rectified rows, a coded axis that barely
        changes along them, or a coordinate that runs opposite ways in the two cameras.

    Examples
    --------
    >>> import cv2
    >>> from bistair.geometry.calibration import Device, StereoCalibration
    >>> from bistair.geometry.stereo import rectify
    >>> cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
    >>> rot = cv2.Rodrigues(np.array([0.0, 0.2, 0.0]))[0]
    >>> rect = rectify(StereoCalibration(cam, cam, rot, -rot @ np.array([120.0, 0, 0])))
    >>> nan = np.full((480, 640), np.nan, np.float32)
    >>> match({"columns": (nan, nan)}, rect, 0.0, np.inf, 1.0, 2.0, 3, 1.0, 2.0, 1.0)
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the two cameras share too few decoded pixels ...
    """
    spread = {name: _step(pair[0]) for name, pair in coords.items()}
    on_grid = {name: (remap_valid(lc, *rect.maps_left, spread[name]),
                      remap_valid(rc, *rect.maps_right, spread[name]))
               for name, (lc, rc) in coords.items()}
    axis, slope = _matched_axis(on_grid)
    # the thresholds grow with the noise: the phase's own (a row's second differences)
    # as a position along the row (a map and its negation have the same)
    noise_l, noise_r = (_noise(m) for m in on_grid[axis])
    noise = max(noise_l, noise_r) / abs(slope)
    # both maps rising along the rows, without their kinks, smoothed: one pass each
    src, dst = (smooth_runs(m, smooth, spread[axis], max(KINK * n * math.sqrt(6.0),
                                                         0.5 * abs(slope)), KINK_REACH,
                            negate=slope < 0)
                for m, n in zip(on_grid[axis], (noise_l, noise_r), strict=True))
    wiggle, tolerance = max(wiggle, 4.0 * noise), max(tolerance, 3.0 * noise)
    support = max(support, 4.0 * math.sqrt(2.0) * noise)
    low, high = rect.disparities(min_depth, max_depth)
    high = min(high, 4.0 * max(rect.size_left))  # farther than any image: same window
    low = max(low, -4.0 * max(rect.size_left))
    other = [name for name in on_grid if name != axis]
    pair = on_grid[other[0]] if other else (None, None)
    disparity, status = match_pair(src, dst, -high - rect.shift, -low - rect.shift,
                                   rect.shift, tolerance, gap, wiggle, spread[axis],
                                   other=pair[0], other_right=pair[1],
                                   other_tolerance=other_tolerance)
    disparity, status = supported(disparity, status, support)
    depth, mask, outside, per_row, decoded = depth_counts(
        disparity, *rect.positions, coords[axis][0], rect.f, rect.cx_left, rect.cy, rect.tx,
        rect.R1, min_depth, max_depth)
    return Matched(axis, disparity, status, depth, mask, per_row, outside, decoded, noise,
                   tolerance, wiggle, support)


def _step(coord: np.ndarray) -> float:
    """The largest spread of 2 x 2 neighbours taken as one surface: four times the median
    spread of the decode (blocks at every fourth row and column), at least one projector
    pixel."""
    h, w = coord.shape
    c = [coord[dy:h - 1 + dy:4, dx:w - 1 + dx:4] for dy in (0, 1) for dx in (0, 1)]
    with np.errstate(invalid="ignore"):
        spread = (np.maximum(np.maximum(c[0], c[1]), np.maximum(c[2], c[3]))
                  - np.minimum(np.minimum(c[0], c[1]), np.minimum(c[2], c[3])))
    spread = spread[np.isfinite(spread)]
    return max(1.0, 4.0 * float(np.median(spread))) if spread.size else 1.0


def _matched_axis(on_grid: dict[str, tuple[np.ndarray, np.ndarray]]) -> tuple[str, float]:
    """The coded axis that changes along the rectified rows, and its change per pixel
    there (its sign: the way the phase runs)."""
    slopes = {}
    for name, (lc, rc) in on_grid.items():
        slopes[name] = tuple(_row_slope(m) for m in (lc, rc))
    axis = max(slopes, key=lambda n: abs(slopes[n][0]) if math.isfinite(slopes[n][0]) else -1)
    sl, sr = slopes[axis]
    if not (math.isfinite(sl) and math.isfinite(sr)):
        raise BistairError("the two cameras share too few decoded pixels on their rectified "
                           "rows to match: is the calibration for these cameras?")
    if abs(sl) < 0.05:
        raise BistairError(f"the projector {axis} barely change along the cameras' baseline "
                           f"({sl:.3f} per rectified pixel): code the projector axis along it "
                           "(columns for cameras side by side) or both")
    if sl * sr <= 0:
        raise BistairError("the projector coordinate runs one way along the rows in the left "
                           "camera and the other way in the right one: is one image mirrored?")
    return axis, sl


def _noise(values: np.ndarray) -> float:
    """The noise (standard deviation) of a map along its rows, from second differences of
    every sixteenth row (a robust spread: 1.4826 MAD / sqrt(6)); 0 without data."""
    rows = values[::16]
    second = (rows[:, 2:] - 2 * rows[:, 1:-1] + rows[:, :-2]).ravel()
    second = second[np.isfinite(second)]
    if second.size < 10:
        return 0.0
    return float(1.4826 * np.median(np.abs(second - np.median(second))) / math.sqrt(6.0))


def _row_slope(coord: np.ndarray) -> float:
    """Median change of a map along its rows (every sixteenth row), NaN without data."""
    with np.errstate(invalid="ignore"):
        steps = np.diff(coord[::16], axis=1)
    steps = steps[np.isfinite(steps)]
    return float(np.median(steps)) if steps.size >= 10 else math.nan
