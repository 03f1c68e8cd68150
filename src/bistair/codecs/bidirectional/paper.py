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
from ...core.resolve import mode_by_label
from ...core.stair import quantize
from .bands import nearest_level, union_levels

if TYPE_CHECKING:
    from . import BidirectionalSpec


def paper_orders(ks: np.ndarray, theta: np.ndarray, fs: FringeSet,
                  spec: BidirectionalSpec) -> np.ndarray:
    """The paper's column scan (Sec. 2.3) and per-fringe mode (Sec. 3)."""
    S, P = spec.stairs, spec.partitions
    h, w = ks.shape
    v = fs.valid.T.ravel()
    t = theta.T.ravel()
    # Runs of equal k_s; with P != S the levels of both stairs are told apart.
    q = ks.T.ravel() if P == S else nearest_level(t, union_levels(P, S))
    col_start = np.zeros(v.size, bool)
    col_start[::h] = True
    seg_start = v & (col_start | ~np.r_[False, v[:-1]])
    start = seg_start | (v & np.r_[True, q[1:] != q[:-1]])
    pix = np.flatnonzero(v)
    run_of = np.cumsum(start)[pix] - 1
    first = np.flatnonzero(start)
    c_len = np.bincount(run_of)  # C: run lengths
    run_theta = np.arctan2(np.bincount(run_of, np.sin(t[pix])), np.bincount(run_of, np.cos(t[pix])))
    new_group = seg_start[first].copy()
    new_group[1:] |= c_len[1:] > c_len[:-1]  # difference of C above zero: a group starts
    # "When k_s1 and k_s2 are the same, the value of C is very large": such a run is a
    # group of its own. Very large = 1.4 times the run length a typical pixel sits in.
    merged = c_len > 1.4 * np.median(c_len[run_of])
    new_group[1:] |= merged[:-1]
    group = np.cumsum(new_group) - 1
    g_first = np.flatnonzero(new_group)
    g_second = g_first + 1
    has_second = np.zeros(g_first.size, bool)
    ok = g_second < first.size
    has_second[ok] = group[g_second[ok]] == group[g_first[ok]]
    has_second &= ~merged[g_first]
    second_theta = np.where(has_second, run_theta[np.minimum(g_second, first.size - 1)],
                            run_theta[g_first])
    # The longer run opens a group: the local one unless the spec gives it fewer rows.
    local_first = 2 * spec.local_rows > spec.group_rows
    local_theta, part_theta = ((run_theta[g_first], second_theta) if local_first
                               else (second_theta, run_theta[g_first]))
    k1 = quantize(local_theta, S)
    k2 = quantize(part_theta, P)  # merged runs: k = k_s1 + S*k_s1 (= 7 k_s1 for 6 x 6)
    k_group = k1 + S * k2
    order = np.full(v.size, -1, np.int64)
    order[pix] = k_group[group[run_of]]
    order = order.reshape(w, h).T
    fringes, n_fringes = fringe_regions(fs.phi, fs.valid, min_size=1,
                                        phase_noise=fs.phase_noise)
    mode, _ = mode_by_label(fringes, order, n_fringes, S * P)
    return np.where(fringes > 0, mode[fringes], -1)
