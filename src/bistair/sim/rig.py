"""Pinhole camera and projector models (OpenCV conventions) and the rig that holds them.

Conventions follow OpenCV exactly: x right, y down, z forward; pixel centres at integer
coordinates; distortion ``(k1, k2, p1, p2, k3)`` applied to normalised coordinates before the
intrinsics. The world frame is the camera frame; a device's pose ``(R, t)`` maps world points
into its frame, ``X_dev = R @ X + t`` (what ``cv2.stereoCalibrate`` reports for the projector).
Units are millimetres.

Examples
--------
>>> import numpy as np
>>> rig = Rig.default(camera_size=(64, 48), projector_size=(96, 54))
>>> rig.camera.width, rig.projector.width, rig.projector.center.round(3).tolist()
(64, 96, [200.0, 0.0, 0.0])
>>> uv = rig.camera.project(np.array([[0.0, 0.0, 600.0]]))
>>> uv.round(3).tolist()  # the optical axis meets the principal point
[[31.5, 23.5]]
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import cv2
import numpy as np
from numpy.typing import ArrayLike

from ..errors import BistairError

_NO_DIST = (0.0, 0.0, 0.0, 0.0, 0.0)
_EYE = np.eye(3)


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot product of ``(N, 3)`` vectors with ``(N, 3)`` vectors or one ``(3,)``."""
    if b.ndim == 1:
        return a @ b
    return np.einsum("ij,ij->i", a, b)


def apply(m: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``points @ m.T`` for ``(N, 3)`` points (``points`` itself if ``m`` is the identity)."""
    if m is _EYE or np.array_equal(m, _EYE):
        return points
    return (m @ points.T).T


def euler(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    """Rotation matrix ``Rz @ Ry @ Rx`` from angles in degrees about the x, y and z axes.

    Examples
    --------
    >>> euler(z=90).round(6).tolist()
    [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    """
    ax, ay, az = np.deg2rad([x, y, z])
    rx = np.array([[1, 0, 0], [0, np.cos(ax), -np.sin(ax)], [0, np.sin(ax), np.cos(ax)]])
    ry = np.array([[np.cos(ay), 0, np.sin(ay)], [0, 1, 0], [-np.sin(ay), 0, np.cos(ay)]])
    rz = np.array([[np.cos(az), -np.sin(az), 0], [np.sin(az), np.cos(az), 0], [0, 0, 1]])
    return rz @ ry @ rx


def distort(x: np.ndarray, y: np.ndarray, dist: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """OpenCV's distortion of normalised coordinates ``(x, y) = (X/Z, Y/Z)``."""
    if not any(dist):
        return x, y
    k1, k2, p1, p2, k3 = dist
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
    yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
    return xd, yd


def undistort(xd: np.ndarray, yd: np.ndarray, dist: Sequence[float],
              iterations: int = 30) -> tuple[np.ndarray, np.ndarray]:
    """Invert :func:`distort` by Newton's method (to machine precision for usual lenses)."""
    k1, k2, p1, p2, k3 = dist
    xd, yd = np.asarray(xd, float), np.asarray(yd, float)
    if not any(dist):
        return xd.copy(), yd.copy()
    x, y = xd.copy(), yd.copy()
    for _ in range(iterations):
        r2 = x * x + y * y
        radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        drad = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2)
        fx, fy = distort(x, y, dist)
        ex, ey = fx - xd, fy - yd
        a = radial + 2.0 * x * x * drad + 2.0 * p1 * y + 6.0 * p2 * x
        b = 2.0 * x * y * drad + 2.0 * p1 * x + 2.0 * p2 * y
        d = radial + 2.0 * y * y * drad + 6.0 * p1 * y + 2.0 * p2 * x
        det = a * d - b * b
        x = x - (d * ex - b * ey) / det
        y = y - (a * ey - b * ex) / det
        if max(np.abs(ex).max(initial=0.0), np.abs(ey).max(initial=0.0)) < 1e-15:
            break
    return x, y


MIN_SIDE, MAX_SIDE = 8, 8192  # pixels per side of a simulated device


def check_size(size: Sequence[int], device: str = "camera") -> tuple[int, int]:
    """A simulated device's ``(width, height)``: whole numbers of pixels from
    :data:`MIN_SIDE` (what a decode needs) to :data:`MAX_SIDE` per side (ray tracing takes
    about 150 bytes per pixel: 8192 x 8192 needs some 10 GB).

    Raises
    ------
    BistairError
        If ``size`` is not two whole numbers in that range.

    Examples
    --------
    >>> check_size((640, 512))
    (640, 512)
    >>> check_size((0, 0))
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: camera size 0x0 must be 8 to 8192 whole pixels per side
    """
    try:
        width, height = size
    except (TypeError, ValueError):
        raise BistairError(f"{device} size must be (width, height), got {size!r}") from None
    sides = [v if isinstance(v, int | np.integer) and not isinstance(v, bool) else None
             for v in (width, height)]
    if any(v is None or not MIN_SIDE <= v <= MAX_SIDE for v in sides):
        raise BistairError(f"{device} size {width}x{height} must be {MIN_SIDE} to {MAX_SIDE} whole "
                           "pixels per side")
    return int(width), int(height)


@dataclass(frozen=True, eq=False)
class Pinhole:
    """A pinhole device: resolution, intrinsics, OpenCV distortion and pose.

    Parameters
    ----------
    width, height : pixels.
    fx, fy, cx, cy : intrinsics in pixels (pixel centres at integer coordinates).
    dist : ``(k1, k2, p1, p2, k3)``, OpenCV order.
    R, t : pose mapping world points into the device frame, ``X_dev = R @ X + t``.
    """

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    dist: tuple[float, float, float, float, float] = _NO_DIST
    R: np.ndarray = field(default_factory=lambda: np.eye(3))
    t: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        object.__setattr__(self, "dist", tuple(float(d) for d in self.dist))
        if len(self.dist) != 5:
            raise ValueError("dist must hold (k1, k2, p1, p2, k3)")
        object.__setattr__(self, "R", np.asarray(self.R, float).reshape(3, 3))
        object.__setattr__(self, "t", np.asarray(self.t, float).reshape(3))

    @property
    def K(self) -> np.ndarray:  # noqa: N802 - the usual name
        """The 3x3 intrinsic matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def dist_coeffs(self) -> np.ndarray:
        """Distortion as the array OpenCV takes."""
        return np.array(self.dist)

    @property
    def rvec(self) -> np.ndarray:
        """The rotation as an OpenCV rotation vector (``cv2.Rodrigues``)."""
        return cv2.Rodrigues(self.R)[0].ravel()

    @property
    def center(self) -> np.ndarray:
        """Optical centre in world coordinates."""
        return -self.R.T @ self.t

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)``."""
        return self.width, self.height

    def to_device(self, points: ArrayLike) -> np.ndarray:
        """World points ``(..., 3)`` in the device frame."""
        p = np.asarray(points, float)
        if p.ndim != 2:
            return p @ self.R.T + self.t
        return apply(self.R, p) + self.t

    def project(self, points: ArrayLike) -> np.ndarray:
        """Pixel coordinates ``(..., 2)`` of world points (as ``cv2.projectPoints``).

        Points at or behind the device plane (``z <= 0``) give NaN.
        """
        p = self.to_device(points)
        z = p[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.where(z > 0, z, np.nan)
            xd, yd = distort(p[..., 0] / z, p[..., 1] / z, self.dist)
        return np.stack([self.fx * xd + self.cx, self.fy * yd + self.cy], axis=-1)

    def rays(self, u: ArrayLike, v: ArrayLike) -> np.ndarray:
        """World directions ``(..., 3)`` of the rays through pixel coordinates ``(u, v)``.

        Each direction has device-frame ``z = 1``, so a point ``center + s * d`` lies at
        depth ``s`` in the device frame.
        """
        x, y = undistort((np.asarray(u, float) - self.cx) / self.fx,
                         (np.asarray(v, float) - self.cy) / self.fy, self.dist)
        if x.ndim != 1:
            return np.stack([x, y, np.ones_like(x)], axis=-1) @ self.R
        d = np.empty((x.size, 3), order="F")  # column-major: fast per-component work
        d[:, 0], d[:, 1], d[:, 2] = x, y, 1.0
        return apply(self.R.T, d)


class Camera(Pinhole):
    """The camera (normally at the world origin, ``R = I``, ``t = 0``)."""


class Projector(Pinhole):
    """The projector; its pose maps world (camera-frame) points into projector coordinates."""


def look_rotation(yaw_deg: float, roll_deg: float = 0.0) -> np.ndarray:
    """World-to-device rotation of a device yawed about world y, then rolled about its axis.

    Positive yaw turns the optical axis from +z toward -x (toward the scene centre for a
    device to the right of the camera).
    """
    a, r = np.deg2rad(yaw_deg), np.deg2rad(roll_deg)
    x_axis = np.array([np.cos(a), 0.0, np.sin(a)])
    y_axis = np.array([0.0, 1.0, 0.0])
    z_axis = np.array([-np.sin(a), 0.0, np.cos(a)])
    rx = np.cos(r) * x_axis + np.sin(r) * y_axis
    ry = -np.sin(r) * x_axis + np.cos(r) * y_axis
    return np.stack([rx, ry, z_axis])


@dataclass(frozen=True, eq=False)
class Rig:
    """A camera (the world frame) and a projector, and the working distance (mm)."""

    camera: Camera
    projector: Projector
    working_distance: float = 600.0

    @classmethod
    def default(cls, camera_size: tuple[int, int] = (1280, 1024),
                projector_size: tuple[int, int] = (1920, 1080),
                camera_focal: float | None = None, projector_focal: float = 2000.0,
                working_distance: float = 600.0, baseline: float = 200.0,
                convergence_deg: float | None = None, roll_deg: float = 0.0,
                camera_dist: Sequence[float] = _NO_DIST,
                projector_dist: Sequence[float] = _NO_DIST,
                projector_principal: tuple[float, float] | None = None) -> Rig:
        """A camera at the origin and a projector ``baseline`` mm to its right (+x).

        Parameters
        ----------
        camera_size, projector_size : ``(width, height)`` in pixels (MER-130 camera,
            1920 x 1080 projector by default).
        camera_focal : camera focal length in pixels (default ``1.875 * width``, 2400 px at
            1280 wide, so a smaller camera sees the same field of view).
        projector_focal : projector focal length in pixels.
        working_distance : depth of the scene centre ``(0, 0, working_distance)``.
        baseline : projector centre at ``(baseline, 0, 0)``.
        convergence_deg : yaw of the projector toward -x (default: aimed at the scene
            centre, ``atan(baseline / working_distance)``).
        roll_deg : rotation of the projector about its optical axis.
        camera_dist, projector_dist : OpenCV ``(k1, k2, p1, p2, k3)``.
        projector_principal : ``(cx, cy)``, default the image centre.
        """
        cw, ch = check_size(camera_size, "camera")
        pw, ph = check_size(projector_size, "projector")
        fc = 1.875 * cw if camera_focal is None else float(camera_focal)
        camera = Camera(cw, ch, fc, fc, (cw - 1) / 2, (ch - 1) / 2, tuple(camera_dist))
        if convergence_deg is None:
            convergence_deg = float(np.rad2deg(np.arctan2(baseline, working_distance)))
        rot = look_rotation(convergence_deg, roll_deg)
        pcx, pcy = projector_principal or ((pw - 1) / 2, (ph - 1) / 2)
        projector = Projector(pw, ph, projector_focal, projector_focal, pcx, pcy,
                              tuple(projector_dist), rot,
                              -rot @ np.array([baseline, 0.0, 0.0]))
        return cls(camera, projector, working_distance)

    @property
    def scene_center(self) -> np.ndarray:
        """The point both devices aim at, ``(0, 0, working_distance)``."""
        return np.array([0.0, 0.0, self.working_distance])

    @property
    def projector_distance(self) -> float:
        """Distance from the projector centre to the scene centre (mm)."""
        return float(np.linalg.norm(self.scene_center - self.projector.center))
