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
     "poses_used": n, "poses_total": m, "board": {...}}

Examples
--------
>>> cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
>>> proj = Device(800, 600, [[1000.0, 0, 399.5], [0, 1000, 299.5], [0, 0, 1]], [0.1, 0, 0, 0])
>>> cal = Calibration(cam, proj, np.eye(3), [-150.0, 0.0, 0.0])
>>> cal.baseline, proj.dist.tolist()
(150.0, [0.1, 0.0, 0.0, 0.0, 0.0])
>>> Calibration.from_dict(cal.to_dict()).T.tolist()
[-150.0, 0.0, 0.0]
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import BistairError
from ..io.files import output_file
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

    def __post_init__(self) -> None:
        object.__setattr__(self, "R", np.asarray(self.R, float).reshape(3, 3))
        object.__setattr__(self, "T", np.asarray(self.T, float).reshape(3))

    @property
    def baseline(self) -> float:
        """Distance between the camera and projector centres (mm)."""
        return float(np.linalg.norm(self.T))

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
                "poses_total": self.poses_total, "board": self.board}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Calibration:
        """Validate and build from the dictionary of a calibration file."""
        if not isinstance(data, Mapping) or data.get("format") != FORMAT:
            raise BistairError(f"not a bistair calibration (no \"format\": \"{FORMAT}\")")
        if data.get("version") != VERSION:
            raise BistairError(f"calibration version {data.get('version')!r} is not supported")
        devices = [_device(data, name) for name in ("camera", "projector")]
        rot = _array(data, "R", ((3, 3),))
        if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-6) or np.linalg.det(rot) < 0:
            raise BistairError("calibration field 'R' is not a rotation matrix")
        return cls(*devices, rot, _array(data, "T", ((3,),)), data.get("rms"),
                   tuple(data.get("poses") or ()), data.get("board"), data.get("poses_total"))


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


def _device(data: Mapping[str, Any], name: str) -> Device:
    dev = data.get(name)
    if not isinstance(dev, Mapping):
        raise BistairError(f"calibration misses the object '{name}'")
    width, height = (_array(dev, key, ((),), f"{name}.") for key in ("width", "height"))
    if min(width, height) < 1 or width != int(width) or height != int(height):
        raise BistairError(f"calibration {name} width and height must be positive integers")
    dist = _array(dev, "dist", ((4,), (5,)), f"{name}.")  # k1, k2, p1, p2[, k3]
    rms = dev.get("rms")
    return Device(int(width), int(height), _array(dev, "K", ((3, 3),), f"{name}."),
                  dist,
                  float(rms) if isinstance(rms, int | float) else None)


def save_calibration(calibration: Calibration, path: str | Path) -> Path:
    """Write the calibration JSON file atomically; returns ``path``."""
    path = Path(path)
    with output_file(path) as tmp:
        tmp.write_text(json.dumps(calibration.to_dict(), indent=2) + "\n")
    return path


def load_calibration(path: str | Path) -> Calibration:
    """Read and validate a calibration file (one-line :class:`BistairError` if it cannot)."""
    path = Path(path)
    data = read_json(path, "calibration file")
    try:
        return Calibration.from_dict(data)
    except BistairError as exc:
        raise BistairError(f"calibration file {path}: {exc}") from None
