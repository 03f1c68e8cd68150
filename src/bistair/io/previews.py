"""PNG previews of a decode: the paper's Fig. 9 and 10 views.

``wrapped.png`` (wrapped phase), ``ks.png`` (the decoded code word, ``k_s`` for the stair
methods), ``order.png`` (fringe order), ``phase.png`` (absolute phase) and
``modulation.png``; invalid pixels are black.
"""

from __future__ import annotations

from pathlib import Path

import imageio.v3 as iio
import numpy as np
from matplotlib import colormaps

from ..core.result import DecodeResult


def colorize(values: np.ndarray, cmap: str = "jet", vmin: float | None = None,
             vmax: float | None = None) -> np.ndarray:
    """Map a 2-D array to RGB uint8 with a matplotlib colormap; NaN (or masked) -> black.

    Examples
    --------
    >>> import numpy as np
    >>> rgb = colorize(np.array([[0.0, 1.0, np.nan]]), "gray")
    >>> rgb.shape, rgb[0, :, 0].tolist()
    ((1, 3, 3), [0, 255, 0])
    """
    vals = np.asarray(values, dtype=np.float64)
    ok = np.isfinite(vals)
    if vmin is None:
        vmin = float(vals[ok].min()) if ok.any() else 0.0
    if vmax is None:
        vmax = float(vals[ok].max()) if ok.any() else 1.0
    norm = np.clip((np.where(ok, vals, vmin) - vmin) / max(vmax - vmin, 1e-12), 0.0, 1.0)
    rgb = (colormaps[cmap](norm)[..., :3] * 255).round().astype(np.uint8)
    rgb[~ok] = 0
    return rgb


def preview_images(result: DecodeResult) -> dict[str, np.ndarray]:
    """The preview images of a result, by file stem."""
    code = np.where(result.code >= 0, result.code, np.nan).astype(np.float64)
    order = np.where(result.order >= 0, result.order, np.nan).astype(np.float64)
    return {
        "wrapped": colorize(result.wrapped, "gray", 0.0, 2 * np.pi),
        "ks": colorize(code, "viridis"),
        "order": colorize(order, "jet"),
        "phase": colorize(result.phase, "jet"),
        "modulation": colorize(result.modulation, "gray", 0.0),
    }


def write_previews(result: DecodeResult, folder: str | Path, suffix: str = "") -> list[Path]:
    """Write the preview PNGs of a result into ``folder`` (``STEM + suffix + .png``);
    returns their paths."""
    folder = Path(folder)
    paths = []
    for stem, rgb in preview_images(result).items():
        path = folder / f"{stem}{suffix}.png"
        iio.imwrite(path, rgb)
        paths.append(path)
    return paths
