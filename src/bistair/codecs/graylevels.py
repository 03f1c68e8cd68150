"""Multi-level Gray code (``code_levels`` L > 2): N phase shifts, then ``D`` frames of L
grey levels forming a base-L reflected Gray code of the fringe order.

The quaternary code (L = 4) is He et al., *Quaternary gray-code phase unwrapping for binary
fringe projection profilometry*, Opt. Lasers Eng. 121, 2019, as SLMaster projects it
(``InterzoneSinusFourGrayscalePattern``: 3 steps, 16 fringes, two frames of grey levels 0,
85, 170, 255), decoded with the inter-zone idea of Wu et al., Opt. Express 29(17), 2021: the
code's edges sit on the phase wraps, and the pixels beside them take their order from their
fringe, not from their own digits.

Patterns: ``D = ceil(log_L(fringes))`` frames ``gray-0 .. gray-(D-1)``, most significant
digit first; digit ``d`` is drawn at ``offset + amplitude * (2 d / (L - 1) - 1)``. The
digits of fringe ``k`` are its base-L reflected Gray code: digit ``i`` is ``b_i`` where the
index of the digits before it, ``floor(k / L**(D - i))``, is even, ``L - 1 - b_i`` where it
is odd (``b_i`` the base-L digits of ``k``): across the blocks of the digit before, each
digit runs forward, backward, forward, ...; neighbouring fringes differ in one digit by one
level.

Decode (stage 2, :func:`levels_code`): each code frame is read as ``v = (I - A) / B``
against the fringes' own average ``A`` and modulation ``B`` (no white or black frame). The
level positions are estimated from the capture, per frame (:func:`estimate_levels`: 1-D
k-means on a sample of the valid pixels, from the nominal positions and from the sample's
quantiles, the tighter kept), so a camera gamma, blur or contrast loss that moves the middle
levels (real captures: about -0.45 and +0.37 instead of -1/3 and 1/3) is followed. A digit
is clear where ``v`` lies outside the middle half between two levels and its margin clears
the noise by three sigmas; a pixel with a digit that is not clear has no order of its own.

Stage 3 (:func:`order_levels`, the default per-pixel strategy): a pixel whose digits are
clear and whose phase is at least pi/3 from the code's edges carries its order; every other
pixel read takes the order its fringe region's carried pixels settle (over 99% of at least
50 of them), if its own nearest-level reading is that order or, within pi/3 of an edge, the
neighbour on that edge's side (the misread the edge's blur makes); else it is left out.
``strategy="region"`` votes every clear pixel over its fringe region (the binary code's
region strategy). The checks refuse a capture whose levels cannot be told apart
(:func:`separation_problem`): a binary code read as L = 4, L = 4 read as L = 8, levels
washed out.

Examples
--------
>>> import numpy as np
>>> from bistair import decode, encode, make_spec
>>> spec = make_spec("graycode", width=1920, height=64, steps=3, period=120, code_levels=4)
>>> spec.frames
('shift-0', 'shift-1', 'shift-2', 'gray-0', 'gray-1')
>>> (encode(spec)[3:, 0, 60::120] * 3).round().astype(int).tolist()  # the digits
[[0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3], [0, 1, 2, 3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0]]
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ..core.captures import Prepared
from ..core.checks import refuse
from ..core.measure import FringeSet
from ..core.phase import TWO_PI
from ..core.regions import fringe_regions
from ..core.resolve import code_evidence
from ..errors import BistairError
from .base import CodeMap, Orders, fringe_index
from .graylevels_cells import CELL_MIN, cell_digits, fit_blur, narrow, read_cells
from .graylevels_jit import read_levels, row_fill, sample_levels

MAX_LEVELS = 16  # an 8-bit projector's levels 17 grey values apart at most
# a clear digit: outside the middle CLEAR_SHARE of the gap between two levels, by
# CLEAR_NOISE sigmas of I - A; a pixel within EDGE_ZONE of the code's edges (on the phase
# wraps) is carried by its fringe region, not by its own digits (SLMaster's pi/3)
CLEAR_NOISE = 3.0
CLEAR_SHARE = 0.5
EDGE_ZONE = math.pi / 3
# a digit is read on the pixels of its fringe within REACH rows along it (the column
# layout's columns), their phase within SAME_FRINGE radians of the pixel's
REACH = 3
SAME_FRINGE = 0.5
# a fringe region settles its order where over SETTLED of at least MIN_STRONG of its
# carried pixels read it
SETTLED = 0.99
MIN_STRONG = 50
# and the rest from their fringe along the row: the first carried pixel either way within
# ROW_REACH pixels, reached without a phase step of ROW_CUT radians or more
ROW_REACH = 64
ROW_CUT = math.pi / 4
# the checks: between two neighbouring levels of a frame at most MAX_BAND times as many
# sample pixels as at the fainter of the two (measured on renders: see
# docs/guide/methods.md); a level under ABSENT of a frame's sample is out of view there
MAX_BAND = 0.5
ABSENT = 0.005
# and no two neighbouring levels of a frame closer than MIN_GAP of the fringes' modulation
# in v (renders: right readings 0.165 and more, codes washed out to 5-10% 0.056 and less)
MIN_GAP = 0.1
SAMPLE = 5_000  # about as many values the levels are estimated on (cell means, repeated)
ALONE = 100_000  # pixels the levels' separation one by one is judged on


def code_digits(fringes: int, levels: int) -> int:
    """Digits of base ``levels`` that count ``fringes`` orders: ``ceil(log_L(fringes))``,
    at least 1.

    Parameters
    ----------
    fringes, levels : int
        The orders to count and the base L.

    Returns
    -------
    int

    Examples
    --------
    >>> code_digits(16, 4), code_digits(17, 4), code_digits(36, 3), code_digits(1, 4)
    (2, 3, 4, 1)
    """
    digits, span = 1, max(int(levels), 2)
    while span < fringes:
        digits, span = digits + 1, span * max(int(levels), 2)
    return digits


def reflected_digits(index: np.ndarray, levels: int, digits: int) -> np.ndarray:
    """The base-``levels`` reflected Gray code of each index, most significant digit first.

    Parameters
    ----------
    index : numpy.ndarray
        Non-negative integers below ``levels ** digits``.
    levels, digits : int
        The base L and the number of digits.

    Returns
    -------
    numpy.ndarray
        Shape ``(digits, *index.shape)``, int64.

    Examples
    --------
    >>> reflected_digits(np.arange(9), 3, 2).tolist()
    [[0, 0, 0, 1, 1, 1, 2, 2, 2], [0, 1, 2, 2, 1, 0, 0, 1, 2]]
    """
    index = np.asarray(index, dtype=np.int64)
    out = np.empty((digits, *index.shape), dtype=np.int64)
    for i in range(digits):
        parent = index // levels ** (digits - i)
        b = (index // levels ** (digits - 1 - i)) % levels
        out[i] = np.where(parent % 2 == 0, b, levels - 1 - b)
    return out


def reflected_index(gray: np.ndarray, levels: int) -> np.ndarray:
    """The index of base-``levels`` reflected Gray code digits (inverse of
    :func:`reflected_digits`).

    Parameters
    ----------
    gray : numpy.ndarray
        (digits, ...) digits, most significant first.
    levels : int
        The base L.

    Returns
    -------
    numpy.ndarray
        int64 indices, ``gray.shape[1:]``.

    Examples
    --------
    >>> reflected_index(reflected_digits(np.arange(64), 4, 3), 4).tolist() == list(range(64))
    True
    """
    gray = np.asarray(gray, dtype=np.int64)
    parent = np.zeros(gray.shape[1:], dtype=np.int64)
    for g in gray:
        parent = parent * levels + np.where(parent % 2 == 0, g, levels - 1 - g)
    return parent


def validate_levels(spec: Any) -> None:
    """Refuse a ``code_levels`` and its combinations that are not defined: L from 2 to
    ``MAX_LEVELS``; for L > 2 no complementary
    pattern, shifted code, inverse patterns or second period (each is a binary code's) and
    phase shifts to read the levels against. A white frame is the texture frame, as
    always.

    Parameters
    ----------
    spec : GrayCodeSpec
        The spec being validated.

    Raises
    ------
    BistairError
        One line naming what is not defined.

    Examples
    --------
    >>> from bistair import make_spec
    >>> make_spec("graycode", width=240, height=32, code_levels=4).code_bits
    2
    >>> make_spec("graycode", width=240, height=32, code_levels=4, inverse=1)
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: inverse patterns are a binary code's: ... (inverse 0)
    """
    levels = spec.code_levels
    if not isinstance(levels, (int, np.integer)) or isinstance(levels, bool) or not (
            2 <= levels <= MAX_LEVELS):
        raise BistairError(f"code_levels must be a whole number from 2 to {MAX_LEVELS}, got "
                           f"{levels}")
    if levels == 2:
        return
    what = f"a code of {levels} levels"
    if spec.steps == 0:
        raise BistairError(f"{what} is read against the fringes' average and modulation: it "
                           "needs phase shifts (steps 3 or more)")
    if spec.complementary:
        raise BistairError(f"a complementary pattern is a binary code's: {what} has its edges "
                           "on the phase wraps, fixed from the phase (complementary 0)")
    if spec.gray_offset:
        raise BistairError(f"the shifted Gray code (gray_offset 0.5) is binary: {what} has "
                           "its edges on the phase wraps (gray_offset 0)")
    if spec.inverse:
        raise BistairError(f"inverse patterns are a binary code's: {what} is read against "
                           "the fringes' average and modulation (inverse 0)")
    if spec.second_period:
        raise BistairError(f"a second period checks a binary code: {what} has its edges "
                           "fixed from the phase (second_period 0)")


def level_patterns(spec: Any) -> np.ndarray:
    """The code frames of a multi-level spec along the coded axis: ``(D, coded_length)``
    float64, digit ``d`` at ``offset + amplitude * (2 d / (L - 1) - 1)``.

    Parameters
    ----------
    spec : GrayCodeSpec
        A spec with ``code_levels`` > 2.

    Returns
    -------
    numpy.ndarray

    Examples
    --------
    >>> from bistair import make_spec
    >>> spec = make_spec("graycode", width=90, height=8, period=10, code_levels=3)
    >>> (level_patterns(spec)[:, 5::10] * 2).round().astype(int).tolist()
    [[0, 0, 0, 1, 1, 1, 2, 2, 2], [0, 1, 2, 2, 1, 0, 0, 1, 2]]
    """
    levels = spec.code_levels
    gray = reflected_digits(fringe_index(spec), levels, spec.code_bits)
    return spec.offset + spec.amplitude * (2.0 * gray / (levels - 1) - 1.0)


def frame_digits(spec: Any) -> list[np.ndarray]:
    """The digits each code frame of ``spec`` draws somewhere on the projector, increasing.

    Parameters
    ----------
    spec : GrayCodeSpec
        A spec with ``code_levels`` > 2.

    Returns
    -------
    list of numpy.ndarray
        One array of digits per code frame.

    Examples
    --------
    >>> from bistair import make_spec
    >>> spec = make_spec("graycode", width=1080, height=8, period=30, code_levels=4)
    >>> [d.tolist() for d in frame_digits(spec)]  # 36 fringes
    [[0, 1, 2], [0, 1, 2, 3], [0, 1, 2, 3]]
    """
    gray = reflected_digits(np.arange(spec.fringes), spec.code_levels, spec.code_bits)
    return [np.unique(g) for g in gray]


def _kmeans(values: np.ndarray, centres: np.ndarray, rounds: int = 30) -> np.ndarray:
    """1-D k-means (Lloyd) of sorted ``values`` from ``centres`` (increasing); a centre
    that loses every value stays where it was."""
    centres = np.array(centres, dtype=np.float64)
    cum = np.concatenate([[0.0], np.cumsum(values)])
    for _ in range(rounds):
        cuts = np.searchsorted(values, 0.5 * (centres[1:] + centres[:-1]))
        bounds = np.concatenate([[0], cuts, [values.size]])
        counts = np.diff(bounds)
        sums = cum[bounds[1:]] - cum[bounds[:-1]]
        new = np.where(counts > 0, sums / np.maximum(counts, 1), centres)
        if np.allclose(new, centres, atol=1e-6):
            return new
        centres = new
    return centres


def _spread(values: np.ndarray, centres: np.ndarray) -> float:
    """The sum of squared distances of sorted ``values`` to their nearest centre."""
    cuts = np.searchsorted(values, 0.5 * (centres[1:] + centres[:-1]))
    nearest = np.repeat(centres, np.diff(np.concatenate([[0], cuts, [values.size]])))
    return float(np.sum((values - nearest) ** 2))


def estimate_levels(values: np.ndarray, digits: np.ndarray, levels: int) -> np.ndarray:
    """The positions of a frame's levels in ``v = (I - A) / B`` from a sample of its pixels.

    1-D k-means over the sample, started from the nominal positions ``2 d / (L - 1) - 1``
    of the frame's digits and from the sample's quantiles (as many values each as the
    digits' share of the levels); the start that ends tighter is kept.

    Parameters
    ----------
    values : numpy.ndarray
        ``v`` of the frame's sample pixels (any order).
    digits : numpy.ndarray
        The digits the frame draws, increasing.
    levels : int
        L.

    Returns
    -------
    numpy.ndarray
        (len(digits),) float64, increasing where the levels separate.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> v = np.repeat([-0.9, -0.45, 0.37, 1.1], 1000) + rng.normal(0, 0.03, 4000)
    >>> estimate_levels(v, np.arange(4), 4).round(2).tolist()
    [-0.9, -0.45, 0.37, 1.1]
    """
    values = np.sort(np.clip(np.asarray(values, dtype=np.float64), -4.0, 4.0))
    if values.size == 0:
        return 2.0 * digits / (levels - 1) - 1.0
    nominal = _kmeans(values, 2.0 * digits / (levels - 1) - 1.0)
    spaced = (np.arange(digits.size) + 0.5) / digits.size
    quantile = _kmeans(values, np.quantile(values, spaced))
    return min((nominal, quantile), key=lambda c: _spread(values, c))


def separation(values: np.ndarray, centres: np.ndarray) -> tuple[float, int]:
    """How badly a frame's levels separate: the largest count of sample values in the middle
    half between two neighbouring levels over the count within a quarter gap of the
    fainter of them (each plus one: a level no value is at gives 1 or more), and that
    pair's lower level (index into ``centres``). Levels out of order give ``inf``.

    Parameters
    ----------
    values : numpy.ndarray
        ``v`` of a frame's sample pixels.
    centres : numpy.ndarray
        The frame's level positions, increasing.

    Returns
    -------
    ratio : float
    pair : int

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> four = np.repeat([-1.0, -1 / 3, 1 / 3, 1.0], 500) + rng.normal(0, 0.05, 2000)
    >>> separation(four, np.array([-1.0, -1 / 3, 1 / 3, 1.0]))[0] < 0.01
    True
    >>> two = np.repeat([-1.0, 1.0], 1000) + rng.normal(0, 0.05, 2000)  # a binary frame
    >>> separation(two, np.array([-1.0, -1 / 3, 1 / 3, 1.0]))[0] >= 1
    True
    """
    values = np.asarray(values, dtype=np.float64)
    gaps = np.diff(centres)
    if gaps.size == 0:
        return 0.0, 0
    if not np.all(gaps > 0):
        return math.inf, int(np.argmin(gaps))
    reach = np.minimum(np.concatenate([[np.inf], gaps]), np.concatenate([gaps, [np.inf]])) / 4
    values = np.sort(values)

    def between(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return np.searchsorted(values, hi) - np.searchsorted(values, lo, side="right")

    at = between(centres - reach, centres + reach)
    band = between(centres[:-1] + gaps / 4, centres[1:] - gaps / 4)
    ratio = (band + 1) / (np.minimum(at[:-1], at[1:]) + 1)  # an empty level: 1 at least
    worst = int(np.argmax(ratio))
    return float(ratio[worst]), worst


def frame_levels(samples: list[np.ndarray], used: list[np.ndarray], levels: int
                 ) -> tuple[np.ndarray, tuple[float, int, int]]:
    """Each code frame's level positions and how badly the worst frame's levels separate.

    The L levels are first estimated on every frame's sample pooled
    (:func:`estimate_levels`; every digit recurs every L fringes in the last frame, so all
    of them are in view); then per frame, from those, over the levels the frame shows
    (a level holding under ``ABSENT`` of the frame's sample is out of view there and keeps
    the pooled position).

    Parameters
    ----------
    samples : list of numpy.ndarray
        ``v`` of each frame's sample pixels.
    used : list of numpy.ndarray
        The digits each frame draws (:func:`frame_digits`).
    levels : int
        L.

    Returns
    -------
    centres : numpy.ndarray
        (frames, levels) float32, row ``i``'s first ``len(used[i])`` set.
    worst : (ratio, frame, pair)
        The worst :func:`separation` (frame -1: the pooled levels).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> pos = np.array([-0.9, -0.45, 0.37, 1.1])
    >>> first = pos[np.repeat([0, 1], 800)] + rng.normal(0, 0.03, 1600)  # digits 2, 3 out of view
    >>> last = pos[np.repeat([0, 1, 2, 3], 400)] + rng.normal(0, 0.03, 1600)
    >>> centres, worst = frame_levels([first, last], [np.arange(4)] * 2, 4)
    >>> centres.astype(float).round(2).tolist(), worst[0] < 0.01
    ([[-0.9, -0.45, 0.37, 1.1], [-0.9, -0.45, 0.37, 1.1]], True)
    """
    pooled = np.concatenate(samples) if samples else np.empty(0)
    ref = estimate_levels(pooled, np.arange(levels), levels)
    clipped = np.clip(pooled, -4.0, 4.0)
    ratio, pair = separation(clipped, ref)
    worst = (ratio, -1, pair)
    centres = np.full((len(samples), levels), np.nan, np.float32)
    for i, (values, ds) in enumerate(zip(samples, used, strict=True)):
        start = ref[ds]
        values = np.sort(np.clip(values.astype(np.float64), -4.0, 4.0))
        cuts = np.searchsorted(values, 0.5 * (start[1:] + start[:-1]))
        counts = np.diff(np.concatenate([[0], cuts, [values.size]]))
        seen = counts >= ABSENT * max(values.size, 1)
        c = start.copy()
        if np.count_nonzero(seen) > 0:
            c[seen] = _kmeans(values, start[seen])
            ratio, pair = separation(values, c[seen])
            if ratio > worst[0]:
                worst = (ratio, i, int(ds[seen][pair]))
        centres[i, :ds.size] = c
    return centres, worst


def _alone_values(prepared: Prepared, start: int, digits: int, fs: FringeSet, mod: np.ndarray
                  ) -> list[np.ndarray]:
    """``v`` of each code frame as a pixel read one by one reads it (averaged along the
    fringe within ``REACH`` rows), against the modulation ``mod`` (the blur taken out), on
    an even grid of at most ``ALONE`` valid pixels at least ``EDGE_ZONE`` from the code's
    edges, the better modulated half of them."""
    h, w = fs.phi.shape
    step = max(1, int(math.ceil(math.sqrt(h * w / ALONE))))
    sub, phi = fs.mod[::step, ::step], fs.phi[::step, ::step]
    valid = fs.valid[::step, ::step] & (sub > 0) & (phi >= EDGE_ZONE) & (
        phi <= TWO_PI - EDGE_ZONE)  # away from the code's edges: no level between two
    if np.any(valid):
        valid &= sub >= np.median(sub[valid])
    ys, xs = np.nonzero(valid)
    return list(sample_levels(prepared.raw, start, digits, prepared.scale, fs.avg, mod,
                              fs.valid, fs.phi, ys * step, xs * step, REACH, SAME_FRINGE))


class Cells(NamedTuple):
    """A capture's code cells (:mod:`~bistair.codecs.graylevels_cells`) and its levels."""

    labels: np.ndarray  # (H, W) fringe regions
    cid: np.ndarray  # (H, W) each pixel's cell
    mean: np.ndarray  # (D, n) each cell's v, the blur taken out
    sigma: np.ndarray  # (D, n) the sigma of each mean
    count: np.ndarray  # (n,) pixels each mean is over
    usable: np.ndarray  # (n,) the cells read (not mixed)
    gain: np.ndarray  # (n,) what the blur taken out multiplies each cell's v by
    blur: float  # the blur constant c (:func:`~bistair.codecs.graylevels_cells.fit_blur`)
    centres: np.ndarray  # (D, L) the levels (:func:`frame_levels`)
    worst: tuple[float, int, int]  # the worst separation


def code_cells(prepared: Prepared, spec: Any, fs: FringeSet) -> Cells:
    """The code cells of a multi-level capture read, the fringes' blur fitted and taken
    out of their ``v`` and the levels estimated on them (each cell weighted by its pixels).

    Parameters
    ----------
    prepared : Prepared
        The method's frames in method order, column layout.
    spec : GrayCodeSpec
        A spec with ``code_levels`` > 2.
    fs : FringeSet
        Stage 1.

    Returns
    -------
    Cells

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=480, height=64, period=30, code_levels=4)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> cells = code_cells(cols, spec, measure_shifts(cols, spec))
    >>> cells.centres.astype(float).round(2).tolist(), cells.worst[0] < 0.01
    ([[-1.0, -0.33, 0.33, 1.0], [-1.0, -0.33, 0.33, 1.0]], True)
    """
    levels, digits = spec.code_levels, spec.code_bits
    used = frame_digits(spec)
    noise_d = fs.noise * math.sqrt(1.0 + 1.0 / spec.steps)
    labels, _ = fringe_regions(fs.phi, fs.valid, phase_noise=fs.phase_noise)
    cid, mean, count, sigma, spread, period, clean = read_cells(
        prepared.raw, spec.steps, digits, prepared.scale, fs.avg, fs.mod, fs.valid, fs.phi,
        labels, noise_d, EDGE_ZONE)
    big = count >= CELL_MIN
    big[0] = False  # (no region)
    usable = big & clean  # the levels are estimated on these
    # each cell's mean repeated for its pixels (about SAMPLE values in all)
    times = np.where(usable, -(-count // max(1, int(count[usable].sum()) // SAMPLE)), 0)
    blur = fit_blur(mean, count, usable, period,
                    lambda values: frame_levels(values, used, levels)[0], times)
    gain = np.exp(-blur * np.where(np.isfinite(period), 1.0 / period ** 2, 0.0))
    mean, sigma, spread = mean * gain, sigma * gain, spread * gain
    centres, worst = frame_levels([np.repeat(m, times) for m in mean], used, levels)
    read = big & (clean | narrow(spread, mean, centres, np.array([d.size for d in used])))
    return Cells(labels, cid, mean, sigma, count, read, gain, blur, centres, worst)


def levels_code(prepared: Prepared, spec: Any, fs: FringeSet) -> CodeMap:
    """Stage 2 of a multi-level code: the level positions estimated per frame, the levels
    checked for separation, each pixel's digits and order read (:func:`read_levels`).

    Parameters
    ----------
    prepared : Prepared
        The method's frames in method order, column layout.
    spec : GrayCodeSpec
        A spec with ``code_levels`` > 2.
    fs : FringeSet
        Stage 1: phase, average, modulation, validity, noise.

    Returns
    -------
    CodeMap
        ``code``: the order of the pixel's cell where the cell is read (every digit clear:
        ``maps["cells"]``), else of its own reading where every digit is clear (-1
        elsewhere); ``maps["nearest"]`` the order of a pixel's nearest levels (read one by
        one where its cell is not), ``maps["carried"]`` where its own digits carry its
        order, ``maps["labels"]`` the fringe regions; ``edge_phase`` 0; ``beyond``.

    Raises
    ------
    BistairError
        A code frame's levels cannot be told apart (through
        :func:`~bistair.core.checks.refuse`).

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=480, height=32, period=30, code_levels=4)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> code = levels_code(cols, spec, measure_shifts(cols, spec))
    >>> code.code[0, 15::30].tolist()
    [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]
    """
    levels, digits, start = spec.code_levels, spec.code_bits, spec.steps
    used = frame_digits(spec)
    noise_d = fs.noise * math.sqrt(1.0 + 1.0 / spec.steps)
    cells = code_cells(prepared, spec, fs)
    centres, worst = cells.centres, cells.worst
    refuse(separation_problem(worst, levels) or washed_problem(centres, used))
    digit_of = np.zeros((digits, levels), np.int32)
    for i, ds in enumerate(used):
        digit_of[i, :ds.size] = ds
    cell_order, cell_clear = cell_digits(cells.mean, cells.sigma, centres, digit_of,
                                         np.array([d.size for d in used]), levels,
                                         CLEAR_NOISE, CLEAR_SHARE)
    cell_order = np.where(cells.usable & cell_clear & (cell_order < spec.fringes), cell_order,
                          -1)
    read = np.where(fs.valid, cell_order[cells.cid], -1).astype(np.int32)
    mod = (fs.mod / cells.gain[cells.cid]).astype(np.float32)
    # a pixel read one by one carries its order only where the levels separate pixel by
    # pixel too (the same check on its readings; else only the cells carry)
    alone = frame_levels(_alone_values(prepared, start, digits, fs, mod), used, levels)
    alone_ok = alone[1][0] <= MAX_BAND
    code, nearest, carried, beyond = read_levels(
        prepared.raw, start, digits, prepared.scale, fs.avg, mod, fs.valid, fs.phi,
        centres, digit_of, np.array([d.size for d in used], np.int32), levels, spec.fringes,
        noise_d, CLEAR_NOISE, CLEAR_SHARE, EDGE_ZONE, REACH, SAME_FRINGE, read < 0)
    if not alone_ok:
        code, carried = np.where(read >= 0, code, -1), np.zeros_like(carried)
    code = np.where(read >= 0, read, code)
    return CodeMap(code, {"nearest": nearest, "carried": carried, "cells": read,
                          "labels": cells.labels}, edge_phase=0.0, beyond=beyond)


def separation_problem(worst: tuple[float, int, int], levels: int) -> str | None:
    """The one-line reason to refuse a capture whose levels do not separate (the worst
    :func:`separation` over ``MAX_BAND``), or ``None``.

    Parameters
    ----------
    worst : (ratio, frame, digit)
        From :func:`frame_levels` (frame -1: the pooled levels).
    levels : int
        L.

    Returns
    -------
    str or None

    Examples
    --------
    >>> separation_problem((0.02, 1, 0), 4) is None
    True
    >>> separation_problem((1.3, 1, 1), 4)  # doctest: +ELLIPSIS
    'code frame gray-1 does not show 4 separate grey levels: ...'
    """
    ratio, frame, low = worst
    if ratio <= MAX_BAND:
        return None
    where = "the code frames" if frame < 0 else f"code frame gray-{frame}"
    amount = "levels out of order" if math.isinf(ratio) else (
        f"{ratio:.2f}x as many pixels between the levels of digits {low} and {low + 1} as "
        f"at the fainter of them (at most {MAX_BAND})")
    return (f"{where} do{'' if frame < 0 else 'es'} not show {levels} separate grey levels: "
            f"{amount}; is code_levels {levels} right (a binary code, another L), or is the "
            "code washed out?")


def washed_problem(centres: np.ndarray, used: list[np.ndarray]) -> str | None:
    """The one-line reason to refuse a capture two of whose neighbouring levels lie under
    ``MIN_GAP`` apart in ``v`` (a code washed out: its levels too close for the cells'
    systematic spread, whatever the noise), or ``None``.

    Parameters
    ----------
    centres : (D, L) array
        Each frame's levels (:func:`frame_levels`).
    used : list of numpy.ndarray
        The digits each frame draws.

    Returns
    -------
    str or None

    Examples
    --------
    >>> washed_problem(np.float32([[-0.75, -0.56, 0.1, 1.3]]), [np.arange(4)]) is None
    True
    >>> washed_problem(np.float32([[-0.05, -0.02, 0.01, 0.05]]), [np.arange(4)])
    ... # doctest: +ELLIPSIS
    "code frame gray-0's levels of digits 1 and 2 lie 0.030 of the fringes' modulation ..."
    """
    worst = (math.inf, 0, 0)
    for i, ds in enumerate(used):
        gaps = np.diff(centres[i, :ds.size].astype(np.float64))
        if gaps.size and gaps.min() < worst[0]:
            worst = (float(gaps.min()), i, int(ds[int(np.argmin(gaps))]))
    gap, frame, low = worst
    if gap >= MIN_GAP:
        return None
    return (f"code frame gray-{frame}'s levels of digits {low} and {low + 1} lie {gap:.3f} "
            f"of the fringes' modulation apart (at least {MIN_GAP}): is the code washed "
            "out, or do its levels crowd (compensate the projector's gamma, use more steps)?")


def order_levels(fs: FringeSet, code: CodeMap, spec: Any, info: dict) -> Orders:
    """Stage 3 of a multi-level code, per pixel: the carried pixels keep their order; every
    other pixel read takes its fringe region's settled order where its own reading is
    that order or, within ``EDGE_ZONE`` of a code edge, the neighbour on that edge's side.

    Parameters
    ----------
    fs : FringeSet
        Stage 1, column layout.
    code : CodeMap
        Stage 2 (:func:`levels_code`).
    spec : GrayCodeSpec
        The spec (its fringe count).
    info : dict
        The decode's figures so far; ``left_out`` and ``region_carried`` are added.

    Returns
    -------
    Orders
        (H, W) int32 orders, -1 where not decoded.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=480, height=32, period=30, code_levels=4)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> orders = order_levels(fs, levels_code(cols, spec, fs), spec, {})
    >>> bool((orders.order[:, :-1] == np.arange(480)[:-1] // 30).all())
    True
    """
    nearest, carried, cells = code.maps["nearest"], code.maps["carried"], code.maps["cells"]
    # a cell read whole carries its pixels (they are not read one by one)
    k = np.where(cells >= 0, cells, np.where(carried, code.code, -1))
    carried = k >= 0
    labels = code.maps["labels"]
    n = int(labels.max(initial=0))
    shares = code_evidence(labels, n, k, spec.fringes)
    strong = np.bincount(labels[k >= 0], minlength=n + 1)
    settled = np.where((shares.max(axis=1) > SETTLED) & (strong >= MIN_STRONG),
                       shares.argmax(axis=1), -1)
    settled[0] = -1
    region = settled[labels]
    phi = fs.phi
    near_start = phi < EDGE_ZONE
    near_end = phi > np.float32(TWO_PI - EDGE_ZONE)
    clear = code.code >= 0  # a clear reading is not overruled
    fits = (region >= 0) & ((nearest == region) | ~clear & (
        (near_start & (nearest == region - 1)) | (near_end & (nearest == region + 1))))
    take = (k < 0) & (nearest >= 0) & fits
    order = np.where(take, region, k).astype(np.int32)
    order = row_fill(order, nearest, clear, carried, phi, fs.valid, EDGE_ZONE, ROW_REACH,
                     ROW_CUT)
    info["region_carried"] = int(np.count_nonzero(order >= 0)) - int(np.count_nonzero(k >= 0))
    info["left_out"] = int(np.count_nonzero((nearest >= 0) | (cells >= 0))) - int(
        np.count_nonzero(order >= 0))
    return Orders(order, info)
