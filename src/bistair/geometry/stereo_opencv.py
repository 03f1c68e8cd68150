"""Stereo calibrations made with OpenCV (``cv2.stereoCalibrate``, the ``stereo_calib``
sample, any tool writing FileStorage YAML or XML) as bistair's :class:`StereoCalibration`.

The left camera is device 1 and the right one device 2: ``R, T`` map the left camera's frame
to the right one's, ``X_right = R @ X_left + T``, ``T`` in millimetres. The keys of several
files are merged (:func:`~bistair.geometry.opencv.read_filestorage`); their names default
to ``stereo_calib``'s (:data:`DEFAULT_STEREO_KEYS`) and can be renamed. Both cameras have
the image size given, else the size key of the files (the keys
:func:`~bistair.geometry.opencv.read_opencv_calibration` reads, or ``camera_size`` named).

Examples
--------
>>> import pathlib, tempfile
>>> cal = _example_stereo()
>>> with tempfile.TemporaryDirectory() as tmp:
...     path = pathlib.Path(tmp) / "stereo.yml"
...     fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
...     for key, value in (("K1", cal.left.K), ("D1", cal.left.dist), ("K2", cal.right.K),
...                        ("D2", cal.right.dist), ("R", cal.R), ("T", cal.T)):
...         fs.write(key, np.asarray(value))
...     fs.release()
...     got = read_opencv_stereo([path], (1280, 1024), {"left": "K1", "right": "K2"})
>>> got.left.size, round(got.baseline, 3), bool(np.array_equal(got.R, cal.R))
((1280, 1024), 150.0, True)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import cv2
import numpy as np

from ..errors import BistairError
from .calibration import Device
from .opencv import (
    Values,
    _camera_size,
    _distortion,
    _intrinsics,
    _key_names,
    _rotation,
    _size_pair,
    _translation,
    read_filestorage,
)
from .stereo_calibration import StereoCalibration, on_the_left

#: The key of each part of a stereo calibration (OpenCV ``stereo_calib``'s names).
DEFAULT_STEREO_KEYS = {"left": "M1", "left_dist": "D1", "right": "M2", "right_dist": "D2",
                       "R": "R", "T": "T"}
#: What each part is, for messages; ``camera_size`` may be named too (no default).
STEREO_ROLES = {"left": "left camera matrix", "left_dist": "left camera distortion",
                "right": "right camera matrix", "right_dist": "right camera distortion",
                "R": "rotation", "T": "translation", "camera_size": "camera size"}


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
        (:func:`~bistair.geometry.stereo_calibration.check_pair`).

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
