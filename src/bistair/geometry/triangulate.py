"""From absolute phase to 3-D points: triangulation with a calibrated rig.

Triangulation. A valid camera pixel's ray ``X = z * (x, y, 1)`` (``(x, y)`` undistorted
through the camera model) meets the surface of projector points whose coded coordinate (the
column ``x_p`` for ``orientation="columns"``, the row ``y_p`` for ``"rows"``), projected with
the projector's distortion, equals the decoded one. The depth ``z`` starts at the
distortion-free ray-plane intersection and is refined by vectorised Newton steps on the
projector's own projection, so distortion is honoured exactly. Points are in the camera
frame, millimetres.

Both axes. With the projector column and row decoded (``orientation="both"``), the depth is
the one whose projection lies nearest to the decoded pair (Gauss-Newton on the depth, the
same projection with distortion), and the distance left over, from the pair to the image of
the camera ray (its epipolar line), tells a wrong decode: no point on the ray shows that
pair. Where only the coordinate along the baseline is valid, one axis is used.

Examples
--------
>>> cal = _toy_calibration()
>>> pixels = np.array([[320.0, 240.0], [100.0, 400.0]])
>>> point = np.array([[10.0, -20.0, 600.0]])
>>> uv = cal.camera.K @ point[0] / point[0, 2]
>>> xp = cal.projector.K @ (cal.R @ point[0] + cal.T)
>>> triangulate(uv[None, :2], np.array([xp[0] / xp[2]]), cal).round(6).tolist()
[[10.0, -20.0, 600.0]]
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ..core.result import AxesResult, DecodeResult
from ..errors import BistairError
from ..io.atomic import output_folder
from ..io.writers import write_depth, write_ply
from ..spec import BaseSpec
from .calibration import CAMERA_PROJECTOR, Calibration, Device, load_calibration

_UNDISTORT = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 50, 1e-14)


@dataclass
class Reconstruction:
    """Per camera pixel: ``points`` (H, W, 3) float32 mm in the camera frame and ``depth``
    (H, W) float32 ``z`` (NaN where invalid), ``colors`` (H, W, 3) uint8, ``mask``; ``info``
    counts pixels (``outside_range``: triangulated, but dropped by the depth range)."""

    points: np.ndarray
    depth: np.ndarray
    colors: np.ndarray
    mask: np.ndarray
    info: dict[str, Any] = field(default_factory=dict)

    def cloud(self) -> tuple[np.ndarray, np.ndarray]:
        """The valid points ``(N, 3)`` float32 and their colours ``(N, 3)`` uint8."""
        return self.points[self.mask], self.colors[self.mask]

    def __repr__(self) -> str:
        found = self.depth[self.mask]
        depths = (f", depth {float(found.min()):.1f} to {float(found.max()):.1f} mm"
                  if found.size else "")
        count = int(self.mask.sum())
        return (f"Reconstruction({count} point{'s' if count != 1 else ''} of shape "
                f"{self.mask.shape}{depths})")

    def save(self, ply: str | Path, depth_folder: str | Path | None = None) -> Path:
        """Write the coloured point cloud (binary PLY, camera frame, mm) and, with
        ``depth_folder``, ``depth.npy`` and ``depth.png`` there, as ``bistair reconstruct``
        does (atomically); returns ``ply``."""
        pts, cols = self.cloud()
        if depth_folder is None:
            return write_ply(ply, pts, cols)
        with output_folder(depth_folder) as tmp:
            write_depth(self.depth, tmp)
            write_ply(ply, pts, cols)
        return Path(ply)


def _project_coded(dev: Device, pts: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coordinates (coded axis, other axis) of device-frame points ``(N, 3)``."""
    k1, k2, p1, p2, k3 = dev.dist
    with np.errstate(divide="ignore", invalid="ignore"):
        x, y = pts[:, 0] / pts[:, 2], pts[:, 1] / pts[:, 2]
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    u = dev.K[0, 0] * xd + dev.K[0, 1] * yd + dev.K[0, 2]
    v = dev.K[1, 1] * yd + dev.K[1, 2]
    return (u, v) if axis == 0 else (v, u)


def _camera_rays(pixels: np.ndarray, cam: Device) -> np.ndarray:
    """Rays ``(x, y, 1)`` ``(N, 3)`` of camera pixels ``(N, 2)``, undistorted."""
    pix = np.asarray(pixels, np.float64).reshape(-1, 1, 2)
    norm = cv2.undistortPoints(pix, cam.K, cam.dist, criteria=_UNDISTORT).reshape(-1, 2)
    return np.column_stack([norm, np.ones(len(norm))])


def _depth_on_axis(a: np.ndarray, t: np.ndarray, proj: Device, target: np.ndarray,
                   axis: int, iterations: int) -> np.ndarray:
    """Depths ``z`` where the projector-frame points ``z * a + t`` project to ``target``
    along ``axis``: the distortion-free ray-plane intersection, then Newton steps."""
    m = (target - proj.K[axis, 2]) / proj.K[axis, axis]
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (m * t[2] - t[axis]) / (a[:, axis] - m * a[:, 2])
        for _ in range(iterations):
            step = 1e-3 * np.abs(z) + 1e-9
            f0 = _project_coded(proj, z[:, None] * a + t, axis)[0] - target
            f1 = _project_coded(proj, (z + step)[:, None] * a + t, axis)[0] - target
            dz = f0 * step / (f1 - f0)
            z = z - dz
            if not np.nanmax(np.abs(dz) / np.abs(z), initial=0.0) > 1e-12:
                break
    return z


def triangulate(pixels: np.ndarray, coord: np.ndarray, calibration: Calibration,
                orientation: str = "columns", iterations: int = 12, tolerance: float = 1e-4,
                sensitivity: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """3-D points (camera frame, mm) of camera ``pixels`` ``(N, 2)`` whose decoded projector
    coordinate along the coded axis is ``coord`` ``(N,)``; NaN rows where there is no
    solution in front of both devices inside the projector image (to ``tolerance`` px).

    With ``sensitivity``, also the depth change per projector pixel, ``|dz/dcoord|``.

    Parameters
    ----------
    pixels : numpy.ndarray
        ``(N, 2)`` camera pixel coordinates ``(u, v)`` (distorted, as in the images).
    coord : numpy.ndarray
        ``(N,)`` decoded projector coordinate (pixels) along the coded axis.
    calibration : Calibration
        The rig, ``X_p = R @ X_c + T`` (mm).
    orientation : {"columns", "rows"}, optional
        The coded axis: ``coord`` is the projector column (``"columns"``) or row (anything
        else is taken as ``"rows"``).
    iterations : int, optional
        Newton steps at most on the depth.
    tolerance : float, optional
        Projector pixels the projection of a solution may miss ``coord`` by.
    sensitivity : bool, optional
        Also return ``|dz/dcoord|`` (mm per projector pixel).

    Returns
    -------
    points : numpy.ndarray
        ``(N, 3)`` float64 points in the camera frame (mm), NaN rows where there is no
        solution.
    sensitivity : numpy.ndarray
        Only with ``sensitivity``: ``(N,)`` mm of depth per projector pixel, NaN where
        there is no solution.

    Examples
    --------
    >>> cal = _toy_calibration()
    >>> point = np.array([10.0, -20.0, 600.0])
    >>> uv = cal.camera.K @ point / point[2]
    >>> xp = cal.projector.K @ (cal.R @ point + cal.T)
    >>> pts, dz = triangulate([uv[:2], [0, 0]], [xp[0] / xp[2], 5000.0], cal,
    ...                       sensitivity=True)
    >>> pts.round(6).tolist()  # column 5000 is off the 800-pixel projector
    [[10.0, -20.0, 600.0], [nan, nan, nan]]
    >>> dz.round(2).tolist()  # mm per projector column at 600 mm
    [2.52, nan]
    """
    cam, proj = calibration.camera, calibration.projector
    axis = 0 if orientation == "columns" else 1
    target = np.asarray(coord, np.float64).ravel()
    if not len(target):
        return (np.zeros((0, 3)), np.zeros(0)) if sensitivity else np.zeros((0, 3))
    ray = _camera_rays(pixels, cam)
    a = ray @ calibration.R.T  # projector-frame point = z * a + T
    t = calibration.T
    z = _depth_on_axis(a, t, proj, target, axis, iterations)
    with np.errstate(divide="ignore", invalid="ignore"):
        pts_p = z[:, None] * a + t
        coded, other = _project_coded(proj, pts_p, axis)
        span = proj.size[1 - axis]
        ok = ((z > 0) & (pts_p[:, 2] > 0) & (np.abs(coded - target) <= tolerance)
              & (other >= -0.5) & (other <= span - 0.5))
        points = np.where(ok[:, None], z[:, None] * ray, np.nan)
        if not sensitivity:
            return points
        step = 1e-3 * np.abs(z) + 1e-9
        slope = (_project_coded(proj, (z + step)[:, None] * a + t, axis)[0] - coded) / step
        return points, np.where(ok, 1.0 / np.abs(slope), np.nan)


def baseline_orientation(calibration: Calibration) -> str:
    """The projector axis along the baseline, whose coordinate carries the depth:
    ``"columns"`` or ``"rows"``.

    At the projector's principal point the epipolar lines (the images of camera rays) run
    along ``(fx * Tx, fy * Ty)``; the axis with the larger component wins.

    Parameters
    ----------
    calibration : Calibration
        The rig.

    Returns
    -------
    str
        ``"columns"`` (ties included) or ``"rows"``.

    Examples
    --------
    >>> baseline_orientation(_toy_calibration())
    'columns'
    """
    proj, t = calibration.projector, calibration.T
    return "columns" if abs(proj.K[0, 0] * t[0]) >= abs(proj.K[1, 1] * t[1]) else "rows"


def triangulate_axes(pixels: np.ndarray, coord_x: np.ndarray, coord_y: np.ndarray,
                     calibration: Calibration, epipolar_tolerance: float = 1.5,
                     iterations: int = 20, residual: bool = False
                     ) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """3-D points (camera frame, mm) of camera ``pixels`` ``(N, 2)`` whose decoded projector
    column and row are ``coord_x`` and ``coord_y`` ``(N,)``.

    Each point is at the depth along its camera ray whose projection into the projector
    (with the projector's distortion) is nearest to ``(coord_x, coord_y)``: least squares of
    both projector residuals, Gauss-Newton on the depth, started from the one-axis solution
    of the coordinate along the baseline (:func:`baseline_orientation`).

    Parameters
    ----------
    pixels : camera pixel coordinates ``(N, 2)``.
    coord_x, coord_y : decoded projector column and row per pixel.
    calibration : the rig.
    epipolar_tolerance : projector pixels the decoded pair may lie from the projection of
        the ray (the camera pixel's epipolar line), across the baseline at the best fit.
        Farther, no point on the ray shows both coordinates: a wrong decode, dropped.
    iterations : Gauss-Newton steps at most.
    residual : also return that distance per pixel (NaN where there is no fit).

    Returns
    -------
    points : ``(N, 3)``, NaN rows for pixels dropped by the tolerance, behind a device or
        outside the projector image; with ``residual``, ``(points, distance)``.

    Examples
    --------
    >>> cal = _toy_calibration()
    >>> point = np.array([10.0, -20.0, 600.0])
    >>> uv = cal.camera.K @ point / point[2]
    >>> xp = cal.projector.K @ (cal.R @ point + cal.T)
    >>> x, y = xp[0] / xp[2], xp[1] / xp[2]
    >>> triangulate_axes(uv[None, :2], [x], [y], cal).round(6).tolist()
    [[10.0, -20.0, 600.0]]
    >>> pts, dist = triangulate_axes(uv[None, :2], [x], [y + 30], cal, residual=True)
    >>> bool(np.isnan(pts).all()), round(float(dist[0]), 1)  # one fringe off on the rows
    (True, 30.0)
    """
    cam, proj = calibration.camera, calibration.projector
    target = np.column_stack([np.asarray(coord_x, np.float64).ravel(),
                              np.asarray(coord_y, np.float64).ravel()])
    if not len(target):
        return (np.zeros((0, 3)), np.zeros(0)) if residual else np.zeros((0, 3))
    axis = 0 if baseline_orientation(calibration) == "columns" else 1
    ray = _camera_rays(pixels, cam)
    a = ray @ calibration.R.T  # projector-frame point = z * a + T
    t = calibration.T

    def project(z: np.ndarray) -> np.ndarray:
        return np.column_stack(_project_coded(proj, z[:, None] * a + t, 0))

    z = _depth_on_axis(a, t, proj, target[:, axis], axis, 12)
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(iterations):
            step = 1e-6 * np.abs(z) + 1e-9
            jac = (project(z + step) - project(z - step)) / (2 * step[:, None])
            dz = np.sum(jac * (project(z) - target), axis=1) / np.sum(jac * jac, axis=1)
            z = z - dz
            if not np.nanmax(np.abs(dz) / np.abs(z), initial=0.0) > 1e-12:
                break
        fit = project(z)
        dist = np.hypot(*(fit - target).T)
        ok = ((z > 0) & (z * a[:, 2] + t[2] > 0) & (dist <= epipolar_tolerance)
              & (fit >= -0.5).all(axis=1) & (fit[:, 0] <= proj.width - 0.5)
              & (fit[:, 1] <= proj.height - 0.5))
        points = np.where(ok[:, None], z[:, None] * ray, np.nan)
    return (points, dist) if residual else points


def _grey_colors(result: DecodeResult, spec: BaseSpec | None) -> np.ndarray:
    if result.texture is not None:
        grey = np.asarray(result.texture, float)
    else:
        grey = np.asarray(result.average, float) / (spec.offset if spec else 0.5)
    grey = np.round(np.clip(np.nan_to_num(grey), 0.0, 1.0) * 255).astype(np.uint8)
    return np.repeat(grey[..., None], 3, axis=2)


def check_fit(result: DecodeResult | AxesResult, calibration: Calibration,
              spec: BaseSpec | str, orientation: str | None = None) -> str:
    """The coded orientation (``"columns"``, ``"rows"`` or ``"both"``), after checking that
    captures, spec and calibration belong together (one-line :class:`BistairError`
    otherwise).

    Parameters
    ----------
    result : DecodeResult or AxesResult
        The decode; its image size must be the calibrated camera's.
    calibration : Calibration
        The rig.
    spec : BaseSpec or str
        The captures' spec (its projector size must be the calibrated projector's), or just
        its orientation (then the projector size is not checked).
    orientation : str or None, optional
        What the caller expects the spec to code, if anything.

    Returns
    -------
    str
        The spec's orientation: ``"columns"``, ``"rows"`` or ``"both"``.

    Raises
    ------
    BistairError
        An unknown orientation, one other than ``orientation``, a decode of both axes with
        a spec of one or the reverse, or camera or projector sizes other than the
        calibration's.

    Examples
    --------
    >>> from bistair.core.result import make_result
    >>> cal = _toy_calibration()
    >>> res = make_result("demo", np.zeros((480, 640)), np.zeros((480, 640), int), 30.0,
    ...                   modulation=np.ones((480, 640)))
    >>> check_fit(res, cal, "columns")
    'columns'
    >>> check_fit(res, cal, "both")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: a spec of both axes needs the decode of both axes
    >>> check_fit(res, cal, "columns", orientation="rows")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the spec codes columns, but rows were asked for
    """
    coded = spec if isinstance(spec, str) else spec.orientation
    if coded not in ("columns", "rows", "both"):
        raise BistairError(f"orientation must be 'columns', 'rows' or 'both', got {coded!r}")
    if orientation is not None and orientation != coded:
        raise BistairError(f"the spec codes {coded}, but {orientation} were asked for")
    axes = isinstance(result, AxesResult)
    if axes != (coded == "both"):
        raise BistairError("a spec of both axes needs the decode of both axes" if not axes
                           else f"the decode holds both axes, the spec codes {coded} only")
    cam, proj = calibration.camera, calibration.projector
    h, w = (result.x if axes else result).phase.shape
    if (w, h) != cam.size:
        raise BistairError(f"calibration is for {cam.width}x{cam.height} camera images, "
                           f"captures are {w}x{h}")
    if isinstance(spec, BaseSpec) and (spec.width, spec.height) != proj.size:
        raise BistairError(f"calibration is for a {proj.width}x{proj.height} projector, the "
                           f"spec for {spec.width}x{spec.height}")
    return coded


def check_depth_range(min_depth: float, max_depth: float) -> None:
    """Refuse a depth range that is not ``0 <= min_depth < max_depth`` (NaN included).

    Parameters
    ----------
    min_depth, max_depth : float
        The depths ``z`` (mm, camera frame) to keep; ``max_depth`` may be infinite.

    Raises
    ------
    BistairError
        If not ``0 <= min_depth < max_depth`` (a NaN bound fails too).

    Examples
    --------
    >>> check_depth_range(400.0, float("inf"))
    >>> check_depth_range(-1.0, 800.0)
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the depth range needs 0 <= min_depth < max_depth, got -1.0:800.0
    """
    if not 0 <= min_depth < max_depth:
        raise BistairError(f"the depth range needs 0 <= min_depth < max_depth, got "
                           f"{min_depth}:{max_depth}")


def reconstruct(result: DecodeResult | AxesResult, calibration: Calibration | str | Path,
                spec: BaseSpec | str | None = None, orientation: str | None = None,
                min_depth: float = 0.0, max_depth: float = np.inf,
                epipolar_tolerance: float = 1.5, **options: Any) -> Reconstruction:
    """Triangulate every valid pixel of a decode (also ``bistair.reconstruct``).

    ``spec`` is the spec of the captures (or just its orientation), by default the one the
    result was decoded with (``result.spec``, set by :func:`bistair.decode`). It says which
    projector axis the coordinates run along (columns or rows; a decode of both axes needs a
    spec of both), its projector size is checked against the calibration's, and its
    ``offset`` scales the fringes' average into the points' grey colours when there is no
    white frame. ``orientation``, if given, is what the caller expects the spec to code.
    Depths outside ``[min_depth, max_depth]`` are dropped (``0 <= min_depth <
    max_depth``). ``options`` go to :func:`triangulate`. Colours are the white frame if the
    spec has one, else the fringes' average.

    A decode of both axes (:class:`~bistair.core.result.AxesResult`, spec orientation
    ``"both"``) is triangulated with both projector coordinates where both are valid
    (:func:`triangulate_axes`; a pixel whose pair lies more than ``epipolar_tolerance``
    projector pixels off its epipolar line is dropped as a wrong decode), and with the
    coordinate along the baseline alone (:func:`baseline_orientation`) where only that one
    is valid. ``info`` then counts ``both_axes``, ``one_axis`` and ``off_epipolar`` pixels.

    Parameters
    ----------
    result : DecodeResult or AxesResult
        The decode, ``(height, width)`` of the calibrated camera.
    calibration : Calibration, str or Path
        The rig, ``X_p = R @ X_c + T`` (mm), or its calibration file
        (:func:`~bistair.geometry.calibration.load_calibration`).
    spec : BaseSpec, str or None, optional
        The captures' spec, or just its orientation (``"columns"``, ``"rows"``,
        ``"both"``); see :func:`check_fit`. By default ``result.spec``.
    orientation : str or None, optional
        What the caller expects the spec to code, if anything.
    min_depth, max_depth : float, optional
        Depth range kept (mm, ``z`` in the camera frame).
    epipolar_tolerance : float, optional
        Projector pixels a pair of both axes may lie off its epipolar line (positive).
    **options
        Passed to :func:`triangulate` (``iterations``, ``tolerance``).

    Returns
    -------
    Reconstruction
        Points (float32, mm, camera frame; NaN where invalid), depth, grey colours
        (uint8 RGB), mask and counts in ``info`` (``outside_range``, and for both axes
        ``both_axes``, ``one_axis``, ``off_epipolar``, ``other_axis_only``).

    Raises
    ------
    BistairError
        Whatever :func:`check_fit` and :func:`check_depth_range` refuse, a tolerance that
        is not positive, a coded axis that carries almost no depth in this rig (the
        baseline across it), no spec given for a result that does not carry one, or a
        calibration file that cannot be read.

    Examples
    --------
    One valid pixel, its projector column that of a point 600 mm away:

    >>> from bistair.core.result import make_result
    >>> cal = _toy_calibration()
    >>> ray = np.linalg.solve(cal.camera.K, [320.0, 240.0, 1.0])
    >>> xp = cal.projector.K @ (cal.R @ (600 * ray) + cal.T)
    >>> column = xp[0] / xp[2]
    >>> order = np.full((480, 640), -1)
    >>> order[240, 320] = column // 30
    >>> phi = np.full((480, 640), 2 * np.pi * (column / 30 % 1))
    >>> res = make_result("demo", phi, order, 30.0, modulation=np.ones((480, 640)))
    >>> rec = reconstruct(res, cal, "columns")
    >>> [round(float(v), 2) for v in rec.points[240, 320]], int(rec.mask.sum()), rec.info
    ([0.38, 0.38, 600.0], 1, {'outside_range': 0})
    >>> reconstruct(res, cal, "columns", max_depth=500.0).info
    {'outside_range': 1}
    >>> rec
    Reconstruction(1 point of shape (480, 640), depth 600.0 to 600.0 mm)
    """
    if spec is None:
        spec = result.spec
        if spec is None:
            raise BistairError("give the captures' spec: this result does not carry the "
                               "spec it was decoded with")
    if not isinstance(calibration, Calibration):
        calibration = load_calibration(calibration, CAMERA_PROJECTOR)
    coded = check_fit(result, calibration, spec, orientation)
    check_depth_range(min_depth, max_depth)
    if not epipolar_tolerance > 0:
        raise BistairError(f"the epipolar tolerance must be positive, got {epipolar_tolerance}")
    if isinstance(result, AxesResult):
        valid, pts, info = _both_axes(result, calibration, epipolar_tolerance, options)
        first = result.x
    else:
        coord = result.coord.ravel()  # (computed from the phase: read once)
        valid = np.flatnonzero(result.mask.ravel() & np.isfinite(coord))
        pts, sens = triangulate(_pixels(valid, result.phase.shape[1]), coord[valid],
                                calibration, coded, sensitivity=True, **options)
        del coord
        _check_geometry(pts, sens, calibration, coded)
        info, first = {}, result
    h, w = first.phase.shape
    found = np.isfinite(pts[:, 2])
    with np.errstate(invalid="ignore"):
        keep = found & (pts[:, 2] >= min_depth) & (pts[:, 2] <= max_depth)
    points = np.full((h * w, 3), np.nan, np.float32)
    points[valid[keep]] = pts[keep]
    points = points.reshape(h, w, 3)
    mask = np.isfinite(points[..., 2])
    info["outside_range"] = int(found.sum() - keep.sum())
    return Reconstruction(points, points[..., 2].copy(), _grey_colors(
        first, spec if isinstance(spec, BaseSpec) else None), mask, info)


def _pixels(flat: np.ndarray, width: int) -> np.ndarray:
    """``(x, y)`` ``(N, 2)`` of flat pixel indices."""
    return np.column_stack([flat % width, flat // width]).astype(float)


def _both_axes(result: AxesResult, calibration: Calibration, epipolar_tolerance: float,
               options: dict[str, Any]) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
    """``(flat pixel indices, points, info)`` of a decode of both axes: every pixel with a
    valid coordinate along the baseline, triangulated with both coordinates where the other
    is valid too."""
    along = baseline_orientation(calibration)
    coord_x, coord_y = result.coord_x, result.coord_y  # (computed from the phases: read once)
    main, cross = (result.x, result.y) if along == "columns" else (result.y, result.x)
    main_coord, cross_coord = (coord_x, coord_y) if along == "columns" else (coord_y, coord_x)
    ok_main = main.mask & np.isfinite(main_coord)
    ok_cross = cross.mask & np.isfinite(cross_coord)
    valid = np.flatnonzero(ok_main.ravel())
    pix = _pixels(valid, main_coord.shape[1])
    pts, sens = triangulate(pix, main_coord.ravel()[valid], calibration, along,
                            sensitivity=True, **options)
    _check_geometry(pts, sens, calibration, along, both=True)
    two = ok_cross.ravel()[valid]
    pts[two], dist = triangulate_axes(pix[two], coord_x.ravel()[valid[two]],
                                      coord_y.ravel()[valid[two]], calibration,
                                      epipolar_tolerance, residual=True)
    info = {"baseline_axis": along, "both_axes": int(two.sum()),
            "one_axis": int((~two).sum()),
            "off_epipolar": int(np.sum(~(dist <= epipolar_tolerance))),
            "other_axis_only": int(np.sum(ok_cross & ~ok_main))}
    return valid, pts, info


def _check_geometry(points: np.ndarray, sens: np.ndarray, calibration: Calibration,
                    coded: str, both: bool = False) -> None:
    """Refuse a coded axis that carries almost no depth in this rig (baseline across it);
    with ``both``, ``coded`` is the better of the two axes."""
    ok = np.isfinite(sens)
    if ok.sum() < 10:
        return
    axis = 0 if coded == "columns" else 1
    dist = np.linalg.norm(points[ok] @ calibration.R.T + calibration.T, axis=1)
    ideal = np.median(dist) ** 2 / (calibration.projector.K[axis, axis] * calibration.baseline)
    ratio = float(np.median(sens[ok]) / ideal)
    if ratio > 8:
        other = "rows" if coded == "columns" else "columns"
        advice = ("neither axis does better: is the baseline along the optical axes?" if both
                  else f"capture {other} instead")
        raise BistairError(f"projector {coded} barely change with depth in this rig "
                           f"({np.median(sens[ok]):.1f} mm per projector pixel, {ratio:.0f}x "
                           f"worse than along the baseline): {advice}")


def _toy_calibration() -> Calibration:
    """A distortion-free camera and projector for the examples."""
    cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
    proj = Device(800, 600, [[1000.0, 0, 399.5], [0, 1000, 299.5], [0, 0, 1]])
    rot = cv2.Rodrigues(np.array([0.0, 0.3, 0.0]))[0]
    return Calibration(cam, proj, rot, -rot @ np.array([150.0, 0.0, 0.0]))
