"""Projector-camera calibration: the projector as an inverse camera (Zhang and Huang, Opt.
Eng. 45(8), 083601, 2006).

For every pose of a planar board the board features are found in the camera's white frame;
the absolute phases of both orientations map each feature to projector pixels (a robust local
quadratic fit to the decoded projector x and y around the feature); the camera and the
projector are calibrated like two cameras with the same model points (``cv2.calibrateCamera``)
and then as a pair (``cv2.stereoCalibrate``), giving ``R, T`` with ``X_p = R @ X_c + T``
(camera frame to projector frame, millimetres; the convention of :mod:`bistair.sim`).

Capture layout (``calibrate_folder``)::

    calib/
      board.json            {"type": "checkerboard", "columns": 9, "rows": 6, "spacing": 20.0}
      pose-00/columns/      images in name order + spec.json (orientation columns, white=1)
      pose-00/rows/         images in name order + spec.json (orientation rows, white=1)
      pose-01/...

Every sub-folder holding ``columns/`` and ``rows/`` is a pose (in natural name order); both
specs must code the same projector size. ``board.json``: see :mod:`bistair.board`
(``columns x rows`` inner corners or circles, ``spacing`` in mm).

Calibration file (JSON, :func:`save_calibration`)::

    {"format": "bistair-calibration", "version": 1,
     "camera":    {"width": W, "height": H, "K": 3x3, "dist": [k1, k2, p1, p2, k3], "rms": px},
     "projector": {... the same, for the projector ...},
     "R": 3x3, "T": [tx, ty, tz], "baseline": |T| (mm), "rms": stereo RMS (px),
     "poses": [{"name": ..., "features": n, "camera_rms": px, "projector_rms": px}, ...],
     "poses_used": n, "poses_total": m, "board": {...}}

Reprojection errors are those of the final (stereo) model.

Examples
--------
>>> rng = np.random.default_rng(0)
>>> cam = Device(640, 480, np.array([[800.0, 0, 320], [0, 800, 240], [0, 0, 1]]))
>>> proj = Device(800, 600, np.array([[1000.0, 0, 400], [0, 1000, 400], [0, 0, 1]]))
>>> truth = Calibration(cam, proj, cv2.Rodrigues(np.array([0.0, 0.3, 0.0]))[0],
...                     np.array([-150.0, 0.0, 45.0]))
>>> obj, cpts, ppts = synthetic_views(truth, Board(columns=8, rows=6, spacing=15), 6, rng)
>>> cal = calibrate_points(obj, cpts, ppts, (640, 480), (800, 600))
>>> round(cal.baseline, 3), round(float(cal.projector.K[0, 0]), 2), cal.rms < 1e-3
(156.605, 1000.0, True)
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from .board import Board
from .errors import BistairError
from .io import natural_key, output_file, read_captures
from .jsonfile import read_json
from .spec import BaseSpec, load_spec

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


# -- the maths on correspondences --------------------------------------------------------------
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
    """
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
    return Calibration(Device(*camera_size, kc, dc.ravel(), float(np.sqrt(sc.sum() / n.sum()))),
                       Device(*projector_size, kp, dp.ravel(),
                              float(np.sqrt(sp.sum() / n.sum()))),
                       rot, t.ravel(), float(rms), poses)


def synthetic_views(calibration: Calibration, board: Board, poses: int,
                    rng: np.random.Generator, noise: float = 0.0, distance: float = 600.0
                    ) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
    """Random board poses seen by both devices of ``calibration``: object points and the
    camera and projector pixels of each pose (``cv2.projectPoints``, Gaussian ``noise`` px).

    The board is tilted by up to 25 degrees about x and y and turned about its normal, near
    ``(0, 0, distance)``; every point falls inside both images.
    """
    obj = board.object_points().astype(float)
    centre = obj.mean(axis=0)
    views: tuple[list, list, list] = ([], [], [])
    for _ in range(100 * poses):
        if len(views[0]) == poses:
            return views
        rvec = np.deg2rad([rng.uniform(-25, 25), rng.uniform(-25, 25), rng.uniform(-20, 20)])
        rot = cv2.Rodrigues(rvec)[0]
        tvec = np.array([rng.uniform(-30, 30), rng.uniform(-30, 30),
                         distance + rng.uniform(-60, 60)]) - rot @ centre
        world = obj @ rot.T + tvec
        pix = [cv2.projectPoints(world @ r.T + t, np.zeros(3), np.zeros(3), d.K, d.dist)[0]
               .reshape(-1, 2) + (rng.normal(0, noise, (len(obj), 2)) if noise else 0.0)
               for d, r, t in ((calibration.camera, np.eye(3), np.zeros(3)),
                               (calibration.projector, calibration.R, calibration.T))]
        if all(((p >= 0) & (p <= np.array(d.size) - 1)).all()
               for p, d in zip(pix, (calibration.camera, calibration.projector), strict=True)):
            for out, value in zip(views, (obj.astype(np.float32), *pix), strict=True):
                out.append(value)
    raise BistairError("the board rarely falls inside both images; check the geometry")


# -- from phases to projector pixels -----------------------------------------------------------
def sample_local(values: np.ndarray, points: np.ndarray, radius: int, min_pixels: int = 12,
                 rounds: int = 3) -> np.ndarray:
    """Robust values of smooth maps at sub-pixel points: a weighted quadratic fit per point.

    Parameters
    ----------
    values : ``(C, H, W)`` maps (e.g. projector x and y per camera pixel), NaN where invalid.
    points : ``(N, 2)`` pixel coordinates ``(u, v)``.
    radius : half-size of the square window around each point (pixels).
    min_pixels : fewest pixels valid in every map that a fit needs.
    rounds : fits; after each, pixels off by more than 3.5 robust sigmas (at least 0.1) are
        dropped (e.g. a wrong fringe order).

    Returns
    -------
    ``(C, N)`` fitted values at the points, NaN where the window holds too few valid pixels or
    they do not surround the point.

    Examples
    --------
    >>> v, u = np.mgrid[0:40, 0:50].astype(float)
    >>> maps = np.stack([2 * u + 0.01 * v**2, 3 * v])
    >>> maps[0, 20, 21] = 500.0  # an outlier
    >>> sample_local(maps, np.array([[20.3, 19.6], [0.0, 45.0]]), 4).round(4).tolist()
    [[44.4416, nan], [58.8, nan]]
    """
    values = np.asarray(values, float)
    h, w = values.shape[1:]
    pts = np.asarray(points, float).reshape(-1, 2)
    off = np.arange(-radius, radius + 1)
    uu = np.rint(pts[:, 0])[:, None, None].astype(int) + off[None, None, :]
    vv = np.rint(pts[:, 1])[:, None, None].astype(int) + off[None, :, None]
    uu, vv = np.broadcast_arrays(uu, vv)
    inside = (uu >= 0) & (uu < w) & (vv >= 0) & (vv < h)
    vals = values[:, np.clip(vv, 0, h - 1), np.clip(uu, 0, w - 1)].reshape(len(values),
                                                                           len(pts), -1)
    good = (inside.reshape(len(pts), -1) & np.isfinite(vals).all(axis=0))
    vals = np.where(good, vals, 0.0)
    du = ((uu - pts[:, 0, None, None]) / radius).reshape(len(pts), -1)
    dv = ((vv - pts[:, 1, None, None]) / radius).reshape(len(pts), -1)
    design = np.stack([np.ones_like(du), du, dv, du * du, du * dv, dv * dv], axis=-1)
    weight = good.astype(float)
    coef = np.zeros((len(values), len(pts), 6))
    for _ in range(rounds):
        normal = np.einsum("npi,np,npj->nij", design, weight, design) + 1e-9 * np.eye(6)
        rhs = np.einsum("npi,np,cnp->cni", design, weight, vals)
        coef = np.linalg.solve(normal[None], rhs[..., None])[..., 0]
        resid = np.abs(vals - np.einsum("npi,cni->cnp", design, coef)).max(axis=0)
        masked = np.where(weight > 0, resid, np.nan)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN windows
            sigma = 1.4826 * np.nanmedian(masked, axis=1)
        limit = np.maximum(3.5 * np.nan_to_num(sigma, nan=0.0), 0.1)
        weight = weight * (resid <= limit[:, None])
    # the kept pixels must surround the point: some on every side of it
    kept = weight > 0
    sides = [(du < 0) & kept, (du > 0) & kept, (dv < 0) & kept, (dv > 0) & kept]
    ok = (kept.sum(axis=1) >= min_pixels) & np.all([s.any(axis=1) for s in sides], axis=0)
    return np.where(ok, coef[..., 0], np.nan)


@dataclass(frozen=True)
class PoseCapture:
    """One board pose in memory: the camera's white frame and the projector column ``x`` and
    row ``y`` decoded per camera pixel (NaN where invalid)."""

    name: str
    white: np.ndarray
    x: np.ndarray
    y: np.ndarray


def feature_spacing(points: np.ndarray, columns: int) -> float:
    """Median image distance between neighbouring features of a row-by-row grid (pixels)."""
    grid = np.asarray(points, float).reshape(-1, columns, 2)
    steps = np.concatenate([np.diff(grid, axis=1).reshape(-1, 2),
                            np.diff(grid, axis=0).reshape(-1, 2)])
    return float(np.median(np.hypot(steps[:, 0], steps[:, 1])))


def calibrate_poses(poses: Sequence[PoseCapture], board: Board,
                    projector_size: tuple[int, int], min_poses: int = 3,
                    min_mapped: float = 0.5, **options: Any) -> Calibration:
    """Detect the board, map its features through the phases and calibrate
    (:func:`calibrate_points`; ``options`` go there).

    A pose is used when the board is found in its white frame and at least ``min_mapped`` of
    its features get projector coordinates in both orientations.
    """
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
    found = [(pose, board.detect(pose.white)) for pose in poses]
    found = [(pose, pts) for pose, pts in found if pts is not None]
    if len(found) < min_poses:
        raise BistairError(f"board found in {len(found)} of {len(poses)} poses, need at least "
                           f"{min_poses}")
    model = board.object_points()
    obj, cam, proj, names = [], [], [], []
    for pose, pts in found:
        spacing = feature_spacing(pts, board.columns)
        share = 0.35 if board.type == "checkerboard" else 0.5
        radius = int(np.clip(round(share * spacing), 3, 30))
        xy = sample_local(np.stack([pose.x, pose.y]), pts, radius).T
        ok = np.isfinite(xy).all(axis=1)
        if ok.mean() >= min_mapped and ok.sum() >= 6:
            obj.append(model[ok])
            cam.append(pts[ok])
            proj.append(xy[ok])
            names.append(pose.name)
    if len(obj) < min_poses:
        raise BistairError(f"board features mapped to the projector in {len(obj)} of "
                           f"{len(poses)} poses, need at least {min_poses} (are the phases "
                           "valid on the board?)")
    cal = calibrate_points(obj, cam, proj, (size[1], size[0]), projector_size, names,
                           **options)
    return Calibration(cal.camera, cal.projector, cal.R, cal.T, cal.rms, cal.poses,
                       board.to_dict(), len(poses))


# -- folders --------------------------------------------------------------------------------
def pose_folders(folder: Path) -> list[Path]:
    """The pose sub-folders of a calibration capture folder (natural name order)."""
    subs = sorted((p for p in folder.iterdir() if p.is_dir()), key=lambda p: natural_key(p.name))
    poses = []
    for sub in subs:
        have = [(sub / o).is_dir() for o in ("columns", "rows")]
        if all(have):
            poses.append(sub)
        elif any(have):
            missing = "rows" if have[0] else "columns"
            raise BistairError(f"pose {sub.name} has no {missing}/ folder")
    return poses


def read_pose(folder: Path, orientation: str) -> tuple[np.ndarray, np.ndarray, BaseSpec]:
    """Decode one orientation of a pose: the projector coordinate, the white frame, the spec."""
    from . import decode

    sub = folder / orientation
    spec = load_spec(sub / "spec.json")
    where = f"{folder.name}/{orientation}"
    if spec.orientation != orientation:
        raise BistairError(f"{where}/spec.json codes {spec.orientation}, the folder is for "
                           f"{orientation}")
    if not spec.white:
        raise BistairError(f"{where}/spec.json has no white frame (white=1 is needed to "
                           "find the board)")
    try:
        result = decode(read_captures(sub), spec)
    except BistairError as exc:
        raise BistairError(f"{where}: {exc}") from None
    return result.coord, result.texture, spec


def calibrate_folder(folder: str | Path, out: str | Path | None = None,
                     board: Board | str | Path | None = None, min_poses: int = 3,
                     **options: Any) -> Calibration:
    """Calibrate from a capture folder (layout in the module docstring); write the
    calibration file to ``out`` (atomically) if given. ``options`` go to
    :func:`calibrate_poses` and :func:`calibrate_points` (``fix_k3``, ``refine``)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise BistairError(f"calibration captures {folder} not found")
    if not isinstance(board, Board):
        board = Board.load(folder / "board.json" if board is None else board)
    folders = pose_folders(folder)
    if not folders:
        raise BistairError(f"no pose folders with columns/ and rows/ in {folder}")
    poses, proj_size, cam_size = [], None, None
    for sub in folders:
        x, white, sx = read_pose(sub, "columns")
        y, _, sy = read_pose(sub, "rows")
        for s, o in ((sx, "columns"), (sy, "rows")):
            if proj_size is None:
                proj_size = (s.width, s.height)
            elif (s.width, s.height) != proj_size:
                raise BistairError(f"{sub.name}/{o}/spec.json is for a {s.width}x{s.height} "
                                   f"projector, earlier specs for {proj_size[0]}x{proj_size[1]}")
        for arr, o in ((x, "columns"), (y, "rows")):
            if cam_size is None:
                cam_size = arr.shape
            elif arr.shape != cam_size:
                raise BistairError(f"{sub.name}/{o} images are {arr.shape[1]}x{arr.shape[0]}, "
                                   f"earlier ones {cam_size[1]}x{cam_size[0]}")
        poses.append(PoseCapture(sub.name, white, x, y))
    assert proj_size is not None
    cal = calibrate_poses(poses, board, proj_size, min_poses=min_poses, **options)
    if out is not None:
        save_calibration(cal, out)
    return cal
