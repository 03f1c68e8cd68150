"""PNG previews of a decode: the paper's Fig. 9 and 10 views, each with a colour bar.

``wrapped.png`` (wrapped phase, rad), ``ks.png`` (the decoded code word, ``k_s`` for the
stair methods), ``order.png`` (fringe order), ``phase.png`` (absolute phase, rad) and
``modulation.png`` (fraction of full scale); invalid pixels are black. Each image keeps the
camera's pixels one for one, with a colour bar labelled in its unit to its right
(:func:`with_colorbar`).
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np
from matplotlib import colormaps
from matplotlib.ticker import MaxNLocator

from ..core.phase import TWO_PI
from ..core.result import DecodeResult

# the file stems of preview_images, in its order
PREVIEW_NAMES = ("wrapped", "ks", "order", "phase", "modulation")


@dataclass(frozen=True)
class Scale:
    """How a view maps values to colours: colormap, unit of its colour bar, value range
    (``None``: the smallest or largest valid value) and whether the values are whole."""

    title: str
    cmap: str
    unit: str
    vmin: float | None = None
    vmax: float | None = None
    integer: bool = False


# the scales of the previews (by file stem) and of the figure's other panels
SCALES = {
    "wrapped": Scale("wrapped phase", "gray", "rad", 0.0, TWO_PI),
    "ks": Scale("code word (k_s)", "viridis", "code level", integer=True),
    "order": Scale("fringe order", "jet", "fringe order", integer=True),
    "phase": Scale("absolute phase", "jet", "rad"),
    "modulation": Scale("modulation", "gray", "fraction of full scale", 0.0),
    "coord": Scale("projector coordinate", "jet", "projector px"),
}
_FONT = cv2.FONT_HERSHEY_SIMPLEX


def colorize(values: np.ndarray, cmap: str = "jet", vmin: float | None = None,
             vmax: float | None = None, unit: str | None = None,
             integer: bool = False) -> np.ndarray:
    """Map a 2-D array to RGB uint8 with a matplotlib colormap; NaN (or masked) -> black;
    with ``unit``, a colour bar labelled in it beside the image (:func:`with_colorbar`).

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
    unit : str or None, optional
        The unit of the values: add a colour bar labelled in it at the right.
    integer : bool, optional
        The colour bar's ticks at whole numbers only.

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB, ``(0, 0, 0)`` where ``values`` is not finite;
        with ``unit``, wider (and at least 60 rows tall) by the colour bar.

    Examples
    --------
    >>> import numpy as np
    >>> rgb = colorize(np.array([[0.0, 1.0, np.nan]]), "gray")
    >>> rgb.shape, rgb[0, :, 0].tolist()
    ((1, 3, 3), [0, 255, 0])
    >>> depth = np.full((80, 100), 600.0)
    >>> barred = colorize(depth, "turbo_r", 550, 650, unit="mm")
    >>> barred.shape[0], barred.shape[1] > 100
    (80, True)
    >>> bool((barred[:, :100] == colorize(depth, "turbo_r", 550, 650)).all())
    True
    """
    vals = np.asarray(values)
    if not np.issubdtype(vals.dtype, np.floating):
        vals = vals.astype(np.float64)
    ok = np.isfinite(vals)
    vmin, vmax = value_range(vals, vmin, vmax, ok)
    # the colormap's own lookup: index floor(norm * 256), the top value in the last entry
    scale = 256.0 / max(vmax - vmin, 1e-12)
    norm = np.subtract(vals, vmin, dtype=vals.dtype)
    norm *= scale
    np.clip(norm, 0.0, 255.0, out=norm)
    with np.errstate(invalid="ignore"):  # NaN casts to anything: masked out below
        index = norm.astype(np.uint8)
    rgb = cv2.LUT(cv2.merge([index, index, index]), _lut(cmap).reshape(256, 1, 3))
    rgb = cv2.bitwise_and(rgb, rgb, mask=ok.view(np.uint8)).reshape(index.shape + (3,))
    return rgb if unit is None else with_colorbar(rgb, cmap, vmin, vmax, unit, integer)


def value_range(values: np.ndarray, vmin: float | None = None, vmax: float | None = None,
                valid: np.ndarray | None = None) -> tuple[float, float]:
    """The value range a colour scale spans: ``vmin`` and ``vmax`` where given, else the
    smallest and largest finite value (0 and 1 if there is none).

    Parameters
    ----------
    values : numpy.ndarray
        The values, any real dtype.
    vmin, vmax : float or None, optional
        Fixed ends of the range.
    valid : numpy.ndarray, optional
        ``np.isfinite(values)`` if already known.

    Returns
    -------
    tuple of float
        ``(vmin, vmax)``.

    Examples
    --------
    >>> value_range(np.array([3.0, np.nan, 7.5])), value_range(np.array([np.nan]), 0.0)
    ((3.0, 7.5), (0.0, 1.0))
    """
    vals = np.asarray(values)
    ok = np.isfinite(vals) if valid is None else valid
    any_ok = bool(ok.any())
    if vmin is None:
        vmin = float(vals.min(where=ok, initial=np.inf)) if any_ok else 0.0
    if vmax is None:
        vmax = float(vals.max(where=ok, initial=-np.inf)) if any_ok else 1.0
    return float(vmin), float(vmax)


@lru_cache(maxsize=16)
def _lut(cmap: str) -> np.ndarray:
    return (colormaps[cmap](np.arange(256))[:, :3] * 255).round().astype(np.uint8)


def with_colorbar(rgb: np.ndarray, cmap: str, vmin: float, vmax: float, unit: str,
                  integer: bool = False) -> np.ndarray:
    """An image with a colour bar at its right: the colormap from ``vmin`` (bottom) to
    ``vmax`` (top), ticks with their values and the unit along the bar, black on white.

    The image keeps its pixels one for one at the top left; text is scaled to the image's
    height (an image under 60 rows gets white rows below it, for the bar's labels).

    Parameters
    ----------
    rgb : numpy.ndarray
        ``(height, width, 3)`` ``uint8`` image, coloured as :func:`colorize` does.
    cmap : str
        The matplotlib colormap it was coloured with.
    vmin, vmax : float
        The values at the ends of the colormap (``vmax <= vmin``: one value, shown at the
        bottom of a bar one unit tall).
    unit : str
        The values' unit, written along the bar (e.g. ``"rad"``, ``"mm"``).
    integer : bool, optional
        Ticks at whole numbers only.

    Returns
    -------
    numpy.ndarray
        ``(max(height, 60), width + bar width, 3)`` ``uint8`` RGB.

    Examples
    --------
    >>> rgb = colorize(np.linspace(0, 2 * np.pi, 300 * 200).reshape(300, 200), "gray")
    >>> out = with_colorbar(rgb, "gray", 0, 2 * np.pi, "rad")
    >>> out.shape[0], out.shape[1] > 200, bool((out[:, :200] == rgb).all())
    (300, True, True)
    >>> strip = out[:, 200:]
    >>> bool((strip == 0).any() and (strip == 255).any())  # the bar, black and white text
    True
    """
    h, w = rgb.shape[:2]
    if not vmax > vmin:
        vmax = vmin + 1.0
    size = float(np.clip(h / 700, 0.35, 1.5))  # font scale: text readable at the image's size
    thick = max(1, round(1.5 * size))
    text_h = cv2.getTextSize("0", _FONT, size, thick)[0][1]
    pad = max(3, round(0.6 * text_h))
    height = max(h, 60)
    top, bottom = pad + text_h, height - pad - text_h  # the bar's rows, labels beside
    ticks, labels = _ticks(vmin, vmax, integer, max(2, (bottom - top) // (3 * text_h)))
    bar_w, tick_w = max(8, round(1.4 * text_h)), max(3, round(text_h / 3))
    widths = [cv2.getTextSize(t, _FONT, size, thick)[0][0] for t in labels]
    x0 = w + 2 * pad
    x_text = x0 + bar_w + tick_w + pad // 2
    x_unit = x_text + max(widths, default=0) + pad
    unit_img = _vertical_text(unit, size, thick, bottom - top)
    width = x_unit + unit_img.shape[1] + pad
    out = cv2.copyMakeBorder(np.ascontiguousarray(rgb), 0, height - h, 0, width - w,
                             cv2.BORDER_CONSTANT, value=(255, 255, 255))
    rows = np.arange(top, bottom + 1)
    index = np.clip(((bottom - rows) / max(bottom - top, 1) * 256).astype(int), 0, 255)
    out[top:bottom + 1, x0:x0 + bar_w] = _lut(cmap)[index][:, None, :]
    cv2.rectangle(out, (x0 - 1, top - 1), (x0 + bar_w, bottom + 1), (0, 0, 0), 1)
    for value, label in zip(ticks, labels, strict=True):
        y = round(bottom - (value - vmin) / (vmax - vmin) * (bottom - top))
        cv2.line(out, (x0 + bar_w, y), (x0 + bar_w + tick_w, y), (0, 0, 0), 1)
        cv2.putText(out, label, (x_text, y + text_h // 2), _FONT, size, (0, 0, 0), thick,
                    cv2.LINE_AA)
    y_unit = top + (bottom - top - unit_img.shape[0]) // 2
    out[y_unit:y_unit + unit_img.shape[0], x_unit:x_unit + unit_img.shape[1]] = unit_img
    return out


def _ticks(vmin: float, vmax: float, integer: bool, most: int) -> tuple[list[float],
                                                                         list[str]]:
    """Tick values inside ``[vmin, vmax]`` and their labels (multiples of pi for a
    wrapped phase)."""
    if (vmin, vmax) == (0.0, TWO_PI):
        return [0.0, np.pi, TWO_PI], ["0", "pi", "2pi"]
    found = MaxNLocator(nbins=min(most, 8), integer=integer, min_n_ticks=2).tick_values(
        vmin, vmax)
    span = vmax - vmin
    ticks = [float(v) for v in found if vmin - 1e-9 * span <= v <= vmax + 1e-9 * span]
    if len(ticks) < 2:
        ticks = [vmin, vmax]
    step = min(b - a for a, b in zip(ticks, ticks[1:], strict=False))
    digits = 0 if integer or step >= 1 else max(0, -math.floor(math.log10(step) + 1e-9))
    return ticks, [f"{v:.{digits}f}" for v in ticks]


def _vertical_text(text: str, size: float, thick: int, room: int) -> np.ndarray:
    """``text`` black on white, read from the bottom up, at most ``room`` pixels long."""
    (tw, th), base = cv2.getTextSize(text, _FONT, size, thick)
    if tw > room > 0:  # a long unit beside a short bar: smaller
        size *= room / tw
        (tw, th), base = cv2.getTextSize(text, _FONT, size, thick)
    img = np.full((th + base + 2, tw + 2, 3), 255, np.uint8)
    cv2.putText(img, text, (1, th + 1), _FONT, size, (0, 0, 0), thick, cv2.LINE_AA)
    return np.ascontiguousarray(np.rot90(img))


def preview_images(result: DecodeResult, colorbar: bool = False) -> dict[str, np.ndarray]:
    """The preview images of a result, by file stem.

    Parameters
    ----------
    result : DecodeResult
        A decode of one axis.
    colorbar : bool, optional
        Add each image's colour bar, labelled in its unit (:func:`with_colorbar`).

    Returns
    -------
    dict of str to numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB images (black where invalid) under
        ``"wrapped"`` (grey, 0 to 2 pi), ``"ks"`` (the code word, viridis), ``"order"``
        (fringe order, jet), ``"phase"`` (absolute phase, jet) and ``"modulation"`` (grey,
        0 to the largest), each scaled to its valid values unless said (:data:`SCALES`);
        with ``colorbar``, wider by it.

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
    >>> preview_images(res, colorbar=True)["order"][:2, :3].tolist() == images["order"].tolist()
    True
    """
    return {stem: _preview(result, stem, colorbar) for stem in PREVIEW_NAMES}


def _preview(result: DecodeResult, stem: str, colorbar: bool) -> np.ndarray:
    """One preview image (:func:`preview_images`)."""
    if stem in ("ks", "order"):  # -1: not decoded
        codes = result.code if stem == "ks" else result.order
        values = np.where(codes >= 0, codes, np.nan).astype(np.float32)
    else:
        values = getattr(result, stem)
    s = SCALES[stem]
    return colorize(values, s.cmap, s.vmin, s.vmax, unit=s.unit if colorbar else None,
                    integer=s.integer)


def write_previews(result: DecodeResult, folder: str | Path, suffix: str = "") -> list[Path]:
    """Write the preview PNGs of a result, each with its colour bar, into ``folder``
    (``STEM + suffix + .png``); returns their paths.

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
    paths = [folder / f"{stem}{suffix}.png" for stem in PREVIEW_NAMES]

    # Each image is coloured here and encoded on a pool thread (OpenCV frees the GIL while
    # it encodes) as the next is coloured. Colouring on the pool threads as well was
    # slower (172 against 118 ms at 1.3 MP on two cores): its many short NumPy and OpenCV
    # steps each wait for the GIL again.
    with ThreadPoolExecutor(max_workers=min(len(paths), max(2, os.cpu_count() or 1))) as pool:
        writes = [pool.submit(_write_png, path, _preview(result, stem, colorbar=True))
                  for stem, path in zip(PREVIEW_NAMES, paths, strict=True)]
        done = [w.result() for w in writes]
    if not all(done):
        raise OSError(f"cannot write the previews in {folder}")
    return paths


def _write_png(path: Path, rgb: np.ndarray) -> bool:
    # fast deflate (level 1) after the 'up' row filter alone: previews are views, and must
    # not take longer than a decode. At 1.3 MP the five previews encode in about half the
    # time that OpenCV's default filter choice takes, into files of about the same size
    # (2.21 against 2.20 MB for the five; the same pixels)
    return bool(cv2.imwrite(str(path), np.ascontiguousarray(rgb[..., ::-1]),
                            [cv2.IMWRITE_PNG_COMPRESSION, 1,
                             cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_UP]))
