"""Calibrating a rig from views of a board: a camera and a projector from board captures
(Zhang and Huang, Opt. Eng. 45(8), 083601, 2006), or two cameras from image pairs.

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

**Two cameras** (:func:`calibrate_stereo_images`, ``bistair calibrate-stereo``): the board's
corners are found in each image (OpenCV ``findChessboardCornersSB``, else
``findChessboardCorners`` + ``cornerSubPix``; circle grids with ``findCirclesGrid``:
:meth:`~bistair.geometry.board.Board.detect`); a pose whose board is not found in both
images is skipped. :func:`calibrate_points` calibrates the pair as it does a camera and a
projector (any two devices that see the same board points), with one standard deviation of
each parameter, and the result is read as two cameras
(:class:`~bistair.geometry.calibration.StereoCalibration`). A chessboard's corners come back
from OpenCV starting at either end of the board; both images of a pose are put in the same
order (the first corner the one nearer the image's top-left), which is the same corner of
the board for two cameras side by side.

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
>>> pts = Board("checkerboard", 4, 3, 10.0).object_points()[:, :2] * 3 + 50  # upright
>>> bool(np.array_equal(_upright(pts[::-1]), pts))
True
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import cv2
import numpy as np

from ..errors import BistairError
from .board import Board
from .calibration import (
    MIN_BASELINE,
    Calibration,
    Device,
    StereoCalibration,
    Uncertainty,
    on_the_left,
)
from .corners import (  # noqa: F401  (sample_local, feature_spacing: here until a release)
    CORNER_FITS,
    BoardView,
    PoseCapture,
    board_view,
    feature_spacing,
    sample_local,
)

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


def calibrate_stereo_images(left: Sequence[np.ndarray], right: Sequence[np.ndarray],
                            board: Board, names: Sequence[str] | None = None,
                            min_poses: int = MIN_POSES, fix_k3: bool = True
                            ) -> tuple[StereoCalibration, list[str]]:
    """Calibrate two cameras from grey images of a board, pose by pose.

    Parameters
    ----------
    left, right : sequence of numpy.ndarray
        Per pose, the left and the right camera's grey image (2-D, any dtype; every left
        image of one size, every right image of one size).
    board : Board
        The board (``columns x rows`` inner corners or circles, spacing in mm).
    names : sequence of str, optional
        The poses' names (for the per-pose errors and the skipped poses).
    min_poses : int, optional
        The fewest poses with the board found in both images (3 at least).
    fix_k3 : bool, optional
        Keep ``k3 = 0``.

    Returns
    -------
    calibration : StereoCalibration
        With the stereo RMS, the per-pose errors (``left_rms``, ``right_rms``), the board,
        the number of poses given and the uncertainty of every parameter.
    skipped : list of str
        The poses whose board was not found in both images.

    Raises
    ------
    BistairError
        Different numbers of left and right images, images of different sizes or not 2-D,
        the board found in both images of fewer than ``min_poses`` poses, OpenCV failing, the
        camera of the right images on the left of the other (images named the wrong way
        round) or the cameras under 1 mm apart (a board's square not in millimetres).

    Examples
    --------
    Blank images show no board (``tests/test_stereo_calibrate.py`` calibrates from rendered
    board pairs):

    >>> blank = [np.ones((60, 80))] * 3
    >>> calibrate_stereo_images(blank, blank, Board())
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: board found in both images of 0 of 3 poses, need at least 3
    """
    if len(left) != len(right):
        raise BistairError(f"{len(left)} left and {len(right)} right images: they go in pairs")
    if min_poses < MIN_POSES:
        raise BistairError(f"min_poses {min_poses} is too few: a stereo calibration needs at "
                           f"least {MIN_POSES} board poses")
    names = list(names) if names is not None else [f"pose-{i:02d}" for i in range(len(left))]
    sizes = {}
    for side, images in (("left", left), ("right", right)):
        for name, img in zip(names, images, strict=True):
            if np.ndim(img) != 2:
                raise BistairError(f"{name}: the {side} image must be grey (2-D), got shape "
                                   f"{np.shape(img)}")
            h, w = np.shape(img)
            first = sizes.setdefault(side, (w, h, name))
            if (w, h) != first[:2]:
                raise BistairError(f"{name}: the {side} image is {w}x{h}, the {side} image of "
                                   f"{first[2]} {first[0]}x{first[1]}")
    obj, lpts, rpts, used, skipped = [], [], [], [], []
    for name, li, ri in zip(names, left, right, strict=True):
        a, b = board.detect(li), board.detect(ri)
        if a is None or b is None:
            skipped.append(name)
            continue
        if board.type != "asymmetric-circles":  # its corners come in one order only
            a, b = _upright(a), _upright(b)
        obj.append(board.object_points())
        lpts.append(a)
        rpts.append(b)
        used.append(name)
    if len(used) < min_poses:
        raise BistairError(f"board found in both images of {len(used)} of {len(names)} poses, "
                           f"need at least {min_poses}")
    pair = calibrate_points(obj, lpts, rpts, sizes["left"][:2], sizes["right"][:2], used,
                            fix_k3=fix_k3)
    left_of = on_the_left(pair.R, pair.T)
    if left_of > 0:
        raise BistairError(f"the camera of the right images sits {left_of:.1f} mm to the left "
                           "of the other (the right camera is the one at +x of the left, to "
                           "the right in its image): are the board images named the wrong way "
                           "round? Exchange left and right")
    if pair.baseline < MIN_BASELINE:
        raise BistairError(f"the cameras come out {pair.baseline:.3g} mm apart: is the "
                           f"board's square size ({board.spacing:g}) in millimetres?")
    cal = StereoCalibration.from_pair(pair)
    return cal.replace(board=board.to_dict(), poses_total=len(names)), skipped


def _upright(points: np.ndarray) -> np.ndarray:
    """Detected board points in the order that starts at the end nearer the image's
    top-left (the list reversed otherwise: the same grid turned by 180 degrees)."""
    first, last = points[0], points[-1]
    return points[::-1].copy() if first.sum() > last.sum() else points
