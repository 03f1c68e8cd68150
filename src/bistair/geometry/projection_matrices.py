"""A rig of two cameras and a projector given as three 3x4 projection matrices.

Each matrix ``P`` maps a world point to its pixel, ``s * (u, v, 1) = P @ (X, Y, Z, 1)``, all
three in the same world frame. :func:`decompose` splits it into ``P = K [R | t]`` (an RQ
decomposition: positive focal lengths, a proper rotation, ``X_device = R X_world + t``);
:func:`rig_from_matrices` puts the three in the left camera's frame, without distortion.

Files (:func:`read_matrix`): ``.npy``, text (``.txt``, ``.csv``, ...: three rows of four
numbers separated by spaces or commas, ``#`` comments) or MATLAB ``.mat`` holding exactly
one 3x4 numeric array.

Pixel origin. bistair's pixel ``[v, u]`` (0-based array index) is the camera coordinate
``(u, v)``, OpenCV's convention. MATLAB's grid (``meshgrid(1:W, 1:H)``) calls it
``(u + 1, v + 1)``: a matrix made there, read 0-based, puts every camera pixel one pixel
off (about 4 mm of depth on the virtual rig at 600 mm). ``pixel_origin`` 1 moves the cameras'
principal points by -1 (:func:`with_pixel_origin`), so that nothing downstream changes; the
default is 1 for ``.mat`` files, 0 otherwise (:func:`default_origin`). The projector's
column is not moved: it is the pattern's column, which the phase (``2*pi*x_p/T``) and the
spec's ``phase_offset`` define. The calibration file records the origin
(``"pixel_origin"``, :func:`save_matrix_calibration`).

Examples
--------
>>> K = np.array([[1000.0, 0, 320], [0, 1000, 240], [0, 0, 1]])
>>> k, r, t = decompose(-3 * K @ np.hstack([np.eye(3), [[-100.0], [0], [0]]]))
>>> k.round(6).tolist() == K.tolist(), np.allclose(r, np.eye(3)), t.round(6).tolist()
(True, True, [-100.0, 0.0, 0.0])
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import BistairError
from ..io.atomic import output_file
from .calibration import Device, ProjectorPose, StereoCalibration

#: The pixel origins a camera's matrix may use: 0 (OpenCV, bistair) or 1 (MATLAB).
PIXEL_ORIGINS = (0, 1)


def read_matrix(path: str | Path) -> np.ndarray:
    """The one 3x4 projection matrix of a ``.npy``, ``.mat`` or text file (float64).

    Parameters
    ----------
    path : str or pathlib.Path
        The file: ``.npy``, ``.mat`` (exactly one 3x4 numeric array) or any other suffix
        read as text (three rows of four numbers, spaces or commas, ``#`` comments).

    Returns
    -------
    numpy.ndarray
        ``(3, 4)`` float64, finite: ``s * (u, v, 1) = P @ (X, Y, Z, 1)`` (pixels, world
        units).

    Raises
    ------
    BistairError
        A missing or unreadable file, not a 3x4 finite matrix, or a ``.mat`` with no or
        several 3x4 arrays; the message names the file.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "P.txt"
    >>> _ = path.write_text("1, 0, 0, 5\\n0 1 0 0\\n0 0 1 0\\n")
    >>> read_matrix(path)[0].tolist()
    [1.0, 0.0, 0.0, 5.0]
    """
    path = Path(path)
    if not path.is_file():
        raise BistairError(f"projection matrix {path}: no such file")
    suffix = path.suffix.lower()
    try:
        if suffix == ".npy":
            arr = np.load(path, allow_pickle=False)
        elif suffix == ".mat":
            arr = _from_mat(path)
        else:
            lines = [line.split("#")[0].replace(",", " ").split()
                     for line in path.read_text().splitlines()]
            arr = np.array([[float(v) for v in line] for line in lines if line])
    except BistairError:
        raise
    except (OSError, ValueError, UnicodeDecodeError, NotImplementedError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise BistairError(f"projection matrix {path}: cannot be read ({reason})") from None
    arr = np.asarray(arr)
    if arr.shape != (3, 4) or not np.issubdtype(arr.dtype, np.number):
        raise BistairError(f"projection matrix {path}: a 3x4 matrix is needed, got "
                           f"{'x'.join(map(str, arr.shape)) or 'a scalar'}")
    arr = arr.astype(np.float64)
    if not np.isfinite(arr).all():
        raise BistairError(f"projection matrix {path}: has values that are not finite")
    return arr


def _from_mat(path: Path) -> np.ndarray:
    """The one 3x4 numeric array of a MATLAB file."""
    from scipy.io import loadmat

    try:
        data = loadmat(str(path))
    except (ValueError, TypeError) as exc:
        raise ValueError(f"not a MATLAB file: {exc}") from None
    found = {k: v for k, v in data.items() if not k.startswith("__")
             and isinstance(v, np.ndarray) and v.shape == (3, 4)
             and np.issubdtype(v.dtype, np.number)}
    if len(found) != 1:
        names = ", ".join(sorted(found)) or "none"
        raise BistairError(f"projection matrix {path}: a .mat file must hold exactly one 3x4 "
                           f"array, it holds {len(found)} ({names})")
    return next(iter(found.values()))


def decompose(P: np.ndarray, name: str = "projection matrix"
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``P = K [R | t]`` up to scale: ``K`` upper triangular with ``K[2, 2] = 1`` and
    positive focal lengths, ``R`` a proper rotation, ``X_device = R X_world + t``.

    Parameters
    ----------
    P : numpy.ndarray
        A 3x4 projection matrix (any overall scale and sign; 12 numbers reshaped to 3x4).
    name : str, optional
        What the error messages call the matrix.

    Returns
    -------
    K : numpy.ndarray
        ``(3, 3)`` intrinsics (pixels), ``K[2, 2] = 1``, positive diagonal.
    R : numpy.ndarray
        ``(3, 3)`` rotation (``det R = +1``), world frame to the device's.
    t : numpy.ndarray
        ``(3,)`` translation (world units): the world origin in the device's frame.

    Raises
    ------
    BistairError
        A matrix of rank under 3, or whose left 3x3 block is singular (no pinhole device).

    Examples
    --------
    >>> K = np.array([[1000.0, 0, 320], [0, 1000, 240], [0, 0, 1]])
    >>> k, r, t = decompose(-3 * K @ np.hstack([np.eye(3), [[-100.0], [0], [0]]]))
    >>> k.round(6).tolist() == K.tolist(), np.allclose(r, np.eye(3)), t.round(6).tolist()
    (True, True, [-100.0, 0.0, 0.0])
    >>> decompose(np.zeros((3, 4)), "LEFT projection matrix")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: LEFT projection matrix has rank 0 (a projection matrix has rank 3)
    """
    P = np.asarray(P, np.float64).reshape(3, 4)
    if np.linalg.matrix_rank(P) < 3:
        raise BistairError(f"{name} has rank {np.linalg.matrix_rank(P)} (a projection "
                           "matrix has rank 3)")
    M = P[:, :3]
    if abs(np.linalg.det(M)) <= 1e-12 * np.linalg.norm(M) ** 3:
        raise BistairError(f"{name}: its left 3x3 block is singular (a camera at infinity, "
                           "not a pinhole device)")
    if np.linalg.det(M) < 0:  # the overall sign of P is free: take the one with det > 0
        P, M = -P, -M
    # RQ of M from the QR of its rows reversed
    flip = np.eye(3)[::-1]
    q, r = np.linalg.qr((flip @ M).T)
    K, R = flip @ r.T @ flip, flip @ q.T
    signs = np.diag(np.sign(np.diag(K)))
    K, R = K @ signs, signs @ R
    t = np.linalg.solve(K, P[:, 3])
    if np.linalg.det(R) < 0:  # cannot happen with det M > 0 and K's diagonal positive
        raise BistairError(f"{name} gives an improper rotation")
    return K / K[2, 2], R, t


def with_pixel_origin(calibration: StereoCalibration, shift: float) -> StereoCalibration:
    """The calibration with both cameras' principal points moved by ``-shift`` pixels (the
    projector's kept): a camera model of pixel origin ``o`` read as one of origin
    ``o - shift``.

    Parameters
    ----------
    calibration : StereoCalibration
        The cameras (and the projector).
    shift : float
        What to subtract from each camera's ``cx`` and ``cy`` (pixels): 1 turns a MATLAB
        (1-based) camera model into bistair's 0-based one.

    Returns
    -------
    StereoCalibration
        A copy; ``shift`` 0 returns ``calibration`` itself. A recorded ``pixel_origin``
        (the origin its file was read with) moves with it: the model read from origin
        ``o`` is the one read from origin ``o + shift``.

    Examples
    --------
    >>> K = np.array([[1000.0, 0, 320.5], [0, 1000, 240.5], [0, 0, 1]])
    >>> cal = StereoCalibration(Device(640, 480, K), Device(640, 480, K), np.eye(3),
    ...                         [-200.0, 0, 0])
    >>> moved = with_pixel_origin(cal, 1)
    >>> moved.left.K[:2, 2].tolist(), moved.right.K[:2, 2].tolist()
    ([319.5, 239.5], [319.5, 239.5])
    >>> with_pixel_origin(cal.replace(pixel_origin=1), -1).pixel_origin  # read as 0-based
    0
    """
    if shift == 0:
        return calibration

    def moved(dev: Device) -> Device:
        K = dev.K.copy()
        K[0, 2] -= shift
        K[1, 2] -= shift
        return dataclasses.replace(dev, K=K)

    read = calibration.pixel_origin  # the origin the file was read with, if recorded
    read = None if read is None or read + shift not in (0, 1) else int(read + shift)
    return calibration.replace(left=moved(calibration.left), right=moved(calibration.right),
                               pixel_origin=read)


def registration(calibration: StereoCalibration, left: np.ndarray, right: np.ndarray,
                 column: np.ndarray, shift: float = 0.0) -> float:
    """How well two cameras' matched pixels and the projector agree: the median of the
    projector column of each pair's triangulated point minus the column its absolute phase
    gives (projector pixels), with the cameras' principal points moved by ``-shift``
    (:func:`with_pixel_origin`). A wrong pixel origin moves every point sideways by about a
    camera pixel's width: the median moves by about the ratio of the focal lengths.

    Parameters
    ----------
    calibration : StereoCalibration
        The cameras and the projector.
    left, right : numpy.ndarray
        ``(N, 2)`` matched pixels ``(u, v)`` of the left and right camera (0-based).
    column : numpy.ndarray
        ``(N,)`` the projector column of each match's absolute phase.
    shift : float, optional
        The principal points' move (pixels): 0 for the calibration as it is, +-1 for the
        other pixel origin.

    Returns
    -------
    float
        The median residual (projector pixels), NaN without matches.

    Examples
    --------
    >>> K = np.array([[1000.0, 0, 319.5], [0, 1000, 239.5], [0, 0, 1]])
    >>> P = [K @ np.hstack([np.eye(3), [[x], [0], [0]]]) for x in (50.0, -150.0, -50.0)]
    >>> cal = rig_from_matrices(P, (640, 480), (640, 480))
    >>> X = np.array([[10.0, 5.0, 500.0], [-30.0, 0.0, 600.0]])  # left camera frame
    >>> pix = [(k @ (X + [x, 0, 0]).T).T for k, x in ((K, 0.0), (K, -200.0), (K, -100.0))]
    >>> l, r, p = (q[:, :2] / q[:, 2:] for q in pix)
    >>> round(registration(cal, l, r, p[:, 0]), 6)
    0.0
    >>> round(registration(cal, l, r, p[:, 0], shift=-1.0), 3)  # 1-based read as 0-based
    -1.0
    """
    import cv2

    if not len(column):
        return math.nan
    cal = with_pixel_origin(calibration, shift)
    rays = [cv2.undistortPoints(np.asarray(px, np.float64).reshape(-1, 1, 2), dev.K,
                                dev.dist).reshape(-1, 2)
            for px, dev in ((left, cal.left), (right, cal.right))]
    points = cv2.triangulatePoints(np.hstack([np.eye(3), np.zeros((3, 1))]),
                                   np.hstack([cal.R, cal.T[:, None]]), rays[0].T, rays[1].T)
    points = (points[:3] / points[3]).T
    u = cal.projector.project(points)[:, 0]
    return float(np.median(u - np.asarray(column, np.float64)))


def default_origin(files: Sequence[str | Path]) -> int:
    """The cameras' pixel origin when none is given: 1 when the camera matrices (the first
    two files) are MATLAB ``.mat`` files, 0 otherwise.

    Parameters
    ----------
    files : sequence of str or pathlib.Path
        The left camera's, the right camera's (and the projector's) matrix files.

    Returns
    -------
    int
        0 or 1.

    Raises
    ------
    BistairError
        One camera's file a ``.mat`` and the other's not: the origin must be given.

    Examples
    --------
    >>> default_origin(["mCamera1Rectified.mat", "mCamera2Rectified.mat", "mProjector.mat"])
    1
    >>> default_origin(["left.npy", "right.txt", "projector.npy"])
    0
    """
    mat = [Path(f).suffix.lower() == ".mat" for f in list(files)[:2]]
    if len(set(mat)) > 1:
        raise BistairError("one camera's matrix is a .mat file and the other's not: give "
                           "--pixel-origin 0 (OpenCV) or 1 (MATLAB)")
    return int(all(mat))


def recorded_origin(data: Mapping[str, Any]) -> int:
    """The cameras' pixel origin a calibration file's dictionary records (0 when it records
    none: bistair's own calibrations are 0-based).

    Parameters
    ----------
    data : Mapping
        A stereo calibration file's content.

    Returns
    -------
    int
        0 or 1: the origin of the matrices it was made from (its ``K`` are 0-based).

    Raises
    ------
    BistairError
        A ``pixel_origin`` that is not 0 or 1.

    Examples
    --------
    >>> recorded_origin({"pixel_origin": 1}), recorded_origin({})
    (1, 0)
    """
    origin = data.get("pixel_origin", 0)
    if origin not in PIXEL_ORIGINS:
        raise BistairError(f"calibration field 'pixel_origin' must be 0 or 1, got {origin!r}")
    return int(origin)


def save_matrix_calibration(calibration: StereoCalibration, pixel_origin: int,
                            path: str | Path) -> Path:
    """Write a stereo calibration file (atomically) that records the pixel origin of the
    matrices it came from (``"pixel_origin"``; its ``K`` are 0-based either way).

    Parameters
    ----------
    calibration : StereoCalibration
        What to save (:func:`import_matrices`).
    pixel_origin : int
        0 or 1.
    path : str or pathlib.Path
        The JSON file.

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> K = np.array([[1000.0, 0, 319.5], [0, 1000, 239.5], [0, 0, 1]])
    >>> P = [K @ np.hstack([np.eye(3), [[x], [0], [0]]]) for x in (50.0, -150.0, -50.0)]
    >>> path = save_matrix_calibration(rig_from_matrices(P, (640, 480), (640, 480)), 1,
    ...                                tmp / "rig.json")
    >>> json.loads(path.read_text())["pixel_origin"]
    1
    >>> shutil.rmtree(tmp)
    """
    path = Path(path)
    with output_file(path) as tmp:
        tmp.write_text(json.dumps({**calibration.to_dict(), "pixel_origin": int(pixel_origin)},
                                  indent=2) + "\n")
    return path


def rig_from_matrices(matrices: tuple[np.ndarray, np.ndarray, np.ndarray],
                      camera_size: tuple[int, int], projector_size: tuple[int, int],
                      names: tuple[str, str, str] = ("LEFT", "RIGHT", "PROJECTOR"),
                      pixel_origin: int = 0) -> StereoCalibration:
    """The two-camera-and-projector calibration of three projection matrices of one world
    frame, in the left camera's frame (no distortion).

    Parameters
    ----------
    matrices : tuple of numpy.ndarray
        The left camera's, the right camera's and the projector's 3x4 matrices, one world
        frame (:func:`decompose` of each).
    camera_size, projector_size : tuple of int
        ``(width, height)`` in pixels of each camera and of the projector.
    names : tuple of str, optional
        What the error messages call the three matrices.
    pixel_origin : int, optional
        The cameras' pixel origin in the matrices: 0 (OpenCV) or 1 (MATLAB; moved to 0 by
        :func:`with_pixel_origin`).

    Returns
    -------
    StereoCalibration
        The cameras' intrinsics, the right camera's ``R, T`` (``X_right = R X_left + T``,
        world units) and the ``projector`` pose the same way, all without distortion; its
        ``pixel_origin`` records ``pixel_origin`` (``stereo`` checks it against the data).

    Raises
    ------
    BistairError
        What :func:`decompose` refuses, naming the matrix.

    Examples
    --------
    >>> K = np.array([[1000.0, 0, 319.5], [0, 1000, 239.5], [0, 0, 1]])
    >>> P = [K @ np.hstack([np.eye(3), [[x], [0], [0]]]) for x in (50.0, -150.0, -50.0)]
    >>> cal = rig_from_matrices(P, (640, 480), (640, 480))
    >>> cal.T.round(6).tolist(), cal.projector.T.round(6).tolist()
    ([-200.0, 0.0, 0.0], [-100.0, 0.0, 0.0])
    >>> rig_from_matrices(P, (640, 480), (640, 480), pixel_origin=1).left.K[:2, 2].tolist()
    [318.5, 238.5]
    >>> rig_from_matrices(P, (640, 480), (640, 480), pixel_origin=1).pixel_origin  # recorded
    1
    """
    if pixel_origin not in PIXEL_ORIGINS:
        raise BistairError(f"the pixel origin must be 0 (OpenCV) or 1 (MATLAB), got "
                           f"{pixel_origin!r}")
    parts = [decompose(P, f"{n} projection matrix") for P, n in zip(matrices, names,
                                                                    strict=True)]
    (kl, rl, tl), (kr, rr, tr), (kp, rp, tp) = parts

    def relative(r: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        rot = r @ rl.T
        return rot, t - rot @ tl

    (cw, ch), (pw, ph) = camera_size, projector_size
    R, T = relative(rr, tr)
    Rp, Tp = relative(rp, tp)
    cal = StereoCalibration(Device(cw, ch, kl), Device(cw, ch, kr), R, T,
                            projector=ProjectorPose(Device(pw, ph, kp), Rp, Tp))
    return with_pixel_origin(cal, pixel_origin).replace(pixel_origin=int(pixel_origin))


def import_matrices(files: tuple[str | Path, str | Path, str | Path],
                    camera_size: tuple[int, int], projector_size: tuple[int, int],
                    pixel_origin: int | None = None) -> StereoCalibration:
    """:func:`read_matrix` of three files (left camera, right camera, projector) and
    :func:`rig_from_matrices` of them.

    Parameters
    ----------
    files : tuple of str or pathlib.Path
        The left camera's, the right camera's and the projector's matrix files.
    camera_size, projector_size : tuple of int
        ``(width, height)`` in pixels of each camera and of the projector.
    pixel_origin : int, optional
        The cameras' pixel origin in the matrices (0 or 1); :func:`default_origin` of the
        files by default.

    Returns
    -------
    StereoCalibration
        As :func:`rig_from_matrices`; its errors name the role and the file.

    Raises
    ------
    BistairError
        Not three files, or what :func:`read_matrix` or :func:`decompose` refuses.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> K = np.array([[1000.0, 0, 319.5], [0, 1000, 239.5], [0, 0, 1]])
    >>> for name, x in (("L.npy", 50.0), ("R.npy", -150.0), ("P.npy", -50.0)):
    ...     np.save(tmp / name, K @ np.hstack([np.eye(3), [[x], [0], [0]]]))
    >>> files = (tmp / "L.npy", tmp / "R.npy", tmp / "P.npy")
    >>> import_matrices(files, (640, 480), (1280, 800)).T.round(6).tolist()
    [-200.0, 0.0, 0.0]
    >>> import_matrices(files[:2], (640, 480), (1280, 800))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: --projection-matrices takes ...: three files, got 2
    >>> shutil.rmtree(tmp)
    """
    if len(files) != 3:
        raise BistairError(f"--projection-matrices takes LEFT,RIGHT,PROJECTOR: three files, "
                           f"got {len(files)}")
    roles = ("LEFT", "RIGHT", "PROJECTOR")
    matrices = tuple(read_matrix(f) for f in files)
    origin = default_origin(files) if pixel_origin is None else pixel_origin
    return rig_from_matrices(matrices, camera_size,
                             projector_size,
                             tuple(f"{r} ({Path(f).name})" for r, f in zip(roles, files,
                                                                           strict=True)),
                             origin)
