"""A calibrated pair of cameras (binocular structured light): the type and its file.

The two cameras use OpenCV's pinhole model and distortion ``(k1, k2, p1, p2, k3)``
(:class:`~bistair.geometry.calibration.Device`); ``R, T`` map the left camera's frame to the
right one's, ``X_right = R @ X_left + T`` (millimetres; what ``cv2.stereoCalibrate``
returns with the left camera first). The projector is optional: matching equal absolute
phase needs none, stereo phase unwrapping (:mod:`bistair.geometry.unwrap`) needs it, as a
``projector`` entry with its pose in the left camera's frame, ``X_projector = R @ X_left + T``.

File (JSON): bistair's calibration format with ``"kind": "stereo"``::

    {"format": "bistair-calibration", "version": 1, "kind": "stereo",
     "left":  {"width": W, "height": H, "K": 3x3, "dist": [k1, k2, p1, p2, k3], "rms": px},
     "right": {... the same ...},
     "R": 3x3, "T": [tx, ty, tz], "baseline": |T| (mm), "rms": stereo RMS (px),
     "poses": [{"name": ..., "features": n, "left_rms": px, "right_rms": px}, ...],
     "poses_used": n, "poses_total": m, "board": {...},
     "uncertainty": {"left": {"fx": ..., ...}, "right": {...}, "rotation_deg": [...],
                     "T": [...], "baseline": mm, "noise": {"left": px, "right": px}},
     "projector": {"width": W, "height": H, "K": 3x3, "dist": [...], "R": 3x3, "T": [3]}}

``"projector"`` is absent (or ``null``) in a calibration of the two cameras alone; files
without it read as before.

A camera-projector calibration (:mod:`bistair.geometry.calibration`, no ``kind`` or
``"kind": "camera-projector"``) keeps its own layout; each reader refuses the other kind with
one line.

The right camera is the one at ``+x`` of the left camera (to the right in its image): its
centre ``-R.T @ T`` has a positive x in the left camera's frame. A pair that breaks this
(``R, T`` inverted, right to left; two cameras named the other way round) and a baseline
under :data:`MIN_BASELINE` (zero, or ``T`` in metres) are refused wherever a
:class:`StereoCalibration` is made (:func:`check_pair`): a file, an import, a calibration.

Examples
--------
>>> cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
>>> cal = StereoCalibration(cam, cam, np.eye(3), [-120.0, 0.0, 0.0])
>>> data = cal.to_dict()
>>> data["kind"], data["baseline"], StereoCalibration.from_dict(data).right.size
('stereo', 120.0, (640, 480))
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import BistairError
from ..io.atomic import output_file
from ..io.jsonfile import read_json
from .calibration import FORMAT, VERSION, Calibration, Device, Uncertainty, _array, _device

KIND = "stereo"
#: No two cameras sit closer than this (mm): their lenses are wider. ``T`` in metres reads
#: 1000 times too short (a 200 mm baseline as 0.2).
MIN_BASELINE = 1.0
#: A shorter baseline is warned about: ``T`` in metres of a rig 1-10 m wide, or in board
#: squares, reads so (cameras this close exist: a stereo endoscope's are 4-6 mm apart).
WARN_BASELINE = 10.0
_SIDES = (("left", "camera"), ("right", "projector"))  # our names, Uncertainty's


@dataclass(frozen=True, eq=False)
class ProjectorPose:
    """The projector of a two-camera rig: the device and its pose in the left camera's
    frame, ``X_projector = R @ X_left + T`` (mm).

    Examples
    --------
    >>> proj = Device(1280, 800, [[1600.0, 0, 639.5], [0, 1600, 399.5], [0, 0, 1]])
    >>> pose = ProjectorPose(proj, np.eye(3), [-100.0, 0.0, 0.0])
    >>> pose.project(np.array([[0.0, 0.0, 800.0]])).round(3).tolist()
    [[439.5, 399.5]]
    """

    device: Device
    R: np.ndarray
    T: np.ndarray

    def __post_init__(self) -> None:
        rot = np.asarray(self.R, float).reshape(3, 3)
        if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-6) or np.linalg.det(rot) < 0:
            raise BistairError("the projector's 'R' is not a rotation matrix")
        object.__setattr__(self, "R", rot)
        object.__setattr__(self, "T", np.asarray(self.T, float).reshape(3))

    def project(self, points: np.ndarray) -> np.ndarray:
        """Projector pixels ``(N, 2)`` of points ``(N, 3)`` in the left camera's frame
        (with the projector's distortion, as ``cv2.projectPoints``)."""
        import cv2

        pts = np.asarray(points, np.float64).reshape(-1, 1, 3)
        if not len(pts):
            return np.zeros((0, 2))
        out, _ = cv2.projectPoints(pts, cv2.Rodrigues(self.R)[0], self.T, self.device.K,
                                   self.device.dist)
        return out.reshape(-1, 2)

    def to_dict(self) -> dict[str, Any]:
        return {**self.device.to_dict(), "R": self.R.tolist(), "T": self.T.tolist()}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ProjectorPose:
        """The ``projector`` entry of a stereo calibration file (validated)."""
        entry = data["projector"]
        if not isinstance(entry, Mapping):
            raise BistairError("calibration field 'projector' must be an object or null")
        return cls(_device(data, "projector"), _array(entry, "R", ((3, 3),), "projector."),
                   _array(entry, "T", ((3,),), "projector."))


@dataclass(frozen=True, eq=False)
class StereoCalibration:
    """Two calibrated cameras; ``X_right = R @ X_left + T`` (mm). ``uncertainty`` holds one
    standard deviation of every quantity (its ``camera`` is the left camera, its
    ``projector`` the right one). ``projector``: the projector and its pose in the left
    camera's frame, when known (stereo phase unwrapping needs it)."""

    left: Device
    right: Device
    R: np.ndarray
    T: np.ndarray
    rms: float | None = None
    poses: tuple[dict[str, Any], ...] = ()
    board: dict[str, Any] | None = None
    poses_total: int | None = None
    uncertainty: Uncertainty | None = None
    projector: ProjectorPose | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "R", np.asarray(self.R, float).reshape(3, 3))
        object.__setattr__(self, "T", np.asarray(self.T, float).reshape(3))
        check_pair(self.R, self.T)

    @property
    def baseline(self) -> float:
        """Distance between the camera centres (mm)."""
        return float(np.linalg.norm(self.T))

    def replace(self, **changes: Any) -> StereoCalibration:
        """A copy with some fields changed."""
        return dataclasses.replace(self, **changes)

    @classmethod
    def from_pair(cls, pair: Calibration) -> StereoCalibration:
        """The same numbers read as two cameras: the pair's camera is the left camera, its
        "projector" the right one (e.g. from
        :func:`~bistair.geometry.calibrate.calibrate_points`)."""
        poses = tuple({"name": p["name"], "features": p["features"],
                       "left_rms": p["camera_rms"], "right_rms": p["projector_rms"]}
                      for p in pair.poses)
        return cls(pair.camera, pair.projector, pair.R, pair.T, pair.rms, poses, pair.board,
                   pair.poses_total, pair.uncertainty)

    @classmethod
    def from_rig(cls, rig: Any) -> StereoCalibration:
        """The exact calibration of a :class:`bistair.sim.stereo.StereoRig` (left camera at
        the world origin), its projector included."""
        left, right, proj = rig.left, rig.right, rig.projector
        if not (np.allclose(left.R, np.eye(3)) and np.allclose(left.t, 0)):
            raise BistairError("the rig's left camera must sit at the world origin")
        return cls(Device(left.width, left.height, left.K, left.dist_coeffs),
                   Device(right.width, right.height, right.K, right.dist_coeffs),
                   right.R, right.t,
                   projector=ProjectorPose(Device(proj.width, proj.height, proj.K,
                                                  proj.dist_coeffs), proj.R, proj.t))

    def to_dict(self) -> dict[str, Any]:
        sigma = None
        if self.uncertainty is not None:
            sigma = self.uncertainty.to_dict()
            for ours, theirs in _SIDES:
                sigma[ours] = sigma.pop(theirs)
                sigma["noise"][ours] = sigma["noise"].pop(theirs)
        data = {"format": FORMAT, "version": VERSION, "kind": KIND,
                "left": self.left.to_dict(), "right": self.right.to_dict(),
                "R": self.R.tolist(), "T": self.T.tolist(), "baseline": self.baseline,
                "rms": self.rms, "poses": list(self.poses), "poses_used": len(self.poses),
                "poses_total": self.poses_total, "board": self.board, "uncertainty": sigma}
        if self.projector is not None:
            data["projector"] = self.projector.to_dict()
        return data

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> StereoCalibration:
        """Validate and build from the dictionary of a stereo calibration file."""
        if not isinstance(data, Mapping) or data.get("format") != FORMAT:
            raise BistairError(f"not a bistair calibration (no \"format\": \"{FORMAT}\")")
        if data.get("version") != VERSION:
            raise BistairError(f"calibration version {data.get('version')!r} is not supported")
        if data.get("kind") != KIND:
            raise BistairError("a camera-projector calibration, not a stereo one (two "
                               "cameras, \"kind\": \"stereo\"; make one with bistair "
                               "calibrate-stereo or import-calibration --stereo)")
        devices = [_device(data, side) for side, _ in _SIDES]
        rot = _array(data, "R", ((3, 3),))
        if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-6) or np.linalg.det(rot) < 0:
            raise BistairError("calibration field 'R' is not a rotation matrix")
        sigma = data.get("uncertainty")
        if isinstance(sigma, Mapping):
            sigma = dict(sigma)
            noise = dict(sigma.get("noise") or {})
            for ours, theirs in _SIDES:
                sigma[theirs] = sigma.pop(ours, None)
                noise[theirs] = noise.pop(ours, None)
            sigma = Uncertainty.from_dict({**sigma, "noise": noise})
        elif sigma is not None:
            raise BistairError("calibration field 'uncertainty' must be an object or null")
        rms = data.get("rms")
        projector = None if data.get("projector") is None else ProjectorPose.from_dict(data)
        return cls(*devices, rot, _array(data, "T", ((3,),)),
                   float(rms) if isinstance(rms, int | float) and math.isfinite(rms) else None,
                   tuple(data.get("poses") or ()), data.get("board"), data.get("poses_total"),
                   sigma, projector)


def right_centre(R: np.ndarray, T: np.ndarray) -> np.ndarray:
    """The right camera's centre in the left camera's frame, ``-R.T @ T`` (mm).

    Parameters
    ----------
    R, T : numpy.ndarray
        The pair's rotation and translation (``X_right = R @ X_left + T``).

    Returns
    -------
    numpy.ndarray
        ``(3,)`` the centre (mm).

    Examples
    --------
    >>> right_centre(np.eye(3), np.array([-120.0, 0.0, 0.0])).tolist()
    [120.0, 0.0, 0.0]
    """
    return -np.asarray(R, float).reshape(3, 3).T @ np.asarray(T, float).reshape(3)


def on_the_left(R: np.ndarray, T: np.ndarray) -> float:
    """How far the right camera sits to the left of the left one.

    Parameters
    ----------
    R, T : numpy.ndarray
        The pair's rotation and translation (``X_right = R @ X_left + T``).

    Returns
    -------
    float
        The distance (mm) of the right camera's centre at ``-x`` of the left camera's frame
        when that is the axis of the baseline rather than its y; 0 for a pair in bistair's
        convention (and for cameras stacked vertically, which rectification refuses).

    Examples
    --------
    >>> on_the_left(np.eye(3), [-120.0, 0.0, 0.0]), on_the_left(np.eye(3), [120.0, 0.0, 0.0])
    (0.0, 120.0)
    """
    x, y, _ = right_centre(R, T)
    return float(-x) if x < 0 and abs(x) >= abs(y) else 0.0


def check_pair(R: np.ndarray, T: np.ndarray) -> None:
    """Refuse a pair that no stereo reconstruction should use.

    A baseline under :data:`MIN_BASELINE` (zero: ``cv2.stereoRectify`` would fail; ``T``
    in metres: every depth 1000 times too small) or a right camera on the left
    (:func:`on_the_left`: ``R, T`` inverted, or the cameras named the other way round).

    Parameters
    ----------
    R, T : numpy.ndarray
        The pair's rotation and translation (``X_right = R @ X_left + T``, mm).

    Raises
    ------
    BistairError
        One line naming the problem and the likely cause.

    Examples
    --------
    >>> check_pair(np.eye(3), [-120.0, 0.0, 0.0])
    >>> check_pair(np.eye(3), [-0.12, 0.0, 0.0])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the cameras would be 0.12 mm apart (T = [-0.12, 0, 0]): T must ...
    """
    T = np.asarray(T, float).reshape(3)
    baseline = float(np.linalg.norm(T))
    shown = "[" + ", ".join(f"{t + 0.0:g}" for t in np.round(T, 3)) + "]"
    if baseline == 0:
        raise BistairError("T = [0, 0, 0]: the two cameras would be at one place (a stereo "
                           "pair needs a baseline, T in mm)")
    if baseline < MIN_BASELINE:
        raise BistairError(f"the cameras would be {baseline:.3g} mm apart (T = {shown}): T "
                           f"must be in millimetres (in metres, this is a "
                           f"{1000 * baseline:.4g} mm baseline)")
    left = on_the_left(R, T)
    if left > 0:
        raise BistairError(f"the right camera sits {left:.1f} mm to the left of the left one "
                           f"(T = {shown}; the right camera is the one at +x of the left, "
                           "T's x negative): are R, T inverted (right to left), or the "
                           "cameras named the other way round?")


def short_baseline(calibration: StereoCalibration) -> str | None:
    """The warning for a baseline under :data:`WARN_BASELINE`, else ``None``.

    Parameters
    ----------
    calibration : StereoCalibration
        The pair.

    Returns
    -------
    str or None

    Examples
    --------
    >>> cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
    >>> short_baseline(StereoCalibration(cam, cam, np.eye(3), [-5.0, 0.0, 0.0]))
    'a baseline of 5 mm: T must be in millimetres, not metres or board squares'
    """
    if calibration.baseline >= WARN_BASELINE:
        return None
    return (f"a baseline of {calibration.baseline:.3g} mm: T must be in millimetres, not "
            "metres or board squares")


def save_stereo_calibration(calibration: StereoCalibration, path: str | Path) -> Path:
    """Write a stereo calibration file atomically (layout in the module docstring).

    Parameters
    ----------
    calibration : StereoCalibration
        What to save.
    path : str or Path
        The JSON file (its folder is created if needed; an existing file is replaced).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    BistairError
        Raised by :func:`~bistair.io.atomic.output_file` if the file cannot be written.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
    >>> path = save_stereo_calibration(StereoCalibration(cam, cam, np.eye(3), [-120, 0, 0]),
    ...                                tmp / "stereo.json")
    >>> json.loads(path.read_text())["kind"]
    'stereo'
    >>> shutil.rmtree(tmp)
    """
    path = Path(path)
    with output_file(path) as tmp:
        tmp.write_text(json.dumps(calibration.to_dict(), indent=2) + "\n")
    return path


def load_stereo_calibration(path: str | Path) -> StereoCalibration:
    """Read and validate a stereo calibration file.

    Parameters
    ----------
    path : str or Path
        A JSON file written by :func:`save_stereo_calibration` (``bistair calibrate-stereo``,
        ``bistair import-calibration --stereo``).

    Returns
    -------
    StereoCalibration

    Raises
    ------
    BistairError
        A missing, unreadable or malformed file, or a camera-projector calibration; the
        message names the file.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.geometry.calibration import save_calibration
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
    >>> _ = save_stereo_calibration(StereoCalibration(cam, cam, np.eye(3), [-120, 0, 0]),
    ...                             tmp / "stereo.json")
    >>> load_stereo_calibration(tmp / "stereo.json").baseline
    120.0
    >>> _ = save_calibration(Calibration(cam, cam, np.eye(3), [-120, 0, 0]), tmp / "mono.json")
    >>> load_stereo_calibration(tmp / "mono.json")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: calibration file .../mono.json: a camera-projector calibration, ...
    >>> shutil.rmtree(tmp)
    """
    path = Path(path)
    data = read_json(path, "calibration file")
    try:
        return StereoCalibration.from_dict(data)
    except BistairError as exc:
        raise BistairError(f"calibration file {path}: {exc}") from None


def is_stereo_file(path: str | Path) -> bool:
    """Whether a calibration file says it is a stereo calibration (``"kind": "stereo"``).

    Parameters
    ----------
    path : str or Path
        A calibration JSON file.

    Returns
    -------
    bool
        ``True`` for a stereo calibration; ``False`` for any other JSON object.

    Raises
    ------
    BistairError
        A missing or unreadable file, or one that is not JSON.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (tmp / "a.json").write_text('{"kind": "stereo"}')
    >>> is_stereo_file(tmp / "a.json")
    True
    >>> shutil.rmtree(tmp)
    """
    data = read_json(path, "calibration file")
    return isinstance(data, Mapping) and data.get("kind") == KIND
