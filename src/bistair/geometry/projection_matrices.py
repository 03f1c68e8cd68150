"""A rig of two cameras and a projector given as three 3x4 projection matrices.

Each matrix ``P`` maps a world point to its pixel, ``s * (u, v, 1) = P @ (X, Y, Z, 1)``, all
three in the same world frame. :func:`decompose` splits it into ``P = K [R | t]`` (an RQ
decomposition: positive focal lengths, a proper rotation, ``X_device = R X_world + t``);
:func:`rig_from_matrices` puts the three in the left camera's frame, without distortion.

Files (:func:`read_matrix`): ``.npy``, text (``.txt``, ``.csv``, ...: three rows of four
numbers separated by spaces or commas, ``#`` comments) or MATLAB ``.mat`` holding exactly
one 3x4 numeric array.

Examples
--------
>>> K = np.array([[1000.0, 0, 320], [0, 1000, 240], [0, 0, 1]])
>>> k, r, t = decompose(-3 * K @ np.hstack([np.eye(3), [[-100.0], [0], [0]]]))
>>> k.round(6).tolist() == K.tolist(), np.allclose(r, np.eye(3)), t.round(6).tolist()
(True, True, [-100.0, 0.0, 0.0])
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import BistairError
from .calibration import Device
from .stereo_calibration import ProjectorPose, StereoCalibration


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


def rig_from_matrices(matrices: tuple[np.ndarray, np.ndarray, np.ndarray],
                      camera_size: tuple[int, int], projector_size: tuple[int, int],
                      names: tuple[str, str, str] = ("LEFT", "RIGHT", "PROJECTOR")
                      ) -> StereoCalibration:
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

    Returns
    -------
    StereoCalibration
        The cameras' intrinsics, the right camera's ``R, T`` (``X_right = R X_left + T``,
        world units) and the ``projector`` pose the same way, all without distortion.

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
    """
    parts = [decompose(P, f"{n} projection matrix") for P, n in zip(matrices, names,
                                                                    strict=True)]
    (kl, rl, tl), (kr, rr, tr), (kp, rp, tp) = parts

    def relative(r: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        rot = r @ rl.T
        return rot, t - rot @ tl

    (cw, ch), (pw, ph) = camera_size, projector_size
    R, T = relative(rr, tr)
    Rp, Tp = relative(rp, tp)
    return StereoCalibration(Device(cw, ch, kl), Device(cw, ch, kr), R, T,
                             projector=ProjectorPose(Device(pw, ph, kp), Rp, Tp))


def import_matrices(files: tuple[str | Path, str | Path, str | Path],
                    camera_size: tuple[int, int], projector_size: tuple[int, int]
                    ) -> StereoCalibration:
    """:func:`read_matrix` of three files (left camera, right camera, projector) and
    :func:`rig_from_matrices` of them.

    Parameters
    ----------
    files : tuple of str or pathlib.Path
        The left camera's, the right camera's and the projector's matrix files.
    camera_size, projector_size : tuple of int
        ``(width, height)`` in pixels of each camera and of the projector.

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
    return rig_from_matrices(tuple(read_matrix(f) for f in files), camera_size,
                             projector_size,
                             tuple(f"{r} ({Path(f).name})" for r, f in zip(roles, files,
                                                                           strict=True)))
