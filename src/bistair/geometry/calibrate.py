"""Calibrating a camera and a projector from board captures (Zhang and Huang, Opt. Eng.
45(8), 083601, 2006).

For every pose of a planar board the board features are found in the camera's white frame;
the absolute phases of both orientations map each feature to projector pixels (a robust local
quadratic fit to the decoded projector x and y around the feature, :func:`sample_local`); the
camera and the projector are calibrated like two cameras with the same model points
(``cv2.calibrateCamera``) and then as a pair (``cv2.stereoCalibrate``), giving ``R, T`` with
``X_p = R @ X_c + T`` (:class:`~bistair.geometry.calibration.Calibration`). Reprojection
errors are those of the final (stereo) model. Reading the capture folders is
:func:`bistair.app.jobs.calibrate_folder`.

Examples
--------
>>> from bistair.sim.boards import synthetic_views
>>> rng = np.random.default_rng(0)
>>> cam = Device(640, 480, np.array([[800.0, 0, 320], [0, 800, 240], [0, 0, 1]]))
>>> proj = Device(800, 600, np.array([[1000.0, 0, 400], [0, 1000, 400], [0, 0, 1]]))
>>> truth = Calibration(cam, proj, cv2.Rodrigues(np.array([0.0, 0.3, 0.0]))[0],
...                     np.array([-150.0, 0.0, 45.0]))
>>> obj, cpts, ppts = synthetic_views(truth, Board(columns=8, rows=6, spacing=15), 6, rng)
>>> cal = calibrate_points(obj, cpts, ppts, (640, 480), (800, 600))
>>> round(cal.baseline, 3), round(float(cal.projector.K[0, 0]), 2), cal.rms < 1e-3
(156.605, 1000.0, True)
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from ..errors import BistairError
from .board import Board
from .calibration import Calibration, Device


def calibrate_points(object_points: Sequence[np.ndarray], camera_points: Sequence[np.ndarray],
                     projector_points: Sequence[np.ndarray], camera_size: tuple[int, int],
                     projector_size: tuple[int, int], names: Sequence[str] | None = None,
                     fix_k3: bool = True, refine: bool = True) -> Calibration:
    """Calibrate camera, projector and pair from per-pose correspondences.

    Parameters
    ----------
    object_points : per pose, ``(n, 3)`` board points (mm, ``z = 0``).
    camera_points, projector_points : per pose, ``(n, 2)`` pixel coordinates of those points.
    camera_size, projector_size : ``(width, height)``.
    names : pose names for the per-pose errors.
    fix_k3 : keep ``k3 = 0`` (advisable unless many well-spread poses).
    refine : after calibrating each device alone, refine all parameters jointly in
        ``cv2.stereoCalibrate``; otherwise the intrinsics stay fixed there.
    """
    obj = [np.asarray(o, np.float32).reshape(-1, 3) for o in object_points]
    cam = [np.asarray(p, np.float32).reshape(-1, 2) for p in camera_points]
    proj = [np.asarray(p, np.float32).reshape(-1, 2) for p in projector_points]
    names = list(names) if names is not None else [f"pose-{i:02d}" for i in range(len(obj))]
    flags = cv2.CALIB_FIX_K3 if fix_k3 else 0
    try:
        _, kc, dc, *_ = cv2.calibrateCamera(obj, cam, tuple(camera_size), None, None,
                                            flags=flags)
        _, kp, dp, *_ = cv2.calibrateCamera(obj, proj, tuple(projector_size), None, None,
                                            flags=flags)
        stereo_flags = flags | (cv2.CALIB_USE_INTRINSIC_GUESS if refine
                                else cv2.CALIB_FIX_INTRINSIC)
        criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 200, 1e-12)
        out = cv2.stereoCalibrateExtended(obj, cam, proj, kc, dc, kp, dp, tuple(camera_size),
                                          None, None, flags=stereo_flags, criteria=criteria)
    except cv2.error as exc:
        raise BistairError(f"calibration failed in OpenCV: {str(exc).strip().splitlines()[-1]}"
                           ) from None
    rms, kc, dc, kp, dp, rot, t, _, _, rvecs, tvecs, _ = out
    errs = []  # per pose and device: squared-error sums and counts under the final model
    for o, c, p, rv, tv in zip(obj, cam, proj, rvecs, tvecs, strict=True):
        rc = cv2.Rodrigues(rv)[0]
        rp_vec = cv2.Rodrigues(rot @ rc)[0]
        ec = cv2.projectPoints(o, rv, tv, kc, dc)[0].reshape(-1, 2) - c
        ep = cv2.projectPoints(o, rp_vec, rot @ tv.reshape(3) + t.ravel(), kp, dp)[0]
        errs.append((np.sum(ec**2), np.sum((ep.reshape(-1, 2) - p) ** 2), len(o)))
    sc, sp, n = (np.array(v, float) for v in zip(*errs, strict=True))
    poses = tuple({"name": name, "features": int(k), "camera_rms": float(np.sqrt(a / k)),
                   "projector_rms": float(np.sqrt(b / k))}
                  for name, a, b, k in zip(names, sc, sp, n, strict=True))
    return Calibration(Device(*camera_size, kc, dc.ravel(), float(np.sqrt(sc.sum() / n.sum()))),
                       Device(*projector_size, kp, dp.ravel(),
                              float(np.sqrt(sp.sum() / n.sum()))),
                       rot, t.ravel(), float(rms), poses)


def sample_local(values: np.ndarray, points: np.ndarray, radius: int, min_pixels: int = 12,
                 rounds: int = 3) -> np.ndarray:
    """Robust values of smooth maps at sub-pixel points: a weighted quadratic fit per point.

    Parameters
    ----------
    values : ``(C, H, W)`` maps (e.g. projector x and y per camera pixel), NaN where invalid.
    points : ``(N, 2)`` pixel coordinates ``(u, v)``.
    radius : half-size of the square window around each point (pixels).
    min_pixels : fewest pixels valid in every map that a fit needs.
    rounds : fits; after each, pixels off by more than 3.5 robust sigmas (at least 0.1) are
        dropped (e.g. a wrong fringe order).

    Returns
    -------
    ``(C, N)`` fitted values at the points, NaN where the window holds too few valid pixels or
    they do not surround the point.

    Examples
    --------
    >>> v, u = np.mgrid[0:40, 0:50].astype(float)
    >>> maps = np.stack([2 * u + 0.01 * v**2, 3 * v])
    >>> maps[0, 20, 21] = 500.0  # an outlier
    >>> sample_local(maps, np.array([[20.3, 19.6], [0.0, 45.0]]), 4).round(4).tolist()
    [[44.4416, nan], [58.8, nan]]
    """
    values = np.asarray(values, float)
    h, w = values.shape[1:]
    pts = np.asarray(points, float).reshape(-1, 2)
    off = np.arange(-radius, radius + 1)
    uu = np.rint(pts[:, 0])[:, None, None].astype(int) + off[None, None, :]
    vv = np.rint(pts[:, 1])[:, None, None].astype(int) + off[None, :, None]
    uu, vv = np.broadcast_arrays(uu, vv)
    inside = (uu >= 0) & (uu < w) & (vv >= 0) & (vv < h)
    vals = values[:, np.clip(vv, 0, h - 1), np.clip(uu, 0, w - 1)].reshape(len(values),
                                                                           len(pts), -1)
    good = (inside.reshape(len(pts), -1) & np.isfinite(vals).all(axis=0))
    vals = np.where(good, vals, 0.0)
    du = ((uu - pts[:, 0, None, None]) / radius).reshape(len(pts), -1)
    dv = ((vv - pts[:, 1, None, None]) / radius).reshape(len(pts), -1)
    design = np.stack([np.ones_like(du), du, dv, du * du, du * dv, dv * dv], axis=-1)
    weight = good.astype(float)
    coef = np.zeros((len(values), len(pts), 6))
    for _ in range(rounds):
        normal = np.einsum("npi,np,npj->nij", design, weight, design) + 1e-9 * np.eye(6)
        rhs = np.einsum("npi,np,cnp->cni", design, weight, vals)
        coef = np.linalg.solve(normal[None], rhs[..., None])[..., 0]
        resid = np.abs(vals - np.einsum("npi,cni->cnp", design, coef)).max(axis=0)
        masked = np.where(weight > 0, resid, np.nan)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN windows
            sigma = 1.4826 * np.nanmedian(masked, axis=1)
        limit = np.maximum(3.5 * np.nan_to_num(sigma, nan=0.0), 0.1)
        weight = weight * (resid <= limit[:, None])
    # the kept pixels must surround the point: some on every side of it
    kept = weight > 0
    sides = [(du < 0) & kept, (du > 0) & kept, (dv < 0) & kept, (dv > 0) & kept]
    ok = (kept.sum(axis=1) >= min_pixels) & np.all([s.any(axis=1) for s in sides], axis=0)
    return np.where(ok, coef[..., 0], np.nan)


@dataclass(frozen=True)
class PoseCapture:
    """One board pose in memory: the camera's white frame and the projector column ``x`` and
    row ``y`` decoded per camera pixel (NaN where invalid)."""

    name: str
    white: np.ndarray
    x: np.ndarray
    y: np.ndarray


def feature_spacing(points: np.ndarray, columns: int) -> float:
    """Median image distance between neighbouring features of a row-by-row grid (pixels)."""
    grid = np.asarray(points, float).reshape(-1, columns, 2)
    steps = np.concatenate([np.diff(grid, axis=1).reshape(-1, 2),
                            np.diff(grid, axis=0).reshape(-1, 2)])
    return float(np.median(np.hypot(steps[:, 0], steps[:, 1])))


def calibrate_poses(poses: Sequence[PoseCapture], board: Board,
                    projector_size: tuple[int, int], min_poses: int = 3,
                    min_mapped: float = 0.5, **options: Any) -> Calibration:
    """Detect the board, map its features through the phases and calibrate
    (:func:`calibrate_points`; ``options`` go there).

    A pose is used when the board is found in its white frame and at least ``min_mapped`` of
    its features get projector coordinates in both orientations.
    """
    if not poses:
        raise BistairError("no calibration poses")
    size = poses[0].white.shape
    for pose in poses:
        for what in ("white", "x", "y"):
            if getattr(pose, what).shape != size:
                raise BistairError(
                    f"{pose.name}: {what} is {getattr(pose, what).shape[1]}x"
                    f"{getattr(pose, what).shape[0]} but {poses[0].name} images are "
                    f"{size[1]}x{size[0]}")
    found = [(pose, board.detect(pose.white)) for pose in poses]
    found = [(pose, pts) for pose, pts in found if pts is not None]
    if len(found) < min_poses:
        raise BistairError(f"board found in {len(found)} of {len(poses)} poses, need at least "
                           f"{min_poses}")
    model = board.object_points()
    obj, cam, proj, names = [], [], [], []
    for pose, pts in found:
        spacing = feature_spacing(pts, board.columns)
        share = 0.35 if board.type == "checkerboard" else 0.5
        radius = int(np.clip(round(share * spacing), 3, 30))
        xy = sample_local(np.stack([pose.x, pose.y]), pts, radius).T
        ok = np.isfinite(xy).all(axis=1)
        if ok.mean() >= min_mapped and ok.sum() >= 6:
            obj.append(model[ok])
            cam.append(pts[ok])
            proj.append(xy[ok])
            names.append(pose.name)
    if len(obj) < min_poses:
        raise BistairError(f"board features mapped to the projector in {len(obj)} of "
                           f"{len(poses)} poses, need at least {min_poses} (are the phases "
                           "valid on the board?)")
    cal = calibrate_points(obj, cam, proj, (size[1], size[0]), projector_size, names,
                           **options)
    return Calibration(cal.camera, cal.projector, cal.R, cal.T, cal.rms, cal.poses,
                       board.to_dict(), len(poses))
