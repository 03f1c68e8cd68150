"""Compiled passes of the checks (:mod:`bistair.core.checks`): code steps against the
wrapped phase, and order steps across the phase's wraps (bit for bit the NumPy they
replace).

Examples
--------
>>> import numpy as np
>>> phi = np.float32([[6.0, 0.2, 1.0]])
>>> wrap_step_counts(phi, np.int32([[0, 1, 1]]), np.ones((1, 3), bool), 1, 0)
(0, 0, 1)
"""

from __future__ import annotations

import math

import numpy as np

from .jit import TWO_PI32, kernel

prange = range  # numba's prange once the first kernel of this module compiles


@kernel(parallel=True)
def _step_sums(phi: np.ndarray, edges: np.ndarray, valid: np.ndarray, edge_phase: float,
               levels: int, every: int) -> tuple[int, float, float, int]:
    h, w = edges.shape
    rows = (h + every - 1) // every
    sums = np.zeros((rows, 4), np.float64)
    half = levels / 2.0
    for r in prange(rows):
        y = r * every
        m = 0
        against = 0
        zc = 0.0
        zs = 0.0
        e = np.empty(w, np.int32)  # the row's code, -1 where not valid
        for x in range(w):
            e[x] = edges[y, x] if valid[y, x] else -1
        words = (w + 4) // 8  # the pairs (j+1, j+2) whose code differs: a byte each
        change = np.zeros(8 * words, np.uint8)
        for j in range(w - 3):
            change[j] = e[j + 1] != e[j + 2]
        packed = change.view(np.uint64)
        for q in range(words):
            if packed[q] == 0:  # eight pairs of equal codes
                continue
            for j in range(8 * q, 8 * q + 8):
                if change[j] == 0:
                    continue
                a = e[j + 1]
                b = e[j + 2]
                if a < 0 or b < 0 or e[j] != a or e[j + 3] != b:
                    continue
                pa = np.float64(phi[y, j + 1])
                pb = np.float64(phi[y, j + 2])
                rise = (pb - pa + math.pi) % (2.0 * math.pi) - math.pi  # wrap(pb - pa)
                # the phase between the two: angle(exp(i pa) + exp(i pb)), but for 2*pi
                mid = pa + 0.5 * rise - edge_phase
                zc += math.cos(mid)
                zs += math.sin(mid)
                step = np.int64(b) - np.int64(a)
                if levels > 0:
                    step = 1 if step % levels < half else -1
                if not ((step > 0 and rise > 0) or (step < 0 and rise < 0)):
                    against += 1
                m += 1
        sums[r, 0] = m
        sums[r, 1] = zc
        sums[r, 2] = zs
        sums[r, 3] = against
    count = 0
    zc = 0.0
    zs = 0.0
    against = 0
    for r in range(rows):
        count += np.int64(sums[r, 0])
        zc += sums[r, 1]
        zs += sums[r, 2]
        against += np.int64(sums[r, 3])
    return count, zc, zs, against


def step_sums(phi: np.ndarray, edges: np.ndarray, valid: np.ndarray, edge_phase: float = 0.0,
              levels: int | None = None, every: int = 1) -> tuple[int, float, float, int]:
    """What :func:`~bistair.core.checks.edge_alignment` needs of the code steps of
    the code's steps (on every ``every``-th row), summed in one pass with no list of the
    steps: their count, the sums of the cosine and sine of the phase between the two pixels
    of each less ``edge_phase``, and how many steps the phase falls across where the code
    grows (a step of a code of ``levels`` values grows when it is less than half a cycle,
    modulo ``levels``). The phase between ``pa`` and ``pb`` is ``pa + wrap(pb - pa) / 2``,
    ``angle(exp(i pa) + exp(i pb))`` but for a whole turn, with one sine and cosine a step
    instead of seven trigonometric calls; the sums are added row by row. Against NumPy on
    the steps' arrays (tests/test_checks_jit.py): the counts the same, the sums within
    1e-12 per step.

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in ``[0, 2*pi)``.
    edges : (H, W) int array
        The code per pixel, -1 where not read.
    valid : (H, W) bool array
        Pixels whose phase counts (the others read as -1).
    edge_phase : float
        The wrapped phase (radians) at which the code's edges should sit.
    levels : int, optional
        The code's cycle, if it has one.
    every : int
        Judge every ``every``-th row (from the first).

    Returns
    -------
    count : int
    cos_sum, sin_sum : float
    against : int

    Examples
    --------
    >>> phi = np.float32([[0.1, 0.2, 0.3, 0.4, 0.5, 0.6]])
    >>> code = np.int32([[1, 1, 2, 2, 2, 5]])
    >>> n, c, s, against = step_sums(phi, code, np.ones((1, 6), bool))
    >>> n, round(c, 4), round(s, 4), against
    (1, 0.9689, 0.2474, 0)
    """
    return _step_sums(phi, edges, np.asarray(valid, bool), float(edge_phase),
                      int(levels or 0), int(every))


@kernel()
def level_misfits(theta: np.ndarray, levels: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Each stair phase's distance from its nearest level (the first of equal ones), over
    half that level's gap (:func:`~bistair.core.checks.stair_misfit`'s values): as NumPy's
    ``abs(wrap(theta[:, None] - levels[None, :]))``, ``argmin`` and division give them, in
    one pass with no (n, L) temporaries.

    Parameters
    ----------
    theta : (n,) float64 array
        Stair phases in radians.
    levels : (L,) float64 array
        The levels' phases.
    half : (L,) float64 array
        Half of each level's gap to its neighbour.

    Returns
    -------
    (n,) float64 array

    Examples
    --------
    >>> level_misfits(np.array([0.1, 1.0, -2.0]), np.array([-2.0, 0.0, 2.0]),
    ...               np.ones(3)).round(3).tolist()
    [0.1, 1.0, 0.0]
    """
    n = theta.size
    out = np.empty(n, np.float64)
    for i in range(n):
        best = np.inf
        at = 0
        for j in range(levels.size):
            d = abs((theta[i] - levels[j] + math.pi) % (2.0 * math.pi) - math.pi)
            if d != d:  # NaN: argmin's first NaN
                best = d
                at = j
                break
            if d < best:
                best = d
                at = j
        out[i] = best / half[at]
    return out


@kernel()
def _wrap_steps(phi: np.ndarray, order: np.ndarray, valid: np.ndarray, every: int,
                reach: int, edge: float) -> tuple[int, int, int]:
    h, w = phi.shape
    rows = (h + every - 1) // every
    span = 2 * reach + 1
    pi32 = np.float32(math.pi)
    near = np.float32(0.6)
    e = np.float32(edge)
    counts = np.zeros((rows, 3), np.int64)
    for r in range(rows):
        y = r * every
        # the phase turned by the edge phase and the order plus one past it (edge 0: as is)
        t = np.empty(w, np.float32)
        k = np.empty(w, np.int64)
        for x in range(w):
            p = np.float32(phi[y, x])
            t[x] = p - e if p >= e else p - e + TWO_PI32
            k[x] = -1 if order[y, x] < 0 else np.int64(order[y, x]) + (1 if p >= e else 0)
        bad_sum = np.zeros(w, np.int32)  # prefix counts over the w - 1 pairs
        wrap_sum = np.zeros(w, np.int32)
        for x in range(w - 1):
            d = t[x + 1] - t[x]
            ok = valid[y, x] and k[x] >= 0 and valid[y, x + 1] and k[x + 1] >= 0
            clean = ok and abs(d - TWO_PI32 * np.rint(d / TWO_PI32)) < near
            bad_sum[x + 1] = bad_sum[x] + (0 if clean else 1)
            wrap_sum[x + 1] = wrap_sum[x] + (1 if clean and abs(d) > pi32 else 0)
        bad = 0
        big = 0
        judged = 0
        for j in range(w - span):
            c = j + reach
            d = t[c + 1] - t[c]
            if not abs(d) > pi32:
                continue
            if bad_sum[j + span] - bad_sum[j] != 0 or wrap_sum[j + span] - wrap_sum[j] != 1:
                continue
            judged += 1
            want = -1 if d > 0 else 1
            off = abs(k[j + span] - k[j] - want)
            if off != 0:
                bad += 1
            if off >= 2:
                big += 1
        counts[r, 0] = bad
        counts[r, 1] = big
        counts[r, 2] = judged
    return counts[:, 0].sum(), counts[:, 1].sum(), counts[:, 2].sum()


def wrap_step_counts(phi: np.ndarray, order: np.ndarray, valid: np.ndarray, every: int,
                     reach: int, edge: float = 0.0) -> tuple[int, int, int]:
    """:func:`~bistair.core.checks.wrap_steps` in one pass over the rows it judges:
    ``(violations, big violations, places)``.

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in [0, 2*pi) (read as float32).
    order : (H, W) int array
        Fringe orders, -1 where invalid.
    valid : (H, W) bool array
        Pixels to judge.
    every : int
        Judge every ``every``-th row.
    reach : int
        Pixels on either side of a wrap that must run on smoothly.
    edge : float, default 0.0
        Judge the wraps of the phase turned by ``edge`` (radians, in [0, 2*pi)) and the
        orders plus one where the phase is ``edge`` or more: the steps at a code's edges
        mid-fringe (:func:`~bistair.core.checks.edge_steps`); 0: the phase's own wraps.

    Returns
    -------
    (violations, big violations, places) : tuple of int
        As :func:`~bistair.core.checks.wrap_steps` counts them.

    Examples
    --------
    >>> x = np.arange(80) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 20) % (2 * np.pi), (2, 1)).astype(np.float32)
    >>> order = np.tile((x // 20).astype(np.int32), (2, 1))
    >>> wrap_step_counts(phi, order, np.ones(phi.shape, bool), 1, 3)
    (0, 0, 6)
    >>> wrap_step_counts(phi, np.where(x < 40, order, order + 2), np.ones(phi.shape, bool), 1, 3)
    (2, 2, 6)
    """
    if phi.shape[1] < 2 * reach + 2:
        return 0, 0, 0
    bad, big, places = _wrap_steps(phi, order, np.asarray(valid, bool), int(every),
                                   int(reach), float(edge))
    return int(bad), int(big), int(places)
