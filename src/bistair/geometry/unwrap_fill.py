"""Stereo phase unwrapping's last step (:mod:`bistair.geometry.unwrap`): the left pixels
the right camera cannot see, continued from their decided neighbours by the left camera's
own phase.

A left pixel whose point the right camera does not see (its match falls off the right
image, or a nearer surface hides it there) has no candidate; the projector lights it and
the left camera sees it, so its wrapped phase is as good as its neighbours'. It takes the
fringe order that continues the absolute phase of at least two decided (or continued)
8-neighbours, all that lie within :func:`phase_bound` of it (and within
:func:`bend_bound` of the line through them and the next pixel beyond) agreeing, when the depth
that order gives lies in the depth range, continues theirs, and the right camera could
not have seen it (:func:`~.unwrap_fill_jit.continue_rows`). That last condition is what
keeps it off the wrong side of a silhouette: a strip of background hidden beside an
object continued from the object's side would lie at the object's depth, where the right
camera sees the background behind it instead of something nearer.

Examples
--------
>>> a = np.float32([[0.0, 0.3, 0.6, 0.9], [0.0, 0.3, 0.6, 0.9]])
>>> round(phase_bound(a, np.ones((2, 4), bool), 0.02), 3)  # three steps of 0.3, the noise
1.013
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from ..core.phase import wrap
from .calibration import StereoCalibration
from .stereo import Rectification
from .unwrap_fill_jit import continue_rows, right_nearest

#: The phase step (radians) a continued pixel may take to a neighbour: this many times the
#: decided pixels' median step along a row or column (the larger), plus
#: :data:`NOISE_SIGMAS` times the noise of two phases; at most :data:`MAX_BOUND`.
STEPS = 3.0
NOISE_SIGMAS = 4.0
MAX_BOUND = 0.5 * math.pi
#: The right view's point at a continued pixel's match must be this many pixels of
#: disparity nearer (a surface that hides it).
MARGIN = 2.0
#: Pixels within this many of one without phase (an object's rim against the dark beyond:
#: the blur mixes their phase) are not continued into. two-masks, projector halfway
#: (benchmarks/spu_reference.py's rig): at 160 x 120, 174 of 1029 continued pixels over
#: 5 mm off the truth (the mask's rim) without this, 65 of 902 with 2, 26 of 803 with 3;
#: at 320 x 240, 135 of 4134, 16 of 3904, 0 of 3698.
RIM = 3


def phase_bound(phase: np.ndarray, decided: np.ndarray, noise: float) -> float:
    """The largest phase step (radians) a continued pixel may take to a neighbour: from the
    decided pixels' own steps (:data:`STEPS` times the median along rows or along columns,
    the larger) and the noise (:data:`NOISE_SIGMAS` times that of two phases), at most
    :data:`MAX_BOUND`.

    Parameters
    ----------
    phase : numpy.ndarray
        ``(H, W)`` wrapped phase (radians).
    decided : numpy.ndarray
        ``(H, W)`` bool: the decided pixels.
    noise : float
        The phase noise (radians, a typical pixel's standard deviation).

    Returns
    -------
    float

    Examples
    --------
    >>> a = np.float32([[0.0, 2.0, 4.0, 6.0]])  # steps of 2 rad: capped
    >>> round(phase_bound(a, np.ones((1, 4), bool), 0.0), 4)
    1.5708
    """
    steps = [0.0]
    for first, second, both in ((phase[:, :-1], phase[:, 1:], decided[:, :-1] & decided[:, 1:]),
                                (phase[:-1], phase[1:], decided[:-1] & decided[1:])):
        if both.any():
            step = np.abs(wrap(second[both] - first[both]))
            steps.append(float(np.median(step)))
    bound = STEPS * max(steps) + NOISE_SIGMAS * math.sqrt(2) * noise
    return min(bound, MAX_BOUND)


def bend_bound(phase: np.ndarray, decided: np.ndarray, noise: float) -> float:
    """The largest second difference of the phase (radians) a continued pixel may make
    with two neighbours in a line: :data:`STEPS` times the decided pixels' median along
    rows plus :data:`NOISE_SIGMAS` times the noise of three phases (``sqrt(6)`` of one).

    Parameters
    ----------
    phase : numpy.ndarray
        ``(H, W)`` wrapped phase (radians).
    decided : numpy.ndarray
        ``(H, W)`` bool: the decided pixels.
    noise : float
        The phase noise (radians, a typical pixel's standard deviation).

    Returns
    -------
    float

    Examples
    --------
    >>> a = np.float32([[0.0, 0.3, 0.6, 0.9, 1.3]])  # one bend of 0.1
    >>> round(bend_bound(a, np.ones((1, 5), bool), 0.01), 3)
    0.098
    """
    both = decided[:, :-2] & decided[:, 1:-1] & decided[:, 2:]
    median = 0.0
    if both.any():
        second = phase[:, 2:][both] - 2 * phase[:, 1:-1][both] + phase[:, :-2][both]
        median = float(np.median(np.abs(wrap(second))))
    return STEPS * median + NOISE_SIGMAS * math.sqrt(6) * noise


def continue_unseen(lrect: np.ndarray, rrect: np.ndarray, disparity: np.ndarray, n_in: np.ndarray,
                    rect: Rectification, calibration: StereoCalibration, period: float,
                    noise: float, tolerance: float, min_depth: float, max_depth: float,
                    reach: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The decided disparities of the rectified left grid continued into the pixels the
    right camera cannot see (module docstring).

    Parameters
    ----------
    lrect, rrect : numpy.ndarray
        ``(H, W)``, ``(H, W_right)`` float32 the left and the right camera's wrapped phase
        on the rectified grids.
    disparity : numpy.ndarray
        ``(H, W)`` float32 decided disparities, NaN where undecided.
    n_in : numpy.ndarray
        ``(H, W)`` int16 each pixel's candidates (only those of none, 0 or -1, continue;
        not at the left camera's outermost pixels, whose phase the blur bends: 0.19 rad
        off on the virtual rig, 6 mm; nor within :data:`RIM` pixels of one without phase).
    rect : Rectification
        :func:`~.stereo.rectify` of ``calibration``.
    calibration : StereoCalibration
        The cameras and the projector.
    period : float
        The fringe period (projector pixels).
    noise, tolerance : float
        The left camera's phase noise and the largest disagreement of the right phase at a
        seen match (:func:`~.unwrap_fill_jit.continue_rows`; radians).
    min_depth, max_depth : float
        The depth range (left camera frame, mm).
    reach : float, optional
        The smallest disparity step (pixels) allowed to a neighbour.

    Returns
    -------
    disparity : numpy.ndarray
        ``(H, W)`` float32 with the continued pixels.
    continued : numpy.ndarray
        ``(H, W)`` bool: the continued pixels.

    Examples
    --------
    >>> from bistair.geometry.stereo import rectify
    >>> from bistair.sim import preset, trace
    >>> from bistair.sim.stereo import StereoRig
    >>> from bistair.geometry.unwrap import rectified_phase
    >>> rig, scene = preset("plane", camera_size=(80, 60))  # a plane at 600 mm
    >>> srig = StereoRig.default(camera_size=(80, 60), projector_size=rig.projector.size)
    >>> cal = StereoCalibration.from_rig(srig)
    >>> rect = rectify(cal)
    >>> lrect, rrect = (rectified_phase(np.float32(2 * np.pi * x / 48 % (2 * np.pi)), m)
    ...                 for x, m in ((trace(srig.rig(side), scene).truth.coord_x, maps)
    ...                              for side, maps in (("left", rect.maps_left),
    ...                                                 ("right", rect.maps_right))))
    >>> d = np.full(lrect.shape, np.nan, np.float32)
    >>> d[:, 40:] = np.float32(rect.disparities(600.0, 600.0)[0])  # the right half decided
    >>> n = np.where(np.isfinite(d), 1, 0).astype(np.int16)
    >>> out, continued = continue_unseen(lrect, rrect, d, n, rect, cal, 48.0, 0.0, 0.1,
    ...                                 500.0, 700.0)
    >>> bool(continued[:, :40].any()), bool(np.isnan(out[:, 20]).all())  # seen: left
    (False, True)
    """
    proj = calibration.projector
    mx, my = rect.maps_left  # the left camera's outermost pixels are not continued into
    cam = calibration.left
    inner = (mx >= 1) & (mx <= cam.width - 2) & (my >= 1) & (my <= cam.height - 2)
    rim = 2 * RIM + 1  # nor within RIM pixels of one without phase
    inner &= cv2.erode(np.isfinite(lrect).astype(np.uint8), np.ones((rim, rim), np.uint8),
                       borderValue=1) > 0
    lrect = np.where(inner | np.isfinite(disparity), lrect, np.float32(np.nan))
    right = right_nearest(disparity, rect.shift, rect.size_right[0])
    bound = phase_bound(lrect, np.isfinite(disparity), noise)
    bend = bend_bound(lrect, np.isfinite(disparity), noise)
    return continue_rows(lrect, rrect, disparity, n_in, right, rect.shift, rect.f, rect.cx_left,
                         rect.cy, rect.tx, rect.R1.T, proj.device.K, proj.device.dist,
                         proj.R, proj.T, period, proj.device.width, min_depth, max_depth,
                         bound, bend, reach, MARGIN, tolerance)
