"""The paper's decoder for the bidirectional code (Sec. 2.3 and 3 of Qi, Zhou et al.).

``k_s`` by Eq. 19-20, a column scan of run lengths ``C`` whose increases mark group starts,
``k = k_s1 + S*k_s2`` per group (``k_s1 * (S+1)`` where the runs merge), then each fringe (a
2-D stripe between two phase jumps) takes the mode.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...core.measure import FringeSet
from ...core.regions import fringe_regions
from ...core.stair import quantize
from .bands import nearest_level, union_levels
from .paper_jit import column_median, column_runs, paint_labels, run_label_modes

if TYPE_CHECKING:
    from . import BidirectionalSpec


def paper_orders(ks: np.ndarray, theta: np.ndarray, fs: FringeSet,
                 spec: BidirectionalSpec, median: int = 5, min_run: int = 3) -> np.ndarray:
    """The paper's column scan (Sec. 2.3) and per-fringe mode (Sec. 3).

    The paper's steps: ``k_s`` by Eq. 19-20 (given); down each column, runs of equal
    ``k_s`` and their lengths ``C``; a group starts where ``C`` grows (its difference is
    above zero); in each group the long run is the local information ``k_s1``, the short
    one the partition information ``k_s2``, and ``k = k_s1 + S*k_s2`` (Eq. 22); a run that
    is "very large" is a merged band, ``k = (S+1)*k_s1``; then every fringe (a stripe
    between two phase jumps) takes the mode of its orders.

    Additions where the paper is silent, as an implementer of it would make them:

    1. ``k_s`` is median-filtered down each column over ``median`` pixels before the scan,
       so that single noisy pixels do not cut runs.
    2. Runs shorter than ``min_run`` pixels (a band's blurred edge, noise) are left out of
       the scan; their pixels join the run above them (or, at a column's top, below).
    3. A "very large" run is one over 1.4 times the median run length a pixel sits in; a
       column's valid stretch (between invalid pixels) starts a group.
    4. Where the partitions and stairs differ in number (the paper has 6 x 6), runs are of
       the nearest level of either stair rather than of ``k_s``.

    Parameters
    ----------
    ks : numpy.ndarray
        (H, W) int ``k_s``, the stair phase quantised to ``S`` levels (-1 where invalid),
        column layout (coded axis along the image rows).
    theta : numpy.ndarray
        (H, W) stair phase in radians.
    fs : FringeSet
        Stage 1: the wrapped phase in [0, 2*pi) and the valid pixels.
    spec : BidirectionalSpec
        The spec of one coded axis.
    median : int, default 5
        Pixels of the median filter down each column (1: none).
    min_run : int, default 3
        The shortest run, in pixels, the scan counts.

    Returns
    -------
    numpy.ndarray
        (H, W) int32 fringe order per pixel, -1 outside the fringe regions.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.codecs.bidirectional import code_columns
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("bidirectional", width=240, height=64, period=20, partitions=3,
    ...                  stairs=4, group_rows=16, local_rows=10)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> order = paper_orders(code.code, code.maps["stair_phase"], fs, spec)
    >>> order[0, ::20].tolist(), order[40, ::20].tolist() == order[0, ::20].tolist()
    ([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11], True)
    """
    S, P = spec.stairs, spec.partitions
    h, w = ks.shape
    code = ks if P == S else np.where(fs.valid, nearest_level(theta.ravel(), union_levels(
        P, S)).reshape(h, w), -1)
    # -1 outside the pixels the scan reads (valid, code >= 0); addition 1: the median
    code = (column_median(code, fs.valid, median) if median > 1
            else np.where(fs.valid, code, -1))
    runs = column_runs(code, np.sin(theta), np.cos(theta), min_run)  # addition 2
    del code
    if runs.start.size == 0:
        return np.full((h, w), -1, np.int32)
    c_len = runs.length  # C: run lengths
    run_theta = np.arctan2(runs.sum_sin, runs.sum_cos)
    new_group = runs.first.copy()  # a column's valid stretch starts a group
    new_group[1:] |= c_len[1:] > c_len[:-1]  # difference of C above zero: a group starts
    # "When k_s1 and k_s2 are the same, the value of C is very large": such a run is a
    # group of its own (addition 3).
    merged = c_len > 1.4 * _pixel_median(c_len)
    new_group[1:] |= merged[:-1]
    group = np.cumsum(new_group) - 1
    g_first = np.flatnonzero(new_group)
    g_second = g_first + 1
    n_runs = c_len.size
    has_second = np.zeros(g_first.size, bool)
    ok = g_second < n_runs
    has_second[ok] = group[g_second[ok]] == group[g_first[ok]]
    has_second &= ~merged[g_first]
    second_theta = np.where(has_second, run_theta[np.minimum(g_second, n_runs - 1)],
                            run_theta[g_first])
    # The longer run opens a group: the local one unless the spec gives it fewer rows.
    local_first = 2 * spec.local_rows > spec.group_rows
    local_theta, part_theta = ((run_theta[g_first], second_theta) if local_first
                               else (second_theta, run_theta[g_first]))
    k1 = quantize(local_theta, S)
    k2 = quantize(part_theta, P)  # merged runs: k = k_s1 + S*k_s1 (= 7 k_s1 for 6 x 6)
    run_k = (k1 + S * k2)[group]
    # the per-run work is done: let it go before the fringe regions, the stage's peak
    del run_theta, new_group, merged, group, g_first, g_second, has_second, second_theta
    del local_theta, part_theta, k1, k2, c_len, ok
    fringes, n_fringes = fringe_regions(fs.phi, fs.valid, min_size=1,
                                        phase_noise=fs.phase_noise, links=fs.links)
    mode, _ = run_label_modes(fringes, runs, run_k, n_fringes, S * P)
    return paint_labels(fringes, mode)


def _pixel_median(length: np.ndarray) -> float:
    """``np.median(np.repeat(length, length))``: the median run length a pixel sits in.

    Examples
    --------
    >>> _pixel_median(np.array([1, 3, 2])), float(np.median([1, 3, 3, 3, 2, 2]))
    (2.5, 2.5)
    """
    pixels = np.bincount(length) * np.arange(length.max() + 1)  # pixels per run length
    cum = np.cumsum(pixels)
    n = int(cum[-1])
    mid = np.searchsorted(cum, [(n - 1) // 2, n // 2], side="right")
    return float(mid.mean()) if n % 2 == 0 else float(mid[1])
