"""Passes of the binocular matching before issue 32's stereo work (1b3e4f3), kept as the
oracle of their replacements in bistair.geometry.stereo_match_jit and stereo_checks: the kinks
dropped (``drop_kinks``) and both maps negated before the smoothing within runs (two
full-image copies, then ``smooth_runs`` along the rows and down the columns in strips),
the misfit check's sample (``np.nonzero`` of every point, then evenly spaced picks), the
status counts (``np.bincount``) and ``projector_misfits`` with its cubic made column by
column and every fit on copies. Plain Python (the smoothing is run on small maps only)."""

from __future__ import annotations

import math

import numpy as np

from bistair.geometry.stereo_checks import MISFIT_PX, MISFIT_SAMPLE, _dlt
from bistair.geometry.stereo_match_jit import line_coefficients


def drop_kinks(values: np.ndarray, limit: float, reach: int) -> np.ndarray:
    h, w = values.shape
    out = values.copy()
    for y in range(h):
        row = values[y]
        for x in range(1, w - 1):
            a, b, c = float(row[x - 1]), float(row[x]), float(row[x + 1])
            if a == a and b == b and c == c and abs(a - 2.0 * b + c) > limit:
                out[y, max(0, x - reach):min(w, x + reach + 1)] = np.nan
    return out


def _joined(a: float, b: float, jump: float) -> bool:
    return abs(float(a) - float(b)) <= jump


def _fit_at(line: np.ndarray, x: int, a: int, b: int, radius: int,
            coefficients: np.ndarray) -> float:
    total = 0.0
    for k in range(-a, b + 1):
        total += coefficients[a, b, k + radius] * float(line[x + k])
    return total


def _smooth(values: np.ndarray, r: int, coefficients: np.ndarray, jump: float) -> np.ndarray:
    """The old kernel's arithmetic, in its order: the whole window's weights, the windows
    cut short fitted again."""
    h, w = values.shape
    full = coefficients[r, r]
    rows = np.empty_like(values)
    for y in range(h):
        line = values[y]
        left = np.zeros(w, np.int64)
        run = 0
        for x in range(1, w):
            run = min(run + 1, r) if _joined(line[x], line[x - 1], jump) else 0
            left[x] = run
        acc = np.zeros(w)
        for x in range(r, w - r):
            total = 0.0
            for k in range(2 * r + 1):
                total += full[k] * float(line[x + k - r])
            acc[x] = total
        run = 0
        for x in range(w - 1, -1, -1):
            if x < w - 1:
                run = min(run + 1, r) if _joined(line[x], line[x + 1], jump) else 0
            if left[x] < r or run < r:
                acc[x] = (_fit_at(line, x, int(left[x]), run, r, coefficients)
                          if line[x] == line[x] else line[x])
            rows[y, x] = acc[x]
    out = np.empty_like(values)
    for x in range(w):
        column = rows[:, x]
        up = np.zeros(h, np.int64)
        for y in range(1, h):
            up[y] = min(up[y - 1] + 1, r) if _joined(column[y], column[y - 1], jump) else 0
        down = 0
        for y in range(h - 1, -1, -1):
            if y < h - 1:
                down = min(down + 1, r) if _joined(column[y], column[y + 1], jump) else 0
            if up[y] < r or down < r:
                v = column[y]
                out[y, x] = _fit_at(column, y, int(up[y]), down, r, coefficients) if v == v else v
            else:
                total = 0.0
                for k in range(2 * r + 1):
                    total += full[k] * float(column[y + k - r])
                out[y, x] = total
    return out


def prepared(values: np.ndarray, sigma: float, jump: float, kink: float, reach: int,
             negate: bool) -> np.ndarray:
    """A map as the old matching prepared it: negated, its kinks dropped, smoothed."""
    values = np.ascontiguousarray(values, np.float32)
    values = drop_kinks(-values if negate else values, kink, reach)
    if not sigma > 0:
        return values
    radius = max(1, int(math.ceil(3 * sigma)))
    weights = np.exp(-0.5 * (np.arange(radius + 1) / sigma) ** 2)
    return _smooth(values, radius, line_coefficients(weights), float(jump))


def sample(depth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows and columns of the misfit check's points."""
    rows, cols = np.nonzero(np.isfinite(depth))
    pick = np.linspace(0, len(rows) - 1, min(len(rows), MISFIT_SAMPLE)).astype(np.int64)
    return rows[pick], cols[pick]


def projector_misfits(points: np.ndarray, coord: np.ndarray, rows: np.ndarray) -> float:
    n = len(coord)
    if n < 1000:
        return 0.0
    pick = np.linspace(0, n - 1, min(n, MISFIT_SAMPLE)).astype(np.int64)
    pts, x, v = (np.asarray(a, float)[pick] for a in (points, coord, rows))
    centre = pts.mean(axis=0)
    scale = np.sqrt(((pts - centre) ** 2).sum(axis=1).mean() / 3) or 1.0
    pts = (pts - centre) / scale
    x_mean, x_scale = x.mean(), x.std() or 1.0
    xn = (x - x_mean) / x_scale
    vn = (v - v.mean()) / (v.std() or 1.0)
    cubic = np.column_stack([xn**i * vn**j for i in range(4) for j in range(4 - i)])
    system = np.empty((len(xn), 8))
    system[:, :3], system[:, 3] = pts, 1.0
    bent = np.zeros_like(xn)
    keep = np.arange(len(xn))
    for _ in range(4):
        corrected = xn - bent
        system[:, 4:7], system[:, 7] = -corrected[:, None] * pts, -corrected
        p = _dlt(system[keep], pts[keep])
        residual = xn - (pts @ p[:3] + p[3]) / (pts @ p[4:7] + p[7])
        sub = cubic[keep]
        bent = cubic @ np.linalg.solve(sub.T @ sub, sub.T @ residual[keep])
        off = np.abs(residual - bent)
        keep = np.flatnonzero(off <= np.partition(off, int(0.9 * (len(off) - 1)))[
            int(0.9 * (len(off) - 1))])
    return float(np.mean(off * x_scale > MISFIT_PX))
