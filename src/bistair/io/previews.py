"""PNG previews of a decode: the paper's Fig. 9 and 10 views.

``wrapped.png`` (wrapped phase), ``ks.png`` (the decoded code word, ``k_s`` for the stair
methods), ``order.png`` (fringe order), ``phase.png`` (absolute phase) and
``modulation.png``; invalid pixels are black.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np
from matplotlib import colormaps

from ..core.result import DecodeResult

# the file stems of preview_images, in its order
PREVIEW_NAMES = ("wrapped", "ks", "order", "phase", "modulation")


def colorize(values: np.ndarray, cmap: str = "jet", vmin: float | None = None,
             vmax: float | None = None) -> np.ndarray:
    """Map a 2-D array to RGB uint8 with a matplotlib colormap; NaN (or masked) -> black.

    Values are scaled linearly from ``[vmin, vmax]`` to the colormap and clipped there.

    Parameters
    ----------
    values : numpy.ndarray
        ``(height, width)`` values, any real dtype; non-finite values (NaN, inf) are invalid.
    cmap : str, optional
        Name of a matplotlib colormap (``"jet"``, ``"gray"``, ``"viridis"``, ...).
    vmin, vmax : float or None, optional
        The values mapped to the ends of the colormap; by default the smallest and largest
        finite value (0 and 1 if there is none).

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB, ``(0, 0, 0)`` where ``values`` is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> rgb = colorize(np.array([[0.0, 1.0, np.nan]]), "gray")
    >>> rgb.shape, rgb[0, :, 0].tolist()
    ((1, 3, 3), [0, 255, 0])
    """
    vals = np.asarray(values)
    if not np.issubdtype(vals.dtype, np.floating):
        vals = vals.astype(np.float64)
    ok = np.isfinite(vals)
    any_ok = bool(ok.any())
    if vmin is None:
        vmin = float(vals.min(where=ok, initial=np.inf)) if any_ok else 0.0
    if vmax is None:
        vmax = float(vals.max(where=ok, initial=-np.inf)) if any_ok else 1.0
    # the colormap's own lookup: index floor(norm * 256), the top value in the last entry
    scale = 256.0 / max(vmax - vmin, 1e-12)
    norm = np.subtract(vals, vmin, dtype=vals.dtype)
    norm *= scale
    np.clip(norm, 0.0, 255.0, out=norm)
    with np.errstate(invalid="ignore"):  # NaN casts to anything: masked out below
        index = norm.astype(np.uint8)
    rgb = cv2.LUT(cv2.merge([index, index, index]), _lut(cmap).reshape(256, 1, 3))
    return cv2.bitwise_and(rgb, rgb, mask=ok.view(np.uint8)).reshape(index.shape + (3,))


@lru_cache(maxsize=16)
def _lut(cmap: str) -> np.ndarray:
    return (colormaps[cmap](np.arange(256))[:, :3] * 255).round().astype(np.uint8)


def preview_images(result: DecodeResult) -> dict[str, np.ndarray]:
    """The preview images of a result, by file stem.

    Parameters
    ----------
    result : DecodeResult
        A decode of one axis.

    Returns
    -------
    dict of str to numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB images (black where invalid) under
        ``"wrapped"`` (grey, 0 to 2 pi), ``"ks"`` (the code word, viridis), ``"order"``
        (fringe order, jet), ``"phase"`` (absolute phase, jet) and ``"modulation"`` (grey,
        0 to the largest), each scaled to its valid values unless said.

    Examples
    --------
    >>> from bistair.core.result import make_result
    >>> phi = np.full((2, 3), np.pi)
    >>> res = make_result("demo", phi, np.array([[0, 1, 2], [0, -1, 2]]), 30.0,
    ...                   modulation=np.full((2, 3), 0.4))
    >>> images = preview_images(res)
    >>> tuple(images) == PREVIEW_NAMES, images["order"].shape, images["order"].dtype
    (True, (2, 3, 3), dtype('uint8'))
    >>> images["phase"][1, 1].tolist(), images["wrapped"][1, 1].tolist()  # order -1
    ([0, 0, 0], [128, 128, 128])
    """
    code = np.where(result.code >= 0, result.code, np.nan).astype(np.float32)
    order = np.where(result.order >= 0, result.order, np.nan).astype(np.float32)
    return {
        "wrapped": colorize(result.wrapped, "gray", 0.0, 2 * np.pi),
        "ks": colorize(code, "viridis"),
        "order": colorize(order, "jet"),
        "phase": colorize(result.phase, "jet"),
        "modulation": colorize(result.modulation, "gray", 0.0),
    }


def write_previews(result: DecodeResult, folder: str | Path, suffix: str = "") -> list[Path]:
    """Write the preview PNGs of a result into ``folder`` (``STEM + suffix + .png``);
    returns their paths.

    The files are written in place (not atomically; see
    :func:`bistair.io.atomic.output_folder`) and replace files of the same names.

    Parameters
    ----------
    result : DecodeResult
        A decode of one axis.
    folder : str or Path
        An existing folder.
    suffix : str, optional
        Added to each stem, e.g. ``"_x"`` for the columns of a decode of both axes.

    Returns
    -------
    list of Path
        The RGB PNGs written, in the order of :func:`preview_images`.

    Raises
    ------
    OSError
        A preview could not be written (the folder is missing or not writable).

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.core.result import make_result
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> res = make_result("demo", np.full((2, 3), 1.0), np.zeros((2, 3), int), 30.0,
    ...                   modulation=np.ones((2, 3)))
    >>> [p.name for p in write_previews(res, tmp, suffix="_x")]
    ['wrapped_x.png', 'ks_x.png', 'order_x.png', 'phase_x.png', 'modulation_x.png']
    >>> shutil.rmtree(tmp)
    """
    folder = Path(folder)
    images = preview_images(result)
    paths = [folder / f"{stem}{suffix}.png" for stem in images]
    with ThreadPoolExecutor(max_workers=len(paths)) as pool:  # the encoder frees the GIL
        done = list(pool.map(_write_png, paths, images.values()))
    if not all(done):
        raise OSError(f"cannot write the previews in {folder}")
    return paths


def _write_png(path: Path, rgb: np.ndarray) -> bool:
    # fast deflate (level 1): previews are views, and must not take longer than a decode
    return bool(cv2.imwrite(str(path), np.ascontiguousarray(rgb[..., ::-1]),
                            [cv2.IMWRITE_PNG_COMPRESSION, 1]))
