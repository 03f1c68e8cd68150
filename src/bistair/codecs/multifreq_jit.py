"""Compiled passes of multi-frequency unwrapping (:mod:`bistair.codecs.multifreq`): the
hierarchical unwrap from the longest period down, and the orders where the periods agree
(bit for bit the NumPy they replace).
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import kernel

prange = range  # numba's prange once the first kernel of this module compiles


@kernel(parallel=True)
def _unwrap_chain(phases: tuple, ratios: np.ndarray, top_scale: float, top_fold: float,
                  phi: np.ndarray, valid: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    h, w = phi.shape
    n = len(ratios)
    two_pi = 2.0 * math.pi
    inv = 1.0 / two_pi
    code = np.empty((h, w), np.int32)
    worst = np.empty((h, w), np.float32)
    last = np.zeros((h, w), np.float32)
    zero = np.float32(0.0)
    for y in prange(h):  # step by step along the row (vector loops), the phase in `a`
        a = np.empty(w, np.float64)
        most = np.zeros(w, np.float64)  # the row's worst miss, float64 until stored
        top = phases[0]
        for x in range(w):
            p = np.float64(top[y, x])
            a[x] = p - two_pi if p * top_scale >= top_fold else p
        for i in range(n):
            fine = phases[i + 1]
            ratio = ratios[i]
            for x in range(w):
                f = np.float64(fine[y, x])
                ref = a[x] * ratio
                k = np.rint((ref - f) * inv)
                miss = (ref - f) / two_pi - k
                m = abs(miss)
                was = most[x]
                most[x] = m if was == was and (m != m or m > was) else was  # NaN wins
                last[y, x] = np.float32(miss)
                a[x] = f + two_pi * k
        for x in range(w):
            order = np.rint((a[x] - np.float64(phi[y, x])) * inv)
            code[y, x] = np.int32(order) if valid[y, x] and np.isfinite(order) else -1
            m32 = np.float32(most[x])  # rounded toward zero: `< limit` as in float64
            worst[y, x] = np.nextafter(m32, zero) if m32 > most[x] else m32
    return code, worst, last


def unwrap_chain(phases: tuple[np.ndarray, ...], periods: tuple[float, ...], length: int,
                 phi: np.ndarray, valid: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hierarchical temporal unwrapping, per pixel in float64: the coarsest phase made
    absolute (:func:`~bistair.codecs.multifreq.top_phase`), each finer one unwrapped from
    the one before (``order_from_reference`` of the scaled coarser phase), and the order
    of ``phi`` (the finest phase) from the last.

    Parameters
    ----------
    phases : tuple of (H, W) float32 arrays
        Wrapped phases in [0, 2*pi), coarsest period first (at least two).
    periods : tuple of float
        Their periods in projector pixels, descending; the first covers the coded axis.
    length : int
        Projector pixels along the coded axis.
    phi : (H, W) float32 array
        The finest wrapped phase (whose order is wanted).
    valid : (H, W) bool array
        Pixels to give an order.

    Returns
    -------
    code : (H, W) int32 array
        The order of ``phi``, -1 where not valid (or not finite).
    worst : (H, W) float32 array
        The largest miss of any unwrapping step, in fringes: computed in float64 and
        rounded toward zero, so that it is below a float32 limit (such as 0.25) exactly
        where the float64 miss is.
    last : (H, W) float32 array
        The signed miss of the last step, in fringes.

    Examples
    --------
    >>> x = np.arange(0.5, 300.0, 50.0)[None]
    >>> phases = tuple(np.float32((2 * np.pi * x / t) % (2 * np.pi)) for t in (300.0, 30.0))
    >>> code, worst, last = unwrap_chain(phases, (300.0, 30.0), 300, phases[1],
    ...                                  np.ones(x.shape, bool))
    >>> code.tolist(), bool(worst.max() < 1e-5)
    ([[0, 1, 3, 5, 6, 8]], True)
    """
    two_pi = 2.0 * math.pi
    ratios = np.array([a / b for a, b in zip(periods[:-1], periods[1:], strict=True)])
    top = periods[0]
    return _unwrap_chain(tuple(np.ascontiguousarray(p, np.float32) for p in phases), ratios,
                         top / two_pi, 0.5 * (length + top), np.asarray(phi, np.float32),
                         np.asarray(valid, bool))


@kernel(parallel=True)
def _agreed(code: np.ndarray, worst: np.ndarray, valid: np.ndarray, phi: np.ndarray,
            limit: float, every: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    h, w = code.shape
    two_pi = 2.0 * math.pi
    order = np.empty((h, w), np.int32)
    counts = np.zeros((h, 5), np.int64)  # valid, agreeing, kept, falling steps, others
    ends = np.zeros((h, 2), np.float64)  # the falling step nearest 0, the other one too
    for y in prange(h):
        lit = 0
        agree = 0
        kept = 0
        for x in range(w):
            v = valid[y, x]
            a = worst[y, x] < limit
            ok = v and a and code[y, x] >= 0
            order[y, x] = code[y, x] if ok else -1
            lit += v
            agree += v and a
            kept += ok
        counts[y, 0], counts[y, 1], counts[y, 2] = lit, agree, kept
        if y % every:
            continue
        fall = 0
        rise = 0
        top = -np.inf  # the largest falling step
        low = np.inf  # the smallest other one
        for x in range(w - 1):
            if order[y, x] < 0 or order[y, x + 1] < 0:
                continue
            d = ((np.float64(phi[y, x + 1]) + two_pi * np.float64(code[y, x + 1]))
                 - (np.float64(phi[y, x]) + two_pi * np.float64(code[y, x])))
            if d < 0:
                fall += 1
                top = max(top, d)
            elif d >= 0:  # (NaN steps are left out)
                rise += 1
                low = min(low, d)
        counts[y, 3], counts[y, 4] = fall, rise
        ends[y, 0], ends[y, 1] = top, low
    return order, counts, ends


def agreed_orders(code: np.ndarray, worst: np.ndarray, valid: np.ndarray, phi: np.ndarray,
                  limit: float = 0.25, every: int = 4) -> tuple[np.ndarray, int, int, bool]:
    """The orders kept where every unwrapping step agrees, in one pass: ``order =
    np.where(valid & (worst < limit) & (code >= 0), code, -1)`` (int32), the counts of
    ``valid`` and of ``valid & (worst < limit)``, and whether the absolute phase falls
    along the rows: ``np.nanmedian(np.diff(sub, axis=1)) < 0`` for ``sub =
    np.where(kept, phi + 2*pi*code, nan)`` on every ``every``-th row, judged only with
    over 100 kept pixels.

    Parameters
    ----------
    code : (H, W) int array
        Order per pixel.
    worst : (H, W) float array
        The largest miss of the unwrapping steps, in fringes.
    valid : (H, W) bool array
        The well-modulated pixels.
    phi : (H, W) float array
        The wrapped phase of ``code``'s period.
    limit : float, default 0.25
        The largest miss kept.
    every : int, default 4
        The rows whose steps are judged: 0, every, 2*every, ...

    Returns
    -------
    order : (H, W) int32 array
        ``code`` where kept, -1 elsewhere.
    lit : int
        Valid pixels.
    agreeing : int
        Valid pixels with ``worst < limit``.
    falling : bool
        The median step of the absolute phase along the rows is negative.

    Examples
    --------
    >>> code = np.int32([[0, 0, 1, 1, -1]])
    >>> worst = np.array([[0.1, 0.3, 0.0, 0.0, 0.0]])
    >>> order, lit, agreeing, falling = agreed_orders(code, worst, np.ones((1, 5), bool),
    ...                                               np.zeros((1, 5), np.float32))
    >>> order.tolist(), lit, agreeing, falling
    ([[0, -1, 1, 1, -1]], 5, 4, False)
    """
    code, worst, phi = (np.ascontiguousarray(a) for a in (code, worst, phi))
    order, counts, ends = _agreed(code, worst, np.ascontiguousarray(valid, np.bool_), phi,
                                  float(limit), int(max(every, 1)))
    lit, agreeing, kept, fall, rise = (int(c) for c in counts.sum(axis=0))
    n = fall + rise
    if kept <= 100 or n == 0:  # (no step: NumPy's median is NaN, not negative)
        return order, lit, agreeing, False
    half = n // 2
    if n % 2:  # the middle step falls when over half do
        return order, lit, agreeing, fall > half
    if fall != half:  # both middle steps fall, or neither
        return order, lit, agreeing, fall > half
    # the mean of the largest falling step and the smallest other one
    middle = (np.float64(ends[:, 0].max()) + np.float64(ends[:, 1].min())) / 2.0
    return order, lit, agreeing, bool(middle < 0)
