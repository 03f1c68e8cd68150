"""A calibrated camera-projector pair: the devices, their pose, and the calibration file.

The projector is modelled as an inverse camera (Zhang and Huang, Opt. Eng. 45(8), 083601,
2006) with OpenCV's pinhole model and distortion ``(k1, k2, p1, p2, k3)``; ``R, T`` map the
camera frame to the projector frame, ``X_p = R @ X_c + T`` (millimetres; the convention of
:mod:`bistair.sim` and of ``cv2.stereoCalibrate``).

Calibration file (JSON, :func:`save_calibration`)::

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
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import BistairError
from ..io.atomic import output_file
from ..io.jsonfile import read_json

FORMAT, VERSION = "bistair-calibration", 1


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
    """

    camera: np.ndarray
    projector: np.ndarray
    rotation: np.ndarray
    T: np.ndarray
    baseline: float
    noise: tuple[float, float] = (math.nan, math.nan)

    def __post_init__(self) -> None:
        for name, size in (("camera", 9), ("projector", 9), ("rotation", 3), ("T", 3)):
            object.__setattr__(self, name, np.asarray(getattr(self, name), float).reshape(size))
        object.__setattr__(self, "baseline", float(self.baseline))
        object.__setattr__(self, "noise", tuple(float(v) for v in self.noise))

    @property
    def angle(self) -> float:
        """Root-mean-square angle of the rotation error (degrees)."""
        return float(np.linalg.norm(self.rotation))

    def to_dict(self) -> dict[str, Any]:
        def device(sd: np.ndarray) -> dict[str, Any]:
            return {**dict(zip(INTRINSICS, map(float, sd[:4]), strict=True)),
                    "dist": sd[4:].tolist()}

        return {"camera": device(self.camera), "projector": device(self.projector),
                "rotation_deg": self.rotation.tolist(), "T": self.T.tolist(),
                "baseline": self.baseline,
                "noise": {name: value if math.isfinite(value) else None
                          for name, value in zip(("camera", "projector"), self.noise,
                                                 strict=True)}}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Uncertainty:
        """Validate and build from the ``"uncertainty"`` object of a calibration file."""
        where = "uncertainty."
        if not isinstance(data, Mapping):
            raise BistairError("calibration field 'uncertainty' must be an object or null")
        devices = []
        for name in ("camera", "projector"):
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
                   tuple(_number_or_nan(noise.get(name)) for name in ("camera", "projector")))


def _number_or_nan(value: Any) -> float:
    """A number from a file, NaN for anything else (JSON has no NaN: null stands for it)."""
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    return float(value) if ok else math.nan


@dataclass(frozen=True, eq=False)
class Calibration:
    """A calibrated camera and projector; ``X_p = R @ X_c + T`` (mm)."""

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
        kind = data.get("kind", "camera-projector")
        if kind == "stereo":
            raise BistairError("a stereo calibration (two cameras: for bistair stereo), not a "
                               "camera-projector one")
        if kind != "camera-projector":
            raise BistairError(f"calibration kind {kind!r} is not a camera-projector one")
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


def save_calibration(calibration: Calibration, path: str | Path) -> Path:
    """Write the calibration JSON file atomically; returns ``path``.

    The file has the layout of the module docstring (2-space indent, final newline); it is
    written to a temporary file beside ``path`` and renamed onto it
    (:func:`~bistair.io.atomic.output_file`), so a reader never sees half a file.

    Parameters
    ----------
    calibration : Calibration
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
    >>> proj = Device(800, 600, [[1000.0, 0, 399.5], [0, 1000, 299.5], [0, 0, 1]])
    >>> path = save_calibration(Calibration(cam, proj, np.eye(3), [-150.0, 0, 0]),
    ...                         tmp / "calibration.json")
    >>> data = json.loads(path.read_text())
    >>> data["format"], data["baseline"], data["camera"]["dist"]
    ('bistair-calibration', 150.0, [0.0, 0.0, 0.0, 0.0, 0.0])
    >>> shutil.rmtree(tmp)
    """
    path = Path(path)
    with output_file(path) as tmp:
        tmp.write_text(json.dumps(calibration.to_dict(), indent=2) + "\n")
    return path


def load_calibration(path: str | Path) -> Calibration:
    """Read and validate a calibration file (one-line :class:`BistairError` if it cannot).

    Parameters
    ----------
    path : str or Path
        A calibration JSON file (layout in the module docstring), e.g. from
        :func:`save_calibration` or ``bistair calibrate``.

    Returns
    -------
    Calibration
        The devices, ``R, T`` (``X_p = R @ X_c + T``, mm) and whatever else the file holds
        (RMS figures, poses, board, uncertainty).

    Raises
    ------
    BistairError
        If the file is missing, unreadable or not JSON, or is not a valid bistair
        calibration (wrong format or version, a missing or malformed field, ``R`` not a
        rotation); the message names the file.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
    >>> proj = Device(800, 600, [[1000.0, 0, 399.5], [0, 1000, 299.5], [0, 0, 1]])
    >>> path = save_calibration(Calibration(cam, proj, np.eye(3), [-150.0, 0, 0], rms=0.2),
    ...                         tmp / "calibration.json")
    >>> cal = load_calibration(path)
    >>> cal.baseline, cal.rms, cal.projector.size
    (150.0, 0.2, (800, 600))
    >>> _ = (tmp / "other.json").write_text('{"format": "something-else"}')
    >>> load_calibration(tmp / "other.json")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: calibration file .../other.json: not a bistair calibration ...
    >>> shutil.rmtree(tmp)
    """
    path = Path(path)
    data = read_json(path, "calibration file")
    try:
        return Calibration.from_dict(data)
    except BistairError as exc:
        raise BistairError(f"calibration file {path}: {exc}") from None
