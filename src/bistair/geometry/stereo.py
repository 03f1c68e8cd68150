"""Two cameras and a projector: rectify, match equal phase along rows, triangulate.

Both cameras decode the same projected patterns into absolute phase (projector coordinates);
a scene point has the same projector coordinate in both, so matching needs no projector
calibration at all: only the two cameras' (:class:`StereoCalibration`).

1. Rectification (:func:`rectify`): ``cv2.stereoRectify`` turns both cameras so that their
   rows are the same epipolar lines (``R1``, ``R2``); each camera gets its own rectified
   grid (focal length ``f``, the mean of the four focal lengths, so no resolution is lost;
   a common principal row ``cy``, its own ``cx``) large enough for its whole image, filled
   through ``cv2.initUndistortRectifyMap``. The projector coordinates are resampled there
   bilinearly, never between two surfaces (:func:`~.stereo_jit.remap_valid`: four valid
   neighbours whose spread is that of a surface).
2. Before matching, the kinks of each rectified row are dropped
   (:func:`~.stereo_match_jit.drop_kinks`: second differences over four times the measured noise,
   the blurred step between two surfaces whose pixels mix both), and with ``smooth`` both
   maps are smoothed within each surface (:func:`~.stereo_match_jit.smooth_runs`, which does
   both, and turns a falling coordinate round, in one pass).
3. Matching (:func:`~.stereo_match_jit.match_pair`): for each valid left pixel, the right pixel
   of equal projector coordinate on the same rectified row, interpolated between the two
   valid neighbours that bracket it (a line through four samples where it crosses once),
   only where the coordinate rises along the row (up to ``wiggle`` px of noise) without a
   gap of more than ``gap`` px or a step of two surfaces, and only if one place in the
   search window gives it. The coordinate along the cameras' baseline is matched (the
   other carries nothing along a row); with both projector axes decoded, the other must
   agree too. The same value searched back on the left row must come back within
   ``tolerance`` px of the pixel, and a disparity must be confirmed by the row above or
   below (:func:`~.stereo_match_jit.supported`). ``wiggle``, ``tolerance`` and ``support`` grow
   with the measured noise (four, three and 5.7 times it, as a position along the row).
   Occlusions and mismatches are NaN, never a guess.
4. Points (:func:`~.stereo_jit.grid_depth`; :func:`~.stereo_jit.depth_counts` counts the
   points per row in the same pass): each decoded left pixel reads the disparity
   at its rectified position and is triangulated there, ``Z = -f * tx / d`` (``tx``: the
   right camera's x in the rectified frame), then turned back into the left camera's
   frame: its depth ``z``, and the point ``z`` times the pixel's ray. Depth and points are
   on the left camera's own (distorted) image grid. The resampling and steps 2 to 4 are
   :func:`~.stereo_match.match`.
5. Checks of the inputs against each other (:mod:`.stereo_checks`): too few matches,
   projector rows that disagree (both axes), points that one projector explains only with
   the cameras exchanged or the right images upside down.

Examples
--------
>>> cal = _toy_stereo()
>>> rect = rectify(cal)
>>> round(rect.f, 1), rect.size_left[1] == rect.size_right[1]
(800.0, True)
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ..codecs import decode, get_codec
from ..core.jit import side_by_side
from ..core.result import AxesResult, DecodeResult, make_result
from ..errors import BistairError
from ..spec import BaseSpec
from .calibration import (
    STEREO,
    Calibration,
    Device,
    StereoCalibration,
    load_calibration,
    short_baseline,
)
from .stereo_checks import (
    MIN_MATCHED,
    MISFIT_SAMPLE,
    Coords,
    check_matches,
    other_readings,
    projector_misfits,
    same_captures,
)
from .stereo_jit import (  # depth_counts, resample_wrapped: the face's for unwrap*.py
    cloud_points,
    depth_counts,  # noqa: F401
    grid_points,
    pick_finite,
    rectified_positions,
    resample_wrapped,  # noqa: F401
)
from .stereo_match import Matched, match
from .triangulate import check_depth_range

_UNDISTORT = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 50, 1e-12)


@dataclass(frozen=True, eq=False)
class Rectification:
    """Rectified grids of a stereo pair: rotations ``R1`` (left) and ``R2`` (right), the
    common focal length ``f`` and principal row ``cy``, each grid's ``cx`` and size
    ``(width, height)``, ``tx`` (the right camera's x in the rectified frame, mm), the
    remap tables (rectified pixel -> camera pixel) and where the left camera's own pixels
    land on its grid (``positions``: ``u, v``) with their rays in its frame (``rays``:
    ``x, y``, the point at depth ``z`` being ``z * (x, y, 1)``)."""

    R1: np.ndarray
    R2: np.ndarray
    f: float
    cy: float
    cx_left: float
    cx_right: float
    size_left: tuple[int, int]
    size_right: tuple[int, int]
    tx: float
    maps_left: tuple[np.ndarray, np.ndarray]
    maps_right: tuple[np.ndarray, np.ndarray]
    positions: tuple[np.ndarray, np.ndarray]
    rays: tuple[np.ndarray, np.ndarray]

    @property
    def shift(self) -> float:
        """``cx_left - cx_right``: a point at infinity lies this many columns apart."""
        return self.cx_left - self.cx_right

    def disparities(self, min_depth: float = 0.0, max_depth: float = math.inf
                    ) -> tuple[float, float]:
        """The disparities ``d = (x_l - cx_left) - (x_r - cx_right)`` points at depths
        ``[min_depth, max_depth]`` (left camera frame) can have anywhere in the left
        image (signed: positive when the right camera is to the right)."""
        w, h = self.size_left
        corners = np.array([[0, 0], [w - 1, 0], [0, h - 1], [w - 1, h - 1]], float)
        rays = np.column_stack([(corners - [self.cx_left, self.cy]) / self.f, np.ones(4)])
        ratio = (rays @ self.R1)[:, 2]  # left-frame z per unit rectified Z along each ray
        near = min_depth / ratio.max() if min_depth > 0 else 0.0
        far = max_depth / ratio.min()
        scale = self.f * abs(self.tx)
        low, high = scale / far, (scale / near if near > 0 else math.inf)
        return (float(low), float(high)) if self.tx < 0 else (float(-high), float(-low))


@functools.lru_cache(maxsize=2)
def rectify(calibration: StereoCalibration) -> Rectification:
    """The rectified grids of a stereo pair (kept for the last two calibrations used).

    Parameters
    ----------
    calibration : StereoCalibration
        The two cameras.

    Returns
    -------
    Rectification

    Raises
    ------
    BistairError
        Cameras stacked vertically, views that share no rows, or a pair whose
        rectification would turn a view by 90 degrees or more or blow a grid up to over
        three times the camera's size (a baseline along the view).

    Examples
    --------
    >>> rect = rectify(_toy_stereo())
    >>> rect.size_left, rect.size_right, round(rect.tx, 6)
    ((640, 480), (671, 480), -120.0)
    >>> [round(d, 6) for d in rect.disparities(400.0, 800.0)]  # f * B / Z
    [120.0, 240.0]
    """
    left, right = calibration.left, calibration.right
    r1, r2, *_ = cv2.stereoRectify(left.K, left.dist, right.K, right.dist, left.size,
                                   calibration.R, calibration.T.reshape(3, 1),
                                   flags=cv2.CALIB_ZERO_DISPARITY, alpha=-1)
    t = r2 @ calibration.T
    if abs(t[1]) > abs(t[0]):
        raise BistairError("the cameras are stacked vertically (baseline along the image "
                           "columns): only side-by-side pairs are rectified")
    f = float(np.mean([d.K[i, i] for d in (left, right) for i in (0, 1)]))
    (lx, ly), (rx, ry) = (_extent(d, r) for d, r in ((left, r1), (right, r2)))
    top, bottom = max(ly[0], ry[0]), min(ly[1], ry[1])
    if not bottom > top:
        raise BistairError("the two cameras' views share no rows after rectification: is "
                           "the calibration for this pair?")
    cy = -f * top
    height = int(math.ceil(f * (bottom - top) - 1e-6)) + 1
    grids = []
    for device, rot, (x0, x1) in ((left, r1, lx), (right, r2, rx)):
        cx = -f * x0
        width = int(math.ceil(f * (x1 - x0) - 1e-6)) + 1
        if width > 3 * device.width or height > 3 * device.height:
            raise BistairError(f"rectifying this pair would stretch a {device.width}x"
                               f"{device.height} view to {width}x{height}: is the baseline "
                               "along the view?")
        proj = np.array([[f, 0.0, cx], [0.0, f, cy], [0.0, 0.0, 1.0]])
        maps = cv2.initUndistortRectifyMap(device.K, device.dist, rot, proj, (width, height),
                                           cv2.CV_32FC1)
        grids.append((cx, (width, height), (maps[0], maps[1])))
    (cxl, size_l, maps_l), (cxr, size_r, maps_r) = grids
    u, v, rx, ry = rectified_positions(left.K, left.dist, r1, f, cxl, cy, left.size)
    return Rectification(r1, r2, f, cy, cxl, cxr, size_l, size_r, float(t[0]), maps_l,
                         maps_r, (u, v), (rx, ry))


def _extent(device: Device, rot: np.ndarray) -> tuple[tuple[float, float], ...]:
    """``((xmin, xmax), (ymin, ymax))`` of a camera image's border on the rectified plane
    ``z = 1`` (normalised coordinates)."""
    w, h = device.size
    xs, ys = np.arange(0, w, 4.0), np.arange(0, h, 4.0)
    border = np.concatenate([np.column_stack([xs, np.zeros_like(xs)]),
                             np.column_stack([xs, np.full_like(xs, h - 1)]),
                             np.column_stack([np.zeros_like(ys), ys]),
                             np.column_stack([np.full_like(ys, w - 1), ys]),
                             [[w - 1, h - 1]]])
    norm = cv2.undistortPoints(border.reshape(-1, 1, 2), device.K, device.dist,
                               criteria=_UNDISTORT).reshape(-1, 2)
    rays = np.column_stack([norm, np.ones(len(norm))]) @ rot.T
    if not (rays[:, 2] > 0.1).all():
        raise BistairError("rectifying this pair would turn a view by 90 degrees or more: "
                           "is the calibration for two cameras side by side?")
    x, y = rays[:, 0] / rays[:, 2], rays[:, 1] / rays[:, 2]
    return (float(x.min()), float(x.max())), (float(y.min()), float(y.max()))


@dataclass
class StereoResult:
    """A binocular reconstruction.

    ``disparity``: float32 on the rectified left grid (``x_l - x_r`` with both grids'
    principal points removed; ``Z = -f * tx / d`` in the rectified frame), NaN where
    unmatched. ``depth`` (float32 ``z``, mm) and ``mask``: on the left camera's own image
    grid; ``points``: ``(H, W, 3)`` float32 in its frame (mm, NaN where unknown), made
    from the depth and each pixel's ray when asked for. ``grey``: ``(H, W)`` uint8 from the
    white frame (else the fringes' average), ``colors`` the same as RGB. ``left``,
    ``right``: each camera's decode. ``info``: counts and settings (see
    :func:`reconstruct_stereo`).
    """

    disparity: np.ndarray
    depth: np.ndarray
    grey: np.ndarray
    mask: np.ndarray
    left: DecodeResult | AxesResult
    right: DecodeResult | AxesResult
    rectification: Rectification
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def points(self) -> np.ndarray:
        """``(H, W, 3)`` float32, the left camera's frame (mm), NaN where unknown."""
        return grid_points(self.depth, *self.rectification.rays)

    @property
    def colors(self) -> np.ndarray:
        """``(H, W, 3)`` uint8 RGB (grey)."""
        return np.repeat(self.grey[..., None], 3, axis=2)

    def cloud(self) -> tuple[np.ndarray, np.ndarray]:
        """The valid points ``(N, 3)`` float32 and their colours ``(N, 3)`` uint8."""
        return cloud_points(self.depth, *self.rectification.rays, self.grey, self.mask)


def reconstruct_stereo(left: DecodeResult | AxesResult, right: DecodeResult | AxesResult,
                       calibration: StereoCalibration, orientation: str,
                       rectification: Rectification | None = None, min_depth: float = 0.0,
                       max_depth: float = math.inf, tolerance: float = 1.0,
                       other_tolerance: float = 2.0, gap: int = 3, wiggle: float = 1.0,
                       support: float = 2.0, smooth: float = 1.0, offset: float = 0.5,
                       force: bool = False) -> StereoResult:
    """Match two cameras' decodes of the same patterns and triangulate (module docstring).

    Parameters
    ----------
    left, right : DecodeResult or AxesResult
        Each camera's decode (both of one axis, or both of both axes).
    calibration : StereoCalibration
        The cameras; their image sizes must be the decodes'.
    orientation : str
        What the spec codes: ``"columns"``, ``"rows"`` or ``"both"``.
    rectification : Rectification, optional
        :func:`rectify` of ``calibration``, if already made.
    min_depth, max_depth : float, optional
        Depths ``z`` (left camera frame, mm) kept; they also narrow the search.
    tolerance : float, optional
        Pixels the match back from the right camera may miss the left pixel by.
    other_tolerance : float, optional
        Projector pixels the second coordinate may differ by (both axes decoded).
    gap : int, optional
        Largest step (px) between valid neighbours on a rectified row interpolated across.
    wiggle : float, optional
        Pixels the phase may run back by (noise) where a value is matched.
    support : float, optional
        Pixels a disparity may differ by from the row above or below (one of them must
        confirm it).
    smooth : float, optional
        Gaussian sigma (px) of a smoothing of both cameras' projector coordinates on the
        rectified grids before matching (:func:`~.stereo_match_jit.smooth_runs`: never across
        two surfaces; the default, 1 px); 0 matches the decoded values as they are. Smoothing
        trades lateral resolution for depth noise (sigma 1 px: about a third of it).
    offset : float, optional
        The patterns' mean (the spec's ``offset``): scales the fringes' average to grey
        when there is no white frame.
    force : bool, optional
        Keep a reconstruction that the checks of the matches
        (:func:`~.stereo_checks.check_matches`) would refuse, with the reason as a warning in
        ``info``.

    Returns
    -------
    StereoResult
        ``info`` counts ``left_decoded`` (valid left pixels on the matched axis),
        ``matched`` (their points), ``unmatched``, ``ambiguous``, ``not_monotonic``,
        ``inconsistent`` and ``other_axis`` (on the rectified grid), ``outside_range``,
        and gives ``matched_axis``, ``rectified`` (grids, ``f``, ``tx``), the tolerances,
        ``other_axis_share`` (both axes), ``projector_misfits`` (the share of points off
        the projector that lit the others), ``other_readings`` (when tried) and
        ``warnings`` (a baseline under 10 mm, misfits over 1%).

    Raises
    ------
    BistairError
        A bad depth range, tolerance or smoothing, decodes of different kinds or sizes,
        sizes other than the calibration's, a coded axis that does not change along the
        baseline, phases that run opposite ways in the two cameras, or (without ``force``)
        what :func:`~.stereo_checks.check_matches` refuses: too few matches, projector rows
        that disagree, points that fit one projector only with the cameras exchanged or the
        right images upside down.

    Examples
    --------
    A plane 500 mm in front of the toy pair, its projector columns exact in both cameras:

    >>> cal = _toy_stereo()
    >>> left, right = (_plane_decode(cal, side, 500.0) for side in ("left", "right"))
    >>> rec = reconstruct_stereo(left, right, cal, "columns")
    >>> float(np.abs(rec.depth[rec.mask] - 500.0).max()) < 1e-3, rec.info["matched_fraction"]
    (True, 0.990872)
    """
    check_depth_range(min_depth, max_depth)
    if not 0 <= smooth <= 10:
        raise BistairError(f"the smoothing must be 0 to 10 px, got {smooth}")
    for name, value in (("tolerance", tolerance), ("other tolerance", other_tolerance),
                        ("wiggle", wiggle), ("support", support)):
        if not value > 0:
            raise BistairError(f"the {name} must be positive, got {value}")
    rect = rectification or rectify(calibration)
    coords = _coordinates(left, right, calibration, orientation)
    settings = (min_depth, max_depth, tolerance, other_tolerance, gap, wiggle, support, smooth)
    m = match(coords, rect, *settings)
    mask, matched = m.mask, int(m.per_row.sum())
    info: dict[str, Any] = {
        "left_decoded": m.decoded, "matched": matched,
        "matched_fraction": round(float(matched / max(m.decoded, 1)), 6),
        **m.counts, "outside_range": int(m.outside),
        "matched_axis": m.axis,
        "rectified": {"left": list(rect.size_left), "right": list(rect.size_right),
                      "f": rect.f, "cy": rect.cy, "cx_left": rect.cx_left,
                      "cx_right": rect.cx_right, "tx": rect.tx,
                      "R1": rect.R1.tolist(), "R2": rect.R2.tolist()},
        "noise_px": round(m.noise, 4), "tolerance_px": round(m.tolerance, 4),
        "other_tolerance": other_tolerance, "gap_px": gap, "wiggle_px": round(m.wiggle, 4),
        "support_px": round(m.support, 4), "smooth_px": smooth, "warnings": []}
    problems = check_matches(info, coords, lambda alt: _misfits(alt, rect, settings),
                             calibration.left.size == calibration.right.size,
                             _misfits(coords, rect, settings, m)[0])
    if problems and not force:
        if info["matched_fraction"] < MIN_MATCHED and (min_depth > 0 or max_depth < math.inf):
            # the depth range may keep the matches out: say so when it does
            whole = reconstruct_stereo(left, right, calibration, orientation, rect, 0.0,
                                       math.inf, tolerance, other_tolerance, gap, wiggle,
                                       support, smooth, offset, force=True)
            raise BistairError(_ranged(info, whole, min_depth, max_depth))
        raise BistairError(problems[0])
    info["warnings"] += problems
    short = short_baseline(calibration)
    if short:
        depths = m.depth[mask]
        info["warnings"].append(short + (f"; the points lie {np.min(depths):.3g}-"
                                         f"{np.max(depths):.3g} mm away" if depths.size else ""))
    return StereoResult(m.disparity, m.depth, grey_image(left, offset), mask, left, right, rect,
                        info)


def _misfits(coords: Coords, rect: Rectification, settings: tuple,
             m: Matched | None = None) -> tuple[float, float]:
    """The projector misfits (:func:`~.stereo_checks.projector_misfits`) of the match of
    ``coords`` (``m`` if already made) and its share of the decoded left pixels with a
    point."""
    m = m or match(coords, rect, *settings)
    matched = int(m.per_row.sum())
    share = float(matched / max(m.decoded, 1))
    pick = np.linspace(0, matched - 1, min(matched, MISFIT_SAMPLE)).astype(np.int64)
    rows, cols = pick_finite(m.depth, m.per_row, pick)  # (not the list of all matches)
    z = m.depth[rows, cols]
    points = np.column_stack([z * rect.rays[0][rows, cols], z * rect.rays[1][rows, cols], z])
    return projector_misfits(points, coords[m.axis][0][rows, cols], rows), share


def readings(left: DecodeResult | AxesResult, right: DecodeResult | AxesResult,
             calibration: StereoCalibration, orientation: str,
             rectification: Rectification | None = None, min_depth: float = 0.0,
             max_depth: float = math.inf, tolerance: float = 1.0,
             other_tolerance: float = 2.0, gap: int = 3, wiggle: float = 1.0,
             support: float = 2.0, smooth: float = 1.0) -> dict[str, tuple[float, float]]:
    """How well each reading of two decodes fits one projector: as given, with the cameras
    exchanged and with the right images upside down (:func:`~.stereo_checks.other_readings`),
    each ``(misfits, matched share)``: what :func:`reconstruct_stereo` weighs when the
    reading as given has misfits over :data:`~.stereo_checks.MISFIT_FLOOR`
    (``benchmarks/stereo_margins.py`` prints them for every case).

    Parameters
    ----------
    left, right, calibration, orientation, rectification
        As for :func:`reconstruct_stereo`.
    min_depth, max_depth, tolerance, other_tolerance, gap, wiggle, support, smooth
        The matching's settings, as for :func:`reconstruct_stereo`.

    Returns
    -------
    dict
        ``{"as given": (misfits, share), reading: (misfits, share), ...}``; a reading
        whose matching refuses the inputs is left out.

    Examples
    --------
    >>> cal = _toy_stereo()
    >>> left, right = (_plane_decode(cal, side, 500.0) for side in ("left", "right"))
    >>> readings(left, right, cal, "columns")["as given"]
    (0.0, 0.990872)
    """
    rect = rectification or rectify(calibration)
    coords = _coordinates(left, right, calibration, orientation)
    settings = (min_depth, max_depth, tolerance, other_tolerance, gap, wiggle, support, smooth)
    out = {}
    for name, alt in {"as given": coords,
                      **other_readings(coords, calibration.left.size ==
                                       calibration.right.size)}.items():
        try:
            misfits, share = _misfits(alt, rect, settings)
        except BistairError:
            continue
        out[name] = (round(misfits, 6), round(share, 6))
    return out


def _ranged(info: dict[str, Any], whole: StereoResult, low: float, high: float) -> str:
    """The refusal of too few matches (``info``) within a depth range, naming the range: the
    range is to blame when the pair matches without it (``whole``), else the calibration or
    the cameras' order."""
    head = (f"only {100 * info['matched_fraction']:.1f}% of the {info['left_decoded']} "
            "decoded left pixels found their match in the right camera")
    ask = "is the calibration for these cameras, and are LEFT and RIGHT the right way round?"
    within = f"{head} at depths {low:g} to {high:g} mm (--depth-range, left camera frame)"
    found = whole.depth[whole.mask]
    share = whole.info["matched_fraction"]
    if share < MIN_MATCHED or not found.size:
        return f"{within}, and {100 * share:.1f}% without it: {ask}"
    lo, hi = np.percentile(found, [1, 99])
    return (f"{within}; without it {100 * share:.1f}% match, at depths of {lo:.0f} to "
            f"{hi:.0f} mm: widen or leave out --depth-range")


def _coordinates(left: DecodeResult | AxesResult, right: DecodeResult | AxesResult,
                 calibration: StereoCalibration, orientation: str
                 ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The projector coordinates of both cameras per coded axis, after the size checks."""
    both = isinstance(left, AxesResult)
    if both != isinstance(right, AxesResult) or both != (orientation == "both"):
        raise BistairError("the left and right decodes must both be of the spec's axes "
                           f"({orientation})")
    for side, res, dev in (("left", left, calibration.left), ("right", right,
                                                               calibration.right)):
        h, w = res.mask.shape
        if (w, h) != dev.size:
            raise BistairError(f"the calibration is for {dev.width}x{dev.height} {side} "
                               f"images, the {side} captures are {w}x{h}")
    if both:
        return {"columns": (left.coord_x, right.coord_x), "rows": (left.coord_y, right.coord_y)}
    return {orientation: (left.coord, right.coord)}


def grey_image(result: DecodeResult | AxesResult, offset: float) -> np.ndarray:
    """Grey per pixel (uint8) for a point cloud's colours: the white frame, else the
    fringes' average over the patterns' mean.

    Parameters
    ----------
    result : DecodeResult or AxesResult
        A decode (its first axis for both axes).
    offset : float
        The patterns' mean ``a`` (fraction of full scale; 0 means 0.5).

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` uint8, 0 where the average is unknown.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> r = SimpleNamespace(texture=None, average=np.array([[0.25, np.nan]], np.float32))
    >>> grey_image(r, 0.5).tolist()
    [[128, 0]]
    """
    first = result.x if isinstance(result, AxesResult) else result
    if first.texture is not None:
        grey = np.asarray(first.texture, np.float32) * np.float32(255)
    else:
        grey = np.asarray(first.average, np.float32) * np.float32(255 / (offset or 0.5))
    np.clip(grey, 0, 255, out=grey)
    grey[np.isnan(grey)] = 0
    return np.rint(grey, out=grey).astype(np.uint8)


def decode_options(method: str, force: bool, options: dict[str, Any]) -> dict[str, Any]:
    """The decoder options for a stereo decode: ``options``, plus ``force=True`` when asked
    for and the method's decoder takes it (its :attr:`~bistair.codecs.base.Codec.options`).

    Parameters
    ----------
    method : str
        The spec's method.
    force : bool
        Whether the decode should keep what its checks would refuse (as warnings).
    options : dict
        The other decoder options.

    Returns
    -------
    dict
        The options to pass to :func:`~bistair.codecs.decode`.

    Examples
    --------
    >>> decode_options("graycode", False, {"strategy": "region"})
    {'strategy': 'region'}
    """
    if force and "force" in get_codec(method).options:
        return {**options, "force": True}
    return dict(options)


def stereo(left_images: np.ndarray, right_images: np.ndarray, spec: BaseSpec,
           calibration: StereoCalibration | str | Path, *,
           rectification: Rectification | None = None, min_depth: float = 0.0,
           max_depth: float = math.inf, force: bool = False, tolerance: float = 1.0,
           other_tolerance: float = 2.0, smooth: float = 1.0, **options: Any) -> StereoResult:
    """Decode two cameras' captures of the same patterns and reconstruct by matching equal
    absolute phase along rectified rows (:func:`reconstruct_stereo`).

    Parameters
    ----------
    left_images, right_images : numpy.ndarray
        ``(frames, height, width)`` captures of each camera, any dtype; the same frames.
    spec : BaseSpec
        The pattern set (any method, one axis or both).
    calibration : StereoCalibration, str or Path
        The cameras, or their calibration file.
    rectification : Rectification, optional
        :func:`rectify` of the calibration, if already made.
    min_depth, max_depth : float, optional
        Depths ``z`` (left camera frame, mm) kept.
    force : bool, optional
        Passed to the decoder when it takes it; keeps a reconstruction with few matches
        (a warning in ``info``).
    tolerance, other_tolerance, smooth : float, optional
        See :func:`reconstruct_stereo`.
    **options
        Decoder options (``strategy``, ``min_modulation``, ...).

    Returns
    -------
    StereoResult
        ``disparity``, ``depth``, ``points``, ``colors``, ``mask``, ``left`` and ``right``
        (each camera's decode), ``info``.

    Raises
    ------
    BistairError
        Captures of different shapes, the same captures for both cameras, a
        camera-projector calibration, a decode that refuses its captures or finds no valid
        pixel, or what :func:`reconstruct_stereo` refuses.

    Examples
    --------
    >>> cal = _toy_stereo()
    >>> stereo(np.zeros((7, 480, 640)), np.zeros((6, 480, 640)), None, cal)
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: left and right captures differ: 7 frames of 640x480 and 6 ...
    """
    left_images, right_images = np.asarray(left_images), np.asarray(right_images)
    if left_images.shape != right_images.shape:
        raise BistairError("left and right captures differ: " + " and ".join(
            f"{s[0]} frames of {s[2]}x{s[1]}" if len(s) == 3 else f"shape {s}"
            for s in (left_images.shape, right_images.shape)))
    same_captures(left_images, right_images)
    if isinstance(calibration, Calibration):
        raise BistairError("a camera-projector calibration was given: stereo needs the two "
                           "cameras' calibration (bistair calibrate-stereo)")
    if not isinstance(calibration, StereoCalibration):
        calibration = load_calibration(calibration, STEREO)
    opts = decode_options(spec.method, force, options)

    def decoded(side: str, images: np.ndarray) -> DecodeResult | AxesResult:
        try:
            res = decode(images, spec, **opts)
        except BistairError as exc:
            raise BistairError(f"{side}: {exc}") from None
        if not res.mask.any():
            raise BistairError(f"{side}: no pixel decoded: does the spec fit the captures?")
        return res

    # both cameras at once, the cores shared (the same results as one after the other)
    results = side_by_side(lambda: decoded("left", left_images),
                           lambda: decoded("right", right_images))
    return reconstruct_stereo(*results, calibration, spec.orientation, rectification,
                              min_depth, max_depth, tolerance, other_tolerance,
                              smooth=smooth, offset=spec.offset, force=force)


def _toy_stereo() -> StereoCalibration:
    """Two distortion-free 640 x 480 cameras 120 mm apart, turned toward each other, for
    the examples."""
    cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
    rot = cv2.Rodrigues(np.array([0.0, 0.2, 0.0]))[0]
    return StereoCalibration(cam, cam, rot, -rot @ np.array([120.0, 0.0, 0.0]))


def _plane_decode(cal: StereoCalibration, side: str, z: float,
                  period: float = 20.0) -> DecodeResult:
    """The decode a camera of ``cal`` makes of the plane at depth ``z`` (left frame) lit by
    patterns whose projector column is ``2 * x + 640`` at the point ``(x, y, z)``."""
    dev = cal.left if side == "left" else cal.right
    v, u = np.mgrid[0:dev.height, 0:dev.width].astype(float)
    rays = np.linalg.solve(dev.K, np.stack([u.ravel(), v.ravel(), np.ones(u.size)]))
    rot, t = (np.eye(3), np.zeros(3)) if side == "left" else (cal.R, cal.T)
    origin, dirs = -rot.T @ t, rot.T @ rays  # in the left frame
    pts = origin[:, None] + dirs * (z - origin[2]) / dirs[2]
    coord = (2 * pts[0] + 640).reshape(dev.height, dev.width)
    return make_result("demo", 2 * np.pi * (coord / period % 1), np.floor(coord / period),
                       period, modulation=np.ones(coord.shape))
