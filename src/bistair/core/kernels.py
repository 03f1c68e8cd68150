"""Compiled loops for the per-pixel and per-link work NumPy cannot express in one pass.

Every kernel here is written in plain Python over arrays and compiled with numba on its
first call (``cache=True``: once per machine, kept in ``__pycache__``); numba itself is
imported only then, so importing bistair or starting the command line does not pay for it.
Kernels that loop over image rows run them on every core (``prange``); :func:`set_threads`
limits that.

Examples
--------
>>> import numpy as np
>>> x = np.arange(40, dtype=np.float32)
>>> phi = np.tile(np.where(x < 20, 0.2 * x, 0.6 * x) % np.float32(2 * np.pi), (6, 1))
>>> vert, horiz = period_jump_links(phi, np.ones(phi.shape, bool),
...                                 np.full(phi.shape, 0.01, np.float32), 3, 0.3)
>>> np.flatnonzero(horiz[0]).tolist(), bool(vert.any())
([18, 19, 20], False)
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from functools import wraps
from typing import Any

import numpy as np

prange = range  # numba's prange once the first kernel compiles
_COMPILED: dict[str, Any] = {}


def kernel(parallel: bool = False) -> Callable[[Callable], Callable]:
    """Compile the decorated function with ``numba.njit`` on its first call."""

    def wrap(fn: Callable) -> Callable:
        @wraps(fn)
        def call(*args: Any) -> Any:
            compiled = _COMPILED.get(fn.__name__)
            if compiled is None:
                import numba  # heavy: imported when the first kernel runs

                module = globals()
                module["prange"] = numba.prange
                for name, value in list(module.items()):
                    if getattr(value, "_inline", False):
                        module[name] = numba.njit(cache=True, inline="always")(value)
                compiled = numba.njit(cache=True, parallel=parallel, fastmath=False,
                                      error_model="numpy")(fn)
                _COMPILED[fn.__name__] = compiled
            return compiled(*args)

        call.py_func = fn  # type: ignore[attr-defined]
        return call

    return wrap


def set_threads(count: int | None) -> int:
    """Use ``count`` threads in the kernels (all cores when ``None``); returns the count."""
    import numba

    count = count or os.cpu_count() or 1
    numba.set_num_threads(max(1, min(int(count), numba.config.NUMBA_NUM_THREADS)))
    return numba.get_num_threads()


TWO_PI32 = np.float32(2.0 * math.pi)
PI32 = np.float32(math.pi)


def _numba_inline(fn: Callable) -> Callable:
    """Mark a helper that the kernels call: compiled into them with ``numba.njit``."""
    fn._inline = True  # type: ignore[attr-defined]
    return fn


@_numba_inline
def _wrapped(raw: np.float32) -> np.float32:
    """``((raw + pi) % 2pi) - pi`` in float32, as NumPy computes it, for ``|raw| < 2pi``."""
    d = raw + PI32
    if d >= TWO_PI32:
        d = d - TWO_PI32
    elif d < 0:
        d = d + TWO_PI32
    return d - PI32


@_numba_inline
def _jump(px: np.float32, py: np.float32, pn: np.float32, qx: np.float32, qy: np.float32,
          qn: np.float32, noise_p: np.float32, noise_q: np.float32, rel: np.float32,
          half: np.float32) -> bool:
    """Whether two mean gradients differ by more than ``rel`` of the larger and four times
    their noise (float32, as :func:`bistair.core.regions.period_jumps` computes it)."""
    if pn < half or qn < half:
        return False
    one = np.float32(1.0)
    spread = np.float32(2.0) * max(noise_p / np.float32(math.sqrt(max(pn, one))),
                                   noise_q / np.float32(math.sqrt(max(qn, one))))
    step = np.float32(math.hypot(px - qx, py - qy))
    if not step > np.float32(4.0) * spread:
        return False
    size = max(np.float32(math.hypot(px, py)), np.float32(math.hypot(qx, qy)))
    return step > rel * size


@kernel(parallel=True)
def period_jump_links(phi: np.ndarray, valid: np.ndarray, noise: np.ndarray, half: int,
                      relative: float) -> tuple[np.ndarray, np.ndarray]:
    """The links across which the fringes' spacing or slant jumps (see
    :func:`bistair.core.regions.period_jumps`): ``(vertical (H-1, W), horizontal (H, W-1))``.

    Gradients are wrapped phase differences along the row (``x``) and down the column
    (``y``), averaged over windows of columns: ``[x-half, x+half)`` around a pixel (for the
    vertical links), ``[x-half, x)`` and ``[x+1, x+1+half)`` either side of a horizontal
    link. Float32 throughout, in the order of the NumPy formulation.
    """
    h, w = phi.shape
    rel = np.float32(relative)
    fhalf = np.float32(half)
    one = np.float32(1.0)
    ax = np.zeros((h, w), np.float32)
    ay = np.zeros((h, w), np.float32)
    an = np.zeros((h, w), np.float32)
    horiz = np.zeros((h, w - 1), np.bool_)
    vert = np.zeros((h - 1, w), np.bool_)
    for y in prange(h):
        sx = np.zeros(w + 1, np.float32)
        cx = np.zeros(w + 1, np.float32)
        sy = np.zeros(w + 1, np.float32)
        cy = np.zeros(w + 1, np.float32)
        for x in range(w):
            gx = np.float32(0.0)
            nx = np.float32(0.0)
            if x < w - 1 and valid[y, x] and valid[y, x + 1]:
                gx = _wrapped(phi[y, x + 1] - phi[y, x])
                nx = one
            gy = np.float32(0.0)
            ny = np.float32(0.0)
            if y < h - 1 and valid[y, x] and valid[y + 1, x]:
                gy = _wrapped(phi[y + 1, x] - phi[y, x])
                ny = one
            sx[x + 1] = sx[x] + gx
            cx[x + 1] = cx[x] + nx
            sy[x + 1] = sy[x] + gy
            cy[x + 1] = cy[x] + ny
        for x in range(w):
            lo = max(x - half, 0)
            hi = min(x + half, w)
            nxs = cx[hi] - cx[lo]
            nys = cy[hi] - cy[lo]
            ax[y, x] = (sx[hi] - sx[lo]) / max(nxs, one)
            ay[y, x] = (sy[hi] - sy[lo]) / max(nys, one)
            an[y, x] = min(nxs, nys)
        for x in range(w - 1):
            lo, hi = max(x - half, 0), x
            n1 = cx[hi] - cx[lo]
            m1 = cy[hi] - cy[lo]
            px = (sx[hi] - sx[lo]) / max(n1, one)
            py = (sy[hi] - sy[lo]) / max(m1, one)
            pn = min(n1, m1)
            lo, hi = x + 1, min(x + 1 + half, w)
            n2 = cx[hi] - cx[lo]
            m2 = cy[hi] - cy[lo]
            qx = (sx[hi] - sx[lo]) / max(n2, one)
            qy = (sy[hi] - sy[lo]) / max(m2, one)
            qn = min(n2, m2)
            horiz[y, x] = _jump(px, py, pn, qx, qy, qn, noise[y, x], noise[y, x + 1], rel,
                                fhalf)
    for y in prange(h - 1):
        for x in range(w):
            vert[y, x] = _jump(ax[y, x], ay[y, x], an[y, x], ax[y + 1, x], ay[y + 1, x],
                               an[y + 1, x], noise[y, x], noise[y + 1, x], rel, fhalf)
    return vert, horiz
