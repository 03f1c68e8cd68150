"""Compiled passes of the phase stage's measure (:mod:`bistair.core.measure`): pass 1 of a
decode (:func:`front_end`: every pixel of an N-step set and its stair pair measured in one
pass over tiles of rows), the phase noise per pixel, the fit residual sample of the camera
noise (the full-resolution reference of pass 0's) and the coherent dim pixels.

Each gives, bit for bit, what the NumPy it replaces gives (:func:`front_end`: what
:func:`bistair.core.phase_jit.phase_of_sums32` and
:func:`bistair.core.sample.judge` give from the same sums; the noise sample's cosines come
from the C library's ``cosf``, whose last bit may differ from NumPy's: see
:func:`fit_residual_energy`).

Examples
--------
>>> import numpy as np
>>> phase_noise(np.float32([0.5, 0.05]), 0.01, 4).astype(float).round(4).tolist()
[0.0141, 0.1414]
"""

from __future__ import annotations

import numpy as np

from .jit import chunk_count, kernel, kernel_frames
from .phase_jit import angle32, hypot32, phase32, quarter_sums, quarter_turns

prange = range  # numba's prange once the first kernel of this module compiles


@kernel(parallel=True)
def keep_coherent(labels: np.ndarray, roots: np.ndarray, size: np.ndarray,
                  bright: np.ndarray, strong: np.ndarray, min_strong: int, min_size: int,
                  min_region: int) -> np.ndarray:
    """``strong | region kept``, a region kept when it holds ``min_region`` pixels and
    ``min_strong`` strong pixels or ``min_size`` pixels (see
    :func:`bistair.core.measure.coherent_pixels`; ``min_region``: the regions
    :func:`bistair.core.regions.fringe_regions` would drop as too small).

    The regions are those of :func:`bistair.core.regions.label_fringes` on the weak mask,
    whose scan counted each one's pixels and strong pixels: one pass over the labels here.
    A labelled pixel is always weak (valid for the labelling).

    Parameters
    ----------
    labels : (H, W) int32 array
        Provisional labels of the fringe regions of the weak mask, 0 outside any (never
        kept).
    roots : int32 array
        The region of each label (``roots[0]`` is 0).
    size, bright : (n+1,) int64 arrays
        Pixels and strong pixels per region.
    strong : (H, W) bool array
        Pixels with at least the full modulation threshold.
    min_strong : int
        Strong pixels that keep a region.
    min_size : int
        Pixels in all that keep a region.
    min_region : int
        Pixels a region needs to be kept at all.

    Returns
    -------
    (H, W) bool array
        The pixels to count as valid.

    Examples
    --------
    >>> labels = np.int32([[1, 1, 1, 2, 2, 0]])
    >>> roots = np.int32([0, 1, 2])
    >>> size, bright = np.int64([0, 3, 2]), np.int64([0, 1, 0])
    >>> strong = np.array([[True, False, False, False, False, False]])
    >>> keep_coherent(labels, roots, size, bright, strong, 1, 10, 1).tolist()
    [[True, True, True, False, False, False]]
    >>> keep_coherent(labels, roots, size, bright, strong, 1, 10, 4).tolist()
    [[True, False, False, False, False, False]]
    """
    h, w = labels.shape
    n = size.shape[0] - 1
    keep = np.zeros(n + 1, np.bool_)
    for i in range(1, n + 1):
        keep[i] = ((bright[i] >= min_strong or size[i] >= min_size)
                   and size[i] >= min_region)
    out = np.empty((h, w), np.bool_)
    for y in prange(h):
        lab = labels[y]
        s = strong[y]
        o = out[y]
        last = np.int32(0)
        kept = False
        for x in range(w):  # a run of one label looked up once
            if lab[x] != last:
                last = lab[x]
                kept = keep[roots[last]]
            o[x] = s[x] or kept
    return out


def fit_residual_energy(raw: np.ndarray, start: int, steps: int, scale: float,
                        phi: np.ndarray, avg: np.ndarray, mod: np.ndarray,
                        shifts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The sample :func:`~bistair.core.measure.noise_level` takes its median of, in one
    pass: on every fourth row ``y`` and column, the squared norm over the frames of the
    difference between the fit residuals of pixel ``(y + 1, x)`` and pixel ``(y, x)``, and
    whether neither pixel's frames reach 0 or full scale.

    A residual is ``f - (avg + mod * cos(phi + shift))`` in float32 (the cosine as the C
    library's ``cosf``), ``f`` a frame value times ``scale``.

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, any numeric dtype.
    start, steps : int
        The set's first frame and its frame count ``N``.
    scale : float
        Factor that turns a raw value into a fraction of full scale.
    phi, avg, mod : (H, W) float32 arrays
        The set's fitted phase, average and modulation.
    shifts : (N,) float32 array
        The frames' phase shifts (:func:`~bistair.core.phase.shifts_of`).

    Returns
    -------
    energy : (rows, cols) float32 array
        The squared norms, ``rows`` the pairs of rows ``(4i, 4i + 1)`` in the image.
    ok : (rows, cols) bool array
        Neither pixel clipped or black in any frame.

    Examples
    --------
    >>> raw = np.full((4, 6, 5), 0.5, np.float32)
    >>> raw[2, 1, 0] = 0.6  # one frame of the pixel below (0, 0) off its fit
    >>> flat = np.zeros((6, 5), np.float32)
    >>> energy, ok = fit_residual_energy(raw, 0, 4, 1.0, flat, flat + 0.5, flat,
    ...                                  np.zeros(4, np.float32))
    >>> energy.shape, round(float(energy[0, 0]), 4), bool(ok.all())
    ((2, 2), 0.01, True)
    """
    raw, start = kernel_frames(raw, start, steps)
    return _fit_residual_energy(raw, start, int(steps), float(np.float32(scale)),
                                *(np.ascontiguousarray(a, np.float32) for a in (phi, avg, mod)),
                                np.asarray(shifts, np.float32))


@kernel(parallel=True)
def _fit_residual_energy(raw: np.ndarray, start: int, steps: int, scale: float,
                         phi: np.ndarray, avg: np.ndarray, mod: np.ndarray,
                         shifts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    _, h, w = raw.shape
    rows = min(len(range(0, h - 1, 4)), len(range(1, h, 4)))
    cols = (w + 3) // 4
    s32 = np.float32(scale)
    zero = np.float32(0.0)
    one = np.float32(1.0)
    energy = np.empty((rows, cols), np.float32)
    ok = np.empty((rows, cols), np.bool_)
    for r in prange(rows):
        y0 = 4 * r
        y1 = y0 + 1
        for c in range(cols):
            x = 4 * c
            e = zero
            good = True
            for n in range(steps):
                f0 = np.float32(raw[start + n, y0, x]) * s32
                f1 = np.float32(raw[start + n, y1, x]) * s32
                fit0 = avg[y0, x] + mod[y0, x] * np.cos(phi[y0, x] + shifts[n])
                fit1 = avg[y1, x] + mod[y1, x] * np.cos(phi[y1, x] + shifts[n])
                d = (f1 - fit1) - (f0 - fit0)
                e += d * d
                good = good and zero < f0 < one and zero < f1 < one
            energy[r, c] = e
            ok[r, c] = good
    return energy, ok


@kernel(parallel=True)
def _phase_noise(mod: np.ndarray, noise: float, factor: float, chunks: int) -> np.ndarray:
    n = mod.size
    out = np.empty(n, np.float32)
    floor32 = np.float32(1e-6)
    for c in prange(chunks):
        lo = c * n // chunks
        hi = (c + 1) * n // chunks
        for i in range(lo, hi):
            m = mod[i]
            if m < floor32:  # np.maximum(mod, 1e-6), NaN kept
                m = floor32
            out[i] = np.float32(noise / (np.float64(m) * factor))
    return out


def phase_noise(mod: np.ndarray, noise: float, steps: int) -> np.ndarray:
    """Per-pixel phase noise ``noise / (max(B, 1e-6) * sqrt(N/2))`` in radians: computed in
    float64 as NumPy computes it, returned as float32.

    Parameters
    ----------
    mod : float32 array
        The modulation ``B`` (fraction of full scale).
    noise : float
        The camera noise sigma (fraction of full scale).
    steps : int
        Number of frames ``N`` of the set.

    Returns
    -------
    float32 array
        The phase noise, of ``mod``'s shape.

    Examples
    --------
    >>> phase_noise(np.float32([[0.1, 0.0]]), 0.01, 8).tolist()
    [[0.05000000074505806, 5000.0]]
    """
    flat = np.ascontiguousarray(mod, np.float32).reshape(-1)
    out = _phase_noise(flat, float(noise), float(np.sqrt(steps / 2.0)), chunk_count(flat.size))
    return out.reshape(np.shape(mod))


TILE_ROWS = 16  # rows a task of the full pass works on


@kernel(parallel=True)
def front_end(raw: np.ndarray, start: int, steps: int, pair: int, scale: float,
              sin_w: np.ndarray, cos_w: np.ndarray, off_hi: np.float32, off_lo: np.float32,
              full: float, lowest: float, threshold: float, sigma_scale: np.float32,
              white: np.ndarray, black: np.ndarray, contrast: bool
              ) -> tuple[np.ndarray, ...]:
    """Pass 1 of a decode: every pixel of an N-step set (and its stair pair) measured in one
    pass over tiles of rows on every core, each frame read once.

    Per pixel: the N-step sums (:func:`~bistair.core.phase_jit._set_sums`), the wrapped
    phase less the phase offset in ``[0, 2*pi)`` (:func:`~bistair.core.phase_jit.phase32`,
    the float32 arctangent of :func:`~bistair.core.phase_jit.arctan2_32`), the modulation
    ``2/N * hypot`` and the average (float32); whether a frame of the set or of the pair
    reaches ``full`` (clipped); valid (modulation at least ``lowest``, not saturated:
    clipped with ``avg + mod`` above 1.02, and, with ``contrast``, ``white - black`` at
    least ``2 * lowest``) and strong (also at least ``threshold``); the phase noise
    ``sigma_scale / max(mod, 1e-6)``; with ``pair >= 0`` the stair phase
    ``atan2(sin - A, cos - A)`` in ``[-pi, pi]`` and its modulation. Each tile writes only
    its own rows, so the results do not depend on the threads.

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, uint8, uint16 or float32, C-contiguous.
    start, steps : int
        The set's first frame and its frame count ``N``.
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
    lowest, threshold : float
        The modulation a valid and a strong pixel need.
    sigma_scale : float32
        ``noise / sqrt(N/2)``.
    white, black : (H, W) float32 arrays
        The fully lit and the dark frame (read with ``contrast`` only).
    contrast : bool
        Judge the white/black contrast.

    Returns
    -------
    phi, mod, avg : (H, W) float32 arrays
    valid, strong : (H, W) bool arrays
    sigma : (H, W) float32 array
        The phase noise, radians.
    theta, stair_mod : (H, W) float32 arrays
        The pair's phase and modulation ((1, 1) without a pair).
    weak : int
        Valid pixels that are not strong.

    Examples
    --------
    >>> from bistair.core.phase_jit import shift_weights
    >>> raw = np.zeros((4, 2, 3), np.uint8)
    >>> raw[0], raw[2] = 200, 100  # a phase of 0, a modulation of 50 levels
    >>> raw[0, 0, 0], raw[2, 0, 0] = 110, 100  # 5 levels
    >>> dummy = np.zeros((1, 1), np.float32)
    >>> out = front_end(raw, 0, 4, -1, 1 / 255, *shift_weights(4), np.float32(0),
    ...                 np.float32(0), 255.0, 0.01, 0.1, np.float32(0.01), dummy, dummy, False)
    >>> phi, valid, strong, weak = out[0], out[3], out[4], out[8]
    >>> float(phi.max()), bool(valid.all()), strong[0].tolist(), weak
    (0.0, True, [False, True, True], 1)
    """
    _, h, w = raw.shape
    s32 = np.float32(scale)
    zero = np.float32(0.0)
    full32 = np.float32(full)
    low32 = np.float32(lowest)
    thr32 = np.float32(threshold)
    sat32 = np.float32(1.02)
    need32 = np.float32(2.0 * lowest)
    floor32 = np.float32(1e-6)
    quarter = quarter_turns(sin_w, cos_w)
    phi = np.empty((h, w), np.float32)
    mod = np.empty((h, w), np.float32)
    avg = np.empty((h, w), np.float32)
    valid = np.empty((h, w), np.bool_)
    strong = np.empty((h, w), np.bool_)
    sigma = np.empty((h, w), np.float32)
    ph = h if pair >= 0 else 1
    pw = w if pair >= 0 else 1
    theta = np.empty((ph, pw), np.float32)
    stair_mod = np.empty((ph, pw), np.float32)
    tiles = (h + TILE_ROWS - 1) // TILE_ROWS
    weak = np.zeros(tiles, np.int64)
    for t in prange(tiles):
        s = np.empty(w, np.float32)
        c = np.empty(w, np.float32)
        top = np.empty(w, raw.dtype)
        count = 0
        for y in range(t * TILE_ROWS, min(h, (t + 1) * TILE_ROWS)):
            p = phi[y]
            m = mod[y]
            a = avg[y]
            if quarter:  # four quarter-turn shifts: each pixel's sums in registers
                r0 = raw[start, y]
                r1 = raw[start + 1, y]
                r2 = raw[start + 2, y]
                r3 = raw[start + 3, y]
                for x in range(w):
                    v0 = r0[x]
                    v1 = r1[x]
                    v2 = r2[x]
                    v3 = r3[x]
                    top[x] = max(max(v0, v1), max(v2, v3))
                    num, den, av = quarter_sums(v0, v1, v2, v3, s32, sin_w, cos_w)
                    p[x] = phase32(num, den, off_hi, off_lo)
                    m[x] = hypot32(num, den) * np.float32(0.5)
                    a[x] = av
            else:  # frame by frame along the row, in frame order: the loops vectorise
                n32 = np.float32(steps)
                first = raw[start, y]
                for x in range(w):
                    s[x] = zero
                    c[x] = zero
                    a[x] = zero
                    top[x] = first[x]
                for n in range(steps):
                    sw = sin_w[n]
                    cw = cos_w[n]
                    row = raw[start + n, y]
                    for x in range(w):
                        v = row[x]
                        top[x] = max(top[x], v)
                        f = np.float32(v) * s32
                        s[x] += sw * f
                        c[x] += cw * f
                        a[x] += f
                mod_scale = np.float32(2.0) / n32
                for x in range(w):
                    num = -s[x]
                    a[x] = a[x] / n32
                    p[x] = phase32(num, c[x], off_hi, off_lo)
                    m[x] = hypot32(num, c[x]) * mod_scale
            if pair >= 0:
                cos_row = raw[pair, y]
                sin_row = raw[pair + 1, y]
                th = theta[y]
                sm = stair_mod[y]
                for x in range(w):
                    top[x] = max(top[x], max(cos_row[x], sin_row[x]))
                    cc = np.float32(cos_row[x]) * s32 - a[x]
                    ss = np.float32(sin_row[x]) * s32 - a[x]
                    th[x] = angle32(ss, cc)
                    sm[x] = hypot32(cc, ss)
            ok_row = valid[y]
            st_row = strong[y]
            sg = sigma[y]
            for x in range(w):  # (bitwise: the loop vectorises)
                mx = m[x]
                ok = (mx >= low32) & ~((np.float32(top[x]) >= full32) & (a[x] + mx > sat32))
                ok_row[x] = ok
                st_row[x] = ok & (mx >= thr32)
                sg[x] = sigma_scale / max(mx, floor32)
            if contrast:
                for x in range(w):
                    ok_row[x] = ok_row[x] & (white[y, x] - black[y, x] >= need32)
                    st_row[x] = st_row[x] & ok_row[x]
            for x in range(w):  # (a loop of its own: counted inside, nothing vectorised)
                count += ok_row[x] ^ st_row[x]
        weak[t] = count
    return phi, mod, avg, valid, strong, sigma, theta, stair_mod, weak.sum()
