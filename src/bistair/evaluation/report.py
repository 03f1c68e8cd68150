"""Figures of a comparison (the paper's Fig. 9, 10 and 17 views) and a self-contained HTML
report that embeds them."""

from __future__ import annotations

import base64
import html
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..core.phase import TWO_PI  # noqa: E402
from .benchmark import Row  # noqa: E402


def method_figure(row: Row, truth: Any, path: str | Path) -> Path:
    """Wrapped phase, code (``k_s``), fringe order, absolute phase and |error| of one method."""
    res = row.result
    coord = truth.coord(row.spec)
    err = np.abs(res.phase - coord * (TWO_PI / res.period))
    err[~(res.mask & truth.mask)] = np.nan
    code = np.where(res.code >= 0, res.code, np.nan).astype(float)
    order = np.where(res.order >= 0, res.order, np.nan).astype(float)
    panels = [
        ("wrapped phase", res.wrapped, "gray", (0, TWO_PI)),
        ("code (k_s)", code, "viridis", None),
        ("fringe order", order, "jet", None),
        ("absolute phase", res.phase, "jet", None),
        ("|error| (rad, 0-0.3)", np.minimum(err, 0.3), "magma", (0, 0.3)),
        ("order errors (red)", _order_errors(err, res.mask, truth.mask), None, None),
    ]
    step = max(1, min(err.shape) // 400)  # the panels are about 400 px tall anyway
    fig, axes = plt.subplots(2, 3, figsize=(12, 7.2), constrained_layout=True)
    for ax, (title, img, cmap, lim) in zip(axes.ravel(), panels, strict=True):
        # Downsample by taking every step-th pixel, but keep every order error visible.
        img = _block_max(img, step) if img.ndim == 3 else img[::step, ::step]
        if cmap is None:
            ax.imshow(img)
        else:
            cm = plt.get_cmap(cmap).with_extremes(bad="black")
            kw = {} if lim is None else {"vmin": lim[0], "vmax": lim[1]}
            ax.imshow(np.ma.masked_invalid(img), cmap=cm, interpolation="nearest", **kw)
        ax.set_title(title, fontsize=10)
        ax.set_axis_off()
    s = row.scores
    fig.suptitle(f"{row.label}: {row.frames} frames, coverage {100 * s['coverage']:.2f}%, "
                 f"order errors {100 * s['order_error_rate']:.3f}%, "
                 f"RMSE {s['phase_rmse']:.4f} rad", fontsize=11)
    path = Path(path)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


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


def _embed(path: Path) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{html.escape(path.stem)}">'


def write_report(path: str | Path, title: str, intro: str, rows: list[dict[str, Any]],
                 objects: list[int], figures: list[Path], notes: str = "") -> Path:
    """A single HTML file with the comparison table and the figures embedded."""
    small = objects[1:]
    head = "".join(f"<th>{h}</th>" for h in (
        "method", "frames", "coverage", "order error rate", "phase RMSE vs truth (rad)",
        "RMSE vs reference (rad)", *(f"object {i} right" for i in small)))
    body = []
    for r in rows:
        cells = [html.escape(r["method"]), str(r["frames"]), f"{100 * r['coverage']:.2f}%",
                 f"{100 * r['order_error_rate']:.3f}%", f"{r['phase_rmse']:.4f}",
                 f"{r['rmse_vs_reference']:.4f}",
                 *(f"{100 * r['objects'][i]:.1f}%" for i in small)]
        body.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    figs = "\n".join(f"<h3>{html.escape(p.stem)}</h3>{_embed(p)}" for p in figures)
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
