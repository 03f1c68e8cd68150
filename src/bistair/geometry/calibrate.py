"""Calibrating a camera and a projector from board captures (Zhang and Huang, Opt. Eng.
45(8), 083601, 2006).

For every pose of a planar board the board features are found in the camera's white frame
(or, without one, the mean image of the captures); the decoded projector coordinates of both
axes map each feature to projector pixels (a robust local homography of the decoded projector
x and y around the feature, :func:`~bistair.geometry.corners.local_homography`, after Moreno
and Taubin, 3DIMPVT 2012; or a local quadratic fit, :func:`sample_local`); the camera and the
projector are calibrated like two cameras with the same model points
(``cv2.calibrateCamera``) and then as a pair (``cv2.stereoCalibrate``), giving ``R, T`` with
``X_p = R @ X_c + T`` (:class:`~bistair.geometry.calibration.Calibration`). Reprojection
errors are those of the final (stereo) model. Reading the capture folders is
:func:`bistair.app.calibrate.calibrate_folder`.

How many poses: at least :data:`MIN_POSES` = 3. A view of a plane fixes a homography
(8 numbers), 6 of which go to the board's pose, so each view gives 2 constraints on a
device's pinhole intrinsics (Zhang, IEEE TPAMI 22(11), 2000, Sec. 3.1). OpenCV's model has
4 of them (``fx, fy, cx, cy``, no skew): one view leaves the focal length traded against the
board's distance (one pose "calibrated" a 1200 px camera at 26,000 px and a 200 mm baseline
at 13 m), two determine them with nothing to spare, so noise and a bad pose go unseen, and
three are the fewest with redundancy (6 constraints for 4 unknowns; Zhang's condition
``n >= 3`` for a unique solution). The distortion ``(k1, k2, p1, p2)`` is fixed by how the
points bend within each view, and the pair's ``R, T`` by any one pose, so the projector,
calibrated from the same poses, needs no more; three poses also leave the uncertainty
below with residual degrees of freedom to estimate the noise from.

Uncertainty (:class:`~bistair.geometry.calibration.Uncertainty`): the covariance of the
estimate linearised at the solution, ``Cov = M diag(s^2) M^T`` where ``M`` maps the
correspondence errors to the parameter errors (``-(J^T J)^-1 J^T`` for the joint
refinement, ``J`` the Jacobian of all reprojections with respect to both devices'
intrinsics, ``R, T`` and the board poses) and ``s`` is the correspondence noise estimated
from the residuals, separately for the camera and the projector. This is the formula of
``cv2.calibrateCameraExtended``'s ``stdDeviationsIntrinsics`` applied to the stereo model
that gives the result: on noisy synthetic views the true errors of the focal lengths and the
baseline are spread with one of these standard deviations (tests/test_calib.py). The
single-device deviations of ``calibrateCameraExtended`` overstate the joint estimate's
(they ignore that both devices see the same board poses), and a jackknife over poses with
the intrinsics fixed understates the baseline's (its error comes mostly from the
intrinsics). Errors common to all poses (a board printed at the wrong scale, a biased
feature detector, an unmodelled lens) are not in it.

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
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from ..errors import BistairError
from .board import Board
from .calibration import Calibration, Device, Uncertainty
from .corners import local_homography

MIN_POSES = 3  # the fewest board poses that calibrate a pair (see the module's notes)


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

    Returns
    -------
    Calibration
        With the per-pose errors and the :class:`~bistair.geometry.calibration.Uncertainty`
        of every parameter (see the module's notes).

    Raises
    ------
    BistairError
        Fewer than :data:`MIN_POSES` poses, OpenCV failing, or poses that leave some
        parameter undetermined.

    Examples
    --------
    Four exact views of an 8 x 6 board (see the module's example for more):

    >>> from bistair.sim.boards import synthetic_views
    >>> cam = Device(640, 480, [[800.0, 0, 320], [0, 800, 240], [0, 0, 1]])
    >>> proj = Device(800, 600, [[1000.0, 0, 400], [0, 1000, 300], [0, 0, 1]])
    >>> truth = Calibration(cam, proj, cv2.Rodrigues(np.array([0.0, 0.3, 0.0]))[0],
    ...                     [-150.0, 0.0, 45.0])
    >>> views = synthetic_views(truth, Board(columns=8, rows=6, spacing=15), 4,
    ...                         np.random.default_rng(2))
    >>> cal = calibrate_points(*views, (640, 480), (800, 600), names=["a", "b", "c", "d"])
    >>> round(cal.baseline, 2), round(float(cal.camera.K[0, 0]), 2), cal.camera.size
    (156.6, 800.0, (640, 480))
    >>> [(pose["name"], pose["features"]) for pose in cal.poses][:2]
    [('a', 48), ('b', 48)]
    >>> calibrate_points(views[0][:2], views[1][:2], views[2][:2], (640, 480), (800, 600))
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: 2 board poses cannot calibrate a camera and a projector: ...
    """
    if len(object_points) < MIN_POSES:
        raise BistairError(f"{len(object_points)} board poses cannot calibrate a camera and a "
                           f"projector: at least {MIN_POSES} are needed")
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
    cal = Calibration(Device(*camera_size, kc, dc.ravel(), float(np.sqrt(sc.sum() / n.sum()))),
                      Device(*projector_size, kp, dp.ravel(),
                             float(np.sqrt(sp.sum() / n.sum()))),
                      rot, t.ravel(), float(rms), poses)
    sigma = uncertainty(cal, obj, cam, proj, [np.ravel(r) for r in rvecs],
                        [np.ravel(v) for v in tvecs], fix_k3=fix_k3, refine=refine)
    return cal.replace(uncertainty=sigma)


def uncertainty(cal: Calibration, object_points: Sequence[np.ndarray],
                camera_points: Sequence[np.ndarray], projector_points: Sequence[np.ndarray],
                rvecs: Sequence[np.ndarray], tvecs: Sequence[np.ndarray], fix_k3: bool = True,
                refine: bool = True) -> Uncertainty:
    """Standard deviations of a calibration's parameters from its correspondences.

    Parameters
    ----------
    cal : the calibration (``X_p = R @ X_c + T``).
    object_points, camera_points, projector_points : per pose, as for
        :func:`calibrate_points`.
    rvecs, tvecs : per pose, the board's pose in the camera frame (OpenCV vectors).
    fix_k3 : ``k3`` was held at 0.
    refine : all parameters were refined jointly (else each device's intrinsics come from
        its own calibration and ``R, T`` from the pair with them fixed).

    Returns
    -------
    Uncertainty
        One standard deviation of each parameter, linearised at the solution, with the
        correspondence noise estimated from the residuals of each device (see the module's
        notes).

    Raises
    ------
    BistairError
        If the poses leave some parameter undetermined (a singular normal matrix).

    Examples
    --------
    :func:`calibrate_points` calls it:

    >>> from bistair.sim.boards import synthetic_views
    >>> cam = Device(640, 480, [[800.0, 0, 320], [0, 800, 240], [0, 0, 1]])
    >>> proj = Device(800, 600, [[1000.0, 0, 400], [0, 1000, 300], [0, 0, 1]])
    >>> truth = Calibration(cam, proj, cv2.Rodrigues(np.array([0.0, 0.3, 0.0]))[0],
    ...                     [-150.0, 0.0, 45.0])
    >>> views = synthetic_views(truth, Board(columns=8, rows=6, spacing=15), 5,
    ...                         np.random.default_rng(1), noise=0.1)
    >>> cal = calibrate_points(*views, (640, 480), (800, 600))
    >>> sigma = cal.uncertainty
    >>> [0.08 < noise < 0.12 for noise in sigma.noise]  # the noise added, per coordinate
    [True, True]
    >>> bool(abs(cal.baseline - truth.baseline) < 3 * sigma.baseline)
    True
    """
    n_int = 9 if not fix_k3 else 8  # fx, fy, cx, cy, k1, k2, p1, p2[, k3]
    jac, own, res, on_cam = _jacobian(cal, object_points, camera_points, projector_points,
                                      rvecs, tvecs, n_int)
    if refine:
        sens = _least_squares(jac)
    else:  # each device alone, then R, T and the poses with the intrinsics fixed
        cam_cols = np.r_[0:n_int, 2 * n_int + 6:jac.shape[1]]
        alone = np.zeros((2 * n_int, len(res)))
        alone[:n_int, on_cam] = _least_squares(jac[on_cam][:, cam_cols])[:n_int]
        alone[n_int:, ~on_cam] = _least_squares(own)[:n_int]
        rest = _least_squares(jac[:, 2 * n_int:])
        sens = np.vstack([alone, rest + rest @ jac[:, :2 * n_int] @ alone])
    # noise per device: solve for the variances that give the residual sums expected under
    # the residual maker I + J M (its blocks' squared norms, from p x p products)
    rows = (on_cam, ~on_cam)
    normal = [jac[r].T @ jac[r] for r in rows]  # J_d^T J_d
    gram = [np.ascontiguousarray(sens[:, r]) for r in rows]
    gram = [m @ m.T for m in gram]  # M_d M_d^T
    spread = np.array([[np.sum(normal[i] * gram[j]) for j in range(2)] for i in range(2)])
    for i, r in enumerate(rows):
        spread[i, i] += r.sum() + 2 * np.sum(jac[r] * sens[:, r].T)
    sums = np.array([np.sum(res[r] ** 2) for r in rows])
    var = np.linalg.solve(spread, sums)
    var = np.where(var > 0, var, np.maximum(sums / np.diag(spread), 0.0))  # exact data
    cov = var[0] * gram[0] + var[1] * gram[1]
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    devices = [np.append(sd[k * n_int:(k + 1) * n_int], np.zeros(9 - n_int)) for k in (0, 1)]
    base = 2 * n_int
    turn = _rotation_jacobian(cal.R)
    rot_cov = turn @ cov[base:base + 3, base:base + 3] @ turn.T
    t_cov = cov[base + 3:base + 6, base + 3:base + 6]
    direction = cal.T / np.linalg.norm(cal.T)
    return Uncertainty(devices[0], devices[1], np.rad2deg(np.sqrt(np.diag(rot_cov))),
                       np.sqrt(np.diag(t_cov)), float(np.sqrt(direction @ t_cov @ direction)),
                       tuple(float(v) for v in np.sqrt(var)))


def _jacobian(cal: Calibration, object_points: Sequence[np.ndarray],
              camera_points: Sequence[np.ndarray], projector_points: Sequence[np.ndarray],
              rvecs: Sequence[np.ndarray], tvecs: Sequence[np.ndarray], n_int: int
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Jacobian of every reprojection of the stereo model and the residuals.

    Parameters, in order: the camera's ``n_int`` intrinsics (``fx, fy, cx, cy, k1, ...``),
    the projector's, the rotation vector of ``R``, ``T``, then per pose the board's rotation
    and translation vectors in the camera frame. Returns the Jacobian (rows: every camera
    coordinate, then every projector coordinate), the projector rows' Jacobian with respect
    to the projector's intrinsics and its own per-pose board poses (the projector calibrated
    alone), the residuals and which rows are the camera's.
    """
    n_poses = len(object_points)
    width = 2 * n_int + 6 + 6 * n_poses
    rvec = cv2.Rodrigues(cal.R)[0]
    tvec = cal.T.reshape(3, 1)
    cam_rows, proj_rows, own_rows, cam_res, proj_res = [], [], [], [], []
    for i, (obj, c, p, rv, tv) in enumerate(zip(object_points, camera_points, projector_points,
                                                rvecs, tvecs, strict=True)):
        obj = np.asarray(obj, float).reshape(-1, 3)
        pose = slice(2 * n_int + 6 + 6 * i, 2 * n_int + 12 + 6 * i)
        rv, tv = np.asarray(rv, float).reshape(3, 1), np.asarray(tv, float).reshape(3, 1)
        pc, jc = cv2.projectPoints(obj, rv, tv, cal.camera.K, cal.camera.dist)
        rows = np.zeros((len(jc), width))
        rows[:, :n_int] = jc[:, 6:6 + n_int]
        rows[:, pose] = jc[:, :6]
        cam_rows.append(rows)
        cam_res.append(pc.reshape(-1) - np.asarray(c, float).reshape(-1))
        # projector pose: R_p = R @ R_c, t_p = R @ t_c + T
        rp, tp, dr_drc, _, dr_dr, _, dt_drc, dt_dtc, dt_dr, dt_dt = cv2.composeRT(rv, tv, rvec,
                                                                                   tvec)
        pp, jp = cv2.projectPoints(obj, rp, tp, cal.projector.K, cal.projector.dist)
        jr, jt = jp[:, :3], jp[:, 3:6]
        rows = np.zeros((len(jp), width))
        rows[:, n_int:2 * n_int] = jp[:, 6:6 + n_int]
        rows[:, 2 * n_int:2 * n_int + 3] = jr @ dr_dr + jt @ dt_dr
        rows[:, 2 * n_int + 3:2 * n_int + 6] = jt @ dt_dt
        rows[:, pose] = np.hstack([jr @ dr_drc + jt @ dt_drc, jt @ dt_dtc])
        proj_rows.append(rows)
        own = np.zeros((len(jp), n_int + 6 * n_poses))
        own[:, :n_int] = jp[:, 6:6 + n_int]
        own[:, n_int + 6 * i:n_int + 6 * i + 6] = jp[:, :6]
        own_rows.append(own)
        proj_res.append(pp.reshape(-1) - np.asarray(p, float).reshape(-1))
    jac = np.vstack(cam_rows + proj_rows)
    res = np.concatenate(cam_res + proj_res)
    on_cam = np.arange(len(res)) < sum(len(r) for r in cam_res)
    return jac, np.vstack(own_rows), res, on_cam


def _least_squares(jac: np.ndarray) -> np.ndarray:
    """``-(J^T J)^-1 J^T``: how a least-squares fit's parameters follow its data's errors.

    Raises :class:`BistairError` if some parameter is not determined."""
    scale = np.linalg.norm(jac, axis=0)
    if not (scale > 0).all():
        raise BistairError("the board poses leave some calibration parameter undetermined")
    scaled = jac / scale
    normal = scaled.T @ scaled
    if np.linalg.cond(normal) > 1e13:
        raise BistairError("the board poses leave the calibration undetermined: tilt the board "
                           "differently in each pose and cover the image corners")
    return -np.linalg.solve(normal, scaled.T) / scale[:, None]


def _rotation_jacobian(rot: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """How the rotation error ``w`` (``R_true = exp([w]x) @ R``) follows the rotation vector
    of ``R`` (central differences; ``w`` read from the skew part of the small turn)."""
    base = cv2.Rodrigues(rot)[0].ravel()
    out = np.empty((3, 3))
    for k in range(3):
        turn = [cv2.Rodrigues(base + sign * step * np.eye(3)[k])[0] @ rot.T for sign in (1, -1)]
        diff = (turn[0] - turn[1]) / (2 * step)
        out[:, k] = 0.5 * np.array([diff[2, 1] - diff[1, 2], diff[0, 2] - diff[2, 0],
                                    diff[1, 0] - diff[0, 1]])
    return out


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
    """One board pose in memory: the camera image the board is found in (``white``: the
    white frame, or without one the mean image of the captures) and the projector column
    ``x`` and row ``y`` decoded per camera pixel (NaN where invalid)."""

    name: str
    white: np.ndarray
    x: np.ndarray
    y: np.ndarray


@dataclass(frozen=True)
class BoardView:
    """The board in one pose: its features found in the camera and mapped to the projector.

    ``features`` is the board's number of features; ``object_points`` ``(n, 3)`` (mm),
    ``camera_points`` and ``projector_points`` ``(n, 2)`` (pixels) hold the ``n`` of them
    mapped (none when the board is not ``found``); ``usable`` when enough are (see
    :func:`board_view`); ``why`` says why not."""

    name: str
    found: bool
    features: int
    object_points: np.ndarray
    camera_points: np.ndarray
    projector_points: np.ndarray
    needed: int = 6

    @property
    def usable(self) -> bool:
        """The board was found and at least ``needed`` features were mapped."""
        return self.found and len(self.object_points) >= self.needed

    @property
    def why(self) -> str:
        """Why the view is not usable (empty when it is)."""
        if not self.found:
            return "board not found"
        if not self.usable:
            return (f"{len(self.object_points)} of {self.features} board features mapped to "
                    f"the projector, need {self.needed} (are the phases valid on the board?)")
        return ""


CORNER_FITS = ("homography", "quadratic")  # how a feature is mapped to the projector


def feature_spacing(points: np.ndarray, columns: int) -> float:
    """Median image distance between neighbouring features of a row-by-row grid (pixels).

    Parameters
    ----------
    points : numpy.ndarray
        ``(columns * rows, 2)`` image points ``(u, v)`` in pixels, row by row (as
        :meth:`Board.detect <bistair.geometry.board.Board.detect>` returns them).
    columns : int
        Features per row.

    Returns
    -------
    float
        The median length (pixels) of the steps to the next feature along the rows and
        down the columns.

    Examples
    --------
    >>> u, v = np.meshgrid(np.arange(4) * 12.0, np.arange(3) * 10.0)
    >>> feature_spacing(np.stack([u.ravel(), v.ravel()], axis=1), 4)
    12.0
    """
    grid = np.asarray(points, float).reshape(-1, columns, 2)
    steps = np.concatenate([np.diff(grid, axis=1).reshape(-1, 2),
                            np.diff(grid, axis=0).reshape(-1, 2)])
    return float(np.median(np.hypot(steps[:, 0], steps[:, 1])))


def board_view(pose: PoseCapture, board: Board, corner_fit: str = "homography",
               min_mapped: float = 0.5) -> BoardView:
    """Find the board in a pose and map its features to the projector.

    The board is detected in ``pose.white``; each feature's projector ``x`` and ``y`` come
    from the decoded maps in a window around it: a local homography
    (:func:`~bistair.geometry.corners.local_homography`, Moreno and Taubin) or a quadratic
    fit (:func:`sample_local`). The window is ``0.7`` (checkerboards) or one (circle grids)
    feature spacing wide, at least 7 and at most 61 pixels.

    Parameters
    ----------
    pose : PoseCapture
        The board image and the decoded projector coordinates.
    board : Board
        The board it shows.
    corner_fit : {"homography", "quadratic"}
        How a feature is mapped (:data:`CORNER_FITS`).
    min_mapped : float, default 0.5
        The view is usable when at least this share of the features (and at least 6) are
        mapped.

    Returns
    -------
    BoardView

    Raises
    ------
    BistairError
        An unknown ``corner_fit``.

    Examples
    --------
    >>> blank = np.ones((60, 80))
    >>> view = board_view(PoseCapture("pose-0", blank, blank, blank), Board())
    >>> view.found, view.usable, view.why
    (False, False, 'board not found')
    """
    if corner_fit not in CORNER_FITS:
        raise BistairError(f"corner fit must be one of {', '.join(CORNER_FITS)}, got "
                           f"{corner_fit!r}")
    model = board.object_points()
    needed = max(6, int(np.ceil(min_mapped * len(model))))
    pts = board.detect(pose.white)
    if pts is None:
        none = np.empty((0, 2))
        return BoardView(pose.name, False, len(model), np.empty((0, 3), np.float32), none,
                         none, needed)
    share = 0.35 if board.type == "checkerboard" else 0.5
    radius = int(np.clip(round(share * feature_spacing(pts, board.columns)), 3, 30))
    fit = local_homography if corner_fit == "homography" else sample_local
    xy = fit(np.stack([pose.x, pose.y]), pts, radius).T
    ok = np.isfinite(xy).all(axis=1)
    return BoardView(pose.name, True, len(model), model[ok], pts[ok], xy[ok], needed)


def calibrate_views(views: Sequence[BoardView], board: Board, camera_size: tuple[int, int],
                    projector_size: tuple[int, int], min_poses: int = MIN_POSES,
                    poses_total: int | None = None, **options: Any) -> Calibration:
    """Calibrate from the usable views of the board (:func:`calibrate_points`; ``options``
    go there).

    Parameters
    ----------
    views : sequence of BoardView
        Every pose's view (:func:`board_view`), usable or not.
    board : Board
        The board, recorded in the calibration.
    camera_size, projector_size : tuple of int
        ``(width, height)``.
    min_poses : int
        The fewest usable views to calibrate from (at least :data:`MIN_POSES`).
    poses_total : int, optional
        How many poses there were in all, counting those without a view (default: the
        views).

    Returns
    -------
    Calibration
        With the board and the number of poses.

    Raises
    ------
    BistairError
        ``min_poses`` below :data:`MIN_POSES`, the board found in fewer than ``min_poses``
        poses, fewer than ``min_poses`` usable views, or a failed calibration.

    Examples
    --------
    >>> none = np.empty((0, 2))
    >>> lost = BoardView("p0", False, 54, np.empty((0, 3)), none, none)
    >>> calibrate_views([lost], Board(), (640, 480), (800, 600), poses_total=4)
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: board found in 0 of 4 poses, need at least 3
    """
    check_min_poses(min_poses)
    total = len(views) if poses_total is None else poses_total
    found = sum(view.found for view in views)
    if found < min_poses:
        raise BistairError(f"board found in {found} of {total} poses, need at least "
                           f"{min_poses}")
    used = [view for view in views if view.usable]
    if len(used) < min_poses:
        raise BistairError(f"board features mapped to the projector in {len(used)} of "
                           f"{total} poses, need at least {min_poses} (are the phases "
                           "valid on the board?)")
    cal = calibrate_points([v.object_points for v in used], [v.camera_points for v in used],
                           [v.projector_points for v in used], camera_size, projector_size,
                           [v.name for v in used], **options)
    return cal.replace(board=board.to_dict(), poses_total=total)


def calibrate_poses(poses: Sequence[PoseCapture], board: Board,
                    projector_size: tuple[int, int], min_poses: int = MIN_POSES,
                    min_mapped: float = 0.5, corner_fit: str = "homography",
                    skipped: Callable[[str, str], None] | None = None,
                    **options: Any) -> Calibration:
    """Detect the board, map its features through the phases and calibrate
    (:func:`board_view`, :func:`calibrate_views`; ``options`` go to
    :func:`calibrate_points`).

    Parameters
    ----------
    poses : the captures of every pose.
    board : the board they show.
    projector_size : ``(width, height)``.
    min_poses : the fewest usable poses to calibrate from (at least :data:`MIN_POSES`).
    min_mapped : a pose is used when the board is found in its board image and at least
        this share of its features get projector coordinates in both orientations.
    corner_fit : how a feature is mapped to the projector (:func:`board_view`).
    skipped : called with the name of each pose left out and why.

    Returns
    -------
    Calibration
        With the board and the number of poses given.

    Raises
    ------
    BistairError
        ``min_poses`` below :data:`MIN_POSES`, images of different sizes, fewer than
        ``min_poses`` poses with the board found and mapped, or a failed calibration.

    Examples
    --------
    Poses whose white frames do not show the board are refused (``tests/test_calib.py``
    calibrates from rendered board captures):

    >>> blank = np.ones((60, 80))
    >>> poses = [PoseCapture(f"pose-{i}", blank, blank, blank) for i in range(3)]
    >>> calibrate_poses(poses, Board(), (800, 600))
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: board found in 0 of 3 poses, need at least 3
    """
    check_min_poses(min_poses)
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
    views = [board_view(pose, board, corner_fit, min_mapped) for pose in poses]
    for view in views:
        if not view.usable and skipped is not None:
            skipped(view.name, view.why)
    return calibrate_views(views, board, (size[1], size[0]), projector_size, min_poses,
                           **options)


def check_min_poses(min_poses: int) -> None:
    """Refuse a pose minimum below :data:`MIN_POSES`.

    Parameters
    ----------
    min_poses : int
        The fewest usable board poses asked for (a Python or NumPy integer, not ``bool``).

    Raises
    ------
    BistairError
        If ``min_poses`` is not a whole number or is below :data:`MIN_POSES`.

    Examples
    --------
    >>> check_min_poses(3)
    >>> check_min_poses(1)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: min_poses 1 is too few: a camera-projector calibration ...
    """
    if isinstance(min_poses, bool) or not isinstance(min_poses, int | np.integer):
        raise BistairError(f"min_poses must be a whole number, got {min_poses!r}")
    if min_poses < MIN_POSES:
        raise BistairError(f"min_poses {min_poses} is too few: a camera-projector calibration "
                           f"needs at least {MIN_POSES} board poses")
