"""From absolute phase to 3-D points: triangulation with a calibrated rig, point clouds,
depth maps, views, and a reference-plane phase-to-height mode for uncalibrated setups.

Triangulation. A valid camera pixel's ray ``X = z * (x, y, 1)`` (``(x, y)`` undistorted
through the camera model) meets the surface of projector points whose coded coordinate (the
column ``x_p`` for ``orientation="columns"``, the row ``y_p`` for ``"rows"``), projected with
the projector's distortion, equals the decoded one. The depth ``z`` starts at the
distortion-free ray-plane intersection and is refined by vectorised Newton steps on the
projector's own projection, so distortion is honoured exactly. Points are in the camera
frame, millimetres.

Reference-plane mode (:class:`HeightModel`). Without a calibration, height above a flat
reference plane follows from the shift ``d = x_p - x_ref`` of the projector coordinate
against the reference (the same spec on the empty plane). Along one camera ray the projector
coordinate is a linear-fractional function of the height for a pinhole projector, so per
pixel ``h = d / (a - c * d)`` exactly: the classical ``h = L * dPhi / (dPhi - 2*pi*f0*b)``
(Takeda and Mutoh, Appl. Opt. 22(24), 1983; camera-plane distance ``L``, baseline ``b``,
fringe frequency ``f0`` on the plane) is the special case ``a = -T*f0*b/L``, ``c = -1/L``
with constant coefficients. :meth:`HeightModel.fit` measures ``a`` and ``c`` per pixel from
two or more planes parallel to the reference at known heights, which absorbs the geometry
and the camera's distortion (not the projector's).

Examples
--------
>>> cal = _toy_calibration()
>>> pixels = np.array([[320.0, 240.0], [100.0, 400.0]])
>>> point = np.array([[10.0, -20.0, 600.0]])
>>> uv = cal.camera.K @ point[0] / point[0, 2]
>>> xp = cal.projector.K @ (cal.R @ point[0] + cal.T)
>>> triangulate(uv[None, :2], np.array([xp[0] / xp[2]]), cal).round(6).tolist()
[[10.0, -20.0, 600.0]]
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import imageio.v3 as iio
import numpy as np

from .calib import Calibration, Device, load_calibration
from .errors import BistairError
from .io import output_file, output_folder
from .preview import colorize
from .result import DecodeResult
from .spec import BaseSpec

_UNDISTORT = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 50, 1e-14)


@dataclass
class Reconstruction:
    """Per camera pixel: ``points`` (H, W, 3) float32 mm in the camera frame and ``depth``
    (H, W) float32 ``z`` (NaN where invalid), ``colors`` (H, W, 3) uint8, ``mask``."""

    points: np.ndarray
    depth: np.ndarray
    colors: np.ndarray
    mask: np.ndarray

    def cloud(self) -> tuple[np.ndarray, np.ndarray]:
        """The valid points ``(N, 3)`` float32 and their colours ``(N, 3)`` uint8."""
        return self.points[self.mask], self.colors[self.mask]


def _project_coded(dev: Device, pts: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coordinates (coded axis, other axis) of device-frame points ``(N, 3)``."""
    k1, k2, p1, p2, k3 = dev.dist
    with np.errstate(divide="ignore", invalid="ignore"):
        x, y = pts[:, 0] / pts[:, 2], pts[:, 1] / pts[:, 2]
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    u = dev.K[0, 0] * xd + dev.K[0, 1] * yd + dev.K[0, 2]
    v = dev.K[1, 1] * yd + dev.K[1, 2]
    return (u, v) if axis == 0 else (v, u)


def triangulate(pixels: np.ndarray, coord: np.ndarray, calibration: Calibration,
                orientation: str = "columns", iterations: int = 12, tolerance: float = 1e-4,
                sensitivity: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """3-D points (camera frame, mm) of camera ``pixels`` ``(N, 2)`` whose decoded projector
    coordinate along the coded axis is ``coord`` ``(N,)``; NaN rows where there is no
    solution in front of both devices inside the projector image (to ``tolerance`` px).

    With ``sensitivity``, also the depth change per projector pixel, ``|dz/dcoord|``."""
    cam, proj = calibration.camera, calibration.projector
    axis = 0 if orientation == "columns" else 1
    pix = np.asarray(pixels, np.float64).reshape(-1, 1, 2)
    target = np.asarray(coord, np.float64).ravel()
    if not len(target):
        return (np.zeros((0, 3)), np.zeros(0)) if sensitivity else np.zeros((0, 3))
    norm = cv2.undistortPoints(pix, cam.K, cam.dist, criteria=_UNDISTORT).reshape(-1, 2)
    ray = np.column_stack([norm, np.ones(len(norm))])
    a = ray @ calibration.R.T  # projector-frame point = z * a + T
    t = calibration.T
    # distortion-free start: the ray meets the plane of projector points with this coordinate
    m = (target - proj.K[axis, 2]) / proj.K[axis, axis]
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (m * t[2] - t[axis]) / (a[:, axis] - m * a[:, 2])
        for _ in range(iterations):
            step = 1e-3 * np.abs(z) + 1e-9
            f0 = _project_coded(proj, z[:, None] * a + t, axis)[0] - target
            f1 = _project_coded(proj, (z + step)[:, None] * a + t, axis)[0] - target
            dz = f0 * step / (f1 - f0)
            z = z - dz
            if not np.nanmax(np.abs(dz) / np.abs(z), initial=0.0) > 1e-12:
                break
        pts_p = z[:, None] * a + t
        coded, other = _project_coded(proj, pts_p, axis)
        span = proj.size[1 - axis]
        ok = ((z > 0) & (pts_p[:, 2] > 0) & (np.abs(coded - target) <= tolerance)
              & (other >= -0.5) & (other <= span - 0.5))
        points = np.where(ok[:, None], z[:, None] * ray, np.nan)
        if not sensitivity:
            return points
        step = 1e-3 * np.abs(z) + 1e-9
        slope = (_project_coded(proj, (z + step)[:, None] * a + t, axis)[0] - coded) / step
        return points, np.where(ok, 1.0 / np.abs(slope), np.nan)


def _grey_colors(result: DecodeResult, spec: BaseSpec | None) -> np.ndarray:
    if result.texture is not None:
        grey = np.asarray(result.texture, float)
    else:
        grey = np.asarray(result.average, float) / (spec.offset if spec else 0.5)
    grey = np.round(np.clip(np.nan_to_num(grey), 0.0, 1.0) * 255).astype(np.uint8)
    return np.repeat(grey[..., None], 3, axis=2)


def check_fit(result: DecodeResult, calibration: Calibration,
              spec: BaseSpec | str, orientation: str | None = None) -> str:
    """The coded orientation, after checking that captures, spec and calibration belong
    together (one-line :class:`BistairError` otherwise)."""
    coded = spec if isinstance(spec, str) else spec.orientation
    if coded not in ("columns", "rows"):
        raise BistairError(f"orientation must be 'columns' or 'rows', got {coded!r}")
    if orientation is not None and orientation != coded:
        raise BistairError(f"the spec codes {coded}, but {orientation} were asked for")
    cam, proj = calibration.camera, calibration.projector
    h, w = result.coord.shape
    if (w, h) != cam.size:
        raise BistairError(f"calibration is for {cam.width}x{cam.height} camera images, "
                           f"captures are {w}x{h}")
    if isinstance(spec, BaseSpec) and (spec.width, spec.height) != proj.size:
        raise BistairError(f"calibration is for a {proj.width}x{proj.height} projector, the "
                           f"spec for {spec.width}x{spec.height}")
    return coded


def reconstruct(result: DecodeResult, calibration: Calibration, spec: BaseSpec | str,
                orientation: str | None = None, min_depth: float = 0.0,
                max_depth: float = np.inf, **options: Any) -> Reconstruction:
    """Triangulate every valid pixel of a decode.

    ``spec`` is the spec of the captures (or just its orientation); ``orientation``, if
    given, is what the caller expects the spec to code. Depths outside ``[min_depth,
    max_depth]`` are dropped. ``options`` go to :func:`triangulate`. Colours are the white
    frame if the spec has one, else the fringes' average.
    """
    coded = check_fit(result, calibration, spec, orientation)
    h, w = result.coord.shape
    valid = np.flatnonzero(result.mask.ravel() & np.isfinite(result.coord.ravel()))
    pix = np.column_stack([valid % w, valid // w]).astype(float)
    pts, sens = triangulate(pix, result.coord.ravel()[valid], calibration, coded,
                            sensitivity=True, **options)
    _check_geometry(pts, sens, calibration, coded)
    with np.errstate(invalid="ignore"):
        keep = np.isfinite(pts[:, 2]) & (pts[:, 2] >= min_depth) & (pts[:, 2] <= max_depth)
    points = np.full((h * w, 3), np.nan, np.float32)
    points[valid[keep]] = pts[keep]
    points = points.reshape(h, w, 3)
    mask = np.isfinite(points[..., 2])
    return Reconstruction(points, points[..., 2].copy(), _grey_colors(
        result, spec if isinstance(spec, BaseSpec) else None), mask)


def _check_geometry(points: np.ndarray, sens: np.ndarray, calibration: Calibration,
                    coded: str) -> None:
    """Refuse a coded axis that carries almost no depth in this rig (baseline across it)."""
    ok = np.isfinite(sens)
    if ok.sum() < 10:
        return
    axis = 0 if coded == "columns" else 1
    dist = np.linalg.norm(points[ok] @ calibration.R.T + calibration.T, axis=1)
    ideal = np.median(dist) ** 2 / (calibration.projector.K[axis, axis] * calibration.baseline)
    ratio = float(np.median(sens[ok]) / ideal)
    if ratio > 8:
        other = "rows" if coded == "columns" else "columns"
        raise BistairError(f"projector {coded} barely change with depth in this rig "
                           f"({np.median(sens[ok]):.1f} mm per projector pixel, {ratio:.0f}x "
                           f"worse than along the baseline): capture {other} instead")


# -- writing ------------------------------------------------------------------------------------
def write_ply(path: str | Path, points: np.ndarray, colors: np.ndarray | None = None) -> Path:
    """Write a coloured point cloud as binary little-endian PLY (``x y z`` float32, ``red
    green blue`` uchar) atomically; readable by Open3D, MeshLab and plyfile."""
    from plyfile import PlyData, PlyElement

    pts = np.asarray(points, np.float32).reshape(-1, 3)
    cols = (np.full((len(pts), 3), 255, np.uint8) if colors is None
            else np.asarray(colors, np.uint8).reshape(-1, 3))
    vertex = np.empty(len(pts), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"),
                                       ("red", "u1"), ("green", "u1"), ("blue", "u1")])
    for i, name in enumerate("xyz"):
        vertex[name] = pts[:, i]
    for i, name in enumerate(("red", "green", "blue")):
        vertex[name] = cols[:, i]
    ply = PlyData([PlyElement.describe(vertex, "vertex")], text=False, byte_order="<",
                  comments=["bistair point cloud, camera frame, mm"])
    path = Path(path)
    with output_file(path) as tmp:
        ply.write(str(tmp))
    return path


def depth_files(depth: np.ndarray, folder: Path) -> None:
    """Write ``depth.npy`` (float32, NaN where invalid) and the ``depth.png`` preview."""
    depth = np.asarray(depth, np.float32)
    np.save(folder / "depth.npy", depth)
    ok = np.isfinite(depth)
    lo, hi = np.percentile(depth[ok], [1, 99]) if ok.any() else (0.0, 1.0)
    iio.imwrite(folder / "depth.png", colorize(depth, "turbo_r", float(lo), float(hi)))


def reconstruct_folder(captures: str | Path, spec: BaseSpec | str | Path | None,
                       calibration: Calibration | str | Path, out_ply: str | Path,
                       depth_dir: str | Path | None = None, orientation: str | None = None,
                       min_depth: float = 0.0, max_depth: float = np.inf,
                       **options: Any) -> Reconstruction:
    """Decode a capture folder (or ``.npy`` stack), triangulate it and write the PLY (and
    ``depth.npy``, ``depth.png`` into ``depth_dir``). ``spec`` defaults to
    ``CAPTURES/spec.json``; ``options`` go to the decoder. Nothing is written on error."""
    from . import decode
    from .workflow import read_with_spec

    stack, spec = read_with_spec(captures, spec)
    if not isinstance(calibration, Calibration):
        calibration = load_calibration(calibration)
    blank = DecodeResult(*(np.zeros(stack.shape[1:]),) * 8, period=1.0, method="")
    check_fit(blank, calibration, spec, orientation)  # before the work of decoding
    rec = reconstruct(decode(stack, spec, **options), calibration, spec, orientation,
                      min_depth, max_depth)
    pts, cols = rec.cloud()
    if depth_dir is None:
        write_ply(out_ply, pts, cols)
        return rec
    with output_folder(depth_dir) as tmp:
        depth_files(rec.depth, tmp)
        write_ply(out_ply, pts, cols)
    return rec


# -- views --------------------------------------------------------------------------------------
def render_cloud(points: np.ndarray, colors: np.ndarray | None = None,
                 path: str | Path | None = None, azimuth: float = 25.0,
                 elevation: float = 20.0, size: tuple[int, int] = (800, 600),
                 title: str | None = None) -> np.ndarray:
    """A shaded view of a point cloud from a viewpoint turned ``azimuth`` degrees about the
    camera's y axis and ``elevation`` degrees about its x axis.

    Orthographic and z-buffered, one point per cell of about the points' spacing, small
    holes filled from the nearest cell; Lambert shading from surface normals (from the pixel
    grid when ``points`` is organised ``(H, W, 3)`` like :attr:`Reconstruction.points`, else
    from the splatted depth) times the colours. Returns the RGB image ``(height, width, 3)``
    uint8 and writes it as PNG (matplotlib Agg, with an optional title) if ``path`` is given.

    Examples
    --------
    >>> v, u = np.mgrid[-40:40, -40:40] * 1.0
    >>> pts = np.stack([u, v, 500 + np.hypot(u, v) ** 2 / 80], axis=-1)
    >>> img = render_cloud(pts, size=(160, 120))
    >>> img.shape, bool(img[60, 80].all()), bool(img[2, 2].any())
    ((120, 160, 3), True, False)
    """
    from scipy import ndimage
    from scipy.spatial import cKDTree

    pts = np.asarray(points, float)
    normals = _grid_normals(pts) if pts.ndim == 3 else np.full(pts.shape, np.nan)
    pts, normals = pts.reshape(-1, 3), normals.reshape(-1, 3)
    cols = (np.full((len(pts), 3), 200.0) if colors is None
            else np.asarray(colors, float).reshape(-1, 3))
    finite = np.isfinite(pts).all(axis=1)
    pts, cols, normals = pts[finite], cols[finite], normals[finite]
    width, height = size
    if len(pts) < 3:
        img = np.zeros((height, width, 3), np.uint8)
        if path is not None:
            _save_view(img, Path(path), title)
        return img
    ay, ax = np.deg2rad(azimuth), np.deg2rad(elevation)
    rot = (np.array([[1, 0, 0], [0, np.cos(ax), np.sin(ax)], [0, -np.sin(ax), np.cos(ax)]])
           @ np.array([[np.cos(ay), 0, -np.sin(ay)], [0, 1, 0], [np.sin(ay), 0, np.cos(ay)]]))
    view = (pts - np.median(pts, axis=0)) @ rot.T
    normals = normals @ rot.T
    lo, hi = np.percentile(view[:, :2], [0.5, 99.5], axis=0)
    scale = 0.92 * min(width / max(hi[0] - lo[0], 1e-9), height / max(hi[1] - lo[1], 1e-9))
    # cells of about the points' spacing on screen
    tree = cKDTree(view[:, :2])
    probe = view[:: max(1, len(view) // 5000), :2]
    spacing = float(np.median(tree.query(probe, k=2)[0][:, 1])) * scale
    cell = max(1.0, 1.2 * spacing)
    gw, gh = max(1, int(width / cell)), max(1, int(height / cell))
    gx = np.floor((view[:, 0] - (lo[0] + hi[0]) / 2) * scale / cell + gw / 2).astype(int)
    gy = np.floor((view[:, 1] - (lo[1] + hi[1]) / 2) * scale / cell + gh / 2).astype(int)
    inside = np.flatnonzero((gx >= 0) & (gx < gw) & (gy >= 0) & (gy < gh))
    flat = gy[inside] * gw + gx[inside]
    order = np.lexsort((view[inside, 2], flat))  # nearest point first in each cell
    first = inside[order[np.unique(flat[order], return_index=True)[1]]]
    cells = gy[first] * gw + gx[first]
    zbuf = np.full(gh * gw, np.nan)
    zbuf[cells] = view[first, 2]
    nbuf = np.full((gh * gw, 3), np.nan)
    nbuf[cells] = normals[first]
    cbuf = np.zeros((gh * gw, 3))
    cbuf[cells] = cols[first]
    zbuf, nbuf, cbuf = zbuf.reshape(gh, gw), nbuf.reshape(gh, gw, 3), cbuf.reshape(gh, gw, 3)
    if np.isnan(nbuf).all():  # no grid: normals from the depth buffer
        dzy, dzx = np.gradient(zbuf, cell / scale)
        nbuf = np.stack([dzx, dzy, -np.ones_like(zbuf)], axis=-1)
    nbuf /= np.linalg.norm(nbuf, axis=-1, keepdims=True)
    nbuf *= -np.sign(nbuf[..., 2:])  # facing the viewer (-z)
    light = np.array([-0.4, -0.5, -1.0]) / np.linalg.norm([-0.4, -0.5, -1.0])
    shade = np.nan_to_num(0.2 + 0.8 * np.clip(nbuf @ light, 0, 1), nan=0.2)
    rgb = shade[..., None] * cbuf * np.isfinite(zbuf)[..., None]
    # fill holes of up to two cells from the nearest filled cell
    dist, (iy, ix) = ndimage.distance_transform_edt(np.isnan(zbuf), return_indices=True)
    rgb = np.where((dist <= 2)[..., None], rgb[iy, ix], 0.0)
    rows = np.minimum((np.arange(height) / cell).astype(int), gh - 1)
    cols_idx = np.minimum((np.arange(width) / cell).astype(int), gw - 1)
    img = np.clip(rgb[rows[:, None], cols_idx[None, :]], 0, 255).astype(np.uint8)
    if path is not None:
        _save_view(img, Path(path), title)
    return img


def _grid_normals(points: np.ndarray) -> np.ndarray:
    """Unit normals of an organised ``(H, W, 3)`` cloud from its grid neighbours (NaN)."""
    du = np.gradient(points, axis=1)
    dv = np.gradient(points, axis=0)
    n = np.cross(du, dv)
    with np.errstate(invalid="ignore", divide="ignore"):
        return n / np.linalg.norm(n, axis=-1, keepdims=True)


def _save_view(img: np.ndarray, path: Path, title: str | None) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    h, w = img.shape[:2]
    fig = Figure(figsize=(w / 100, h / 100 + (0.4 if title else 0)), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0, 0, 1, h / (h + (40 if title else 0))))
    ax.imshow(img, interpolation="nearest")
    ax.set_axis_off()
    if title:
        fig.suptitle(title, y=0.99, fontsize=11)
    with output_file(path) as tmp:
        fig.savefig(tmp, format="png", facecolor="black" if not title else "white")


# -- reference-plane phase-to-height ----------------------------------------------------------
@dataclass(frozen=True, eq=False)
class HeightModel:
    """Height above a reference plane from the projector-coordinate shift
    ``d = coord - reference``: ``h = d / (a - c * d)`` per pixel (see the module docstring).

    Examples
    --------
    >>> ref = np.full((2, 2), 100.0)
    >>> model = HeightModel.fit(ref, [ref + 8.0, ref + 15.0], [10.0, 20.0])
    >>> model.height(ref + 8.0).round(6).tolist()
    [[10.0, 10.0], [10.0, 10.0]]
    """

    reference: np.ndarray
    a: np.ndarray | float
    c: np.ndarray | float

    @classmethod
    def classical(cls, reference: np.ndarray, distance: float, baseline: float,
                  frequency: float, period: float) -> HeightModel:
        """Takeda and Mutoh's ``h = L dPhi / (dPhi - 2 pi f0 b)``: camera-plane ``distance``
        ``L`` (mm), ``baseline`` ``b`` (mm), fringe ``frequency`` ``f0`` on the reference
        plane (fringes per mm), ``period`` of the phase in projector pixels.

        Examples
        --------
        >>> model = HeightModel.classical(np.zeros(1), 600.0, 200.0, 0.1, 30.0)
        >>> dphi = 2 * np.pi * np.array([-2.0]) / 30.0  # a shift of -2 projector pixels
        >>> h = model.height(np.array([-2.0]))[0]
        >>> round(float(h), 6), round(float(600 * dphi[0] / (dphi[0] - 2 * np.pi * 0.1 * 200)), 6)
        (1.993355, 1.993355)
        """
        return cls(np.asarray(reference, float), -period * frequency * baseline / distance,
                   -1.0 / distance)

    @classmethod
    def fit(cls, reference: np.ndarray, planes: Sequence[np.ndarray],
            heights: Sequence[float]) -> HeightModel:
        """Per-pixel ``a, c`` (least squares) from projector coordinates measured on planes
        parallel to the reference at known, non-zero ``heights`` (two or more)."""
        ref = np.asarray(reference, float)
        if len(planes) != len(heights) or len(planes) < 2:
            raise BistairError("the height model needs two or more planes with their heights")
        if any(h == 0 for h in heights):
            raise BistairError("plane heights must be non-zero (0 is the reference)")
        shift = np.stack([np.asarray(p, float) - ref for p in planes])
        hts = np.asarray(heights, float).reshape(-1, *([1] * ref.ndim))
        # a * h - c * h * d = d, per pixel: 2x2 normal equations
        c1, c2 = hts * np.ones_like(shift), -hts * shift
        s11, s12, s22 = (c1 * c1).sum(0), (c1 * c2).sum(0), (c2 * c2).sum(0)
        r1, r2 = (c1 * shift).sum(0), (c2 * shift).sum(0)
        det = s11 * s22 - s12 * s12
        with np.errstate(divide="ignore", invalid="ignore"):
            a = np.where(det != 0, (s22 * r1 - s12 * r2) / det, np.nan)
            c = np.where(det != 0, (s11 * r2 - s12 * r1) / det, np.nan)
        return cls(ref, a, c)

    def height(self, coord: np.ndarray) -> np.ndarray:
        """Height (mm, toward the camera for the fitted model) per pixel, NaN where invalid."""
        d = np.asarray(coord, float) - self.reference
        with np.errstate(divide="ignore", invalid="ignore"):
            return d / (self.a - self.c * d)


def _toy_calibration() -> Calibration:
    """A distortion-free camera and projector for the examples."""
    cam = Device(640, 480, [[800.0, 0, 319.5], [0, 800, 239.5], [0, 0, 1]])
    proj = Device(800, 600, [[1000.0, 0, 399.5], [0, 1000, 299.5], [0, 0, 1]])
    rot = cv2.Rodrigues(np.array([0.0, 0.3, 0.0]))[0]
    return Calibration(cam, proj, rot, -rot @ np.array([150.0, 0.0, 0.0]))
