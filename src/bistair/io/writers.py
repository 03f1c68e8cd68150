"""Writers of results: decode arrays and their previews, point clouds (PLY) and depth maps.

Each writes into a folder (or file) the caller made atomic with
:func:`bistair.io.atomic.output_folder` / :func:`~bistair.io.atomic.output_file`.

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

import contextlib
from pathlib import Path

import imageio.v3 as iio
import numpy as np
from plyfile import PlyData, PlyElement

from ..core.result import ARRAY_NAMES, AxesResult, DecodeResult
from .atomic import output_file, output_folder
from .jsonfile import write_json
from .previews import PREVIEW_NAMES, colorize, write_previews

# every file write_result may write, for one axis or both: what an earlier decode left in
# a folder that a new one writes into
RESULT_FILES = frozenset(
    [f"{name}{axis}.npy" for name in ARRAY_NAMES for axis in ("", "_x", "_y")]
    + [f"{name}{axis}.png" for name in PREVIEW_NAMES for axis in ("", "_x", "_y")]
    + ["info.json"])


def write_result(result: DecodeResult | AxesResult, folder: str | Path,
                 previews: bool = True) -> None:
    """Write a decode's arrays (``NAME.npy``), ``info.json`` and, with ``previews``, the PNG
    previews into an existing folder. A decode of both axes writes each axis's files with
    the suffix ``_x`` or ``_y`` (``coord_x.npy``, ``order_y.png``, ...) and ``mask.npy``
    where both are valid.

    The files are written in place, replacing files of the same names; make the folder
    with :func:`bistair.io.atomic.output_folder` for an atomic result.

    Parameters
    ----------
    result : DecodeResult or AxesResult
        The decode: its arrays (``phase``, ``coord``, ``order``, ``wrapped``,
        ``modulation``, ``mask``; see :meth:`DecodeResult.arrays
        <bistair.core.result.DecodeResult.arrays>`) go to ``.npy`` files, its ``info`` to
        ``info.json``.
    folder : str or Path
        An existing folder.
    previews : bool, optional
        Also write the PNG previews (:func:`~bistair.io.previews.write_previews`).

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.core.result import AxesResult, make_result
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> res = make_result("demo", np.full((2, 3), 1.0), np.zeros((2, 3), int), 30.0,
    ...                   modulation=np.ones((2, 3)))
    >>> write_result(AxesResult(res, res), tmp)
    >>> names = sorted(p.name for p in tmp.iterdir())
    >>> len(names), names[:4]
    (24, ['coord_x.npy', 'coord_y.npy', 'info.json', 'ks_x.png'])
    >>> shutil.rmtree(tmp)
    """
    folder = Path(folder)
    for name, arr in result.arrays().items():
        np.save(folder / f"{name}.npy", arr)
    if previews and isinstance(result, AxesResult):
        write_previews(result.x, folder, suffix="_x")
        write_previews(result.y, folder, suffix="_y")
    elif previews:
        write_previews(result, folder)
    write_json(folder / "info.json", result.info)


def save_result(result: DecodeResult | AxesResult, folder: str | Path,
                previews: bool = True) -> Path:
    """Write what ``bistair decode`` writes into ``folder``, atomically: the arrays,
    ``info.json`` and, with ``previews``, the PNG previews (:func:`write_result`); the
    files an earlier decode left there and this one does not write are removed, other files
    are left alone. Also ``result.save(folder)``.

    Parameters
    ----------
    result : DecodeResult or AxesResult
        The decode.
    folder : str or Path
        The output folder (created if needed).
    previews : bool, optional
        Also write the PNG previews.

    Returns
    -------
    Path
        ``folder``.

    Raises
    ------
    BistairError
        Raised by :func:`~bistair.io.atomic.output_folder` if the folder cannot be written;
        nothing is written then.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.core.result import make_result
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> res = make_result("demo", np.full((2, 3), 1.0), np.zeros((2, 3), int), 30.0,
    ...                   modulation=np.ones((2, 3)))
    >>> out = save_result(res, tmp / "result")
    >>> sorted(p.name for p in out.iterdir())[:4]
    ['coord.npy', 'info.json', 'ks.png', 'mask.npy']
    >>> sorted(p.name for p in save_result(res, out, previews=False).iterdir())[:4]
    ['coord.npy', 'info.json', 'mask.npy', 'modulation.npy']
    >>> shutil.rmtree(tmp)
    """
    with output_folder(folder) as tmp:
        write_result(result, tmp, previews=previews)
        written = {p.name for p in tmp.iterdir()}
    for name in RESULT_FILES - written:  # an earlier decode's files there: not this one's
        with contextlib.suppress(OSError):
            (Path(folder) / name).unlink()
    return Path(folder)


def write_ply(path: str | Path, points: np.ndarray, colors: np.ndarray | None = None) -> Path:
    """Write a coloured point cloud as binary little-endian PLY (``x y z`` float32, ``red
    green blue`` uchar) atomically; readable by Open3D, MeshLab and plyfile.

    The file is written to a temporary file beside ``path`` and renamed onto it
    (:func:`~bistair.io.atomic.output_file`); its header comment says the points are in the
    camera frame, in millimetres. Points are written as given: drop invalid (NaN) points
    first (e.g. :meth:`Reconstruction.cloud
    <bistair.geometry.triangulate.Reconstruction.cloud>`).

    Parameters
    ----------
    path : str or Path
        The PLY file (its folder is created if needed).
    points : numpy.ndarray
        ``(N, 3)`` (or anything reshaped to it) coordinates in mm, cast to float32.
    colors : numpy.ndarray or None, optional
        ``(N, 3)`` RGB, cast to uint8; white if ``None``.

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
    >>> from plyfile import PlyData
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> path = write_ply(tmp / "cloud.ply", [[0, 0, 600], [1.5, -2, 601]], [[255, 0, 0]] * 2)
    >>> vertex = PlyData.read(str(path))["vertex"]
    >>> vertex["z"].tolist(), vertex["red"].tolist(), vertex["green"].tolist()
    ([600.0, 601.0], [255, 255], [0, 0])
    >>> shutil.rmtree(tmp)
    """
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
    """Write ``depth.npy`` (float32, NaN where invalid) and the ``depth.png`` preview.

    The preview maps the 1st to 99th percentile of the valid depths to the reversed turbo
    colormap (near red, far blue), invalid pixels black, with a colour bar in mm beside it
    (:func:`~bistair.io.previews.with_colorbar`). Both files are written in place
    (make the folder with :func:`bistair.io.atomic.output_folder` for atomic output).

    Parameters
    ----------
    depth : numpy.ndarray
        ``(height, width)`` depth ``z`` in mm (camera frame), NaN where invalid.
    folder : str or Path
        An existing folder.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> write_depth(np.array([[600.0, 610.0], [620.0, np.nan]]), tmp)
    >>> sorted(p.name for p in tmp.iterdir()), np.load(tmp / "depth.npy").dtype
    (['depth.npy', 'depth.png'], dtype('float32'))
    >>> shutil.rmtree(tmp)
    """
    folder = Path(folder)
    depth = np.asarray(depth, np.float32)
    np.save(folder / "depth.npy", depth)
    ok = np.isfinite(depth)
    lo, hi = np.percentile(depth[ok], [1, 99]) if ok.any() else (0.0, 1.0)
    iio.imwrite(folder / "depth.png", colorize(depth, "turbo_r", float(lo), float(hi),
                                               unit="mm"))
