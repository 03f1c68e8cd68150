"""Compiled passes of the phase stage's measure (:mod:`bistair.core.measure`): pixel
validity, the phase noise per pixel, the fit residual sample of the camera noise and the
coherent dim pixels.

Each gives, bit for bit, what the NumPy it replaces gives (the noise sample's cosines come
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
def _validity(mod: np.ndarray, avg: np.ndarray, clipped: np.ndarray, white: np.ndarray,
              black: np.ndarray, contrast: bool, lowest: float, threshold: float
              ) -> tuple[np.ndarray, np.ndarray, int]:
    h, w = mod.shape
    valid = np.empty((h, w), np.bool_)
    strong = np.empty((h, w), np.bool_)
    weak_rows = np.zeros(h, np.int64)
    low32 = np.float32(lowest)
    thr32 = np.float32(threshold)
    sat32 = np.float32(1.02)
    need32 = np.float32(2.0 * lowest)
    for y in prange(h):
        weak = 0
        for x in range(w):
            m = mod[y, x]
            ok = m >= low32 and not (clipped[y, x] and avg[y, x] + m > sat32)
            if contrast and not (white[y, x] - black[y, x] >= need32):
                ok = False
            valid[y, x] = ok
            s = ok and m >= thr32
            strong[y, x] = s
            if ok and not s:
                weak += 1
        weak_rows[y] = weak
    return valid, strong, weak_rows.sum()



def pixel_validity(mod: np.ndarray, avg: np.ndarray, clipped: np.ndarray, lowest: float,
                   threshold: float, white: np.ndarray | None = None,
                   black: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """The valid pixels of a measured set, those of them with the full modulation
    threshold, and how many valid pixels fall short of it, in one pass.

    Valid: modulation at least ``lowest``, not saturated (clipped with ``avg + mod`` above
    1.02: clipped by the camera) and, with ``white`` and ``black``,
    twice ``lowest`` of contrast between them. Thresholds compare in float32, as NumPy
    compares a float32 array with a Python float.

    Parameters
    ----------
    mod, avg : (H, W) float32 arrays
        The set's modulation and average (fractions of full scale).
    clipped : (H, W) bool array
        Pixels that some frame clips.
    lowest : float
        The modulation a valid pixel needs.
    threshold : float
        The full modulation threshold (``strong`` pixels).
    white, black : (H, W) float32 arrays, optional
        The fully lit and the dark frame, if the capture has both.

    Returns
    -------
    valid : (H, W) bool array
        The valid pixels.
    strong : (H, W) bool array
        The valid pixels with at least ``threshold``.
    weak : int
        Valid pixels below ``threshold``.

    Examples
    --------
    >>> mod = np.float32([[0.004, 0.006, 0.02, 0.5]])
    >>> avg = np.float32([[0.5, 0.5, 0.5, 0.6]])
    >>> clipped = np.array([[False, False, False, True]])
    >>> valid, strong, weak = pixel_validity(mod, avg, clipped, 0.005, 0.01)
    >>> valid.tolist(), strong.tolist(), weak
    ([[False, True, True, False]], [[False, False, True, False]], 1)
    """
    contrast = white is not None and black is not None
    valid, strong, weak = _validity(mod, avg, clipped, white if contrast else avg,
                                    black if contrast else avg, contrast, float(lowest),
                                    float(threshold))
    return valid, strong, int(weak)



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
