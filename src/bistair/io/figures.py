"""The figure of a decode (``result.plot()``): six panels, each with a colour bar in its unit.

Wrapped phase (rad), absolute phase (rad), projector coordinate (projector px), fringe
order, modulation (fraction of full scale) and the mask of valid pixels, coloured as the
PNG previews are (:data:`bistair.io.previews.SCALES`); invalid pixels black. The figure is
a :class:`matplotlib.figure.Figure` made without pyplot (no backend chosen, no window, no
figure kept by pyplot): a notebook shows it as a cell's value (it has ``_repr_png_``, for a
kernel whose matplotlib integration is not active yet), ``fig.savefig("decode.png")``
writes it; ``plt.show()`` does not know it.
"""

from __future__ import annotations

import io

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

from ..core.phase import TWO_PI
from ..core.result import AxesResult, DecodeResult
from .previews import SCALES, Scale

# the panels, in reading order: the result's attribute and the scale it is drawn with
PANELS = (("wrapped", "wrapped"), ("phase", "phase"), ("coord", "coord"),
          ("order", "order"), ("modulation", "modulation"), ("mask", None))
# the mask panel: colour of valid and of invalid pixels
MASK_COLOURS = ((0.85, 0.85, 0.85), (0.0, 0.0, 0.0))


class ResultFigure(Figure):
    """A figure a notebook shows as a PNG even before pyplot (and its inline backend) is
    loaded."""

    def _repr_png_(self) -> bytes:
        buffer = io.BytesIO()
        self.savefig(buffer, format="png", dpi=72)
        return buffer.getvalue()


def plot_result(result: DecodeResult | AxesResult, width: float = 13.0) -> Figure:
    """The six-panel figure of a decode; a decode of both axes gets six panels per axis
    (x above y).

    Parameters
    ----------
    result : DecodeResult or AxesResult
        The decode (``bistair.decode``, ``result.plot()``).
    width : float, optional
        Figure width in inches.

    Returns
    -------
    matplotlib.figure.Figure
        Two rows of three panels per axis, titled with the result's one-line summary; the
        continuous panels with colour bars labelled ``rad``, ``projector px``, ``fringe
        order`` and ``fraction of full scale``, the mask with a legend.

    Examples
    --------
    >>> from bistair.core.result import make_result
    >>> phi = np.tile(np.linspace(0, 6, 40, dtype=np.float32), (30, 1))
    >>> order = np.tile(np.arange(40) // 10, (30, 1))
    >>> fig = plot_result(make_result("demo", phi, order, 30.0, np.full((30, 40), 0.3)))
    >>> [ax.get_title() for ax in fig.axes[:6:2]]
    ['wrapped phase', 'projector coordinate', 'modulation']
    >>> [ax.get_ylabel() for ax in fig.axes if ax.get_label() == "<colorbar>"]
    ['rad', 'rad', 'projector px', 'fringe order', 'fraction of full scale']
    >>> fig._repr_png_()[:4]  # what a notebook shows
    b'\x89PNG'
    """
    axes = [("", result)] if isinstance(result, DecodeResult) else [("x: ", result.x),
                                                                     ("y: ", result.y)]
    h, w = axes[0][1].mask.shape
    panel = width / 3
    height = len(axes) * 2 * (0.72 * panel * h / max(w, 1) + 0.5) + 0.4  # bars beside
    fig = ResultFigure(figsize=(width, height), layout="constrained")
    grid = fig.subplots(2 * len(axes), 3, squeeze=False)
    step = max(1, min(h, w) // 500)  # a panel is a few hundred pixels wide anyway
    for row, (tag, res) in enumerate(axes):
        for ax, (name, scale) in zip(grid[2 * row:2 * row + 2].ravel(), PANELS, strict=True):
            ax.set_xticks([])
            ax.set_yticks([])  # a frame, no ticks: a white image still shows its edges
            if scale is None:
                _mask_panel(ax, res.mask[::step, ::step], tag)
                continue
            _panel(fig, ax, _values(res, name)[::step, ::step], SCALES[scale], tag)
    fig.suptitle(repr(result), fontsize=10)
    return fig


def _values(result: DecodeResult, name: str) -> np.ndarray:
    if name == "order":
        return np.where(result.order >= 0, result.order, np.nan).astype(np.float32)
    return getattr(result, name)


def _panel(fig: Figure, ax: Axes, values: np.ndarray, scale: Scale, tag: str) -> None:
    cmap = colormaps[scale.cmap].with_extremes(bad="black")
    shown = ax.imshow(np.ma.masked_invalid(values), cmap=cmap, interpolation="nearest",
                      vmin=scale.vmin, vmax=scale.vmax)
    ax.set_title(tag + scale.title, fontsize=10)
    bar = fig.colorbar(shown, ax=ax, shrink=0.9)
    bar.set_label(scale.unit, fontsize=9)
    bar.ax.tick_params(labelsize=8)
    if (scale.vmin, scale.vmax) == (0.0, TWO_PI):
        bar.set_ticks([0, np.pi, TWO_PI], labels=["0", "π", "2π"])
    elif scale.integer:
        bar.locator = MaxNLocator(integer=True)
        bar.update_ticks()


def _mask_panel(ax: Axes, mask: np.ndarray, tag: str) -> None:
    rgb = np.where(mask[..., None], MASK_COLOURS[0], MASK_COLOURS[1])
    ax.imshow(rgb, interpolation="nearest")
    ax.set_title(f"{tag}mask ({100 * float(mask.mean()) if mask.size else 0:.1f}% valid)",
                 fontsize=10)
    ax.legend(handles=[Patch(facecolor=MASK_COLOURS[0], edgecolor="0.5", label="valid"),
                       Patch(facecolor=MASK_COLOURS[1], label="invalid")],
              loc="upper center", bbox_to_anchor=(0.5, -0.01), ncol=2, fontsize=8,
              frameon=False)

