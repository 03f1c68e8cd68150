"""Figures of a comparison (the paper's Fig. 9, 10 and 17 views) and a self-contained HTML
report that embeds them."""

from __future__ import annotations

import base64
import html
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch, Rectangle  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from ..core.phase import TWO_PI  # noqa: E402
from .benchmark import Row  # noqa: E402


def method_figure(row: Row, truth: Any, path: str | Path) -> Path:
    """Write :func:`draw_method` of one method to ``path`` (PNG); returns ``path``."""
    fig = draw_method(row, truth)
    path = Path(path)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


# the legend of the order-error panel: colour (as in _order_errors) and meaning
ORDER_LEGEND = (((150, 150, 150), "right order"), ((255, 0, 0), "wrong order"),
                ((40, 80, 255), "not decoded"))


def draw_method(row: Row, truth: Any) -> Figure:
    """Wrapped phase, code (``k_s``), fringe order, absolute phase, the error's size and order
    errors of one method against the truth, each continuous panel with its colour bar and the
    order errors with a legend.

    Parameters
    ----------
    row : the method's decode and scores (:class:`~bistair.evaluation.benchmark.Row`).
    truth : the ground truth (``coord(spec)`` and ``mask``, e.g. :class:`bistair.sim.Truth`).

    Returns
    -------
    matplotlib.figure.Figure
        Two rows of three panels, titled with the method's label and scores.

    Examples
    --------
    >>> from bistair.codecs import decode, encode, make_spec
    >>> from bistair.sim.warp import WarpScene, render_warp
    >>> spec = make_spec("graycode", width=240, height=60, period=20)
    >>> images, truth = render_warp(spec, WarpScene(size=(60, 120), noise=0, blur=0))
    >>> result = decode(images, spec)
    >>> row = Row("graycode", spec, result, {"coverage": 1.0, "order_error_rate": 0.0,
    ...                                       "phase_rmse": 0.0})
    >>> fig = draw_method(row, truth)
    >>> [ax.get_ylabel() for ax in fig.axes if ax.get_label() == "<colorbar>"]
    ['rad', 'code level', 'fringe order', 'rad', 'rad (0.3 and above)']
    >>> plt.close(fig)
    """
    res = row.result
    coord = truth.coord(row.spec)
    err = np.abs(res.phase - coord * (TWO_PI / res.period))
    err[~(res.mask & truth.mask)] = np.nan
    code = np.where(res.code >= 0, res.code, np.nan).astype(float)
    order = np.where(res.order >= 0, res.order, np.nan).astype(float)
    panels = [  # title, image, colour map, value range, colour bar label
        ("wrapped phase", res.wrapped, "gray", (0, TWO_PI), "rad"),
        ("code (k_s)", code, "viridis", None, "code level"),
        ("fringe order", order, "jet", None, "fringe order"),
        ("absolute phase", res.phase, "jet", None, "rad"),
        ("|error| (truth pixels decoded)", np.minimum(err, 0.3), "magma", (0, 0.3),
         "rad (0.3 and above)"),
        ("order errors", _order_errors(err, res.mask, truth.mask), None, None, None),
    ]
    step = max(1, min(err.shape) // 400)  # the panels are about 400 px tall anyway
    fig, axes = plt.subplots(2, 3, figsize=(12.5, 7.2), constrained_layout=True)
    for ax, (title, img, cmap, lim, unit) in zip(axes.ravel(), panels, strict=True):
        # Downsample by taking every step-th pixel, but keep every order error visible.
        img = _block_max(img, step) if img.ndim == 3 else img[::step, ::step]
        ax.set_title(title, fontsize=10)
        ax.set_axis_off()
        if cmap is None:
            ax.imshow(img)
            ax.legend(handles=[Patch(color=np.array(rgb) / 255, label=text)
                               for rgb, text in ORDER_LEGEND],
                      loc="upper center", bbox_to_anchor=(0.5, -0.01), ncol=3, fontsize=8,
                      frameon=False)
            continue
        cm = plt.get_cmap(cmap).with_extremes(bad="black")
        kw = {} if lim is None else {"vmin": lim[0], "vmax": lim[1]}
        shown = ax.imshow(np.ma.masked_invalid(img), cmap=cm, interpolation="nearest", **kw)
        bar = fig.colorbar(shown, ax=ax, shrink=0.85, extend="max" if unit.endswith(
            "and above)") else "neither")
        bar.set_label(unit, fontsize=9)
        bar.ax.tick_params(labelsize=8)
        if lim == (0, TWO_PI):
            bar.set_ticks([0, np.pi, TWO_PI], labels=["0", "π", "2π"])
        elif unit in ("code level", "fringe order"):
            bar.locator = MaxNLocator(integer=True)
            bar.update_ticks()
    s = row.scores
    refused = res.info.get("refused")
    fig.suptitle(f"{row.label}: {row.frames} frames, refused: {refused}" if refused else
                 f"{row.label}: {row.frames} frames, coverage {100 * s['coverage']:.2f}%, "
                 f"order errors {100 * s['order_error_rate']:.3f}%, "
                 f"RMSE {s['phase_rmse']:.4f} rad (black: no value)", fontsize=11)
    return fig


def sweep_figure(curves: dict[str, Sequence[tuple[float, float | None]]], xlabel: str,
                 ylabel: str) -> Figure:
    """One line per method of a score (a share, drawn in %) against a factor; a decode that
    refused the captures (a ``None`` score) is drawn as refused: a cross in the method's
    colour in a hatched "refused" band above the scores, the line broken there, never as a
    score of 0.

    Parameters
    ----------
    curves : method label -> ``(factor value, share or None)`` points.
    xlabel, ylabel : the axes' labels.

    Returns
    -------
    matplotlib.figure.Figure
        The plot, with a legend entry "refused decode" when any decode refused.

    Examples
    --------
    >>> fig = sweep_figure({"a": [(1, 0.0), (2, None), (3, 0.01)], "b": [(1, 0.02)]},
    ...                    "noise", "order error rate (%)")
    >>> ax = fig.axes[0]
    >>> ax.lines[0].get_ydata().tolist()  # the refused point is no score
    [0.0, nan, 1.0]
    >>> [t.get_text() for t in ax.get_legend().get_texts()], [t.get_text() for t in ax.texts]
    (['a', 'b', 'refused decode'], ['refused'])
    >>> ax.collections[0].get_offsets()[:, 0].tolist()  # the cross, where it refused
    [2.0]
    """
    fig = Figure(figsize=(6.4, 4), layout="constrained")
    ax = fig.subplots()
    refused_at: list[tuple[list[float], str]] = []
    scores = []
    for method, points in curves.items():
        pts = sorted(points, key=lambda p: p[0])
        ys = [np.nan if p[1] is None else 100 * p[1] for p in pts]
        line, = ax.plot([p[0] for p in pts], ys, marker="o", label=method)
        scores += [y for y in ys if np.isfinite(y)]
        if any(p[1] is None for p in pts):
            refused_at.append(([x for x, y in pts if y is None], line.get_color()))
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if refused_at:  # a band above the scores: no cross can be read as a score
        low, high = (min(scores), max(scores)) if scores else (0.0, 1.0)
        span = (high - low) or 1.0
        ax.set_ylim(low - 0.05 * span, low + span / 0.78)
        ax.set_yticks([t for t in ax.get_yticks() if low - 0.05 * span <= t <= high])
        ax.add_patch(Rectangle((0, 0.84), 1, 0.16, transform=ax.transAxes, facecolor="0.94",
                               edgecolor="0.75", hatch="//", zorder=0))
        ax.text(0.01, 0.92, "refused", transform=ax.transAxes, va="center", fontsize=8,
                color="0.35")
        top = ax.get_xaxis_transform()  # x in data, y in axes fraction
        for k, (xs, colour) in enumerate(refused_at):
            ax.scatter(xs, [0.97 - 0.1 * k / max(1, len(refused_at) - 1)] * len(xs),
                       transform=top, marker="X", s=60, color=colour, zorder=3)
        handles.append(Line2D([], [], color="0.3", marker="X", linestyle="none",
                              markersize=8))
        labels.append("refused decode")
    ax.legend(handles, labels, fontsize=7, loc="center right")
    return fig


def _order_errors(err: np.ndarray, mask: np.ndarray, truth_mask: np.ndarray) -> np.ndarray:
    """RGB: decoded right in grey, wrong order in red, truth pixels not decoded in blue."""
    rgb = np.zeros((*err.shape, 3), np.uint8)
    ok = mask & truth_mask
    rgb[ok] = (150, 150, 150)
    rgb[ok & (err > np.pi)] = (255, 0, 0)
    rgb[truth_mask & ~mask] = (40, 80, 255)
    return rgb


def _block_max(rgb: np.ndarray, step: int) -> np.ndarray:
    h, w = (rgb.shape[0] // step) * step, (rgb.shape[1] // step) * step
    return rgb[:h, :w].reshape(h // step, step, w // step, step, 3).max(axis=(1, 3))


def _embed(path: Path, alt: str) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{html.escape(alt)}">'


def write_report(path: str | Path, title: str, intro: str, rows: list[dict[str, Any]],
                 objects: list[int], figures: Sequence[tuple[str, Path]],
                 notes: str = "") -> Path:
    """A single HTML file with the comparison table and the figures embedded.

    Parameters
    ----------
    path : the HTML file to write.
    title, intro : the page's heading and first paragraph (``intro`` may hold HTML).
    rows, objects : :func:`~bistair.evaluation.benchmark.table` rows and the object ids,
        largest first (all but the first are the small objects); a refused row reads
        "refused" and why across its score cells.
    figures : ``(heading, PNG file)`` per figure, e.g. the method's label such as
        ``"bidirectional (paper decoder)"``.
    notes : a paragraph after the table.

    Returns
    -------
    Path
        ``path``.
    """
    small = objects[1:]
    head = "".join(f"<th>{h}</th>" for h in (
        "method", "frames", "coverage", "order error rate", "phase RMSE vs truth (rad)",
        "RMSE vs reference (rad)", *(f"object {i} right" for i in small)))
    body = []
    for r in rows:
        if r.get("refused"):  # no scores: the decode refused the captures
            body.append(f"<tr><td>{html.escape(r['method'])}</td><td>{r['frames']}</td>"
                        f"<td colspan=\"{4 + len(small)}\" style=\"text-align:left\">"
                        f"refused: {html.escape(r['refused'])}</td></tr>")
            continue
        cells = [html.escape(r["method"]), str(r["frames"]), f"{100 * r['coverage']:.2f}%",
                 f"{100 * r['order_error_rate']:.3f}%", f"{r['phase_rmse']:.4f}",
                 f"{r['rmse_vs_reference']:.4f}",
                 *(f"{100 * r['objects'][i]:.1f}%" for i in small)]
        body.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    figs = "\n".join(f"<h3>{html.escape(heading)}</h3>{_embed(p, heading)}"
                     for heading, p in figures)
    doc = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>body{{font-family:sans-serif;margin:2em;max-width:1300px}}
table{{border-collapse:collapse}}td,th{{border:1px solid #bbb;padding:4px 8px;text-align:right}}
th{{background:#eee}}td:first-child{{text-align:left}}img{{max-width:100%}}</style></head>
<body><h1>{html.escape(title)}</h1><p>{intro}</p>
<table><tr>{head}</tr>{''.join(body)}</table>
<p>{notes}</p>
{figs}
</body></html>
"""
    path = Path(path)
    path.write_text(doc)
    return path
