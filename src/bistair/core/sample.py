"""Pass 0 of a decode: what describes a whole capture, from a sparse fixed grid of pixels,
before any pass over every pixel.

Two things come from it:

- the **camera noise** of an N-step set (:func:`set_noise`), hence the modulation
  thresholds the full pass (:func:`bistair.core.measure_jit.front_end`) judges every pixel
  against;
- a :class:`Sample`: the pixels of the grid measured exactly as the full pass measures
  every pixel (the same bits of phase, modulation and average; the stair pair's phase and
  modulation), their validity, and every frame's raw values there, on which a check of the
  whole capture (axis, shift order, stair misfit, phase convention, stair fit) can judge
  without scanning the image to find its sample.

**The grid** (:func:`sample_grid`, column layout, the coded axis along the rows): runs of
three adjacent rows every :data:`ROW_STEP` rows and pairs of adjacent columns every
:data:`COL_STEP` columns, 3/64 of the pixels (61 thousand of 1.3 million). A sample's
maps are small images of the sampled rows and columns
(``full[np.ix_(sample.rows, sample.cols)]``); a check takes
differences inside a run (down the columns: ``a[1::3] - a[0::3]``) or a pair (along the
rows: ``a[:, 1::2] - a[:, 0::2]``) and never across them (:meth:`Sample.blocks`).

**For the checks.** :func:`bistair.core.measure.measure` keeps the sample of the set whose
captures it judges (``check=True``: the set every codec's stage 1 measures) in
``FringeSet.sample``, column layout; ``Codec._decode`` lets it go once the orders are made.
What each check of the whole capture reads from it:

- shift order (:func:`bistair.codecs.base.shift_order_problem`):
  ``values[frames_of_a_set][:, strong]`` (every set's frames are there, those of sets
  measured with ``check=False`` too), at most 20000 pixels;
- axis (:func:`bistair.core.checks.axis_rates`): ``wrap(phi[:, 1::2] - phi[:, 0::2])``
  along the rows and ``wrap(phi[2::3] - phi[0::3]) / 2`` down the columns, where both
  pixels are ``strong``;
- stair misfit (:func:`bistair.core.checks.stair_sample`): ``theta[strong]``;
- the stair fit needs the orders: it judges a fixed grid of its own once they are made
  (:func:`bistair.codecs.bidirectional.stairs.grid_sample`; this grid's rows every 16
  rows could fall on one kind of a code's bands of rows);
- still on the full maps: the phase convention (the code of the column pairs cannot
  tell a step between runs of two equal codes from a flicker).

Examples
--------
>>> import numpy as np
>>> rows, cols = sample_grid(40, 20)
>>> rows.tolist(), cols.tolist()
([6, 7, 8, 22, 23, 24], [1, 2, 9, 10, 17, 18])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special

from .captures import Prepared
from .jit import kernel_frames
from .phase import nstep_weights, shifts_of
from .sample_jit import masked_median, residual_energy, sample_pixels, second_differences

ROW_STEP = 16  # a run of three adjacent rows every ROW_STEP rows
COL_STEP = 8  # a pair of adjacent columns every COL_STEP columns


@dataclass(frozen=True)
class Sample:
    """Pixels of a capture on the sparse grid of :func:`sample_grid` (column layout),
    measured as the full pass measures every pixel (the same bits).

    Attributes
    ----------
    rows, cols : (R,), (C,) int64 arrays
        The sampled image rows (runs of three adjacent rows) and columns (pairs of
        adjacent columns).
    values : (F, R, C) array
        Every frame of the prepared stack there, raw (times ``scale``: fractions of full
        scale), in method order: the frames of every set and code.
    scale : float
        Multiply a raw value by this for its fraction of full scale.
    phi, mod, avg : (R, C) float32 arrays
        The N-step set's wrapped phase in ``[0, 2*pi)``, modulation and average.
    valid : (R, C) bool array
        Enough modulation for the lower threshold, not saturated, enough white/black
        contrast: the full pass's validity before the coherence of dim pixels (which judges
        regions, not pixels; a check that wants the pixels it keeps takes ``strong``).
    strong : (R, C) bool array
        Valid with the full modulation threshold.
    clipped : (R, C) bool array
        A frame of the set or of the stair pair at full scale.
    theta, stair_mod : (R, C) float32 arrays or None
        The stair pair's phase in ``[-pi, pi]`` and modulation, if the set has a pair.
    """

    rows: np.ndarray
    cols: np.ndarray
    values: np.ndarray
    scale: float
    phi: np.ndarray
    mod: np.ndarray
    avg: np.ndarray
    valid: np.ndarray
    strong: np.ndarray
    clipped: np.ndarray
    theta: np.ndarray | None = None
    stair_mod: np.ndarray | None = None

    def blocks(self, a: np.ndarray) -> np.ndarray:
        """A sample map (or a stack of them, frames first) as its blocks:
        ``(..., runs, 3, pairs, 2)``, ``[..., i, dy, j, dx]`` the pixel ``(rows[3i + dy],
        cols[2j + dx])``.

        Parameters
        ----------
        a : (..., R, C) array
            A map of the sample.

        Returns
        -------
        (..., R // 3, 3, C // 2, 2) array
            A view of ``a``.

        Examples
        --------
        >>> rows, cols = sample_grid(40, 20)
        >>> s = Sample(rows, cols, np.zeros((1, 6, 6)), 1.0, *(np.zeros((6, 6)),) * 6)
        >>> s.blocks(s.phi).shape
        (2, 3, 3, 2)
        """
        *lead, r, c = a.shape
        return a.reshape(*lead, r // 3, 3, c // 2, 2)


def sample_grid(height: int, width: int) -> tuple[np.ndarray, np.ndarray]:
    """The rows and columns of a capture's sample: runs of three adjacent rows starting at
    rows ``6, 6 + ROW_STEP, ...`` and pairs of adjacent columns starting at columns
    ``1, 1 + COL_STEP, ...`` (from row 0 where an image has too few rows for row 6).

    Parameters
    ----------
    height, width : int
        The image's size (column layout), at least 3 x 2.

    Returns
    -------
    rows, cols : int64 arrays
        Ascending.

    Examples
    --------
    >>> [a.tolist() for a in sample_grid(8, 12)]
    [[0, 1, 2], [1, 2, 9, 10]]
    """
    first = (ROW_STEP - 3) // 2
    top = np.arange(first if height - 2 > first else 0, height - 2, ROW_STEP)
    left = np.arange(1 if width > 2 else 0, width - 1, COL_STEP)
    return ((top[:, None] + np.arange(3)).ravel().astype(np.int64),
            (left[:, None] + np.arange(2)).ravel().astype(np.int64))


def set_noise(prepared: Prepared, start: int, steps: int) -> float:
    """Camera noise sigma (fraction of full scale) of the N-step set at frames
    ``start .. start+steps-1``: what :func:`bistair.core.measure.noise_level` gives, from
    the same sample, without fitting a sinusoid.

    N >= 4: the part of the difference between vertically adjacent pixels' frames that the
    N-step fit leaves (the fit is a projection: for N = 4 the alternating sum ``f0 - f1 +
    f2 - f3`` over 2), on every fourth row pair and column (the reference's own sample),
    its median squared norm scaled by the chi-square median of N - 3 degrees of freedom
    (:func:`~bistair.core.sample_jit.residual_energy`; it agrees with the fitted
    residual's to 1e-5 and better). N = 3: the frames' second differences down the
    columns, ``median|d2| / (0.6745 * sqrt(6))``
    (:func:`bistair.core.measure.along_fringe_noise`), on the runs of three rows of the
    sample grid and every second column (a sixth of the reference's values, so about
    ``1.2 / sqrt(values)`` apart from it, relatively, at one standard error where the
    values are not whole levels of a camera's; on every 8-bit capture the same figure).
    Pixels that a frame of the set clips or that read 0 are left out (all are kept when
    fewer than 100 are left).

    Parameters
    ----------
    prepared : Prepared
        The capture stack, column layout.
    start, steps : int
        The set's first frame and its frame count (at least 3).

    Returns
    -------
    float
        The noise sigma.

    Examples
    --------
    >>> from bistair.core.captures import prepare
    >>> from bistair.core.phase import phase_shift_patterns
    >>> rng = np.random.default_rng(0)
    >>> x = np.tile(np.arange(256.0), (128, 1))
    >>> frames = phase_shift_patterns(x, 32, 4, amplitude=0.4) + rng.normal(0, 0.01, (4, 128, 256))
    >>> round(set_noise(prepare(frames.astype(np.float32), 4, "demo"), 0, 4), 3)
    0.01
    """
    raw, start, _ = kernel_view(prepared, start, steps, None)
    full = float(prepared.full_scale)
    if steps <= 3:
        rows = sample_grid(*raw.shape[1:])[0]
        cols = np.arange(0, raw.shape[2], 2, dtype=np.int64)
        d2, ok = second_differences(raw, int(start), int(steps), float(prepared.scale), rows,
                                    cols, full)
        if d2.size == 0:
            return 0.0
        median = masked_median(d2.ravel(), np.broadcast_to(ok, d2.shape).ravel(), 100 * steps)
        return float(median / (0.6745 * np.sqrt(6.0)))
    d = shifts_of(steps)
    basis = np.linalg.qr(np.stack([np.ones(steps), np.cos(d), np.sin(d)]).T)[0].T
    energy, ok = residual_energy(raw, int(start), int(steps), float(prepared.scale),
                                 np.ascontiguousarray(basis), full)
    median = masked_median(energy.ravel(), ok.ravel(), 100)  # (float32: to 6e-8)
    return float(np.sqrt(median / (2.0 * chi2_median(steps - 3))))


def take_sample(prepared: Prepared, start: int, steps: int, pair: int | None,
                lowest: float, threshold: float, shift_sign: int = 1,
                phase_offset: float = 0.0) -> Sample:
    """The :class:`Sample` of an N-step set (and its stair pair): the grid's pixels
    measured as :func:`bistair.core.measure_jit.front_end` measures every pixel, judged
    against its thresholds.

    Parameters
    ----------
    prepared : Prepared
        The capture stack, column layout.
    start, steps : int
        The set's first frame and its frame count.
    pair : int or None
        The stair pair's cosine frame (its sine frame follows), if any.
    lowest, threshold : float
        The modulation a valid pixel needs, and a strong one.
    shift_sign, phase_offset : int, float
        The rig's phase convention.

    Returns
    -------
    Sample

    Examples
    --------
    >>> from bistair.core.captures import prepare
    >>> from bistair.core.phase import phase_shift_patterns
    >>> x = np.tile(np.arange(64.0), (40, 1))
    >>> stack = np.round(255 * phase_shift_patterns(x, 16, 4, amplitude=0.3)).astype(np.uint8)
    >>> s = take_sample(prepare(stack, 4, "demo"), 0, 4, None, 0.01, 0.02)
    >>> s.values.shape, s.phi.shape, bool(s.strong.all()), round(float(s.mod.mean()), 2)
    ((4, 6, 16), (6, 16), True, 0.3)
    """
    raw, first, cos_frame = kernel_view(prepared, start, steps, pair)
    rows, cols = sample_grid(*raw.shape[1:])
    values, phi, mod, avg, clipped, theta, stair_mod = sample_pixels(
        raw, first, int(steps), cos_frame, float(prepared.scale),
        *nstep_weights(steps, shift_sign, phase_offset), clip_level(prepared),
        rows, cols)
    if raw is not prepared.raw:  # (frames converted for the kernel: the captures' own)
        values = prepared.raw[:, rows][:, :, cols]
    white, black = ((None, None) if prepared.white is None or prepared.black is None else
                    (prepared.white[np.ix_(rows, cols)], prepared.black[np.ix_(rows, cols)]))
    valid, strong = judge(mod, avg, clipped, lowest, threshold, white, black)
    return Sample(rows, cols, values, float(prepared.scale), phi, mod, avg, valid, strong,
                  clipped, *((None, None) if pair is None else (theta, stair_mod)))


def judge(mod: np.ndarray, avg: np.ndarray, clipped: np.ndarray, lowest: float,
          threshold: float, white: np.ndarray | None = None,
          black: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """NumPy reference of the full pass's validity (the same float32 comparisons): valid
    with modulation at least ``lowest``, not saturated (clipped with ``avg + mod`` above
    1.02) and, with white and black frames, ``2 * lowest`` of contrast between them;
    strong with ``threshold`` too.

    Parameters
    ----------
    mod, avg : float32 arrays
        Modulation and average (fractions of full scale).
    clipped : bool array
        A frame at full scale.
    lowest, threshold : float
        The modulation a valid and a strong pixel need.
    white, black : float32 arrays, optional
        The fully lit and the dark frame.

    Returns
    -------
    valid, strong : bool arrays

    Examples
    --------
    >>> mod = np.float32([0.004, 0.006, 0.02, 0.5])
    >>> avg = np.float32([0.5, 0.5, 0.5, 0.6])
    >>> [a.tolist() for a in judge(mod, avg, np.array([0, 0, 0, 1], bool), 0.005, 0.01)]
    [[False, True, True, False], [False, False, True, False]]
    """
    valid = (mod >= np.float32(lowest)) & ~(clipped & (avg + mod > np.float32(1.02)))
    if white is not None and black is not None:
        valid &= (white - black) >= np.float32(2.0 * lowest)
    return valid, valid & (mod >= np.float32(threshold))


def kernel_view(prepared: Prepared, start: int, steps: int, pair: int | None
                ) -> tuple[np.ndarray, int, int]:
    """The stack a compiled pass over an N-step set (and its stair pair) reads
    (:func:`~bistair.core.jit.kernel_frames`): ``(raw, start, pair)``, the prepared stack
    itself if the passes take its type, else the frames from the first of the set and the
    pair to the last as float32, with the indices in it (``pair`` -1 without a pair).

    Parameters
    ----------
    prepared : Prepared
        The capture stack.
    start, steps : int
        The set's first frame and its frame count.
    pair : int or None
        The stair pair's cosine frame, if any.

    Returns
    -------
    raw : (F', H, W) array
    start : int
    pair : int

    Examples
    --------
    >>> from bistair.core.captures import prepare
    >>> p = prepare(np.zeros((6, 8, 8), np.float64), 6, "demo")
    >>> raw, start, pair = kernel_view(p, 0, 4, 4)
    >>> raw.shape, raw.dtype.name, start, pair
    ((6, 8, 8), 'float32', 0, 4)
    """
    lo = start if pair is None else min(start, pair)
    hi = start + steps if pair is None else max(start + steps, pair + 2)
    raw, base = kernel_frames(prepared.raw, lo, hi - lo)
    return raw, int(start - lo + base), -1 if pair is None else int(pair - lo + base)


def clip_level(prepared: Prepared) -> float:
    """The raw value at and above which a frame counts as clipped: full scale for integer
    captures, a millionth below it for floats (as float32 rounds it for float32 stacks).

    Parameters
    ----------
    prepared : Prepared
        The capture stack.

    Returns
    -------
    float

    Examples
    --------
    >>> from bistair.core.captures import prepare
    >>> clip_level(prepare(np.zeros((3, 8, 8), np.uint8), 3, "demo"))
    255.0
    """
    full = float(prepared.full_scale)
    if np.issubdtype(prepared.raw.dtype, np.integer):
        return full
    return float(np.float32(full * (1.0 - 1e-6)))


def chi2_median(dof: int) -> float:
    """The median of a chi-squared distribution of ``dof`` degrees of freedom (scipy.stats'
    ``chi2.ppf(0.5, dof)`` without importing scipy.stats, half a second at start-up).

    Parameters
    ----------
    dof : int
        Degrees of freedom, at least 1.

    Returns
    -------
    float

    Examples
    --------
    >>> round(chi2_median(1), 4)
    0.4549
    """
    return float(2.0 * special.gammaincinv(dof / 2.0, 0.5))
