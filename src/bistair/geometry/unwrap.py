"""Stereo phase unwrapping: the fringe order of one N-step set from two cameras, the
projector and a known depth range.

A single-period set gives each camera the wrapped phase alone. With two calibrated cameras
and the projector's pose (:class:`~.stereo_calibration.ProjectorPose`), the order follows
from geometry instead of extra patterns:

1. Both cameras' wrapped phases are resampled onto the rectified grids
   (:func:`rectified_phase`: bilinearly about one corner's phase, each corner's
   difference from it wrapped, so never across a wrap; a pixel needs its known neighbours
   to carry 0.999 of the weight).
2. For each left pixel, the places of equal wrapped phase along the right camera's
   rectified row within the disparities the depth range allows are its candidates; each is
   triangulated and kept where it projects into the projector at a column whose phase
   agrees with the left pixel's within ``tolerance`` (:func:`~.unwrap_jit.unwrap_rows`).
3. A pixel with exactly one consistent candidate in the depth range is decided (when the
   right camera's own search does not decide another disparity there and a row above or
   below confirms it): its fringe order comes from the projector column of its point.
4. Growth (:func:`~.unwrap_jit.grow`): from the decided pixels outwards, a pixel of one
   to four candidates takes the one within :data:`REACH` pixels of the disparity of
   :data:`GROW_SUPPORT` decided neighbours; with none or several it is left undecided
   (NaN, order -1), never guessed.
5. Continuation (:func:`~.unwrap_fill.continue_unseen`): a left pixel the right camera
   gives no candidate for (its match off the right view, or hidden there by a nearer
   decided surface) takes the order that continues the left phase of two agreeing
   decided neighbours, when the depth it gives lies in the range and continues theirs.
6. The depth of a decided pixel is the left camera's ray cut by the projector column of
   its absolute phase (:func:`projector_depth`, as the published pipeline does).
7. :func:`check_range`: when most points the search finds over a wider range (three
   times as wide, about the same centre) fall outside the depth range, the range is wrong
   and refused. With the calibration's recorded pixel origin, :func:`consistent_share`
   under it and the other tells which one the data fit.

What it cannot decide: a candidate repeats wherever the right camera's and the projector's
fringes line up again along the left pixel's ray. With the projector halfway between the
cameras, every second fringe of the right camera lines up with one of the projector's, so a
depth range wider than about two right-camera fringes along the ray
(:func:`ghost_spacing`) leaves pixels with two consistent candidates: undecided. A projector
nearer one camera, a longer period or a narrower range decide more pixels. A pixel whose
point the right camera does not see (occlusion) has no true candidate: a wrong one that
happens to agree is rejected by the support of the rows above and below, and the pixel
is decided by continuation alone (step 5).

Examples
--------
>>> round(ghost_spacing(200.0, 100.0, 600.0, 16.0, 2000.0), 1)  # mm along the ray
28.8
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.captures import prepare
from ..core.measure import FringeSet, measure
from ..core.result import make_result
from ..errors import BistairError
from .calibration import Calibration, StereoCalibration
from .projection_matrices import with_pixel_origin
from .stereo import (
    Rectification,
    StereoResult,
    depth_counts,
    grey_image,
    grid_points,
    rectify,
    resample_wrapped,
)
from .triangulate import check_depth_range, triangulate
from .unwrap_fill import continue_unseen
from .unwrap_jit import column_terms, grow, mixed_mask, unwrap_candidates

#: The tolerance on the projector's phase is this many times the phase noise of the two
#: cameras together (at least :data:`MIN_TOLERANCE` radians).
TOLERANCE_SIGMAS = 4.0
MIN_TOLERANCE = 0.1
#: A decided disparity must be confirmed within this many pixels by the row above or below.
SUPPORT = 1.0
#: A pixel of two or more candidates takes the one within this many pixels of a decided
#: neighbour's disparity (one surface), when exactly one is (:func:`~.unwrap_jit.grow`).
REACH = 1.0
#: ... and when this many of its decided 4-neighbours agree: one lets growth leak onto a
#: repeat of the surface (benchmarks/stereo_unwrap.py, mugs-on-wall halfway with 48-px
#: fringes: 46731 pixels an order off; objects-on-plane with 16-px: 57630), two none.
GROW_SUPPORT = 2
#: The other pixel origin is taken when the projector confirms more than this many times
#: as many left pixels with it, and more than this share (:func:`_origin_check`;
#: benchmarks/pixel_origin.py).
ORIGIN_RATIO, ORIGIN_MIN = 2.0, 0.2
#: Decided pixels this close (rectified pixels along the row) to one the right camera does
#: not confirm are dropped (:func:`_beside_occlusion`).
EDGE = 2
#: :func:`check_range` refuses when more than this share of the points lies outside.
MOST_OUTSIDE = 0.5
#: ... judged on every this-many-th rectified row, and only on at least this many points
#: (and this share of the valid pixels searched): fewer say nothing.
CHECK_ROWS = 8
CHECK_POINTS, CHECK_SHARE = 100, 0.005
#: The second look: over half the range's near end to twice its far end, refused when more
#: than this share lies outside (the surface beyond the first look's reach: 800-900 mm
#: given for masks at 560-630 mm found repeats at 704-864 mm, 23% outside, and decided
#: 3728 pixels 250 mm off; over 400-1800 mm 98% lie outside). Right ranges on
#: benchmarks/stereo_unwrap.py's 24 cases at 320 x 240: at most 0.752 (a 20-mm range on
#: the plane with 16-px fringes, repeats every 29 mm), wrong ones caught there 0.917-1.0.
MOST_OUTSIDE_WIDE = 0.9
#: :func:`mixed_pixels`: a decided pixel's depth steps the same way to both its neighbours
#: along a row, column or diagonal by more than this many footprints (``z / f`` mm a
#: pixel: a surface turned over 76 degrees from the ray), and more than
#: :data:`EDGE_SIGMAS` times the two depths' noise: a pixel mixing a near and a far
#: surface (the cameras' blur across a depth step), which both cameras and the projector
#: confirm as they would a real surface that steep. Or it differs from every decided
#: 8-neighbour by that much: a spike. Never more than half the depth step of one order.
#: On 22 virtual-rig cases (6 scenes, both rigs of tests/test_unwrap.py and
#: benchmarks/spu_reference.py) 3 left 234 right pixels undecided (within 2 mm of the
#: truth: steep sides) for 437 over 5 mm off; 4: 73 for 300; 5: 28 for 162.
GRAZING = 4.0
EDGE_SIGMAS = 4.0


@dataclass
class Unwrapped:
    """What :func:`unwrap_stereo` finds.

    ``disparity``: float32 on the rectified left grid, NaN where undecided; ``depth``
    (float32 ``z``, mm) and ``mask`` on the left camera's own grid; ``candidates``: int16
    on the rectified left grid, the consistent candidates in the depth range of each pixel
    (0: none, 1: one, 2 or more: decided only by growth; -1: the search reaches past the
    right view); ``info``: counts and settings.
    """

    disparity: np.ndarray
    depth: np.ndarray
    mask: np.ndarray
    candidates: np.ndarray
    rectification: Rectification
    info: dict[str, Any] = field(default_factory=dict)


def ghost_spacing(baseline: float, projector_offset: float, depth: float, period: float,
                  projector_focal: float) -> float:
    """How far along a left pixel's ray (mm) two candidates that the projector both
    confirms lie apart, for a surface facing the rig at ``depth``.

    A candidate steps one right-camera fringe for ``depth * s / baseline`` mm along the ray
    (``s = period * depth / projector_focal``: the fringe's width on the surface), the
    projector's phase by ``projector_offset / baseline`` of a fringe per step; they line up
    again after ``q`` steps, the denominator of that ratio (2 for a projector halfway).

    Parameters
    ----------
    baseline : float
        The cameras' distance (mm).
    projector_offset : float
        The projector's distance from the left camera along the baseline (mm).
    depth, period, projector_focal : float
        The surface's depth (mm), the fringe period and the projector's focal length (px).

    Returns
    -------
    float
        The spacing (mm); a depth range narrower than this decides every pixel it sees.

    Examples
    --------
    >>> round(ghost_spacing(200.0, 100.0, 600.0, 16.0, 2000.0), 1)  # halfway: q = 2
    28.8
    >>> round(ghost_spacing(200.0, 50.0, 600.0, 16.0, 2000.0), 1)  # a quarter: q = 4
    57.6
    """
    step = depth * (period * depth / projector_focal) / baseline
    ratio = abs(projector_offset) / baseline
    for q in range(1, 9):
        if abs(q * ratio - round(q * ratio)) < 0.05:
            return q * step
    return 9 * step


def rectified_phase(phase: np.ndarray, maps: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """A wrapped phase map resampled onto a rectified grid (float32, ``[0, 2*pi)``, NaN
    where the known pixels around the sample carry less than 0.999 of its bilinear weight):
    :func:`~bistair.geometry.stereo_jit.resample_wrapped`, as a stream resamples each
    window (with its modulation threshold).

    Parameters
    ----------
    phase : numpy.ndarray
        ``(H, W)`` wrapped phase (radians), NaN where unknown.
    maps : tuple of numpy.ndarray
        The grid's remap tables (rectified pixel -> camera pixel).

    Returns
    -------
    numpy.ndarray

    Examples
    --------
    >>> phase = np.float32([[6.2, 0.1, np.nan]])
    >>> mx, my = np.float32([[0.5, 1.5]]), np.float32([[0.0, 0.0]])
    >>> out = rectified_phase(phase, (mx, my))
    >>> round(float(out[0, 0]), 4), bool(np.isnan(out[0, 1]))
    (0.0084, True)
    """
    return resample_wrapped(phase, maps)[1]


def _search(lrect: np.ndarray, rrect: np.ndarray, rect: Rectification,
            calibration: StereoCalibration, period: float, tolerance: float, low: float,
            high: float, window: tuple[float, float], rows: np.ndarray | None = None,
            from_right: bool = False, whole: bool = True, everything: bool = False
            ) -> tuple[np.ndarray, ...]:
    """:func:`~.unwrap_jit.unwrap_rows` over the disparities of depths ``window`` (for
    the right grid's pixels with ``from_right``; with ``everything``, the kept candidates
    too: :func:`~.unwrap_jit.unwrap_candidates`)."""
    proj = calibration.projector
    lo, hi = rect.disparities(*window)
    own, other = (rrect, lrect) if from_right else (lrect, rrect)
    out = unwrap_candidates(own, other, lo, min(hi, 4.0 * rect.size_right[0]), rect.shift,
                            rect.f, rect.cx_left, rect.cy, rect.tx, rect.R1.T, proj.device.K,
                            proj.device.dist, proj.R, proj.T, period, tolerance, low, high,
                            proj.device.width, rows, from_right, whole)
    return out if everything else out[:4]


def cross_checked(left: np.ndarray, right: np.ndarray, shift: float,
                  agree: float = 1.0, contradicted: bool = False) -> np.ndarray:
    """The left grid's disparities that the right grid's decision at the matched place
    confirms (within ``agree`` px at the nearest right pixel), else NaN.

    A left pixel whose point the right camera does not see has no true candidate; a wrong
    one the projector happens to confirm lands on a right pixel that decided its own,
    other point.

    Parameters
    ----------
    left : numpy.ndarray
        ``(H, W)`` float32 disparities decided for the left grid's pixels (rectified
        pixels, ``d = x_l - x_r - shift``), NaN where undecided.
    right : numpy.ndarray
        ``(H, W_right)`` float32 disparities decided for the right grid's pixels (the same
        rows, the same convention), NaN where undecided.
    shift : float
        ``cx_left - cx_right`` of the rectification (pixels).
    agree : float, optional
        The largest difference (pixels) of the two disparities.
    contradicted : bool, optional
        Return instead where the right pixel decided a disparity more than ``agree`` off
        (bool: its own, other point; a right pixel undecided says nothing).

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` float32: ``left`` where the right pixel at ``x_l - shift - d`` (rounded)
        decided a disparity within ``agree``, NaN elsewhere.

    Examples
    --------
    >>> left = np.float32([[np.nan, 3.0, 3.0, 9.0]])
    >>> right = np.float32([[3.0, 3.0, 2.0, np.nan]])
    >>> cross_checked(left, right, 0.0).tolist()
    [[nan, nan, nan, nan]]
    >>> cross_checked(np.float32([[np.nan, np.nan, np.nan, 3.0]]), right, 0.0).tolist()
    [[nan, nan, nan, 3.0]]
    >>> one = np.float32([[np.nan, np.nan, np.nan, 0.5]])  # lands on the right's 2.0
    >>> cross_checked(one, right, 0.0, contradicted=True).tolist()
    [[False, False, False, True]]
    """
    h, w = left.shape
    rows, cols = np.nonzero(np.isfinite(left))
    d = left[rows, cols]
    xr = np.rint(cols - shift - d).astype(np.int64)
    inside = (xr >= 0) & (xr < right.shape[1])
    ok = np.zeros(d.shape, bool)
    there = right[rows[inside], xr[inside]]
    if contradicted:
        off = np.zeros((h, w), bool)
        off[rows[inside], cols[inside]] = np.abs(there - d[inside]) > agree
        return off
    ok[inside] = np.abs(there - d[inside]) <= agree
    out = np.full((h, w), np.nan, np.float32)
    out[rows[ok], cols[ok]] = d[ok]
    return out


def _supported(disparity: np.ndarray, support: float) -> np.ndarray:
    """``disparity`` where the row above or below has a disparity within ``support`` px
    at the same column (one of them must confirm it), else NaN."""
    d = disparity
    ok = np.zeros(d.shape, bool)
    with np.errstate(invalid="ignore"):
        ok[1:] |= np.abs(d[1:] - d[:-1]) <= support
        ok[:-1] |= np.abs(d[:-1] - d[1:]) <= support
    return np.where(ok, d, np.float32(np.nan)).astype(np.float32)


def _near_occlusion(occluded: np.ndarray, reach: int) -> np.ndarray:
    """The pixels within ``reach`` pixels along the row of an ``occluded`` pixel (one whose
    point the right camera does not confirm): beside an occlusion, the left ray grazes the
    occluding surface's silhouette, and a point of that surface that the right camera sees
    agrees with the pixel's phase as well as the hidden true point would."""
    near = occluded.copy()
    for k in range(1, reach + 1):
        near[:, k:] |= occluded[:, :-k]
        near[:, :-k] |= occluded[:, k:]
    return near


def projector_depth(depth: np.ndarray, mask: np.ndarray, phase: np.ndarray,
                    calibration: StereoCalibration, period: float, rays: tuple[np.ndarray,
                                                                            np.ndarray]
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The depth of each decided left pixel from the left camera's ray and the projector's
    column of its absolute phase (as one-camera triangulation does); the two cameras' point
    only chooses the fringe order.

    Parameters
    ----------
    depth, mask : numpy.ndarray
        ``(H, W)`` the two cameras' depth (float32, mm) and where a point is decided.
    phase : numpy.ndarray
        ``(H, W)`` the left camera's wrapped phase (radians, ``[0, 2*pi)``).
    calibration : StereoCalibration
        The cameras and the projector.
    period : float
        The fringe period (projector pixels).
    rays : tuple of numpy.ndarray
        The left pixels' undistorted rays ``x / z``, ``y / z`` (:class:`~.stereo.
        Rectification` ``rays``).

    Returns
    -------
    depth : numpy.ndarray
        ``(H, W)`` float32 ``z`` (mm) from the projector, NaN where undecided or where the
        column's plane does not cut the ray in front of both.
    mask : numpy.ndarray
        ``(H, W)`` bool: where it is finite.
    residual : numpy.ndarray
        ``(N,)`` float64 of the decided pixels (row-major): the projector column of the
        two cameras' point minus the absolute phase's column (projector pixels).

    Examples
    --------
    >>> from bistair.geometry.stereo import rectify
    >>> from bistair.geometry.calibration import StereoCalibration
    >>> from bistair.sim import preset, trace
    >>> from bistair.sim.stereo import StereoRig
    >>> rig, scene = preset("plane", camera_size=(80, 60))  # a plane at 600 mm
    >>> srig = StereoRig.default(camera_size=(80, 60), projector_size=rig.projector.size)
    >>> cal = StereoCalibration.from_rig(srig)
    >>> truth = trace(srig.rig("left"), scene).truth
    >>> phase = np.float32(2 * np.pi * truth.coord_x / 48 % (2 * np.pi))
    >>> near = np.where(truth.mask, truth.depth + 3.0, np.nan)  # the pair's point 3 mm off
    >>> z, mask, res = projector_depth(near, truth.mask, phase, cal, 48.0, rectify(cal).rays)
    >>> float(np.abs(z[mask] - truth.depth[mask]).max()) < 1e-3  # mm
    True
    """
    rows, cols = np.nonzero(mask)
    points = grid_points(np.where(mask, depth, np.nan).astype(np.float32), *rays)[rows, cols]
    proj = calibration.projector
    u = proj.project(points)[:, 0]
    phi = phase[rows, cols].astype(np.float64)
    k = np.rint((2 * np.pi * u / period - phi) / (2 * np.pi))
    column = (phi + 2 * np.pi * k) * period / (2 * np.pi)
    pair = Calibration(calibration.left, proj.device, proj.R, proj.T)
    z = triangulate(np.column_stack([cols, rows]).astype(np.float64), column, pair)[:, 2]
    out = np.full(mask.shape, np.nan, np.float32)
    out[rows, cols] = z
    return out, np.isfinite(out), u - column


def mixed_pixels(depth: np.ndarray, mask: np.ndarray, calibration: StereoCalibration,
                 period: float, noise: float, rays: tuple[np.ndarray, np.ndarray],
                 terms: np.ndarray | None = None) -> np.ndarray:
    """The decided left pixels whose depth is no surface's: mixed pixels at a depth step
    and spikes (:data:`GRAZING`), to be left undecided.

    A left pixel across a depth step mixes the near and the far surface's phase; its depth
    lands between them, and with the cameras' blur a band of such pixels ramps from one
    to the other. The pixel is in such a ramp when its depth steps the same way to both
    its neighbours along a row, column or diagonal, each step over the limit; a spike
    differs from every decided 8-neighbour by more. The limit comes from the rig:
    :data:`GRAZING` footprints (``z / f``), at least :data:`EDGE_SIGMAS` times the noise
    of two depths (the projector's depth step per column times the phase noise in
    columns), at most half the depth step of one order (an order off is always a spike);
    the depth a column moves from the projector's pinhole model (its distortion changes it
    little). One compiled pass (:func:`~.unwrap_jit.mixed_mask`).

    Parameters
    ----------
    depth, mask : numpy.ndarray
        ``(H, W)`` float32 ``z`` (mm) of the left camera's pixels and where decided.
    calibration : StereoCalibration
        The cameras and the projector.
    period : float
        The fringe period (projector pixels).
    noise : float
        The left camera's phase noise (radians, a typical pixel's standard deviation).
    rays : tuple of numpy.ndarray
        The left pixels' undistorted rays ``x / z``, ``y / z`` (:class:`~.stereo.
        Rectification` ``rays``).
    terms : numpy.ndarray, optional
        :func:`mixed_terms` of ``calibration`` and ``rays`` (what does not change between
        depth maps of one rig: a stream computes it once); by default computed here.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` bool: the decided pixels to leave undecided.

    Examples
    --------
    >>> from bistair.geometry.stereo import rectify
    >>> from bistair.sim import preset, trace
    >>> from bistair.sim.stereo import StereoRig
    >>> rig, scene = preset("plane", camera_size=(80, 60))  # a plane at 600 mm
    >>> srig = StereoRig.default(camera_size=(80, 60), projector_size=rig.projector.size)
    >>> cal = StereoCalibration.from_rig(srig)
    >>> truth = trace(srig.rig("left"), scene).truth
    >>> z = truth.depth.astype(np.float32)
    >>> float(600.0 / cal.left.K[0, 0])  # mm: the footprint; the limit four of them
    4.0
    >>> z[30, 20:23] = [630.0, 660.0, 690.0]  # a ramp to a step 120 mm behind
    >>> z[30, 23:], z[40, 40] = 720.0, 630.0  # (a wall) and a spike
    >>> np.argwhere(mixed_pixels(z, truth.mask, cal, 48.0, 0.03, rectify(cal).rays)).tolist()
    [[30, 20], [30, 21], [30, 22], [40, 40]]
    """
    proj = calibration.projector
    return mixed_mask(depth, mask, rays, proj.R, proj.T, proj.device.K[0, 0],
                      calibration.left.K[0, 0], noise, period, GRAZING, EDGE_SIGMAS, terms)


def mixed_terms(calibration: StereoCalibration, rays: tuple[np.ndarray, np.ndarray]
                ) -> np.ndarray:
    """What :func:`mixed_pixels` needs of each left pixel beside its depth, for the depth
    one projector column moves along its ray (:func:`~.unwrap_jit.column_terms`).

    Parameters
    ----------
    calibration : StereoCalibration
        The cameras and the projector.
    rays : tuple of numpy.ndarray
        The left pixels' undistorted rays (as for :func:`mixed_pixels`).

    Returns
    -------
    numpy.ndarray
        ``(H, W, 2)`` float64.

    Examples
    --------
    >>> from bistair.geometry.stereo import rectify
    >>> from bistair.sim.stereo import StereoRig
    >>> cal = StereoCalibration.from_rig(StereoRig.default(camera_size=(80, 60)))
    >>> rays = rectify(cal).rays
    >>> z = np.full((60, 80), 600.0, np.float32)
    >>> z[30, 40] = 700.0  # a spike
    >>> mixed = mixed_pixels(z, np.ones(z.shape, bool), cal, 48.0, 0.03, rays,
    ...                      mixed_terms(cal, rays))
    >>> np.argwhere(mixed).tolist()
    [[30, 40]]
    """
    proj = calibration.projector
    return column_terms(rays, proj.R, proj.T, proj.device.K[0, 0])


def check_range(lrect: np.ndarray, rrect: np.ndarray, rect: Rectification,
                calibration: StereoCalibration, period: float, tolerance: float,
                low: float, high: float, wide: tuple[float, float] | None = None
                ) -> tuple[float, int, tuple[float, float] | None]:
    """The share of the points found over a range three times as wide as ``[low, high]``
    (about its centre, from half ``low``) that fall outside ``[low, high]``.

    Every :data:`CHECK_ROWS`-th rectified row is searched over the wider range; each pixel
    with a consistent candidate there gives a point, the candidate whose phase agrees best
    (the true point agrees within the noise; the repeats of the fringes further along the
    ray drift off, a little, with the distance). Fewer than :data:`CHECK_POINTS` points
    (or :data:`CHECK_SHARE` of the valid pixels searched) are not judged: ``share`` 0 and
    ``depths`` ``None``.

    Parameters
    ----------
    lrect, rrect : numpy.ndarray
        ``(H, W)`` float32 wrapped phase of the left and right camera on the rectified grids
        (:func:`rectified_phase`), NaN where unknown.
    rect : Rectification
        :func:`~.stereo.rectify` of ``calibration``.
    calibration : StereoCalibration
        The cameras and the projector.
    period : float
        The fringe period (projector pixels).
    tolerance : float
        The largest disagreement (radians) of the projector's phase.
    low, high : float
        The depth range (left camera frame, mm) to check.
    wide : tuple of float, optional
        The range searched (mm); three times ``[low, high]`` about its centre by default.

    Returns
    -------
    share : float
        Of the points, those outside the range (0 when not judged).
    points : int
        The points found.
    depths : tuple of float or None
        Their 5th and 95th percentile depth (mm), ``None`` when not judged.

    Examples
    --------
    >>> from bistair.geometry.calibration import StereoCalibration
    >>> from bistair.sim import preset, trace
    >>> from bistair.sim.stereo import StereoRig
    >>> rig, scene = preset("plane", camera_size=(80, 60))  # a plane at 600 mm
    >>> srig = StereoRig.default(camera_size=(80, 60), projector_size=rig.projector.size,
    ...                          projector_at=0.3)
    >>> cal = StereoCalibration.from_rig(srig)
    >>> x = [trace(srig.rig(side), scene).truth.coord_x for side in ("left", "right")]
    >>> lp, rp = (np.float32(2 * np.pi * c / 48 % (2 * np.pi)) for c in x)  # period 48
    >>> from bistair.geometry.stereo import rectify
    >>> rect = rectify(cal)
    >>> lrect = rectified_phase(lp, rect.maps_left)
    >>> rrect = rectified_phase(rp, rect.maps_right)
    >>> share, points, depths = check_range(lrect, rrect, rect, cal, 48.0, 0.1, 500.0, 700.0)
    >>> round(share, 3), points, [round(d) for d in depths]  # 2% outside: kept
    (0.023, 640, [600, 600])
    >>> share, points, depths = check_range(lrect, rrect, rect, cal, 48.0, 0.1, 650.0, 750.0)
    >>> round(share, 3), points, [round(d) for d in depths]  # the plane is nearer: refused
    (1.0, 625, [600, 600])
    >>> check_range(lrect, rrect, rect, cal, 48.0, 0.1, 800.0, 900.0)  # 700-1000 finds none
    (0.0, 0, None)
    """
    width = high - low
    wide = wide or (max(low - width, 0.5 * low), high + width)
    rows = np.arange(0, lrect.shape[0], CHECK_ROWS, dtype=np.int64)
    _, _, n_all, z_all = _search(lrect, rrect, rect, calibration, period, tolerance, low,
                                 high, wide, rows, whole=False)
    z = z_all[np.isfinite(z_all)]
    searched = int(np.isfinite(lrect[rows]).sum())
    if z.size < max(CHECK_POINTS, CHECK_SHARE * searched):
        return 0.0, int(z.size), None
    outside = float(np.mean((z < low) | (z > high)))
    lo, hi = np.percentile(z, [5, 95])
    return outside, int(z.size), (float(lo), float(hi))


def unwrap_stereo(left_phase: np.ndarray, right_phase: np.ndarray,
                  calibration: StereoCalibration, period: float, min_depth: float,
                  max_depth: float, noise: tuple[float, float] = (0.0, 0.0),
                  tolerance: float | None = None, rectification: Rectification | None = None,
                  force: bool = False, check: bool = True, depth_from: str = "projector",
                  propagate: bool = True, pixel_origin: int | None = None,
                  drop_mixed: bool = True, continue_unseen: bool = False) -> Unwrapped:
    """Depth from two cameras' wrapped phase of one N-step set, the projector and a depth
    range (module docstring).

    Parameters
    ----------
    left_phase, right_phase : numpy.ndarray
        ``(H, W)`` wrapped phase ``2*pi*x_p/period`` mod ``2*pi`` of each camera (radians,
        NaN where unknown), on its own image grid.
    calibration : StereoCalibration
        The two cameras and the projector (its ``projector`` entry is needed).
    period : float
        The fringe period (projector pixels along its columns).
    min_depth, max_depth : float
        The depth range (left camera frame, mm): a finite ``0 < min_depth < max_depth``.
    noise : tuple of float, optional
        Each camera's phase noise (radians, a typical pixel's standard deviation).
    tolerance : float, optional
        The largest disagreement (radians) of the projector's phase; by default
        :data:`TOLERANCE_SIGMAS` times the two noises together, at least
        :data:`MIN_TOLERANCE`.
    rectification : Rectification, optional
        :func:`~.stereo.rectify` of ``calibration``, if already made.
    force : bool, optional
        Keep the result when :func:`check_range` would refuse the range (a warning in
        ``info``).
    check : bool, optional
        Run :func:`check_range` (about a fifth of the time); a stream of windows of one
        scene may check its first window alone (``info["range_check"]`` is then ``None``).
    depth_from : {"projector", "cameras"}, optional
        The depth of a decided pixel: the left camera's ray cut by the projector column of
        its absolute phase (:func:`projector_depth`, as the published pipeline and
        one-camera triangulation do), or the two cameras' disparity (on the virtual rig
        two to three times more precise with the projector at 0.3 to 0.5 of the
        baseline: the cameras lie further apart).
    propagate : bool, optional
        Grow the decided pixels into those of two or more candidates
        (:func:`~.unwrap_jit.grow`: the one candidate within :data:`REACH` pixels of the
        disparity of :data:`GROW_SUPPORT` decided neighbours, none guessed).
    pixel_origin : int, optional
        The pixel origin (0 or 1) of the matrices the calibration came from
        (:func:`~.projection_matrices.recorded_origin`): checked against the data
        (:func:`_origin_check`), and the other used, with a warning, when it explains the
        data clearly better. ``None``: not checked.
    drop_mixed : bool, optional
        Leave undecided the pixels :func:`mixed_pixels` finds (mixed pixels at depth steps,
        spikes; ``info["mixed"]`` counts them).
    continue_unseen : bool, optional
        Continue the decided pixels into the left pixels the right camera cannot see (no
        candidate: off its view or hidden there by a nearer surface) by the left camera's
        own phase (:func:`~.unwrap_fill.continue_unseen`; ``info["continued"]`` counts
        the left pixels decided so). Off by default: the published pipeline leaves them
        (``stereo --continue-unseen`` turns it on).

    Returns
    -------
    Unwrapped

    Raises
    ------
    BistairError
        No projector in the calibration, a depth range that is not finite and positive, a
        tolerance that is not positive, maps of other sizes than the calibration's, or
        (without ``force``) a depth range that most points fall outside.

    Examples
    --------
    >>> from bistair.geometry.calibration import StereoCalibration
    >>> from bistair.sim import preset, trace
    >>> from bistair.sim.stereo import StereoRig
    >>> rig, scene = preset("plane", camera_size=(80, 60))  # a plane at 600 mm
    >>> srig = StereoRig.default(camera_size=(80, 60), projector_size=rig.projector.size,
    ...                          projector_at=0.3)
    >>> cal = StereoCalibration.from_rig(srig)
    >>> x = [trace(srig.rig(side), scene).truth.coord_x for side in ("left", "right")]
    >>> lp, rp = (np.float32(2 * np.pi * c / 48 % (2 * np.pi)) for c in x)  # period 48
    >>> found = unwrap_stereo(lp, rp, cal, 48.0, 500.0, 700.0)
    >>> found.info["decided_fraction"], found.info["undecided"]
    (0.7725, 0)
    >>> round(float(np.median(found.depth[found.mask])), 1)  # mm
    600.0
    >>> unwrap_stereo(lp, rp, cal, 48.0, 650.0, 750.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: 100% of the points ... at 600 to 600 mm): correct --depth-range
    """
    if calibration.projector is None:
        raise BistairError("stereo phase unwrapping needs the projector in the calibration "
                           "(its \"projector\" entry: bistair simulate --cameras 2 writes it, "
                           "import-calibration --projection-matrices makes one)")
    check_depth_range(min_depth, max_depth)
    if not (min_depth > 0 and math.isfinite(max_depth)):
        raise BistairError(f"stereo phase unwrapping needs a finite depth range above 0 mm "
                           f"(--depth-range ZMIN:ZMAX), got {min_depth:g}:{max_depth:g}")
    for name, phase, dev in (("left", left_phase, calibration.left),
                             ("right", right_phase, calibration.right)):
        if phase.shape != (dev.height, dev.width):
            raise BistairError(f"the calibration is for {dev.width}x{dev.height} {name} "
                               f"images, the {name} captures are {phase.shape[1]}x"
                               f"{phase.shape[0]}")
    if tolerance is None:
        tolerance = max(MIN_TOLERANCE, TOLERANCE_SIGMAS * math.hypot(*noise))
    if not tolerance > 0:
        raise BistairError(f"the phase tolerance must be positive, got {tolerance}")
    if depth_from not in ("projector", "cameras"):
        raise BistairError(f"depth_from must be 'projector' or 'cameras', got {depth_from!r}")
    origin: dict[str, Any] = {}  # the cameras' pixel origin first: the range is judged on it
    if pixel_origin is not None:
        origin = _origin_check(left_phase, right_phase, calibration, period, tolerance,
                               min_depth, max_depth, pixel_origin)
        if origin["pixel_origin"] != pixel_origin:
            calibration = with_pixel_origin(calibration, origin["pixel_origin"] - pixel_origin)
            rectification = None  # (the given grids are the other origin's)
    rect = rectification or rectify(calibration)
    lrect = rectified_phase(left_phase, rect.maps_left)
    rrect = rectified_phase(right_phase, rect.maps_right)
    share, points, depths = (check_range(lrect, rrect, rect, calibration, period, tolerance,
                                         min_depth, max_depth) if check else (0.0, 0, None))
    limit = MOST_OUTSIDE
    if check and share <= MOST_OUTSIDE:  # a second look, further: the surface may lie there
        far = check_range(lrect, rrect, rect, calibration, period, tolerance, min_depth,
                          max_depth, (0.5 * min_depth, 2.0 * max_depth))
        if far[2] is not None and far[0] > MOST_OUTSIDE_WIDE:
            (share, points, depths), limit = far, MOST_OUTSIDE_WIDE
    n_in, crossed, alone, disparity, depth, mask, continued, valid = _decide(
        lrect, rrect, left_phase, rect, calibration, period, tolerance, min_depth, max_depth,
        propagate, noise[0] if continue_unseen else None)
    pdepth, pmask, residual = projector_depth(depth, mask, left_phase, calibration, period,
                                              rect.rays)
    if depth_from == "projector":
        depth, mask = pdepth, pmask
    mixed = (mixed_pixels(depth, mask, calibration, period, noise[0], rect.rays)
             if drop_mixed else np.zeros(mask.shape, bool))
    kept = disparity
    if mixed.any():
        depth, mask = np.where(mixed, np.float32(np.nan), depth), mask & ~mixed
        kept = disparity.copy()
        kept[_nearest_rectified(mixed, rect, kept.shape)] = np.nan
    rectified_valid = int(np.isfinite(lrect).sum())
    info: dict[str, Any] = {
        "unwrapping": "stereo", "period": period, "depth_range": [min_depth, max_depth],
        "depth_from": depth_from,
        "left_decoded": int(valid), "decided": int(mask.sum()),
        "decided_fraction": round(float(mask.sum() / max(valid, 1)), 6),
        "rectified_valid": rectified_valid,
        "no_candidate": int(np.sum(np.isfinite(lrect) & (n_in == 0))),
        "undecided": int(np.sum((n_in >= 2) & np.isnan(disparity))),
        "grown": int(np.sum(np.isfinite(disparity) & np.isnan(alone) & ~continued)),
        "continued": _left_count(mask, continued, rect),
        "not_confirmed": int(np.sum((n_in == 1) & np.isnan(crossed) & np.isnan(disparity))),
        "unsupported": int(np.sum(np.isfinite(crossed) & np.isnan(disparity))),
        "mixed": int(mixed.sum()),
        "tolerance_rad": round(float(tolerance), 6),
        "noise_rad": [round(float(n), 6) for n in noise],
        "range_check": None if not check else {
            "outside": round(share, 6), "points": points,
            "depths": None if depths is None else [round(d, 1) for d in depths]},
        "warnings": []}
    if origin:
        info["pixel_origin"] = origin["pixel_origin"]
        info["consistent"] = origin["consistent"]
        if origin["pixel_origin"] != pixel_origin:
            info["warnings"].append(origin["message"])
    if depths is not None and share > limit:
        lo, hi = depths
        message = (f"{100 * share:.0f}% of the points found near the depth range lie outside "
                   f"it ({min_depth:g} to {max_depth:g} mm; they lie at {lo:.0f} to "
                   f"{hi:.0f} mm): correct --depth-range")
        if not force:
            raise BistairError(message)
        info["warnings"].append(message)
    return Unwrapped(kept, depth, mask, n_in, rect, info)


def _nearest_rectified(mask: np.ndarray, rect: Rectification, shape: tuple[int, ...]
                       ) -> tuple[np.ndarray, np.ndarray]:
    """The rows and columns of the rectified pixels (of a grid of ``shape``) nearest to the
    left pixels of ``mask``, those inside the grid."""
    u, v = (np.rint(p[mask]).astype(np.int64) for p in rect.positions)
    inside = (u >= 0) & (u < shape[1]) & (v >= 0) & (v < shape[0])
    return v[inside], u[inside]


def _left_count(mask: np.ndarray, rectified: np.ndarray, rect: Rectification) -> int:
    """The left pixels of ``mask`` whose nearest rectified pixel is in ``rectified``."""
    return int(rectified[_nearest_rectified(mask, rect, rectified.shape)].sum())


def _decide(lrect: np.ndarray, rrect: np.ndarray, left_phase: np.ndarray,
            rect: Rectification, calibration: StereoCalibration, period: float,
            tolerance: float, min_depth: float, max_depth: float, propagate: bool,
            fill_noise: float | None = None) -> tuple[Any, ...]:
    """The search both ways, the cross-check, the support, the growth, the continuation
    into the pixels the right camera cannot see (unless ``fill_noise`` is ``None``) and the
    pair's depth (:func:`unwrap_stereo`'s steps 2-4)."""
    n_in, disparity, _, _, kept = _search(lrect, rrect, rect, calibration, period,
                                          tolerance, min_depth, max_depth,
                                          (min_depth, max_depth), everything=True)
    _, from_right, _, _ = _search(lrect, rrect, rect, calibration, period, tolerance,
                                  min_depth, max_depth, (min_depth, max_depth),
                                  from_right=True)
    crossed = cross_checked(disparity, from_right, rect.shift, SUPPORT)
    near = _near_occlusion(np.isfinite(lrect) & ((n_in == 0) | cross_checked(
        disparity, from_right, rect.shift, SUPPORT, contradicted=True)), EDGE)
    alone = np.where(near, np.float32(np.nan), _supported(crossed, SUPPORT))
    disparity = grow(alone, n_in, kept, near, REACH, GROW_SUPPORT) if propagate else alone
    continued = np.zeros(disparity.shape, bool)
    if fill_noise is not None:
        disparity, continued = continue_unseen(lrect, rrect, disparity, n_in, rect,
                                               calibration, period, fill_noise, tolerance,
                                               min_depth, max_depth, REACH)
    decoded = np.where(np.isfinite(left_phase), np.float32(1), np.float32(np.nan))
    depth, mask, _, _, valid = depth_counts(
        disparity, *rect.positions, decoded, rect.f, rect.cx_left, rect.cy, rect.tx, rect.R1,
        min_depth, max_depth)
    return n_in, crossed, alone, disparity, depth, mask, continued, valid


def consistent_share(left_phase: np.ndarray, right_phase: np.ndarray,
                     calibration: StereoCalibration, period: float, tolerance: float,
                     min_depth: float, max_depth: float) -> float:
    """The share of the valid left pixels (every :data:`CHECK_ROWS`-th rectified row) with
    at least one candidate in the depth range that the projector confirms: near 1 where
    the calibration fits the cameras' pixels, near 0 where it puts them a pixel off (the
    projector's column then misses by about the ratio of the focal lengths, more than the
    tolerance).

    Parameters
    ----------
    left_phase, right_phase : numpy.ndarray
        ``(H, W)`` each camera's wrapped phase (radians, NaN where unknown).
    calibration : StereoCalibration
        The cameras and the projector.
    period, tolerance, min_depth, max_depth : float
        As :func:`unwrap_stereo`.

    Returns
    -------
    float
        The share (0 without valid pixels).

    Examples
    --------
    >>> from bistair.geometry.projection_matrices import with_pixel_origin
    >>> from bistair.sim import preset, trace
    >>> from bistair.sim.stereo import StereoRig
    >>> rig, scene = preset("plane", camera_size=(80, 60))  # a plane at 600 mm
    >>> srig = StereoRig.default(camera_size=(80, 60), projector_size=rig.projector.size)
    >>> cal = StereoCalibration.from_rig(srig)
    >>> x = [trace(srig.rig(side), scene).truth.coord_x for side in ("left", "right")]
    >>> lp, rp = (np.float32(2 * np.pi * c / 48 % (2 * np.pi)) for c in x)  # period 48
    >>> round(consistent_share(lp, rp, cal, 48.0, 0.1, 500.0, 700.0), 3)
    0.988
    >>> round(consistent_share(lp, rp, with_pixel_origin(cal, 1), 48.0, 0.1, 500.0, 700.0), 3)
    0.0
    """
    rect = rectify(calibration)
    lrect = rectified_phase(left_phase, rect.maps_left)
    rrect = rectified_phase(right_phase, rect.maps_right)
    rows = np.arange(0, lrect.shape[0], CHECK_ROWS, dtype=np.int64)
    n_in = _search(lrect, rrect, rect, calibration, period, tolerance, min_depth, max_depth,
                   (min_depth, max_depth), rows, whole=False)[0]
    valid = int(np.isfinite(lrect[rows]).sum())
    return float(np.sum(n_in >= 1) / valid) if valid else 0.0


def _sign_check(lphase: np.ndarray, rphase: np.ndarray, calibration: StereoCalibration,
                period: float, min_depth: float, max_depth: float,
                noise: tuple[float, float], tolerance: float | None, sign: int) -> str:
    """What to say when the phase negated (the other ``shift_sign``) fits the projector
    clearly better than the spec's: the projector confirms over :data:`ORIGIN_RATIO`
    times as many left pixels with it, and over :data:`ORIGIN_MIN` (benchmark: the wrong
    sign confirms 3-23%, the right one 83-99%); ``""`` otherwise. Judged only when the
    spec's phase confirms under half the pixels."""
    tol = tolerance or max(MIN_TOLERANCE, TOLERANCE_SIGMAS * math.hypot(*noise))
    given = consistent_share(lphase, rphase, calibration, period, tol, min_depth, max_depth)
    if given >= 0.5:
        return ""
    negated = [np.where(np.isfinite(p), np.mod(-p, 2 * np.pi), np.nan).astype(np.float32)
               for p in (lphase, rphase)]
    other = consistent_share(*negated, calibration, period, tol, min_depth, max_depth)
    if not (other > ORIGIN_RATIO * given and other > ORIGIN_MIN):
        return ""
    return (f"the projector confirms {100 * other:.0f}% of the left pixels with the phase "
            f"negated, {100 * given:.0f}% as the spec says (shift_sign {sign}): the "
            f"patterns shift the other way, give a spec with shift_sign {-sign} (bistair "
            f"patterns multifreq --shift-sign {-sign})")


def _origin_check(left_phase: np.ndarray, right_phase: np.ndarray,
                  calibration: StereoCalibration, period: float, tolerance: float,
                  min_depth: float, max_depth: float, given: int) -> dict[str, Any]:
    """Which pixel origin (0 or 1) of the cameras the data fit: :func:`consistent_share`
    under the calibration's origin ``given`` and under the other; the other is taken when
    its share is over :data:`ORIGIN_RATIO` times the given one's and over
    :data:`ORIGIN_MIN`."""
    other = 1 - given
    share = {given: consistent_share(left_phase, right_phase, calibration, period,
                                     tolerance, min_depth, max_depth),
             other: consistent_share(left_phase, right_phase,
                                     with_pixel_origin(calibration, other - given), period,
                                     tolerance, min_depth, max_depth)}
    used = other if (share[other] > ORIGIN_RATIO * share[given]
                     and share[other] > ORIGIN_MIN) else given
    message = (f"the projector confirms {100 * share[other]:.0f}% of the left pixels with "
               f"the cameras' pixel origin {other}, {100 * share[given]:.0f}% with the "
               f"calibration's {given}: used {other} (import-calibration --pixel-origin "
               f"{other} records it)")
    return {"pixel_origin": used, "message": message,
            "consistent": {str(o): round(v, 4) for o, v in share.items()}}


def absolute_phase(unwrapped: Unwrapped, phase: np.ndarray, calibration: StereoCalibration,
                   period: float) -> tuple[np.ndarray, np.ndarray]:
    """The left camera's absolute phase and fringe order where :func:`unwrap_stereo`
    decided a point: the order that puts the wrapped phase nearest the projector column of
    the point.

    Parameters
    ----------
    unwrapped : Unwrapped
        What :func:`unwrap_stereo` found for ``phase``.
    phase : numpy.ndarray
        ``(H, W)`` the left camera's wrapped phase given to :func:`unwrap_stereo` (radians,
        ``[0, 2*pi)``, NaN where unknown).
    calibration : StereoCalibration
        The cameras and the projector (its ``projector`` entry).
    period : float
        The fringe period (projector pixels).

    Returns
    -------
    Phi : numpy.ndarray
        ``(H, W)`` float32 absolute phase (radians), NaN where undecided.
    order : numpy.ndarray
        ``(H, W)`` int32 fringe order, -1 where undecided.

    Examples
    --------
    >>> from bistair.geometry.calibration import StereoCalibration
    >>> from bistair.sim import preset, trace
    >>> from bistair.sim.stereo import StereoRig
    >>> rig, scene = preset("plane", camera_size=(80, 60))  # a plane at 600 mm
    >>> srig = StereoRig.default(camera_size=(80, 60), projector_size=rig.projector.size,
    ...                          projector_at=0.3)
    >>> cal = StereoCalibration.from_rig(srig)
    >>> x = [trace(srig.rig(side), scene).truth.coord_x for side in ("left", "right")]
    >>> lp, rp = (np.float32(2 * np.pi * c / 48 % (2 * np.pi)) for c in x)  # period 48
    >>> found = unwrap_stereo(lp, rp, cal, 48.0, 500.0, 700.0)
    >>> Phi, order = absolute_phase(found, lp, cal, 48.0)
    >>> decided = order >= 0
    >>> bool(np.all(order[decided] == np.floor(x[0][decided] / 48)))  # k = floor(x_p / T)
    True
    >>> float(np.abs(Phi[decided] - 2 * np.pi * x[0][decided] / 48).max()) < 1e-4  # radians
    True
    """
    rect = unwrapped.rectification
    rows, cols = np.nonzero(unwrapped.mask)
    points = grid_points(unwrapped.depth, *rect.rays)[rows, cols]
    u = calibration.projector.project(points)[:, 0]
    phi = phase[rows, cols].astype(np.float64)
    k = np.rint((2 * np.pi * u / period - phi) / (2 * np.pi))
    order = np.full(phase.shape, -1, np.int32)
    order[rows, cols] = k.astype(np.int32)
    absolute = np.full(phase.shape, np.nan, np.float32)
    absolute[rows, cols] = (phi + 2 * np.pi * k).astype(np.float32)
    return absolute, order


def is_single_period(spec: Any) -> bool:
    """Whether a spec is one N-step set of one period (``patterns multifreq --periods T``):
    what stereo phase unwrapping reads.

    Parameters
    ----------
    spec : object
        A pattern spec of any method (:func:`~bistair.codecs.make_spec`).

    Returns
    -------
    bool
        ``True`` for a multi-frequency spec of exactly one period.

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> is_single_period(make_spec("multifreq", width=300, height=32, periods=(300, 30)))
    False
    >>> is_single_period(make_spec("multifreq", width=300, height=32, periods=(30,)))
    True
    """
    return getattr(spec, "method", None) == "multifreq" and len(spec.periods) == 1


def wrapped_of(images: np.ndarray, spec: Any, min_modulation: float | None = None
               ) -> tuple[np.ndarray, FringeSet]:
    """The wrapped phase of a single-period capture (NaN where not valid) and its
    :class:`~bistair.core.measure.FringeSet` (stage 1 of the multi-frequency codec: the one
    N-step set, in the spec's phase convention).

    Parameters
    ----------
    images : numpy.ndarray
        ``(frames, height, width)`` captures of the spec's frames, in its frame order.
    spec : MultiFreqSpec
        A single-period spec (:func:`is_single_period`); its ``steps``, ``shift_sign`` and
        ``phase_offset`` are read.
    min_modulation : float, optional
        The modulation (fraction of full scale) a valid pixel needs; by default a threshold
        from the measured camera noise.

    Returns
    -------
    phase : numpy.ndarray
        ``(height, width)`` float32 wrapped phase ``2*pi*x_p/T`` mod ``2*pi`` (radians, in
        ``[0, 2*pi)``), NaN where not valid.
    fs : FringeSet
        The N-step set's phase, average, modulation, validity and phase noise.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> spec = make_spec("multifreq", width=96, height=8, periods=(48,))
    >>> phase, fs = wrapped_of(encode(spec), spec)
    >>> phase.shape, round(float(phase[0, 24]), 3), bool(fs.valid.all())  # half a period
    ((8, 96), 3.142, True)
    """
    prepared = prepare(images, spec.frame_count, spec.method)
    fs = measure(prepared, 0, spec.steps, min_modulation, shift_sign=spec.shift_sign,
                 phase_offset=spec.phase_offset)
    return np.where(fs.valid, fs.phi, np.float32(np.nan)).astype(np.float32), fs


def stereo_unwrap(left_images: np.ndarray, right_images: np.ndarray, spec: Any,
                  calibration: StereoCalibration, min_depth: float, max_depth: float,
                  force: bool = False, min_modulation: float | None = None,
                  tolerance: float | None = None, pixel_origin: int | None = None,
                  continue_unseen: bool = False) -> StereoResult:
    """Two cameras' captures of one single-period N-step set to depth by stereo phase
    unwrapping (module docstring), as :func:`~bistair.geometry.stereo.stereo` gives it.

    Parameters
    ----------
    left_images, right_images : numpy.ndarray
        ``(frames, height, width)`` captures of each camera (the spec's frames).
    spec : MultiFreqSpec
        One period (:func:`is_single_period`), coding the projector columns.
    calibration : StereoCalibration
        The cameras and the projector.
    min_depth, max_depth : float
        The depth range (left camera frame, mm).
    force : bool, optional
        Keep what the depth range check refuses, as a warning in ``info``.
    min_modulation, tolerance : float, optional
        The modulation a valid pixel needs (fraction of full scale; by default from the
        noise) and the phase tolerance (:func:`unwrap_stereo`).
    pixel_origin : int, optional
        The calibration's recorded pixel origin, checked against the data
        (:func:`unwrap_stereo`).
    continue_unseen : bool, optional
        Continue into the left pixels the right camera cannot see (:func:`unwrap_stereo`).

    Returns
    -------
    StereoResult
        ``left``: the left camera's absolute phase and order where a point is decided;
        ``right``: the right camera's wrapped phase (no order); ``info``: as
        :func:`unwrap_stereo`'s, with ``matched`` and ``matched_fraction`` (the decided
        points).

    Raises
    ------
    BistairError
        A spec that is not one period of columns, or what :func:`unwrap_stereo` refuses.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.geometry.calibration import StereoCalibration
    >>> from bistair.sim import preset, trace
    >>> from bistair.sim.render import Imaging, expose
    >>> from bistair.sim.stereo import StereoRig
    >>> rig, scene = preset("plane", camera_size=(80, 60))  # a plane at 600 mm
    >>> srig = StereoRig.default(camera_size=(80, 60), projector_size=rig.projector.size,
    ...                          projector_at=0.3)
    >>> cal = StereoCalibration.from_rig(srig)
    >>> spec = make_spec("multifreq", width=rig.projector.size[0],
    ...                  height=rig.projector.size[1], periods=(48,))
    >>> traced = [trace(srig.rig(side), scene) for side in ("left", "right")]
    >>> left, right = (expose(t, encode(spec), Imaging()) for t in traced)  # noisy 8-bit
    >>> res = stereo_unwrap(left, right, spec, cal, 500.0, 700.0)
    >>> res.info["matched_fraction"]
    0.64625
    >>> decided = res.left.order >= 0
    >>> err = res.left.phase[decided] - 2 * np.pi * traced[0].truth.coord_x[decided] / 48
    >>> round(float(np.abs(err).max()), 2)  # radians, under pi: no order off
    0.31
    """
    if not is_single_period(spec) or spec.orientation != "columns":
        raise BistairError("stereo phase unwrapping needs one N-step set of one period "
                           "coding the projector columns (bistair patterns multifreq "
                           "--periods T)")
    period = float(spec.periods[0])
    maps = [wrapped_of(images, spec, min_modulation) for images in (left_images, right_images)]
    (lphase, lfs), (rphase, rfs) = maps
    noise = tuple(float(np.median(fs.phase_noise[fs.valid])) if fs.valid.any() else 0.0
                  for fs in (lfs, rfs))
    sign = _sign_check(lphase, rphase, calibration, period, min_depth, max_depth, noise,
                       tolerance, spec.shift_sign)
    if sign and not force:
        raise BistairError(sign)
    found = unwrap_stereo(lphase, rphase, calibration, period, min_depth, max_depth, noise,
                          tolerance, force=force, pixel_origin=pixel_origin,
                          continue_unseen=continue_unseen)
    if sign:
        found.info["warnings"].insert(0, sign)
    _, order = absolute_phase(found, lphase, calibration, period)
    left = make_result(spec.method, np.where(order >= 0, lphase, 0), order, period, lfs.mod,
                       lfs.avg, wrapped=lphase)
    right = make_result(spec.method, np.zeros_like(rphase), np.full(rphase.shape, -1),
                        period, rfs.mod, rfs.avg, wrapped=rphase)
    info = dict(found.info)
    info["matched"] = info["decided"]
    info["matched_fraction"] = info["decided_fraction"]
    return StereoResult(found.disparity, found.depth, grey_image(left, spec.offset), found.mask,
                        left, right, found.rectification, info)
