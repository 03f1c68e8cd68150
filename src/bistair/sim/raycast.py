"""Vectorised ray-triangle intersection for bundles of rays from one centre.

Every query of the simulator is a bundle from one point: camera rays from the camera centre,
shadow rays from the projector centre. Rays are split by their dominant axis (cube-map
faces); on each face they are sorted into a grid of their central-projection coordinates
``(a, b)``. Each triangle, projected the same way, is scan-converted: for every grid row it
covers, the cells its projection spans form one contiguous run of sorted rays, and only
those rays are tested: edge functions in ``(a, b)`` (float32, with a slack of 1e-7, about
1e-4 camera pixels), then the triangle's plane (float64) for ``t``. Triangles reaching
behind the centre are tested against every ray of the face in 3-D (Moller-Trumbore). Pure
NumPy: trimesh's own ray queries need ``rtree`` or ``embree``, which bistair does not
depend on.

Examples
--------
>>> import numpy as np
>>> tri = np.array([[[-1.0, -1.0, 5.0], [1.0, -1.0, 5.0], [0.0, 1.0, 5.0]]])
>>> dirs = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 1.0]])
>>> t, face = Triangles(tri).intersect(np.zeros(3), dirs)
>>> t.tolist(), face.tolist()
([5.0, inf, inf], [0, -1, -1])
"""

from __future__ import annotations

import threading

import numpy as np

_EDGE_TOL = 1e-7  # slack of the (float32) edge test, so rays never slip between two triangles
_RAYS_PER_CELL = 1.0


class Triangles:
    """A triangle set, with its per-centre set-up cached for repeated bundles.

    Parameters
    ----------
    triangles : (M, 3, 3) vertices.
    max_pairs : ray-triangle tests per vectorised batch (bounds the memory).
    """

    def __init__(self, triangles: np.ndarray, max_pairs: int = 1_000_000) -> None:
        self.triangles = np.asarray(triangles, float)
        self.max_pairs = max_pairs
        self._cache: dict[tuple, dict] = {}
        self._lock = threading.Lock()

    def intersect(self, origin: np.ndarray, dirs: np.ndarray,
                  tmin: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Nearest hit with ``t > tmin`` of rays ``origin + t * dirs``.

        Parameters
        ----------
        origin : (3,) common ray origin.
        dirs : (N, 3) directions (any length; ``t`` is in units of them).
        tmin : hits at or before this ``t`` are ignored.

        Returns
        -------
        t : (N,) hit parameter, ``inf`` where missed.
        face : (N,) triangle index, -1 where missed.
        """
        origin = np.asarray(origin, float)
        dirs = np.asarray(dirs, float)
        n = dirs.shape[0]
        best = np.full(n, np.inf)
        face = np.full(n, -1, np.int64)
        if n == 0 or self.triangles.shape[0] == 0:
            return best, face
        axis = np.argmax(np.abs(dirs), axis=1)
        cube = 2 * axis + (np.take_along_axis(dirs, axis[:, None], 1)[:, 0] < 0)
        counts = np.bincount(cube, minlength=6)
        for c in np.flatnonzero(counts):
            rays = np.arange(n) if counts[c] == n else np.flatnonzero(cube == c)
            self._face(self._setup(origin, int(c)), dirs, rays, tmin, best, face)
        return best, face

    def _setup(self, origin: np.ndarray, cube: int) -> dict:
        """Triangles seen from ``origin`` on one cube face: projections, edges, planes."""
        key = (*origin.tolist(), cube)
        with self._lock:
            if key in self._cache:
                return self._cache[key]
        rel = self.triangles - origin
        normal = np.cross(rel[:, 1] - rel[:, 0], rel[:, 2] - rel[:, 0])
        plane = np.einsum("ij,ij->i", normal, rel[:, 0])  # n . (v0 - origin)
        w, ta, tb = _project(rel, cube)
        ahead = (w > 0).any(axis=1)
        straddle = ahead & (w <= 1e-9 * np.abs(rel).max(axis=(1, 2))[:, None]).any(axis=1)
        axis = cube // 2
        i1, i2 = [k for k in range(3) if k != axis]
        sgn = -1.0 if cube % 2 else 1.0
        with np.errstate(invalid="ignore"):
            box = np.column_stack([ta.min(axis=1), ta.max(axis=1), tb.min(axis=1),
                                   tb.max(axis=1)])
        setup = dict(cube=cube, rel=rel, ta=ta, tb=tb, box=box, flat=ahead & ~straddle,
                     straddle=np.flatnonzero(straddle), edges=_edges(ta, tb).astype(np.float32),
                     planes=np.column_stack([normal[:, i1], normal[:, i2], sgn * normal[:, axis],
                                             plane]))
        with self._lock:
            if len(self._cache) >= 8:  # a few centres (camera, projector) are all that recur
                self._cache.pop(next(iter(self._cache)))
            self._cache[key] = setup
        return setup

    def _face(self, setup, dirs, rays, tmin, best, face):
        """Intersect the rays of one cube face."""
        w_ray, a, b = _project(dirs if rays.size == len(dirs) else dirs[rays], setup["cube"])
        n = rays.size
        amin, amax, bmin, bmax = a.min(), a.max(), b.min(), b.max()
        span = max(amax - amin, bmax - bmin, 1e-12)
        area = max((amax - amin) * (bmax - bmin), (span * 1e-3) ** 2)
        h = max(np.sqrt(area / max(n / _RAYS_PER_CELL, 1.0)), span / 4096.0)
        gx = int((amax - amin) / h) + 1
        gy = int((bmax - bmin) / h) + 1
        cell = (np.minimum(((a - amin) / h).astype(np.int64), gx - 1)
                + gx * np.minimum(((b - bmin) / h).astype(np.int64), gy - 1))
        order = np.argsort(cell, kind="stable")
        ends = np.zeros(gx * gy + 1, np.int64)  # rays of cell k: ends[k]:ends[k + 1]
        ends[1:] = np.cumsum(np.bincount(cell, minlength=gx * gy))
        rays = rays[order]  # sorted by cell
        ab32 = np.column_stack([a[order], b[order]]).astype(np.float32)
        axis = setup["cube"] // 2
        wab = dirs[rays][:, [axis, *(k for k in range(3) if k != axis)]]  # (w, d_a, d_b)
        wab[:, 0] = w_ray[order]

        box = setup["box"]
        near = setup["flat"] & (box[:, 1] >= amin) & (box[:, 0] <= amax) \
            & (box[:, 3] >= bmin) & (box[:, 2] <= bmax)
        flat = np.flatnonzero(near)
        runs = [_runs(flat, setup["ta"][flat], setup["tb"][flat], amin, bmin, h, gx, gy, ends)]
        tall = setup["straddle"]
        if tall.size:
            runs.append((tall, np.zeros(tall.size, np.int64), np.full(tall.size, n)))
        tri, lo, hi = (np.concatenate(x) for x in zip(*runs, strict=True))
        length = hi - lo
        keep = length > 0
        tri, lo, length = tri[keep], lo[keep], length[keep]
        edges, planes = setup["edges"], setup["planes"]
        batch = (np.cumsum(length) - length) // self.max_pairs
        for sl in np.split(np.arange(tri.size), np.flatnonzero(np.diff(batch)) + 1):
            if sl.size == 0:
                continue
            count = length[sl]
            pt = np.repeat(tri[sl], count)
            pr = np.arange(count.sum()) + np.repeat(lo[sl] - (np.cumsum(count) - count), count)
            k = edges[pt]
            pab = ab32[pr]
            pa, pb = pab[:, 0], pab[:, 1]
            inside = ((k[:, 0] * pa + k[:, 1] * pb + k[:, 2] >= -_EDGE_TOL)
                      & (k[:, 3] * pa + k[:, 4] * pb + k[:, 5] >= -_EDGE_TOL)
                      & (k[:, 6] * pa + k[:, 7] * pb + k[:, 8] >= -_EDGE_TOL))
            if tall.size:
                st = np.isin(pt, tall)
                inside[st] = _inside_3d(setup["rel"][pt[st]], dirs[rays[pr[st]]])
            pt, pr = pt[inside], pr[inside]
            q, r = planes[pt], wab[pr]  # t = plane / (n . d) in face coordinates
            with np.errstate(divide="ignore", invalid="ignore"):
                t = q[:, 3] / (q[:, 0] * r[:, 1] + q[:, 1] * r[:, 2] + q[:, 2] * r[:, 0])
            ok = (t > tmin) & (t < np.inf)
            pt, ray, t = pt[ok], rays[pr[ok]], t[ok]
            np.minimum.at(best, ray, t)
            win = t == best[ray]
            face[ray[win]] = pt[win]


def barycentric(triangles: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Weights ``(u, v)`` of vertices 1 and 2 of ``triangles`` (N, 3, 3) at ``points`` (N, 3)."""
    e1, e2 = triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]
    p = points - triangles[:, 0]
    d11, d12, d22, p1, p2 = (np.einsum("ij,ij->i", x, y) for x, y in (
        (e1, e1), (e1, e2), (e2, e2), (p, e1), (p, e2)))
    det = d11 * d22 - d12 * d12
    return (d22 * p1 - d12 * p2) / det, (d11 * p2 - d12 * p1) / det


def _project(points: np.ndarray, cube: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Depth ``w`` along the cube face's axis and central-projection coordinates ``a, b``."""
    axis, neg = divmod(cube, 2)
    i1, i2 = [k for k in range(3) if k != axis]
    w = -points[..., axis] if neg else points[..., axis]
    with np.errstate(divide="ignore", invalid="ignore"):
        return w, points[..., i1] / w, points[..., i2] / w


def _runs(tri, ta, tb, amin, bmin, h, gx, gy, ends):
    """Per triangle and grid row, the run ``[lo, hi)`` of sorted rays its projection spans."""
    j0 = np.clip(((tb.min(axis=1) - bmin) / h).astype(np.int64), 0, gy - 1)
    j1 = np.clip(((tb.max(axis=1) - bmin) / h).astype(np.int64), 0, gy - 1)
    nrow = np.maximum(j1 - j0 + 1, 0)
    rep = np.repeat(np.arange(tri.size), nrow)
    j = j0[rep] + np.arange(rep.size) - np.repeat(np.cumsum(nrow) - nrow, nrow)
    band_lo, band_hi = bmin + j * h, bmin + (j + 1) * h
    lo_a = np.full(rep.size, np.inf)
    hi_a = np.full(rep.size, -np.inf)
    for e in range(3):  # clip each edge to the row band; the triangle spans their extent
        a1, b1 = ta[rep, e], tb[rep, e]
        a2, b2 = ta[rep, (e + 1) % 3], tb[rep, (e + 1) % 3]
        db = b2 - b1
        with np.errstate(divide="ignore", invalid="ignore"):
            s0, s1 = (band_lo - b1) / db, (band_hi - b1) / db
        flat_edge = db == 0
        inside_band = (b1 >= band_lo) & (b1 <= band_hi)
        s_lo = np.where(flat_edge, np.where(inside_band, 0.0, 1.0), np.maximum(
            np.minimum(s0, s1), 0.0))
        s_hi = np.where(flat_edge, np.where(inside_band, 1.0, 0.0), np.minimum(
            np.maximum(s0, s1), 1.0))
        seen = s_lo <= s_hi
        ea, eb = a1 + s_lo * (a2 - a1), a1 + s_hi * (a2 - a1)
        lo_a = np.where(seen, np.minimum(lo_a, np.minimum(ea, eb)), lo_a)
        hi_a = np.where(seen, np.maximum(hi_a, np.maximum(ea, eb)), hi_a)
    pad = 1e-9 * h
    i0 = np.clip(np.floor((lo_a - pad - amin) / h), 0, gx - 1).astype(np.int64)
    i1 = np.clip(np.floor((hi_a + pad - amin) / h), 0, gx - 1).astype(np.int64)
    valid = (lo_a <= hi_a) & (hi_a + pad >= amin) & (lo_a - pad <= amin + gx * h)
    lo = np.where(valid, ends[j * gx + i0], 0)
    hi = np.where(valid, ends[j * gx + i1 + 1], 0)
    return tri[rep], lo, hi


def _edges(ta: np.ndarray, tb: np.ndarray) -> np.ndarray:
    """Per triangle three edge lines ``A a + B b + C`` (>= 0 inside), as (M, 9)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        aj, bj = np.roll(ta, -1, axis=1), np.roll(tb, -1, axis=1)
        A, B = -(bj - tb), aj - ta  # noqa: N806
        C = -(A * ta + B * tb)  # noqa: N806
        area = (ta[:, 1] - ta[:, 0]) * (tb[:, 2] - tb[:, 0]) \
            - (tb[:, 1] - tb[:, 0]) * (ta[:, 2] - ta[:, 0])
        scale = np.sign(area)[:, None] / np.hypot(A, B)
        out = np.stack([A * scale, B * scale, C * scale], axis=-1).reshape(-1, 9)
    never = (area == 0) | ~np.isfinite(out).all(axis=1)  # edge-on or degenerate
    out[never] = (0.0, 0.0, -1.0) * 3
    return out


def _inside_3d(rel: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Moller-Trumbore's inside test (for triangles reaching behind the origin)."""
    e1, e2 = rel[:, 1] - rel[:, 0], rel[:, 2] - rel[:, 0]
    s = -rel[:, 0]
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.einsum("ij,ij->i", s, p) / det
        v = np.einsum("ij,ij->i", d, np.cross(s, e1)) / det
    return (u >= -_EDGE_TOL) & (v >= -_EDGE_TOL) & (u + v <= 1 + _EDGE_TOL)
