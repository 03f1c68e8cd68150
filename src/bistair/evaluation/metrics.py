"""Figures of a decode against ground truth.

A pixel's fringe order is wrong when its absolute phase is off by more than pi from the truth
(a 2*pi jump error). Next to a stair edge, order ``k`` with a wrapped phase near 2*pi and
order ``k + 1`` with one near 0 give the same absolute phase; both are right.

Examples
--------
>>> import numpy as np
>>> from bistair.core.result import make_result
>>> truth = np.tile(np.arange(90.0) + 0.5, (4, 1))
>>> phi = (2 * np.pi * truth / 30) % (2 * np.pi)
>>> order = truth // 30
>>> order[0, 10] += 1
>>> res = make_result("demo", phi, order.astype(int), 30, np.ones_like(phi))
>>> m = score(res, truth, np.ones_like(phi, bool))
>>> m["coverage"], round(m["order_error_rate"], 5), m["order_errors"]
(1.0, 0.00278, 1)
"""

from __future__ import annotations

import numpy as np

from ..core.phase import TWO_PI
from ..core.result import DecodeResult


def score(result: DecodeResult, coord: np.ndarray, mask: np.ndarray,
            object_id: np.ndarray | None = None) -> dict:
    """Coverage, order error rate and phase RMSE of ``result`` against the true coordinate.

    ``mask`` marks the pixels with a ground truth (lit, wholly on one surface). With
    ``object_id``, the share of each object's truth pixels decoded right is reported too.
    """
    truth_phase = TWO_PI * coord / result.period
    decoded = result.mask & mask
    err = np.where(decoded, result.phase - truth_phase, 0.0)
    wrong = decoded & (np.abs(err) > np.pi)
    right = decoded & ~wrong
    n_truth, n_dec = int(mask.sum()), int(decoded.sum())
    out = {
        "truth_pixels": n_truth,
        "decoded": n_dec,
        "coverage": n_dec / n_truth if n_truth else 0.0,
        "order_errors": int(wrong.sum()),
        "order_error_rate": float(wrong.sum() / n_dec) if n_dec else 0.0,
        "phase_rmse": float(np.sqrt(np.mean(err[right] ** 2))) if right.any() else float("nan"),
        "outside_truth": int((result.mask & ~mask).sum()),
    }
    if object_id is not None:
        out["objects"] = {
            int(i): float(right[object_id == i].sum() / max(1, (mask & (object_id == i)).sum()))
            for i in np.unique(object_id[mask])
        }
    return out


def fit_sphere(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares sphere through ``(N, 3)`` points: ``(centre, radius)``.

    >>> u = np.random.default_rng(0).normal(size=(200, 3))
    >>> pts = 40 * u / np.linalg.norm(u, axis=1, keepdims=True) + [1.0, 2.0, 500.0]
    >>> c, r = fit_sphere(pts)
    >>> np.round(c, 6).tolist(), round(r, 6)
    ([1.0, 2.0, 500.0], 40.0)
    """
    pts = np.asarray(points, float)
    sol = np.linalg.lstsq(np.column_stack([2 * pts, np.ones(len(pts))]), (pts**2).sum(1),
                          rcond=None)[0]
    return sol[:3], float(np.sqrt(sol[3] + sol[:3] @ sol[:3]))


def fit_plane(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least-squares plane through ``(N, 3)`` points: ``(centre, unit normal, residuals)``."""
    pts = np.asarray(points, float)
    centre = pts.mean(axis=0)
    normal = np.linalg.svd(pts - centre, full_matrices=False)[2][2]
    return centre, normal, (pts - centre) @ normal
