"""Scores of a binocular reconstruction against the virtual rig's ground truth.

Which left pixels could match: those the left camera decodes (on the axis matched) inside its
truth mask whose scene point the right camera sees and decodes too (the point projects into
the right image onto a decoded pixel whose own truth point lies within ``max(2 mm, 0.5%)``
of it: not hidden behind something else). Depth errors are relative to the true depth, over
the points inside the left camera's truth mask; a point off by more than 1% is a wrong match
(an occlusion or a wrong phase).

Examples
--------
>>> import numpy as np
>>> depth = np.array([[600.0, 700.0, np.nan]])
>>> truth = np.array([[600.3, 707.5, 650.0]])
>>> depth_errors(depth, truth, np.ones((1, 3), bool))["wrong"]
1
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.result import AxesResult
from ..geometry.stereo import StereoResult
from ..sim.stereo import StereoRig
from ..sim.truth import Truth


def depth_errors(depth: np.ndarray, truth: np.ndarray, mask: np.ndarray,
                 wrong: float = 0.01) -> dict[str, Any]:
    """Relative depth errors of the finite ``depth`` inside ``mask``: ``points``, ``rms``
    (all points), ``rms_inliers`` (those within ``wrong``), ``p99`` (of the absolute
    errors), ``wrong`` (count beyond ``wrong``), ``wrong_share`` and ``median_mm``."""
    ok = np.isfinite(depth) & mask & np.isfinite(truth)
    rel = (depth[ok] - truth[ok]) / truth[ok]
    if not rel.size:
        return {"points": 0}
    bad = np.abs(rel) > wrong
    return {"points": int(rel.size), "rms": float(np.sqrt(np.mean(rel**2))),
            "rms_inliers": float(np.sqrt(np.mean(rel[~bad] ** 2))) if (~bad).any() else 0.0,
            "p99": float(np.percentile(np.abs(rel), 99)), "wrong": int(bad.sum()),
            "wrong_share": float(bad.mean()),
            "median_mm": float(np.median(np.abs(depth[ok] - truth[ok])))}


def both_decode(result: StereoResult, rig: StereoRig, left: Truth, right: Truth
                ) -> np.ndarray:
    """The left pixels that both cameras decode (module docstring), ``(H, W)`` bool."""
    lres = result.left.x if isinstance(result.left, AxesResult) else result.left
    rres = result.right.x if isinstance(result.right, AxesResult) else result.right
    pts = left.points.reshape(-1, 3)
    h, w = right.mask.shape
    with np.errstate(invalid="ignore"):
        uv = np.rint(rig.right.project(pts))
        inside = (uv[:, 0] >= 0) & (uv[:, 0] < w) & (uv[:, 1] >= 0) & (uv[:, 1] < h)
    flat = np.where(inside, uv[:, 1] * w + uv[:, 0], 0).astype(np.int64)
    seen = np.linalg.norm(right.points.reshape(-1, 3)[flat] - pts, axis=1)
    with np.errstate(invalid="ignore"):
        same = seen <= np.maximum(2.0, 0.005 * left.depth.ravel())
    ok = inside & same & rres.mask.ravel()[flat]
    return (ok.reshape(left.mask.shape) & lres.mask & left.mask)


def score_stereo(result: StereoResult, rig: StereoRig, left: Truth, right: Truth
                 ) -> dict[str, Any]:
    """``matched`` (share of :func:`both_decode` pixels with a point, and their count
    ``both``) and :func:`depth_errors` against the left camera's truth."""
    both = both_decode(result, rig, left, right)
    return {"both": int(both.sum()),
            "matched": float((result.mask & both).sum() / max(both.sum(), 1)),
            **depth_errors(result.depth, left.depth, left.mask)}
