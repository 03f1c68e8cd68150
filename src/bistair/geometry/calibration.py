"""Calibrated rigs of either kind, their devices and poses, and the one calibration file.

A rig is a camera and a projector (:class:`Calibration`, ``"kind": "camera-projector"``)
or two cameras (:class:`StereoCalibration`, ``"kind": "stereo"``, the projector optional);
:func:`load_calibration` returns either as the file says, :func:`save_calibration` writes
either.

**A camera and a projector.** The projector is modelled as an inverse camera (Zhang and
Huang, Opt. Eng. 45(8), 083601, 2006) with OpenCV's pinhole model and distortion
``(k1, k2, p1, p2, k3)``; ``R, T`` map the camera frame to the projector frame,
``X_p = R @ X_c + T`` (millimetres; the convention of :mod:`bistair.sim` and of
``cv2.stereoCalibrate``). File (JSON, no ``"kind"`` or ``"kind": "camera-projector"``)::

    {"format": "bistair-calibration", "version": 1,
     "camera":    {"width": W, "height": H, "K": 3x3, "dist": [k1, k2, p1, p2, k3], "rms": px},
     "projector": {... the same, for the projector ...},
     "R": 3x3, "T": [tx, ty, tz], "baseline": |T| (mm), "rms": stereo RMS (px),
     "poses": [{"name": ..., "features": n, "camera_rms": px, "projector_rms": px}, ...],
     "poses_used": n, "poses_total": m, "board": {...},
     "uncertainty": {"camera": {"fx": px, "fy": px, "cx": px, "cy": px, "dist": [5 numbers]},
                     "projector": {... the same ...}, "rotation_deg": [3 numbers],
                     "T": [3 numbers] (mm), "baseline": mm,
                     "noise": {"camera": px, "projector": px}}}

``"uncertainty"`` holds one standard deviation of each calibrated quantity
(:class:`Uncertainty`, from :func:`bistair.geometry.calibrate.calibrate_points`); it is
``null`` or absent in files from elsewhere.

**Two cameras** (binocular structured light). ``R, T`` map the left camera's frame to the
right one's, ``X_right = R @ X_left + T`` (mm; what ``cv2.stereoCalibrate`` returns with the
left camera first). The projector is optional: matching equal absolute phase needs none,
stereo phase unwrapping (:mod:`bistair.geometry.unwrap`) needs it, as a ``projector`` entry
with its pose in the left camera's frame, ``X_projector = R @ X_left + T``
(:class:`ProjectorPose`). File (JSON, ``"kind": "stereo"``)::

    {"format": "bistair-calibration", "version": 1, "kind": "stereo",
     "left":  {"width": W, "height": H, "K": 3x3, "dist": [k1, k2, p1, p2, k3], "rms": px},
     "right": {... the same ...},
     "R": 3x3, "T": [tx, ty, tz], "baseline": |T| (mm), "rms": stereo RMS (px),
     "poses": [{"name": ..., "features": n, "left_rms": px, "right_rms": px}, ...],
     "poses_used": n, "poses_total": m, "board": {...},
     "uncertainty": {"rotation_deg": [...], "T": [...], "baseline": mm,
                     "noise": {"left": px, "right": px}, "left": {"fx": ..., ...},
                     "right": {...}},
     "projector": {"width": W, "height": H, "K": 3x3, "dist": [...], "R": 3x3, "T": [3]},
     "pixel_origin": 0 or 1}

``"projector"`` is absent (or ``null``) in a calibration of the two cameras alone.
``"pixel_origin"``, written by ``import-calibration --projection-matrices``, is the cameras'
pixel origin in the matrices the file was made from (its ``K`` are 0-based either way;
``stereo`` checks it against the data); absent in other files (``None``). A reader
that needs one kind (``load_calibration(path, kind)``) refuses the other with one line.

The right camera is the one at ``+x`` of the left camera (to the right in its image): its
centre ``-R.T @ T`` has a positive x in the left camera's frame. A pair that breaks this
(``R, T`` inverted, right to left; two cameras named the other way round) and a baseline
under :data:`MIN_BASELINE` (zero, or ``T`` in metres) are refused wherever a
:class:`StereoCalibration` is made (:func:`check_pair`): a file, an import, a calibration.

Examples
--------
>>> cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
>>> proj = Device(800, 600, [[1000.0, 0, 399.5], [0, 1000, 299.5], [0, 0, 1]], [0.1, 0, 0, 0])
>>> cal = Calibration(cam, proj, np.eye(3), [-150.0, 0.0, 0.0])
>>> cal.baseline, proj.dist.tolist()
(150.0, [0.1, 0.0, 0.0, 0.0, 0.0])
>>> Calibration.from_dict(cal.to_dict()).T.tolist()
[-150.0, 0.0, 0.0]
>>> sigma = Uncertainty(np.full(9, 0.5), np.full(9, 0.7), [0.01, 0.02, 0.02], [0.1, 0.1, 0.3],
...                     0.12, (0.1, 0.15))
>>> back = Calibration.from_dict(cal.replace(uncertainty=sigma).to_dict()).uncertainty
>>> back.baseline, round(back.angle, 4), back.projector[:4].tolist()
(0.12, 0.03, [0.7, 0.7, 0.7, 0.7])
>>> pair = StereoCalibration(cam, cam, np.eye(3), [-120.0, 0.0, 0.0])
>>> data = pair.to_dict()
>>> data["kind"], data["baseline"], StereoCalibration.from_dict(data).right.size
('stereo', 120.0, (640, 480))
>>> "pixel_origin" in data, StereoCalibration.from_dict(data).pixel_origin
(False, None)
>>> StereoCalibration.from_dict({**data, "pixel_origin": 1}).pixel_origin
1
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from ..errors import BistairError
from ..io.atomic import output_file
from ..io.jsonfile import read_json

FORMAT, VERSION = "bistair-calibration", 1
CAMERA_PROJECTOR, STEREO = "camera-projector", "stereo"  # the kinds ("kind" in the file)
KIND = STEREO  # (its old name)
DEVICES = {CAMERA_PROJECTOR: ("camera", "projector"), STEREO: ("left", "right")}
#: No two cameras sit closer than this (mm): their lenses are wider. ``T`` in metres reads
#: 1000 times too short (a 200 mm baseline as 0.2).
MIN_BASELINE = 1.0
#: A shorter baseline is warned about: ``T`` in metres of a rig 1-10 m wide, or in board
#: squares, reads so (cameras this close exist: a stereo endoscope's are 4-6 mm apart).
WARN_BASELINE = 10.0


@dataclass(frozen=True, eq=False)
class Device:
    """One pinhole device: image size, intrinsic matrix ``K``, OpenCV distortion
    ``(k1, k2, p1, p2, k3)`` (``k3 = 0`` if four are given) and its reprojection RMS (pixels,
    ``None`` if unknown)."""

    width: int
    height: int
    K: np.ndarray
    dist: np.ndarray = field(default_factory=lambda: np.zeros(5))
    rms: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "K", np.asarray(self.K, float).reshape(3, 3))
        dist = np.asarray(self.dist, float).ravel()
        if dist.size not in (4, 5):
            raise BistairError(f"distortion must be (k1, k2, p1, p2[, k3]), got {dist.size} "
                               "numbers")
        object.__setattr__(self, "dist", np.append(dist, np.zeros(5 - dist.size)))

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)``."""
        return self.width, self.height

    def to_dict(self) -> dict[str, Any]:
        return {"width": self.width, "height": self.height, "K": self.K.tolist(),
                "dist": self.dist.tolist(), "rms": self.rms}


INTRINSICS = ("fx", "fy", "cx", "cy")


@dataclass(frozen=True, eq=False)
class Uncertainty:
    """One standard deviation of each quantity of a calibration.

    ``camera`` and ``projector`` hold ``(fx, fy, cx, cy)`` in pixels then the distortion
    ``(k1, k2, p1, p2, k3)`` (0 for a coefficient held fixed); ``rotation`` the rotation
    error of ``R`` about the projector's x, y and z axes (degrees); ``T`` its components and
    ``baseline`` its length (mm); ``noise`` the correspondence noise (standard deviation per
    image coordinate, pixels) that the residuals show in the camera and in the projector,
    which the deviations are scaled by.

    The devices are named after the calibration's ``kind`` (:attr:`devices`): for two
    cameras (``"stereo"``) they are ``left`` and ``right`` (the right camera in place of the
    projector), in the file too; ``camera`` and ``projector`` still read them.

    Examples
    --------
    >>> sd = Uncertainty(np.full(9, 0.5), np.full(9, 0.7), np.zeros(3), np.zeros(3), 0.1,
    ...                  kind="stereo")
    >>> sd.devices, float(sd.right[0]), float(sd.projector[0]), list(sd.to_dict()["noise"])
    (('left', 'right'), 0.7, 0.7, ['left', 'right'])
    """

    camera: np.ndarray
    projector: np.ndarray
    rotation: np.ndarray
    T: np.ndarray
    baseline: float
    noise: tuple[float, float] = (math.nan, math.nan)
    kind: str = CAMERA_PROJECTOR

    def __post_init__(self) -> None:
        for name, size in (("camera", 9), ("projector", 9), ("rotation", 3), ("T", 3)):
            object.__setattr__(self, name, np.asarray(getattr(self, name), float).reshape(size))
        object.__setattr__(self, "baseline", float(self.baseline))
        object.__setattr__(self, "noise", tuple(float(v) for v in self.noise))
        if self.kind not in DEVICES:
            raise BistairError(f"calibration kind {self.kind!r} is neither "
                               f"{CAMERA_PROJECTOR!r} nor {STEREO!r}")

    @property
    def devices(self) -> tuple[str, str]:
        """The two devices' names: ``("camera", "projector")``, or ``("left", "right")``
        for two cameras (``kind`` ``"stereo"``)."""
        return DEVICES[self.kind]

    @property
    def left(self) -> np.ndarray:
        """A pair's left camera (the first device: ``camera`` is its old name)."""
        return self._of(STEREO, self.camera)

    @property
    def right(self) -> np.ndarray:
        """A pair's right camera (the second device: ``projector`` is its old name)."""
        return self._of(STEREO, self.projector)

    def _of(self, kind: str, value: np.ndarray) -> np.ndarray:
        if self.kind != kind:
            raise AttributeError(f"the uncertainty of a {self.kind} calibration names its "
                                 f"devices {' and '.join(self.devices)}")
        return value

    @property
    def angle(self) -> float:
        """Root-mean-square angle of the rotation error (degrees)."""
        return float(np.linalg.norm(self.rotation))

    def to_dict(self) -> dict[str, Any]:
        def device(sd: np.ndarray) -> dict[str, Any]:
            return {**dict(zip(INTRINSICS, map(float, sd[:4]), strict=True)),
                    "dist": sd[4:].tolist()}

        first, second = self.devices
        rest = {"rotation_deg": self.rotation.tolist(), "T": self.T.tolist(),
                "baseline": self.baseline,
                "noise": {name: value if math.isfinite(value) else None
                          for name, value in zip(self.devices, self.noise, strict=True)}}
        devices = {first: device(self.camera), second: device(self.projector)}
        # (a pair's file has always listed its cameras last)
        return {**rest, **devices} if self.kind == STEREO else {**devices, **rest}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], kind: str = CAMERA_PROJECTOR) -> Uncertainty:
        """Validate and build from the ``"uncertainty"`` object of a calibration file of
        ``kind`` (its devices named accordingly)."""
        where = "uncertainty."
        if not isinstance(data, Mapping):
            raise BistairError("calibration field 'uncertainty' must be an object or null")
        devices = []
        for name in DEVICES[kind]:
            dev = data.get(name)
            if not isinstance(dev, Mapping):
                raise BistairError(f"calibration misses the object '{where}{name}'")
            devices.append(np.array([*(_sigma(dev, k, ((),), f"{where}{name}.")
                                       for k in INTRINSICS),
                                     *_sigma(dev, "dist", ((5,),), f"{where}{name}.")]))
        noise = data.get("noise")
        noise = noise if isinstance(noise, Mapping) else {}
        return cls(*devices, _sigma(data, "rotation_deg", ((3,),), where),
                   _sigma(data, "T", ((3,),), where),
                   float(_sigma(data, "baseline", ((),), where)),
                   tuple(_number_or_nan(noise.get(name)) for name in DEVICES[kind]), kind)


def _number_or_nan(value: Any) -> float:
    """A number from a file, NaN for anything else (JSON has no NaN: null stands for it)."""
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    return float(value) if ok else math.nan


@dataclass(frozen=True, eq=False)
class Calibration:
    """A calibrated camera and projector; ``X_p = R @ X_c + T`` (mm)."""

    kind: ClassVar[str] = CAMERA_PROJECTOR
    camera: Device
    projector: Device
    R: np.ndarray
    T: np.ndarray
    rms: float | None = None
    poses: tuple[dict[str, Any], ...] = ()
    board: dict[str, Any] | None = None
    poses_total: int | None = None
    uncertainty: Uncertainty | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "R", np.asarray(self.R, float).reshape(3, 3))
        object.__setattr__(self, "T", np.asarray(self.T, float).reshape(3))
        _name_devices(self)

    @property
    def baseline(self) -> float:
        """Distance between the camera and projector centres (mm)."""
        return float(np.linalg.norm(self.T))

    def replace(self, **changes: Any) -> Calibration:
        """A copy with some fields changed."""
        return dataclasses.replace(self, **changes)

    @classmethod
    def from_rig(cls, rig: Any) -> Calibration:
        """The exact calibration of a :class:`bistair.sim.Rig` (camera at the origin)."""
        cam, proj = rig.camera, rig.projector
        if not (np.allclose(cam.R, np.eye(3)) and np.allclose(cam.t, 0)):
            raise BistairError("the rig's camera must sit at the world origin")
        return cls(Device(cam.width, cam.height, cam.K, cam.dist_coeffs),
                   Device(proj.width, proj.height, proj.K, proj.dist_coeffs), proj.R, proj.t)

    def to_dict(self) -> dict[str, Any]:
        return {"format": FORMAT, "version": VERSION, "camera": self.camera.to_dict(),
                "projector": self.projector.to_dict(), "R": self.R.tolist(),
                "T": self.T.tolist(), "baseline": self.baseline, "rms": self.rms,
                "poses": list(self.poses), "poses_used": len(self.poses),
                "poses_total": self.poses_total, "board": self.board,
                "uncertainty": None if self.uncertainty is None else self.uncertainty.to_dict()}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Calibration:
        """Validate and build from the dictionary of a calibration file."""
        if not isinstance(data, Mapping) or data.get("format") != FORMAT:
            raise BistairError(f"not a bistair calibration (no \"format\": \"{FORMAT}\")")
        if data.get("version") != VERSION:
            raise BistairError(f"calibration version {data.get('version')!r} is not supported")
        kind = data.get("kind", CAMERA_PROJECTOR)
        if kind == STEREO:
            raise BistairError("a stereo calibration (two cameras: for bistair stereo), not a "
                               "camera-projector one")
        if kind != CAMERA_PROJECTOR:
            raise BistairError(f"calibration kind {kind!r} is neither {CAMERA_PROJECTOR!r} "
                               f"(a camera and a projector) nor {STEREO!r} (two cameras)")
        devices = [_device(data, name) for name in ("camera", "projector")]
        rot = _array(data, "R", ((3, 3),))
        if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-6) or np.linalg.det(rot) < 0:
            raise BistairError("calibration field 'R' is not a rotation matrix")
        sigma = data.get("uncertainty")
        return cls(*devices, rot, _array(data, "T", ((3,),)), data.get("rms"),
                   tuple(data.get("poses") or ()), data.get("board"), data.get("poses_total"),
                   None if sigma is None else Uncertainty.from_dict(sigma))


def _array(data: Mapping[str, Any], key: str, shapes: tuple[tuple[int, ...], ...],
           where: str = "") -> np.ndarray:
    """The field ``key`` as a finite float array of one of ``shapes``."""
    if key not in data:
        raise BistairError(f"calibration misses the field '{where}{key}'")
    try:
        arr = np.asarray(data[key], float)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape not in shapes or not np.isfinite(arr).all():
        want = " or ".join("x".join(map(str, s)) or "1" for s in shapes)
        raise BistairError(f"calibration field '{where}{key}' must be {want} finite number(s)")
    return arr


def _sigma(data: Mapping[str, Any], key: str, shapes: tuple[tuple[int, ...], ...],
           where: str) -> np.ndarray:
    """The field ``key`` as standard deviations: finite and not negative."""
    arr = _array(data, key, shapes, where)
    if (arr < 0).any():
        raise BistairError(f"calibration field '{where}{key}' must not be negative")
    return arr


def _device(data: Mapping[str, Any], name: str) -> Device:
    dev = data.get(name)
    if not isinstance(dev, Mapping):
        raise BistairError(f"calibration misses the object '{name}'")
    width, height = (_array(dev, key, ((),), f"{name}.") for key in ("width", "height"))
    if min(width, height) < 1 or width != int(width) or height != int(height):
        raise BistairError(f"calibration {name} width and height must be positive integers")
    dist = _array(dev, "dist", ((4,), (5,)), f"{name}.")  # k1, k2, p1, p2[, k3]
    K = _array(dev, "K", ((3, 3),), f"{name}.")
    if not (K[0, 0] > 0 and K[1, 1] > 0):  # rectifying or projecting with it is nonsense
        raise BistairError(f"calibration field '{name}.K' has the focal lengths fx "
                           f"{K[0, 0]:g} and fy {K[1, 1]:g} px: both must be positive")
    rms = dev.get("rms")
    return Device(int(width), int(height), K, dist,
                  float(rms) if isinstance(rms, int | float) else None)


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
    standard deviation of every quantity (its ``left`` and ``right`` cameras; ``camera``
    and ``projector``, their old names, still read them). ``projector``: the projector and
    its pose in the left camera's frame, when known (stereo phase unwrapping needs it).
    ``pixel_origin``: the cameras' pixel origin (0 or 1) of the matrices it was imported
    from, when recorded (module docstring)."""

    kind: ClassVar[str] = STEREO
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
    pixel_origin: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "R", np.asarray(self.R, float).reshape(3, 3))
        object.__setattr__(self, "T", np.asarray(self.T, float).reshape(3))
        if self.pixel_origin is not None:
            if self.pixel_origin not in (0, 1):
                raise BistairError(f"calibration field 'pixel_origin' must be 0 or 1, got "
                                   f"{self.pixel_origin!r}")
            object.__setattr__(self, "pixel_origin", int(self.pixel_origin))
        check_pair(self.R, self.T)
        _name_devices(self)

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
        sigma = None if self.uncertainty is None else self.uncertainty.to_dict()
        data = {"format": FORMAT, "version": VERSION, "kind": STEREO,
                "left": self.left.to_dict(), "right": self.right.to_dict(),
                "R": self.R.tolist(), "T": self.T.tolist(), "baseline": self.baseline,
                "rms": self.rms, "poses": list(self.poses), "poses_used": len(self.poses),
                "poses_total": self.poses_total, "board": self.board, "uncertainty": sigma}
        if self.projector is not None:
            data["projector"] = self.projector.to_dict()
        if self.pixel_origin is not None:
            data["pixel_origin"] = self.pixel_origin
        return data

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> StereoCalibration:
        """Validate and build from the dictionary of a stereo calibration file."""
        if not isinstance(data, Mapping) or data.get("format") != FORMAT:
            raise BistairError(f"not a bistair calibration (no \"format\": \"{FORMAT}\")")
        if data.get("version") != VERSION:
            raise BistairError(f"calibration version {data.get('version')!r} is not supported")
        if data.get("kind") != STEREO:
            raise BistairError("a camera-projector calibration, not a stereo one (two "
                               "cameras, \"kind\": \"stereo\"; make one with bistair "
                               "calibrate-stereo or import-calibration --stereo)")
        devices = [_device(data, side) for side in DEVICES[STEREO]]
        rot = _array(data, "R", ((3, 3),))
        if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-6) or np.linalg.det(rot) < 0:
            raise BistairError("calibration field 'R' is not a rotation matrix")
        sigma = data.get("uncertainty")
        if isinstance(sigma, Mapping):
            sigma = Uncertainty.from_dict(sigma, STEREO)
        elif sigma is not None:
            raise BistairError("calibration field 'uncertainty' must be an object or null")
        rms = data.get("rms")
        projector = None if data.get("projector") is None else ProjectorPose.from_dict(data)
        return cls(*devices, rot, _array(data, "T", ((3,),)),
                   float(rms) if isinstance(rms, int | float) and math.isfinite(rms) else None,
                   tuple(data.get("poses") or ()), data.get("board"), data.get("poses_total"),
                   sigma, projector, data.get("pixel_origin"))


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


def _name_devices(calibration: Calibration | StereoCalibration) -> None:
    """Name the uncertainty's devices after the calibration's kind."""
    sigma = calibration.uncertainty
    if sigma is not None and sigma.kind != calibration.kind:
        object.__setattr__(calibration, "uncertainty",
                           dataclasses.replace(sigma, kind=calibration.kind))


def save_calibration(calibration: Calibration | StereoCalibration, path: str | Path) -> Path:
    """Write a calibration JSON file of either kind atomically; returns ``path``.

    The file has the layout of the module docstring (2-space indent, final newline); it is
    written to a temporary file beside ``path`` and renamed onto it
    (:func:`~bistair.io.atomic.output_file`), so a reader never sees half a file.

    Parameters
    ----------
    calibration : Calibration or StereoCalibration
        What to save (a camera and a projector, or two cameras: ``"kind": "stereo"``).
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
    >>> proj = Device(800, 600, [[1000.0, 0, 399.5], [0, 1000, 299.5], [0, 0, 1]])
    >>> path = save_calibration(Calibration(cam, proj, np.eye(3), [-150.0, 0, 0]),
    ...                         tmp / "calibration.json")
    >>> data = json.loads(path.read_text())
    >>> data["format"], data["baseline"], data["camera"]["dist"]
    ('bistair-calibration', 150.0, [0.0, 0.0, 0.0, 0.0, 0.0])
    >>> path = save_calibration(StereoCalibration(cam, cam, np.eye(3), [-120, 0, 0]),
    ...                         tmp / "stereo.json")
    >>> json.loads(path.read_text())["kind"]
    'stereo'
    >>> shutil.rmtree(tmp)
    """
    path = Path(path)
    with output_file(path) as tmp:
        tmp.write_text(json.dumps(calibration.to_dict(), indent=2) + "\n")
    return path


def load_calibration(path: str | Path, kind: str | None = None
                     ) -> Calibration | StereoCalibration:
    """Read and validate a calibration file: a :class:`Calibration` or a
    :class:`StereoCalibration`, as its ``"kind"`` says (one-line :class:`BistairError` if it
    is neither, or not the ``kind`` asked for).

    Parameters
    ----------
    path : str or Path
        A calibration JSON file (layout in the module docstring), e.g. from
        :func:`save_calibration`, ``bistair calibrate`` or ``bistair calibrate-stereo``.
    kind : {None, "camera-projector", "stereo"}, optional
        The kind the caller needs; ``None`` (the default) takes either.

    Returns
    -------
    Calibration or StereoCalibration
        The devices, ``R, T`` (mm) and whatever else the file holds (RMS figures, poses,
        board, uncertainty): a camera and a projector (no ``"kind"``, or
        ``"camera-projector"``), or two cameras (``"kind": "stereo"``).

    Raises
    ------
    BistairError
        If the file is missing, unreadable or not JSON, or is not a valid bistair
        calibration (wrong format, version or kind, a missing or malformed field, ``R`` not
        a rotation), or of the other kind than ``kind``; the message names the file.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
    >>> proj = Device(800, 600, [[1000.0, 0, 399.5], [0, 1000, 299.5], [0, 0, 1]])
    >>> path = save_calibration(Calibration(cam, proj, np.eye(3), [-150.0, 0, 0], rms=0.2),
    ...                         tmp / "calibration.json")
    >>> cal = load_calibration(path)
    >>> cal.kind, cal.baseline, cal.rms, cal.projector.size
    ('camera-projector', 150.0, 0.2, (800, 600))
    >>> path = save_calibration(StereoCalibration(cam, cam, np.eye(3), [-120.0, 0, 0]),
    ...                         tmp / "stereo.json")
    >>> pair = load_calibration(path)
    >>> type(pair).__name__, pair.kind, pair.baseline
    ('StereoCalibration', 'stereo', 120.0)
    >>> load_calibration(path, "camera-projector")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: calibration file .../stereo.json: a stereo calibration (two ...
    >>> _ = (tmp / "other.json").write_text('{"format": "something-else"}')
    >>> load_calibration(tmp / "other.json")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: calibration file .../other.json: not a bistair calibration ...
    >>> shutil.rmtree(tmp)
    """
    if kind not in (None, *DEVICES):
        raise BistairError(f"calibration kind {kind!r} is neither {CAMERA_PROJECTOR!r} nor "
                           f"{STEREO!r}")
    path = Path(path)
    data = read_json(path, "calibration file")
    if kind is None:
        stereo = isinstance(data, Mapping) and data.get("kind") == STEREO
        kind = STEREO if stereo else CAMERA_PROJECTOR
    try:
        return (StereoCalibration if kind == STEREO else Calibration).from_dict(data)
    except BistairError as exc:
        raise BistairError(f"calibration file {path}: {exc}") from None


def load_stereo_calibration(path: str | Path) -> StereoCalibration:
    """Read a stereo calibration file: ``load_calibration(path, "stereo")`` (the old name,
    kept for one release).

    Parameters
    ----------
    path : str or Path
        A JSON file of two cameras (``"kind": "stereo"``).

    Returns
    -------
    StereoCalibration

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
    >>> _ = save_calibration(Calibration(cam, cam, np.eye(3), [-120, 0, 0]), tmp / "mono.json")
    >>> load_stereo_calibration(tmp / "mono.json")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: calibration file .../mono.json: a camera-projector calibration, ...
    >>> shutil.rmtree(tmp)
    """
    return load_calibration(path, STEREO)  # type: ignore[return-value]


save_stereo_calibration = save_calibration  # (the old name, kept for one release)


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
    return isinstance(data, Mapping) and data.get("kind") == STEREO
