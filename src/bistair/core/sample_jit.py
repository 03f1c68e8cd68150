"""Compiled passes of the capture's sparse sample (:mod:`bistair.core.sample`): the camera
noise sample of an N-step set and the sampled pixels measured as the decode's full pass
measures them.

Examples
--------
>>> import numpy as np
>>> basis = np.linalg.qr(np.float64([[1, 1, 1, 1], [1, 0, -1, 0], [0, 1, 0, -1]]).T)[0].T.copy()
>>> raw = np.full((4, 9, 8), 100, np.uint8)
>>> raw[0, 1, 0] = 104  # the pixel below (0, 0) off its neighbour by 4 levels in frame 0
>>> energy, ok = residual_energy(raw, 0, 4, 1.0, basis, 255.0)
>>> energy.shape, round(float(energy[0, 0]), 9), float(energy[0, 1]), bool(ok.all())
((2, 2), 4.0, 0.0, True)
"""

from __future__ import annotations

import numpy as np

from .jit import kernel
from .phase_jit import angle32, hypot32, phase32, quarter_sums, quarter_turns

prange = range  # numba's prange once the first kernel of this module compiles


@kernel(parallel=True)
def residual_energy(raw: np.ndarray, start: int, steps: int, scale: float,
                    basis: np.ndarray, full: float) -> tuple[np.ndarray, np.ndarray]:
    """The N-step camera noise sample (N >= 4) without trigonometry: on every fourth row
    ``y`` and column ``x``, the squared norm of the part of ``g = f(y + 1, x) - f(y, x)``
    (the frames as fractions of full scale) outside the span of the fit (``basis``: its
    orthonormal rows), and whether neither pixel's frames reach 0 or ``full`` (raw units).

    The N-step fit of a pixel is the projection of its frames onto that span (for shifts
    evenly spread over a turn), so this is the squared norm of the difference of the two
    pixels' fit residuals: what :func:`~bistair.core.measure_jit.fit_residual_energy`
    computes through the fitted sinusoid (to float rounding), without a cosine.

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, uint8, uint16 or float32, C-contiguous.
    start, steps : int
        The set's first frame and its frame count ``N``.
    scale : float
        Factor that turns a raw value into a fraction of full scale.
    basis : (3, N) float64 array
        Orthonormal rows spanning ``1``, ``cos d_n`` and ``sin d_n``.
    full : float
        The raw value at which a frame clips.

    Returns
    -------
    energy : (rows, cols) float32 array
        The squared norms (computed in float64), ``rows`` the pairs of rows ``(4i, 4i + 1)``.
    ok : (rows, cols) bool array
        Neither pixel clipped or black in any frame.

    Examples
    --------
    >>> d = 2 * np.pi * np.arange(5) / 5
    >>> q = np.linalg.qr(np.stack([np.ones(5), np.cos(d), np.sin(d)]).T)[0].T.copy()
    >>> raw = np.full((5, 2, 4), 0.5, np.float32)
    >>> raw[:, 1, 0] += np.float32(0.01) * np.cos(2 * d)  # a second harmonic below (0, 0)
    >>> energy, ok = residual_energy(raw, 0, 5, 1.0, q, 1.0)
    >>> round(float(energy[0, 0]) / (0.01 ** 2 * 2.5), 4), bool(ok.all())
    (1.0, True)
    """
    _, h, w = raw.shape
    rows = min(len(range(0, h - 1, 4)), len(range(1, h, 4)))
    cols = (w + 3) // 4
    s32 = np.float32(scale)
    energy = np.empty((rows, cols), np.float32)
    ok = np.empty((rows, cols), np.bool_)
    for r in prange(rows):  # a row pair at a time, the loops along it vectorised
        g = np.empty((steps, cols), np.float64)
        total = np.empty(cols, np.float64)
        good = ok[r]
        for c in range(cols):
            total[c] = 0.0
            good[c] = True
        for n in range(steps):
            top = raw[start + n, 4 * r]
            low = raw[start + n, 4 * r + 1]
            gn = g[n]
            for c in range(cols):
                v0 = top[4 * c]
                v1 = low[4 * c]
                d = np.float64(np.float32(v1) * s32) - np.float64(np.float32(v0) * s32)
                gn[c] = d
                total[c] += d * d
                good[c] = good[c] and v0 > 0 and v1 > 0 and v0 < full and v1 < full
        for k in range(3):
            p = np.zeros(cols, np.float64)
            for n in range(steps):
                b = basis[k, n]
                gn = g[n]
                for c in range(cols):
                    p[c] += b * gn[c]
            for c in range(cols):
                total[c] -= p[c] * p[c]
        out = energy[r]
        for c in range(cols):
            out[c] = np.float32(max(total[c], 0.0))
    return energy, ok


@kernel(parallel=True)
def second_differences(raw: np.ndarray, start: int, steps: int, scale: float,
                       rows: np.ndarray, cols: np.ndarray, full: float
                       ) -> tuple[np.ndarray, np.ndarray]:
    """``|f(y) - 2 f(y + 1) + f(y + 2)|`` of each frame of a set (fractions of full scale,
    float32) for each run of three rows ``y = rows[3i]`` and each column of ``cols``, and
    whether none of the three pixels' frames reaches 0 or ``full`` (raw units).

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, uint8, uint16 or float32, C-contiguous.
    start, steps : int
        The set's first frame and its frame count.
    scale : float
        Factor that turns a raw value into a fraction of full scale.
    rows : (3R,) int64 array
        Runs of three adjacent rows (:func:`~bistair.core.sample.sample_grid`).
    cols : (C,) int64 array
        Columns.
    full : float
        The raw value at which a frame clips.

    Returns
    -------
    d2 : (steps, R, C) float32 array
        The absolute second differences down the columns.
    ok : (R, C) bool array
        Pixels whose three values are neither clipped nor black in any frame.

    Examples
    --------
    >>> raw = np.full((1, 3, 2), 0.5, np.float32)
    >>> raw[0, 1, 0] = 0.4
    >>> d2, ok = second_differences(raw, 0, 1, 1.0, np.arange(3), np.arange(2), 1.0)
    >>> d2.astype(float).round(3).tolist(), ok.tolist()
    ([[[0.2, 0.0]]], [[True, True]])
    """
    runs = rows.size // 3
    s32 = np.float32(scale)
    two = np.float32(2.0)
    d2 = np.empty((steps, runs, cols.size), np.float32)
    ok = np.empty((runs, cols.size), np.bool_)
    for i in prange(runs):
        y = rows[3 * i]
        for j in range(cols.size):
            x = cols[j]
            good = True
            for n in range(steps):
                a = raw[start + n, y, x]
                b = raw[start + n, y + 1, x]
                c = raw[start + n, y + 2, x]
                d2[n, i, j] = abs(np.float32(a) * s32 - two * (np.float32(b) * s32)
                                  + np.float32(c) * s32)
                good = (good and a > 0 and b > 0 and c > 0 and a < full and b < full
                        and c < full)
            ok[i, j] = good
    return d2, ok


@kernel(parallel=True)
def sample_pixels(raw: np.ndarray, start: int, steps: int, pair: int, scale: float,
                  sin_w: np.ndarray, cos_w: np.ndarray, off_hi: np.float32,
                  off_lo: np.float32, full: float, rows: np.ndarray, cols: np.ndarray
                  ) -> tuple[np.ndarray, ...]:
    """The pixels ``rows x cols`` of a capture measured as
    :func:`bistair.core.measure_jit.front_end` measures every pixel, with the same
    operations in the same order (the same bits): wrapped phase, modulation, average, the
    clipped flag and, with ``pair >= 0``, the stair pair's phase and modulation; and every
    frame's raw values there.

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, uint8, uint16 or float32, C-contiguous.
    start, steps : int
        The N-step set's first frame and its frame count.
    pair : int
        The stair pair's cosine frame (its sine frame follows), or -1.
    scale : float
        Factor that turns a raw value into a fraction of full scale.
    sin_w, cos_w : (N,) float32 arrays
        Sine and cosine of each frame's phase shift
        (:func:`~bistair.core.phase_jit.shift_weights`).
    off_hi, off_lo : float32
        The phase offset (:func:`~bistair.core.phase_jit.offset_parts`).
    full : float
        The raw value at which a frame clips.
    rows, cols : int64 arrays
        The sampled rows and columns.

    Returns
    -------
    values : (F, R, C) array
        Every frame's raw values at the sample.
    phi, mod, avg : (R, C) float32 arrays
        As the full pass gives them.
    clipped : (R, C) bool array
        A frame of the set or the pair at ``full`` or above.
    theta, stair_mod : (R, C) float32 arrays
        The pair's phase and modulation (zeros without a pair).

    Examples
    --------
    >>> from bistair.core.phase_jit import shift_weights
    >>> raw = np.zeros((4, 3, 3), np.uint8)
    >>> raw[0], raw[2] = 200, 100  # a phase of 0
    >>> out = sample_pixels(raw, 0, 4, -1, 1 / 255, *shift_weights(4), np.float32(0),
    ...                     np.float32(0), 255.0, np.arange(2), np.arange(1))
    >>> out[0].shape, out[1].ravel().tolist(), round(float(out[2][0, 0]), 4)
    ((4, 2, 1), [0.0, 0.0], 0.1961)
    """
    frames = raw.shape[0]
    nr = rows.size
    nc = cols.size
    s32 = np.float32(scale)
    n32 = np.float32(steps)
    zero = np.float32(0.0)
    full32 = np.float32(full)
    quarter = quarter_turns(sin_w, cos_w)
    values = np.empty((frames, nr, nc), raw.dtype)
    phi = np.empty((nr, nc), np.float32)
    mod = np.empty((nr, nc), np.float32)
    avg = np.empty((nr, nc), np.float32)
    clipped = np.empty((nr, nc), np.bool_)
    theta = np.zeros((nr, nc), np.float32)
    stair_mod = np.zeros((nr, nc), np.float32)
    for i in prange(nr):  # a sampled row at a time, as the full pass works a row
        y = rows[i]
        for f in range(frames):
            src = raw[f, y]
            dst = values[f, i]
            for j in range(nc):
                dst[j] = src[cols[j]]
        p = phi[i]
        m = mod[i]
        a = avg[i]
        top = np.empty(nc, raw.dtype)
        if quarter:
            r0 = values[start, i]
            r1 = values[start + 1, i]
            r2 = values[start + 2, i]
            r3 = values[start + 3, i]
            for j in range(nc):
                top[j] = max(max(r0[j], r1[j]), max(r2[j], r3[j]))
                num, den, av = quarter_sums(r0[j], r1[j], r2[j], r3[j], s32, sin_w, cos_w)
                p[j] = phase32(num, den, off_hi, off_lo)
                m[j] = hypot32(num, den) * np.float32(0.5)
                a[j] = av
        else:
            s = np.empty(nc, np.float32)
            c = np.empty(nc, np.float32)
            first = values[start, i]
            for j in range(nc):
                s[j] = zero
                c[j] = zero
                a[j] = zero
                top[j] = first[j]
            for n in range(steps):  # the full pass's sums, in its order
                sw = sin_w[n]
                cw = cos_w[n]
                row = values[start + n, i]
                for j in range(nc):
                    v = row[j]
                    top[j] = max(top[j], v)
                    f32 = np.float32(v) * s32
                    s[j] += sw * f32
                    c[j] += cw * f32
                    a[j] += f32
            mod_scale = np.float32(2.0) / n32
            for j in range(nc):
                num = -s[j]
                a[j] = a[j] / n32
                p[j] = phase32(num, c[j], off_hi, off_lo)
                m[j] = hypot32(num, c[j]) * mod_scale
        if pair >= 0:
            cos_row = values[pair, i]
            sin_row = values[pair + 1, i]
            th = theta[i]
            sm = stair_mod[i]
            for j in range(nc):
                top[j] = max(top[j], max(cos_row[j], sin_row[j]))
                cc = np.float32(cos_row[j]) * s32 - a[j]
                ss = np.float32(sin_row[j]) * s32 - a[j]
                th[j] = angle32(ss, cc)
                sm[j] = hypot32(cc, ss)
        cl = clipped[i]
        for j in range(nc):
            cl[j] = np.float32(top[j]) >= full32
    return values, phi, mod, avg, clipped, theta, stair_mod


@kernel()
def masked_median(values: np.ndarray, ok: np.ndarray, least: int) -> float:
    """``np.median(values[ok])`` of float32 values, or of all ``values`` when fewer than
    ``least`` are ``ok`` (NaN for none): the two middle values averaged for an even count,
    as NumPy does, found by counting the values' bits (two passes of 16 bits, no sort).

    Parameters
    ----------
    values : 1-D float32 array
        Finite.
    ok : 1-D bool array
        Of ``values``' size.
    least : int
        The fewest ``ok`` values to take the median of those alone.

    Returns
    -------
    float

    Examples
    --------
    >>> masked_median(np.float32([5, 1, 4, 2, 9]), np.array([1, 1, 1, 1, 0], bool), 1)
    3.0
    >>> masked_median(np.float32([5, -1, 4]), np.array([1, 0, 0], bool), 2)
    4.0
    """
    count = 0
    for i in range(values.size):
        count += ok[i]
    every = count < least
    n = values.size if every else count
    if n == 0:
        return np.nan
    bits = values.view(np.uint32)
    sign = np.uint32(1 << 31)
    keys = np.empty(n, np.uint32)  # in the order of the values: the sign bit flipped
    high = np.zeros(1 << 16, np.int32)
    j = 0
    for i in range(values.size):
        if every or ok[i]:
            b = bits[i]
            key = ~b if b & sign else b | sign
            keys[j] = key
            high[key >> 16] += 1
            j += 1
    ranks = (n // 2 - 1 if n % 2 == 0 else n // 2, n // 2)
    tops = np.empty(2, np.int64)
    rests = np.empty(2, np.int64)
    for r in range(2):
        rank = ranks[r]
        top = 0
        while rank >= high[top]:  # the 16 high bits of the rank-th key
            rank -= high[top]
            top += 1
        tops[r] = top
        rests[r] = rank
    found = np.empty(2, np.uint32)
    low = np.zeros(1 << 16, np.int32)
    for r in range(2):
        if r == 0 or tops[1] != tops[0]:
            low[:] = 0
            for i in range(n):
                if keys[i] >> 16 == tops[r]:
                    low[keys[i] & 0xFFFF] += 1
        rank = rests[r]
        bottom = 0
        while rank >= low[bottom]:
            rank -= low[bottom]
            bottom += 1
        key = np.uint32((tops[r] << 16) | bottom)
        found[r] = key & ~sign if key & sign else ~key
    pair = found.view(np.float32)
    return (np.float64(pair[0]) + np.float64(pair[1])) / 2.0
