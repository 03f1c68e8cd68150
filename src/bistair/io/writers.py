"""Writers of results: decode arrays and their previews, point clouds (PLY) and depth maps.

Each writes into a folder (or file) the caller made atomic with
:func:`bistair.io.files.output_folder` / :func:`~bistair.io.files.output_file`.

Examples
--------
>>> import tempfile, pathlib
>>> import bistair
>>> spec = bistair.make_spec("graycode", width=120, height=16, period=30)
>>> result = bistair.decode(bistair.encode(spec), spec)
>>> with tempfile.TemporaryDirectory() as tmp:
...     write_result(result, pathlib.Path(tmp), previews=False)
...     sorted(p.name for p in pathlib.Path(tmp).iterdir())
['coord.npy', 'info.json', 'mask.npy', 'modulation.npy', 'order.npy', 'phase.npy', 'wrapped.npy']
"""

from __future__ import annotations

from pathlib import Path

import imageio.v3 as iio
import numpy as np
from plyfile import PlyData, PlyElement

from ..core.result import AxesResult, DecodeResult
from .files import output_file
from .jsonfile import write_json
from .previews import colorize, write_previews


def write_result(result: DecodeResult | AxesResult, folder: str | Path,
                 previews: bool = True) -> None:
    """Write a decode's arrays (``NAME.npy``), ``info.json`` and, with ``previews``, the PNG
    previews into an existing folder. A decode of both axes writes each axis's files with
    the suffix ``_x`` or ``_y`` (``coord_x.npy``, ``order_y.png``, ...) and ``mask.npy``
    where both are valid."""
    folder = Path(folder)
    for name, arr in result.arrays().items():
        np.save(folder / f"{name}.npy", arr)
    if previews and isinstance(result, AxesResult):
        write_previews(result.x, folder, suffix="_x")
        write_previews(result.y, folder, suffix="_y")
    elif previews:
        write_previews(result, folder)
    write_json(folder / "info.json", result.info)


def write_ply(path: str | Path, points: np.ndarray, colors: np.ndarray | None = None) -> Path:
    """Write a coloured point cloud as binary little-endian PLY (``x y z`` float32, ``red
    green blue`` uchar) atomically; readable by Open3D, MeshLab and plyfile."""
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


def write_depth(depth: np.ndarray, folder: str | Path) -> None:
    """Write ``depth.npy`` (float32, NaN where invalid) and the ``depth.png`` preview."""
    folder = Path(folder)
    depth = np.asarray(depth, np.float32)
    np.save(folder / "depth.npy", depth)
    ok = np.isfinite(depth)
    lo, hi = np.percentile(depth[ok], [1, 99]) if ok.any() else (0.0, 1.0)
    iio.imwrite(folder / "depth.png", colorize(depth, "turbo_r", float(lo), float(hi)))
