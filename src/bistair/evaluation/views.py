"""Views of results: a shaded point cloud rendered without a display.

Examples
--------
>>> v, u = np.mgrid[-40:40, -40:40] * 1.0
>>> pts = np.stack([u, v, 500 + np.hypot(u, v) ** 2 / 80], axis=-1)
>>> img = render_cloud(pts, size=(160, 120))
>>> img.shape, bool(img[60, 80].all()), bool(img[2, 2].any())
((120, 160, 3), True, False)
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from scipy import ndimage
from scipy.spatial import cKDTree

from ..geometry.calibration import Calibration
from ..geometry.triangulate import reconstruct
from ..io.atomic import output_file


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
    """
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


def cloud_view(row: Any, rig: Any, path: str | Path) -> Path:
    """A benchmark row's decode triangulated with the exact calibration of a virtual rig
    (:class:`bistair.sim.Rig`), shaded, written to ``path``."""
    rec = reconstruct(row.result, Calibration.from_rig(rig), row.spec)
    render_cloud(rec.points, rec.colors, path, azimuth=25, elevation=15, size=(900, 700),
                 title=f"{row.label}: {int(rec.mask.sum())} points (mm, camera frame)")
    return Path(path)
