"""Calibrations made with OpenCV (or any tool writing OpenCV FileStorage YAML or XML), of a
camera and a projector or of two cameras.

OpenCV's ``stereo_calib`` sample writes ``intrinsics.yml`` (``M1``, ``D1``, ``M2``, ``D2``)
and ``extrinsics.yml`` (``R``, ``T``, ...). With the camera as device 1 and the projector as
device 2, ``R, T`` map the camera frame to the projector frame, ``X_p = R @ X_c + T``, which
is bistair's convention; ``T`` must be in millimetres. The keys of several files are
merged; a key that two files give differently is refused.

The key of each part (:data:`DEFAULT_KEYS`) can be renamed. The camera size comes from the
caller, else from a size key of the files (:data:`SIZE_KEYS`, :data:`SIZE_PAIRS`, or the
``camera_size`` key if one is named); the projector size from the caller, else from
:data:`PROJECTOR_SIZE_KEYS`, :data:`PROJECTOR_SIZE_PAIRS` (SLStudio's ``screenResX``,
``screenResY``) or the ``projector_size`` key if one is named.

Examples
--------
>>> import tempfile, pathlib
>>> cal = _example_calibration()
>>> with tempfile.TemporaryDirectory() as tmp:
...     path = str(pathlib.Path(tmp) / "stereo.yml")
...     fs = cv2.FileStorage(path, cv2.FILE_STORAGE_WRITE)
...     for key, value in (("M1", cal.camera.K), ("D1", cal.camera.dist[:4]),
...                        ("M2", cal.projector.K), ("D2", cal.projector.dist),
...                        ("R", cal.R), ("T", cal.T), ("image_size", (640, 480))):
...         fs.write(key, np.asarray(value))
...     fs.release()
...     got = read_opencv_calibration([path], projector_size=(1280, 800))
>>> got.camera.size, got.projector.size, round(got.baseline, 3)
((640, 480), (1280, 800), 150.0)
>>> bool(np.array_equal(got.R, cal.R) and np.array_equal(got.projector.dist, cal.projector.dist))
True

Two cameras (:func:`read_opencv_stereo`, ``import-calibration --stereo``): the left camera
is device 1 and the right one device 2, ``X_right = R @ X_left + T`` (mm), the keys named
as ``stereo_calib`` names them (:data:`DEFAULT_STEREO_KEYS`) unless renamed; both cameras
have the image size given, else a size key of the files (as above, or ``camera_size``
named). The result is a :class:`~bistair.geometry.calibration.StereoCalibration`.

>>> pair = _example_stereo()
>>> with tempfile.TemporaryDirectory() as tmp:
...     path = pathlib.Path(tmp) / "stereo.yml"
...     fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
...     for key, value in (("K1", pair.left.K), ("D1", pair.left.dist), ("K2", pair.right.K),
...                        ("D2", pair.right.dist), ("R", pair.R), ("T", pair.T)):
...         fs.write(key, np.asarray(value))
...     fs.release()
...     got = read_opencv_stereo([path], (1280, 1024), {"left": "K1", "right": "K2"})
>>> got.left.size, round(got.baseline, 3), bool(np.array_equal(got.R, pair.R))
((1280, 1024), 150.0, True)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ..errors import BistairError
from .calibration import Calibration, Device, StereoCalibration, on_the_left

#: The key of each part of a calibration in the files (OpenCV ``stereo_calib``'s names).
DEFAULT_KEYS = {"camera": "M1", "camera_dist": "D1", "projector": "M2", "projector_dist": "D2",
                "R": "R", "T": "T"}
#: What each part is, for messages; ``camera_size`` may be named too (no default).
ROLES = {"camera": "camera matrix", "camera_dist": "camera distortion",
         "projector": "projector matrix", "projector_dist": "projector distortion",
         "R": "rotation", "T": "translation", "camera_size": "camera size",
         "projector_size": "projector size"}
#: Keys holding the camera size ``[width, height]``, tried in this order (``S`` only when it
#: holds two numbers).
SIZE_KEYS = ("image_size", "imageSize", "img_size", "camera_size", "cameraSize", "S")
#: Key pairs holding the camera width and height, tried after :data:`SIZE_KEYS`
#: (``frameWidth``, ``frameHeight``: SLStudio's).
SIZE_PAIRS = (("image_width", "image_height"), ("imageWidth", "imageHeight"),
              ("camera_width", "camera_height"), ("frameWidth", "frameHeight"))
#: Keys holding the projector size ``[width, height]``, tried in this order.
PROJECTOR_SIZE_KEYS = ("projector_size", "projectorSize", "proj_size")
#: Key pairs holding the projector width and height (``screenResX``, ``screenResY``:
#: SLStudio's).
PROJECTOR_SIZE_PAIRS = (("screenResX", "screenResY"), ("projector_width", "projector_height"))
# OpenCV's distortion terms after (k1, k2, p1, p2, k3)
#: The key of each part of a stereo calibration (OpenCV ``stereo_calib``'s names).
DEFAULT_STEREO_KEYS = {"left": "M1", "left_dist": "D1", "right": "M2", "right_dist": "D2",
                       "R": "R", "T": "T"}
#: What each part is, for messages; ``camera_size`` may be named too (no default).
STEREO_ROLES = {"left": "left camera matrix", "left_dist": "left camera distortion",
                "right": "right camera matrix", "right_dist": "right camera distortion",
                "R": "rotation", "T": "translation", "camera_size": "camera size"}
_HIGHER = ("k4", "k5", "k6", "s1", "s2", "s3", "s4", "tauX", "tauY")
_ROTATION_TOL = 1e-6  # what Calibration.from_dict accepts as is
_ROUNDED_TOL = 1e-3  # rounded rotations up to this are replaced by the nearest rotation

# a file's readable values: key -> float array, or None when it is not numbers
Values = dict[str, np.ndarray | None]


def read_filestorage(path: str | Path) -> Values:
    """The top-level keys of an OpenCV FileStorage file (YAML, XML or JSON) and their values
    as float arrays (``None`` for a value that is not numbers: a string, a nested map).

    Matrices (``!!opencv-matrix``) keep their shape, sequences become arrays (nested
    sequences 2-D), numbers 0-d arrays.

    Parameters
    ----------
    path : str or Path
        The FileStorage file.

    Returns
    -------
    dict of str to numpy.ndarray or None
        Each top-level key with its value as a float64 array, ``None`` for a value that is
        not numbers (a string, a map that is not a matrix, a ragged or mixed sequence).

    Raises
    ------
    BistairError
        If the file is missing, unreadable or not a FileStorage file with named keys.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = pathlib.Path(tmp) / "a.yml"
    ...     _ = path.write_text("%YAML:1.0\\nimage_size: [ 640, 480 ]\\nname: left\\n")
    ...     values = read_filestorage(path)
    >>> values["image_size"].tolist(), values["name"]
    ([640.0, 480.0], None)
    """
    path = Path(path)
    if path.is_dir():
        raise BistairError(f"{path} is a folder, not an OpenCV FileStorage file")
    if not path.is_file():
        raise BistairError(f"calibration file {path} not found")
    try:
        with path.open("rb"):  # OpenCV would log to stderr on its own
            pass
    except OSError as exc:
        raise BistairError(f"cannot read calibration file {path}: {exc.strerror}") from None
    try:
        fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
        root = fs.root() if fs.isOpened() else None
        if root is None or not root.isMap():
            raise BistairError(f"{path} is not an OpenCV FileStorage file (YAML or XML) with "
                               "named keys")
        return {key: _node_array(fs.getNode(key)) for key in root.keys()}
    except (cv2.error, SystemError):  # the binding wraps parse errors in a SystemError
        raise BistairError(f"{path} is not an OpenCV FileStorage file (YAML or XML)") from None


def _node_array(node: Any) -> np.ndarray | None:
    """A FileStorage node as a float array, ``None`` if it is not numbers."""
    if node.isInt() or node.isReal():
        return np.array(node.real())
    if node.isSeq():
        items = [_node_array(node.at(i)) for i in range(node.size())]
        if any(item is None for item in items):
            return None
        try:
            return np.array(items, float)
        except ValueError:  # ragged
            return None
    if node.isMap():
        try:
            mat = node.mat()
        except cv2.error:
            return None
        return None if mat is None else np.asarray(mat, float)
    return None


def read_opencv_calibration(paths: Sequence[str | Path],
                            projector_size: tuple[int, int] | None = None,
                            camera_size: tuple[int, int] | None = None,
                            keys: Mapping[str, str] | None = None) -> Calibration:
    """A :class:`Calibration` from OpenCV FileStorage files.

    Parameters
    ----------
    paths : the files; their keys are merged.
    projector_size : ``(width, height)`` of the projector in pixels; by default from a
        projector size key (:data:`PROJECTOR_SIZE_KEYS`, :data:`PROJECTOR_SIZE_PAIRS`).
    camera_size : ``(width, height)`` of the camera; by default from a size key
        (:data:`SIZE_KEYS`, :data:`SIZE_PAIRS`).
    keys : key names that replace those of :data:`DEFAULT_KEYS` (``camera``,
        ``camera_dist``, ``projector``, ``projector_dist``, ``R``, ``T``), and optionally
        ``camera_size`` and ``projector_size``.

    Returns
    -------
    Calibration
        With distortion ``(k1, k2, p1, p2, k3)``, ``R`` a rotation matrix (a rotation
        vector is converted; a rotation rounded by up to 1e-3 is replaced by the nearest
        one), no RMS figures.

    Raises
    ------
    BistairError
        One line naming the problem: a missing or unreadable file, a missing key (with the
        keys the files have), a key two files give differently, a matrix of the wrong
        shape, distortion terms bistair's model lacks, ``R`` not a rotation, non-finite
        values, a bad or missing size.

    Examples
    --------
    Two files with other key names, the camera size given (see also the module's example):

    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> cal = _example_calibration()
    >>> parts = {"intrinsics.yml": {"K_cam": cal.camera.K, "d_cam": cal.camera.dist,
    ...                             "K_proj": cal.projector.K, "d_proj": cal.projector.dist},
    ...          "extrinsics.yml": {"R": cal.R, "T": cal.T}}
    >>> for name, values in parts.items():
    ...     fs = cv2.FileStorage(str(tmp / name), cv2.FILE_STORAGE_WRITE)
    ...     for key, value in values.items():
    ...         fs.write(key, np.asarray(value))
    ...     fs.release()
    >>> files = [tmp / "intrinsics.yml", tmp / "extrinsics.yml"]
    >>> keys = {"camera": "K_cam", "camera_dist": "d_cam", "projector": "K_proj",
    ...         "projector_dist": "d_proj"}
    >>> got = read_opencv_calibration(files, (1280, 800), camera_size=(640, 480), keys=keys)
    >>> got.camera.size, round(got.baseline, 3), bool(np.array_equal(got.T, cal.T))
    ((640, 480), 150.0, True)
    >>> read_opencv_calibration(files, (1280, 800), (640, 480))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: no key 'M1' (camera matrix) in ... has K_cam, ...
    >>> shutil.rmtree(tmp)
    """
    names = _key_names(keys)
    files = [(Path(p), read_filestorage(p)) for p in paths]
    if not files:
        raise BistairError("no calibration files given")
    if projector_size is None:
        projector_size = _projector_size(files, names.get("projector_size"))
    proj_w, proj_h = _size_pair(projector_size, "projector size")
    if camera_size is None:
        camera_size = _camera_size(files, names.get("camera_size"))
    cam_w, cam_h = _size_pair(camera_size, "camera size")
    parts = {role: _lookup(files, names[role], role) for role in DEFAULT_KEYS}
    camera = Device(cam_w, cam_h, _intrinsics(*parts["camera"]),
                    _distortion(*parts["camera_dist"]))
    projector = Device(proj_w, proj_h, _intrinsics(*parts["projector"]),
                       _distortion(*parts["projector_dist"]))
    return Calibration(camera, projector, _rotation(*parts["R"]), _translation(*parts["T"]))


def _key_names(keys: Mapping[str, str] | None, defaults: Mapping[str, str] = DEFAULT_KEYS,
               roles: Mapping[str, str] = ROLES) -> dict[str, str]:
    """The file key of every part: ``defaults`` with the user's ``keys`` (parts among
    ``roles``, names not empty) in their place."""
    names = dict(defaults)
    for role, key in (keys or {}).items():
        if role not in roles:
            raise BistairError(f"unknown part {role!r} in the keys (parts: "
                               f"{', '.join(roles)})")
        if not isinstance(key, str) or not key.strip():
            raise BistairError(f"the key name for {role} is empty")
        names[role] = key.strip()
    return names


def _where(files: list[tuple[Path, Values]]) -> str:
    return ", ".join(str(path) for path, _ in files)


def _lookup(files: list[tuple[Path, Values]], key: str, role: str
            ) -> tuple[np.ndarray, str, str]:
    """``(value, label, where)`` of ``key``; one-line errors for a missing key, a value that
    is not numbers or that two files give differently."""
    found = [(path, values[key]) for path, values in files if key in values]
    label = f"{ROLES[role]} '{key}'"
    if not found:
        if len(files) == 1:
            have = f"it has {', '.join(files[0][1]) or 'no keys'}"
        else:
            have = "; ".join(f"{path} has {', '.join(values) or 'no keys'}"
                             for path, values in files)
        raise BistairError(f"no key '{key}' ({ROLES[role]}) in {_where(files)} ({have}); "
                           f"rename it with --keys {role}=KEY")
    (path, value), rest = found[0], found[1:]
    where = f"{path}"
    if value is None:
        raise BistairError(f"{label} in {where} is not a number or matrix of numbers")
    for other, again in rest:
        if again is None or again.shape != value.shape or not np.array_equal(again, value):
            raise BistairError(f"{label} differs between {path} and {other}")
    if not np.isfinite(value).all():
        raise BistairError(f"{label} in {where} has non-finite values")
    return value, label, where


def _shape(value: np.ndarray) -> str:
    if value.ndim == 1:
        return f"{value.size} numbers"
    return "x".join(map(str, value.shape)) or "a single number"


def _vector(value: np.ndarray) -> np.ndarray | None:
    """The numbers of a 1-D array or a 1xN / Nx1 matrix, else ``None``."""
    if value.ndim == 1 or (value.ndim == 2 and 1 in value.shape):
        return value.ravel()
    return None


def _intrinsics(value: np.ndarray, label: str, where: str) -> np.ndarray:
    if value.shape != (3, 3):
        raise BistairError(f"{label} in {where} must be 3x3, got {_shape(value)}")
    if (value[1, 0] != 0 or value[2, 0] != 0 or value[2, 1] != 0 or value[2, 2] != 1
            or value[0, 0] <= 0 or value[1, 1] <= 0):
        raise BistairError(f"{label} in {where} is not an intrinsic matrix "
                           "[[fx, s, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0")
    return value


def _distortion(value: np.ndarray, label: str, where: str) -> np.ndarray:
    coeffs = _vector(value)
    if coeffs is None or coeffs.size not in (4, 5, 8, 12, 14):
        raise BistairError(f"{label} in {where} must hold 4, 5, 8, 12 or 14 numbers, got "
                           f"{_shape(value)}")
    higher = [name for name, c in zip(_HIGHER, coeffs[5:], strict=False) if c != 0]
    if higher:
        raise BistairError(f"{label} in {where} has non-zero {', '.join(higher)}; bistair's "
                           "model keeps only k1, k2, p1, p2, k3 (calibrate without the "
                           "rational, thin-prism and tilted models)")
    return coeffs[:5]


def _rotation(value: np.ndarray, label: str, where: str) -> np.ndarray:
    vec = _vector(value)
    if vec is not None and vec.size == 3:
        return cv2.Rodrigues(vec.reshape(3, 1))[0]
    if value.shape != (3, 3):
        raise BistairError(f"{label} in {where} must be a 3x3 rotation matrix or a rotation "
                           f"vector of 3 numbers, got {_shape(value)}")
    off = np.abs(value @ value.T - np.eye(3)).max()
    if off > _ROUNDED_TOL or np.linalg.det(value) <= 0:
        raise BistairError(f"{label} in {where} is not a rotation matrix (R @ R.T - I is "
                           f"{off:.2g} off, det {np.linalg.det(value):.3g})")
    if off > _ROTATION_TOL:  # written with few digits: the nearest rotation
        u, _, vt = np.linalg.svd(value)
        return u @ vt
    return value


def _translation(value: np.ndarray, label: str, where: str) -> np.ndarray:
    vec = _vector(value)
    if vec is None or vec.size != 3:
        raise BistairError(f"{label} in {where} must hold 3 numbers, got {_shape(value)}")
    return vec


def _camera_size(files: list[tuple[Path, Values]], key: str | None) -> tuple[int, int]:
    """The camera size from the named key, else the first size key or pair found."""
    if key is not None:
        value, label, where = _lookup(files, key, "camera_size")
        return _size_value(value, label, where)
    merged: Values = {}
    for _, values in files:
        merged.update(values)
    for name in SIZE_KEYS:
        if name == "S" and (merged.get(name) is None or merged[name].size != 2):
            continue  # a short name that may mean something else: a size only as 2 numbers
        if name in merged:
            value, label, where = _lookup(files, name, "camera_size")
            return _size_value(value, label, where)
    for wkey, hkey in SIZE_PAIRS:
        if wkey in merged and hkey in merged:
            width, label, where = _lookup(files, wkey, "camera_size")
            height = _lookup(files, hkey, "camera_size")[0]
            return _size_value(np.array([width, height]).ravel(), label, where)
    raise BistairError(f"no camera size in {_where(files)} (none of the keys "
                       f"{', '.join(SIZE_KEYS)} or {SIZE_PAIRS[0][0]} + {SIZE_PAIRS[0][1]}); "
                       "give it with --camera-size WxH")


def _projector_size(files: list[tuple[Path, Values]], key: str | None) -> tuple[int, int]:
    """The projector size from the named key, else the first projector size key or pair."""
    if key is not None:
        value, label, where = _lookup(files, key, "projector_size")
        return _size_value(value, label, where)
    merged: Values = {}
    for _, values in files:
        merged.update(values)
    for name in PROJECTOR_SIZE_KEYS:
        if name in merged:
            value, label, where = _lookup(files, name, "projector_size")
            return _size_value(value, label, where)
    for wkey, hkey in PROJECTOR_SIZE_PAIRS:
        if wkey in merged and hkey in merged:
            width, label, where = _lookup(files, wkey, "projector_size")
            height = _lookup(files, hkey, "projector_size")[0]
            return _size_value(np.array([width, height]).ravel(), label, where)
    raise BistairError(f"no projector size in {_where(files)} (none of the keys "
                       f"{', '.join(PROJECTOR_SIZE_KEYS)} or {PROJECTOR_SIZE_PAIRS[0][0]} + "
                       f"{PROJECTOR_SIZE_PAIRS[0][1]}); give it with --projector-size WxH")


def _size_value(value: np.ndarray, label: str, where: str) -> tuple[int, int]:
    vec = _vector(value)
    if vec is None or vec.size != 2:
        raise BistairError(f"{label} in {where} must be [width, height], got {_shape(value)}")
    return _size_pair(vec, f"{label} in {where}")


def _size_pair(size: Any, label: str) -> tuple[int, int]:
    """``(width, height)`` as positive integers, or a one-line error."""
    try:
        width, height = (float(v) for v in size)
    except (TypeError, ValueError):
        raise BistairError(f"{label} must be WIDTHxHEIGHT, got {size!r}") from None
    if not all(np.isfinite(v) and v >= 1 and v == int(v) for v in (width, height)):
        raise BistairError(f"{label} must be two positive whole numbers of pixels, got "
                           f"{_show(width)}x{_show(height)}")
    return int(width), int(height)


def _show(value: float) -> str:
    return str(int(value)) if np.isfinite(value) and value == int(value) else str(value)


def _example_calibration() -> Calibration:
    """A calibration with distortion on both devices, for the examples and tests."""
    cam = Device(640, 480, [[812.5, 0.2, 322.25], [0, 810.75, 236.5], [0, 0, 1]],
                 [-0.21, 0.13, 0.0011, -0.0023, 0.0])
    proj = Device(1280, 800, [[1510.0, 0, 641.5], [0, 1507.5, 802.25], [0, 0, 1]],
                  [0.081, -0.052, 0.0021, 0.0013, 0.012])
    rot = cv2.Rodrigues(np.array([0.02, 0.31, -0.015]))[0]
    return Calibration(cam, proj, rot, -rot @ np.array([150.0, 0.0, 0.0]))


def read_opencv_stereo(paths: Sequence[str | Path],
                       camera_size: tuple[int, int] | None = None,
                       keys: Mapping[str, str] | None = None) -> StereoCalibration:
    """A :class:`StereoCalibration` from OpenCV FileStorage files.

    Parameters
    ----------
    paths : sequence of str or Path
        The files; their keys are merged.
    camera_size : tuple of int, optional
        ``(width, height)`` of both cameras; by default from a size key of the files.
    keys : mapping, optional
        Key names replacing those of :data:`DEFAULT_STEREO_KEYS` (``left``, ``left_dist``,
        ``right``, ``right_dist``, ``R``, ``T``), and optionally ``camera_size``.

    Returns
    -------
    StereoCalibration
        With distortion ``(k1, k2, p1, p2, k3)`` and ``R`` a rotation matrix (a rotation
        vector is converted), no RMS figures.

    Raises
    ------
    BistairError
        One line naming the problem: a missing or unreadable file, an unknown part in
        ``keys``, a missing key (with the keys the files have), a key two files give
        differently, a matrix of the wrong shape, distortion terms bistair's model lacks,
        ``R`` not a rotation, non-finite values, a bad or missing size, a right camera on the
        left of the left one or a baseline under 1 mm
        (:func:`~bistair.geometry.calibration.check_pair`).

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> cal = _example_stereo()
    >>> fs = cv2.FileStorage(str(tmp / "s.yml"), cv2.FILE_STORAGE_WRITE)
    >>> for key, value in (("M1", cal.left.K), ("D1", cal.left.dist), ("M2", cal.right.K),
    ...                    ("D2", cal.right.dist), ("R", cal.R), ("T", cal.T)):
    ...     fs.write(key, np.asarray(value))
    >>> fs.release()
    >>> read_opencv_stereo([tmp / "s.yml"]).baseline  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: no camera size in .../s.yml (none of the keys ...
    >>> read_opencv_stereo([tmp / "s.yml"], (1280, 1024), {"right": "K2"})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: no key 'K2' (right camera matrix) in .../s.yml (it has M1, ...
    >>> shutil.rmtree(tmp)
    """
    names = _key_names(keys, DEFAULT_STEREO_KEYS, STEREO_ROLES)
    files = [(Path(p), read_filestorage(p)) for p in paths]
    if not files:
        raise BistairError("no calibration files given")
    if camera_size is None:
        camera_size = _camera_size(files, names.get("camera_size"))
    width, height = _size_pair(camera_size, "camera size")
    parts = {role: _part(files, names[role], role) for role in DEFAULT_STEREO_KEYS}
    left = Device(width, height, _intrinsics(*parts["left"]), _distortion(*parts["left_dist"]))
    right = Device(width, height, _intrinsics(*parts["right"]),
                   _distortion(*parts["right_dist"]))
    rot, t = _rotation(*parts["R"]), _translation(*parts["T"])
    where = ", ".join(str(path) for path, _ in files)
    left_of = on_the_left(rot, t)
    if left_of > 0:
        raise BistairError(f"{where}: the right camera ({names['right']}) sits {left_of:.1f} mm "
                           f"to the left of the left one ({names['left']}; T's x is "
                           f"{t[0]:+.1f} mm, negative for a left camera first): is "
                           f"{names['left']} the right camera, or are R, T inverted (right to "
                           "left)? bistair needs the left camera first and R, T from its frame "
                           "to the right one's")
    try:
        return StereoCalibration(left, right, rot, t)
    except BistairError as exc:  # a baseline of zero, or T in metres
        raise BistairError(f"{where}: {exc}") from None


def _part(files: list[tuple[Path, Values]], key: str, role: str
          ) -> tuple[np.ndarray, str, str]:
    """``(value, label, where)`` of ``key``: the lookup of
    :func:`~bistair.geometry.opencv.read_opencv_calibration` with the stereo parts' names."""
    found = [(path, values[key]) for path, values in files if key in values]
    label = f"{STEREO_ROLES[role]} '{key}'"
    where = ", ".join(str(path) for path, _ in files)
    if not found:
        have = "; ".join(f"{path} has {', '.join(values) or 'no keys'}" for path, values in files)
        if len(files) == 1:
            have = f"it has {', '.join(files[0][1]) or 'no keys'}"
        raise BistairError(f"no key '{key}' ({STEREO_ROLES[role]}) in {where} ({have}); "
                           f"rename it with --keys {role}=KEY")
    (path, value), rest = found[0], found[1:]
    if value is None:
        raise BistairError(f"{label} in {path} is not a number or matrix of numbers")
    for other, again in rest:
        if again is None or again.shape != value.shape or not np.array_equal(again, value):
            raise BistairError(f"{label} differs between {path} and {other}")
    if not np.isfinite(value).all():
        raise BistairError(f"{label} in {path} has non-finite values")
    return value, label, str(path)


def _example_stereo() -> StereoCalibration:
    """Two 1280 x 1024 cameras 150 mm apart with distortion, for the examples and tests."""
    left = Device(1280, 1024, [[2402.5, 0.0, 641.25], [0, 2400.75, 509.5], [0, 0, 1]],
                  [-0.11, 0.13, 0.0011, -0.0023, 0.0])
    right = Device(1280, 1024, [[2398.0, 0.0, 636.5], [0, 2397.5, 514.25], [0, 0, 1]],
                   [-0.09, 0.1, -0.0007, 0.0012, 0.0])
    rot = cv2.Rodrigues(np.array([0.01, 0.24, -0.005]))[0]
    return StereoCalibration(left, right, rot, -rot @ np.array([150.0, 0.0, 0.0]))
