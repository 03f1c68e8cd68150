"""Four-adjacent-codeword phase coding after Lv et al. (Applied Optics 58(32), 2019).

N phase shifts plus a coded pair (frames ``shift-n``, ``code-cos``, ``code-sin``) carrying
one code per fringe from a few stair levels; the order of a fringe is found by looking up
the codes of ``window`` adjacent fringes in the code sequence, so many fringes (36 in the
paper's comparison) need only a few levels.

The exact published code sequence is not available to us. This codec builds the documented
design: a sequence over ``levels`` stair levels (4 by default) in which neighbouring codes
differ and every window of four adjacent codes is unique (:func:`code_sequence`, a
deterministic depth-first search). Decoding: each fringe region (2-D stripe between phase
jumps) takes the code most of its pixels read; regions are chained to their right-hand
neighbours across wraps; every chain of ``window`` regions is looked up in the sequence and
votes for the orders of its members; the votes are checked against each other and against
the one-order step across every wrap (:func:`bistair.core.resolve.orders_from_regions`). A region
in an object narrower than ``window`` fringes gets no window and stays invalid: that is the
method's known limit, which the bidirectional coding removes.

Examples
--------
>>> code_sequence(12, levels=4, window=4)
(0, 1, 2, 3, 0, 1, 2, 0, 1, 2, 1, 2)
"""

from __future__ import annotations

import dataclasses
from functools import lru_cache

import numpy as np

from ..core.captures import Prepared
from ..core.checks import refuse, stair_misfit, stair_sample
from ..core.measure import FringeSet
from ..core.memory import row_bands
from ..core.regions import RegionLinks, core_weight, fringe_regions, region_links
from ..core.resolve import code_evidence, orders_from_regions
from ..core.stair import read_stairs, stair_level_phase, stair_pair
from ..errors import BistairError
from ..spec import PeriodSpec, field, format_period
from .base import Codec, CodeMap, Orders, along_columns, fringe_index, shift_patterns

# The share of a region's weight its code needs for the windows through it to be judged by
# the spec check: a region holding two surfaces reads two codes about half and half
SURE_CODE = 0.75
# over this share of the windows read through regions of no one code, the captures do not
# fit: right decodes reach 0.23 (the 1280 x 1024 occlusion render; 0.19 on mugs-on-wall under
# hard optics), another method's captures read as lv 1.0 (tests/test_lv_windows.py)
UNSURE = 0.5
# the limits of window_problem, measured by benchmarks/lv_margins.py on 54 right decodes
# (the presets at 640 x 512, default and hard optics, two seeds; 16 scenes of `simulate
# --count 16 --vary optics,objects,pose`; paper-sim, mugs-on-wall, objects-on-plane at
# 1280 x 1024) and 533 wrong specs: over this share of the judged windows unknown to the
# sequence, when no one misread region explains them (right decodes: at most 0.092, 14 of
# 152 on objects-on-plane's 121 fringes; the wrong specs it refuses: 0.16 to 1.0) ...
UNKNOWN = 0.15
# ... this many windows or more past the spec's last fringe (right decodes: none; a period
# x1.5 seen through 19 windows: 3; one past, mask-prism's period x1.5, is let through) ...
PAST = 2
# ... over this share contradicted by their neighbours, and over window + 2 of them (right
# decodes: at most 0.104, 14 of 135; a window one short: 0.72, 18 of 25)
CONTRADICTED = 0.3
# the code phases fit another count of levels better than the spec's: a misfit on the
# spec's levels over MISFIT_RATIO times the best other count's and over MISFIT_FLOOR (right
# decodes: at most 0.95 times, objects-on-plane's 16-px fringes under hard optics; codes of
# 4 levels read as 5: 2.6 to 9.1 times, those of 5 as 6 under hard optics at 16 px: 1.05, left
# to the windows)
MISFIT_RATIO = 1.5
MISFIT_FLOOR = 0.15


@lru_cache(maxsize=64)
def code_sequence(length: int, levels: int, window: int) -> tuple[int, ...]:
    """A code sequence whose neighbours differ and whose ``window``-long windows are unique.

    Depth-first search that tries the next level up first, which spreads the levels evenly.
    Raises :class:`BistairError` when no such sequence exists.

    Parameters
    ----------
    length : int
        Codes in the sequence (the fringes across the coded axis).
    levels : int
        Stair levels a code may take (codes ``0 .. levels - 1``).
    window : int
        Adjacent codes whose combination must be unique.

    Returns
    -------
    tuple of int
        The codes, one per fringe (cached: the same tuple for the same arguments).

    Raises
    ------
    BistairError
        The search finds no such sequence, or ``length`` is over 900.

    Examples
    --------
    >>> code_sequence(8, levels=3, window=3)
    (0, 1, 2, 0, 1, 0, 2, 0)
    >>> code_sequence(20, levels=2, window=3)
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: no sequence of 20 codes over 2 levels has unique 3-code windows
    """
    seq: list[int] = []
    seen: set[tuple[int, ...]] = set()

    def extend() -> bool:
        if len(seq) == length:
            return True
        last = seq[-1] if seq else -1
        for i in range(levels):
            c = (last + 1 + i) % levels
            if c == last:
                continue
            key = (*seq[len(seq) - window + 1:], c) if len(seq) >= window - 1 else None
            if key in seen:
                continue
            seq.append(c)
            if key:
                seen.add(key)
            if extend():
                return True
            seq.pop()
            seen.discard(key)
        return False

    if length > 900 or not extend():
        raise BistairError(
            f"no sequence of {length} codes over {levels} levels has unique {window}-code windows"
        )
    return tuple(seq)


@dataclasses.dataclass(frozen=True, kw_only=True)
class LvSpec(PeriodSpec):
    method = "lv"

    levels: int = field(4, "stair levels of the code")
    window: int = field(4, "adjacent fringes whose codes fix an order")

    @property
    def sequence(self) -> tuple[int, ...]:
        return code_sequence(self.fringes, self.levels, self.window)

    def method_frames(self) -> tuple[str, ...]:
        return (*self.shift_frames(), "code-cos", "code-sin")

    def validate(self) -> None:
        super().validate()
        if not 2 <= self.levels <= 32:
            raise BistairError(f"levels must lie in 2..32 (more leave too little phase per "
                               f"level), got {self.levels}")
        if self.fringes < 2:
            raise BistairError(f"a {format_period(self.period)}-px period leaves fewer than 2 "
                               f"fringes across the {self.coded_length}-px coded axis")
        if not 2 <= self.window <= self.fringes:
            raise BistairError(f"window must lie in 2..{self.fringes} (the fringes across the "
                               f"coded axis), got {self.window}")
        if self.fringes > self.levels * (self.levels - 1) ** (self.window - 1) + self.window - 1:
            raise BistairError(
                f"{self.fringes} fringes need more than {self.levels} levels for unique "
                f"{self.window}-code windows"
            )
        self.sequence  # noqa: B018 - raises if the search finds none


def encode_columns(spec: LvSpec) -> np.ndarray:
    """The patterns of an Lv spec in the column layout, in method-frame order.

    The N-step set, then the coded pair ``offset + amplitude * cos / sin(code)`` whose code
    phase on fringe ``k`` is the stair level ``spec.sequence[k]`` of ``levels``.

    Parameters
    ----------
    spec : LvSpec
        The spec of one coded axis.

    Returns
    -------
    numpy.ndarray
        (frames, other_length, coded_length) float32 intensities (fractions of full scale),
        a read-only view whose rows are all the same.

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> from bistair.core.stair import quantize
    >>> spec = make_spec("lv", width=480, height=32, period=20)
    >>> pats = encode_columns(spec)
    >>> pats.shape
    (6, 32, 480)
    >>> code = np.arctan2(pats[5, 0] - 0.5, pats[4, 0] - 0.5)  # the code phase, radians
    >>> quantize(code[10::20], spec.levels).tolist() == list(spec.sequence)
    True
    """
    shifts = shift_patterns(spec)
    codes = np.asarray(spec.sequence)[fringe_index(spec)]
    pair = stair_pair(stair_level_phase(codes, spec.levels), spec.offset, spec.amplitude)
    return along_columns(np.concatenate([shifts, pair]), spec)


def _successors(links: RegionLinks, n_regions: int) -> np.ndarray:
    """Each region's strongest neighbour one order up (-1 where none)."""
    src = np.concatenate([links.src, links.dst])
    dst = np.concatenate([links.dst, links.src])
    step = np.concatenate([links.step, -links.step])
    count = np.concatenate([links.count, links.count])
    up = step == 1
    succ = np.full(n_regions + 1, -1, np.int64)
    order = np.argsort(count[up], kind="stable")  # strongest written last
    succ[src[up][order]] = dst[up][order]
    return succ


def window_evidence(region_code: np.ndarray, confidence: np.ndarray, succ: np.ndarray,
                    spec: LvSpec, info: dict | None = None, sure: float = SURE_CODE,
                    judged_out: list | None = None) -> np.ndarray:
    """Votes of every chain of ``window`` adjacent regions for its members' orders.

    Each region starts a window (itself and the next ``window - 1`` regions up); the window's
    codes are looked up in the sequence. Overlapping windows check each other: a window
    whose neighbour (starting one region before or after) was found elsewhere than one place
    before or after it is contradicted and does not vote; one with neighbours must be
    confirmed by one of them. A region's evidence is the share of its windows voting for
    each order, weighted by the least sure code in the window. ``info`` receives how many
    complete windows were read surely (``code_windows``: every member's code at least
    ``sure``), how many of them the sequence does not hold (``unknown_windows``; the spec
    check of :func:`order_columns` judges these two, less the windows across an edge of two
    surfaces, :func:`edge_windows`) and how many windows ran through a
    region whose code is split (``unsure_windows``: two surfaces in one region at an
    occlusion edge, or a region a few pixels wide; they still vote, by their weight, but
    their codes say nothing about the spec).

    Parameters
    ----------
    region_code : numpy.ndarray
        (n_regions + 1,) int, each fringe region's code level (-1 where unknown; entry 0,
        the background, is never read).
    confidence : numpy.ndarray
        (n_regions + 1,) float, how sure each region's code is (share of its weight, 0..1).
    succ : numpy.ndarray
        (n_regions + 1,) int, each region's neighbour one order up (-1 where none).
    spec : LvSpec
        The spec: ``sequence``, ``levels``, ``window`` and ``fringes`` are used.
    info : dict, optional
        Receives ``code_windows``, ``unknown_windows`` and ``unsure_windows``.
    sure : float, default SURE_CODE
        The least share of its weight a region's code needs for the windows through it to
        be judged against the sequence.
    judged_out : list, optional
        Receives (in place of its contents) the judged windows: their (j, window) int64
        regions in chain order, their (j,) places in the sequence (-1 where it does not
        hold them) and (j,) bool, which of those found are contradicted by a neighbour
        (:func:`window_problem` judges these).

    Returns
    -------
    numpy.ndarray
        (n_regions + 1, fringes) float64 evidence for every fringe order per region, in
        [0, 1].

    Examples
    --------
    Sixteen regions left to right, each reading its fringe's code:

    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("lv", width=480, height=64, period=30)
    >>> region_code = np.r_[-1, spec.sequence]
    >>> succ = np.r_[-1, np.arange(2, 17), -1]
    >>> info = {}
    >>> ev = window_evidence(region_code, np.ones(17), succ, spec, info)
    >>> ev.shape, ev[1:].argmax(axis=1).tolist() == list(range(16)), info
    ((17, 16), True, {'code_windows': 13, 'unknown_windows': 0, 'unsure_windows': 0})
    >>> region_code[5] = 3  # a misread: the windows through region 5 are not in the sequence
    >>> ev = window_evidence(region_code, np.ones(17), succ, spec, info)
    >>> ev[1:10].max(axis=1).round(2).tolist(), info["unknown_windows"]
    ([1.0, 0.5, 0.33, 0.25, 0.0, 0.25, 0.5, 0.75, 1.0], 4)
    """
    n_reg = region_code.size - 1
    table = np.full(spec.levels ** spec.window, -1, np.int64)
    seq = np.asarray(spec.sequence)
    for i in range(spec.fringes - spec.window + 1):
        table[_window_key(seq[i:i + spec.window][None], spec.levels)[0]] = i
    members = [np.arange(n_reg + 1)]
    for _ in range(spec.window - 1):
        prev = members[-1]
        members.append(np.where(prev >= 0, succ[np.maximum(prev, 0)], -1))
    chain = np.stack(members, axis=1)
    safe = np.maximum(chain, 0)
    distinct = np.array([np.unique(row).size == spec.window for row in chain])
    ok = (chain >= 0).all(axis=1) & (region_code[safe] >= 0).all(axis=1) & distinct
    ok[0] = False
    start = np.where(ok, table[_window_key(region_code[safe], spec.levels)], -1)
    pred = np.full(n_reg + 1, -1, np.int64)
    has_succ = succ >= 0
    pred[succ[has_succ]] = np.flatnonzero(has_succ)
    after = np.where(succ >= 0, start[np.maximum(succ, 0)], -1)
    before = np.where(pred >= 0, start[np.maximum(pred, 0)], -1)
    contradicted = ((after >= 0) & (after != start + 1)) | ((before >= 0) & (before != start - 1))
    if info is not None:
        judged = ok & (confidence[safe].min(axis=1) >= sure)
        info.update(code_windows=int(judged.sum()),
                    unknown_windows=int((judged & (start < 0)).sum()),
                    unsure_windows=int((ok & ~judged).sum()))
        if judged_out is not None:
            judged_out[:] = [chain[judged], start[judged],
                             (contradicted & (start >= 0))[judged]]
    ok &= start >= 0
    confirmed = (after == start + 1) | (before == start - 1)
    neighbours = (after >= 0) | (before >= 0)
    vote = ok & ~contradicted & (confirmed | ~neighbours)
    seen = np.zeros(n_reg + 1)
    np.add.at(seen, chain[ok | (start < 0) & (chain >= 0).all(axis=1)].ravel(), 1.0)
    votes = np.zeros((n_reg + 1, spec.fringes))
    rows = np.flatnonzero(vote)
    weight = confidence[chain[rows]].min(axis=1)
    for j in range(spec.window):
        np.add.at(votes, (chain[rows, j], start[rows] + j), weight)
    return votes / np.maximum(seen, 1.0)[:, None]


def edge_windows(chains: np.ndarray, region_order: np.ndarray) -> np.ndarray:
    """Which windows run across an edge of two surfaces, as the decoded orders show.

    A window chains each region to its strongest neighbour across a wrap, taken as one
    order up; where a wrap joins two surfaces (one in front of the other) the chain hops to
    a fringe of other order and the window's codes are not in the sequence, rightly. Such
    a window has two neighbours in its chain whose decoded orders (both decided) do not
    step by one.

    Parameters
    ----------
    chains : numpy.ndarray
        (u, window) int, the regions of each window in chain order (``unknown`` of
        :func:`window_evidence`).
    region_order : numpy.ndarray
        (n_regions + 1,) int, each region's decoded order (-1 where undecided).

    Returns
    -------
    numpy.ndarray
        (u,) bool, the windows across such an edge.

    Examples
    --------
    >>> order = np.array([-1, 24, 25, 26, 23, 24, -1])
    >>> edge_windows(np.array([[1, 2, 3, 4], [3, 4, 5, 6], [4, 5, 6, 1]]), order).tolist()
    [True, True, False]
    """
    k = region_order[chains]
    both = (k[:, :-1] >= 0) & (k[:, 1:] >= 0)
    return (both & (np.diff(k, axis=1) != 1)).any(axis=1)


def past_windows(chains: np.ndarray, region_order: np.ndarray, spec: LvSpec) -> np.ndarray:
    """Which windows run past the spec's last fringe (or before its first), as the decoded
    orders of their members place them.

    A member of decided order ``k`` at place ``j`` of its chain puts the window's start at
    ``k - j``; a start below 0 or above ``fringes - window`` names fringes the projector
    does not have. With the right spec no lit region lies beyond the last fringe, so such
    a window (its codes all read surely) says the spec has too few fringes: a period too
    long, a projector too narrow.

    Parameters
    ----------
    chains : numpy.ndarray
        (j, window) int, the regions of each window in chain order.
    region_order : numpy.ndarray
        (n_regions + 1,) int, each region's decoded order (-1 where undecided).
    spec : LvSpec
        ``fringes`` and ``window`` are used.

    Returns
    -------
    numpy.ndarray
        (j,) bool.

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("lv", width=480, height=64, period=30)  # 16 fringes
    >>> order = np.array([-1, 11, 12, 13, 14, 15, -1, -1])
    >>> past_windows(np.array([[1, 2, 3, 4], [2, 3, 4, 5], [3, 4, 5, 6]]), order,
    ...              spec).tolist()
    [False, False, True]
    """
    k = region_order[chains]
    start = np.where(k >= 0, k - np.arange(chains.shape[1]), 0)
    return ((start < 0) | (start > spec.fringes - spec.window)).any(axis=1)


def misread_regions(chains: np.ndarray) -> int:
    """How many regions, misread, it takes to make these windows unknown: 0 for none, 1
    when one region lies in all of them, else (a greedy cover, the region in most windows
    first) 2 or more.

    Parameters
    ----------
    chains : numpy.ndarray
        (u, window) int, the regions of each unknown window.

    Returns
    -------
    int

    Examples
    --------
    >>> misread_regions(np.array([[1, 2, 3, 4], [2, 3, 4, 5], [4, 5, 6, 7]]))
    1
    >>> misread_regions(np.array([[1, 2, 3, 4], [5, 6, 7, 8]]))
    2
    """
    left, count = np.asarray(chains), 0
    while len(left):
        ids, seen = np.unique(left, return_counts=True)
        left = left[~(left == ids[seen.argmax()]).any(axis=1)]
        count += 1
    return count


def window_problem(info: dict, spec: LvSpec) -> str | None:
    """The reason to refuse the captures from their code windows, or ``None``.

    Judged over the windows whose codes were all read surely, less those across an edge of
    two surfaces (``info`` of :func:`order_columns`): more unknown to the sequence than
    :data:`UNKNOWN` of them, when no one region lies in all of them (``unknown_regions``:
    how many misread regions it takes to make them unknown, :func:`misread_regions`; one
    misread code makes up to ``window`` windows unknown: a handful of windows can refuse,
    one misread region cannot);
    more contradicted by their neighbour than :data:`CONTRADICTED` of them and than
    ``window + 2`` (found in the sequence, but not next to where the next window along the
    chain was found: a spec whose sequence holds nearly every window, e.g. a window too
    short; one misread code can contradict the windows through it and their two
    neighbours); :data:`PAST` or more running past the spec's last fringe
    (:func:`past_windows`, none with the right spec); or, of at least 20 windows read,
    over :data:`UNSURE` through a region that reads no one code (checked first).

    Parameters
    ----------
    info : dict
        ``code_windows``, ``unknown_windows``, ``unknown_regions`` (missing: the fewest
        regions that can make that many windows unknown), ``unsure_windows``,
        ``past_windows``, ``contradicted_windows`` (missing: 0).
    spec : LvSpec
        ``window`` is used.

    Returns
    -------
    str or None

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("lv", width=1080, height=64, period=30)
    >>> window_problem({"code_windows": 13, "unknown_windows": 4, "unknown_regions": 1},
    ...                spec) is None  # one misread region
    True
    >>> window_problem({"code_windows": 13, "unknown_windows": 4, "unknown_regions": 2},
    ...                spec)[:40]
    '31% of the 13 code windows read are not '
    """
    windows, unknown = info.get("code_windows", 0), info.get("unknown_windows", 0)
    unsure = info.get("unsure_windows", 0)
    read = windows + unsure
    fit = "does the spec fit (period, projector size, levels, window)?"
    if read >= 20 and unsure > UNSURE * read:  # no window judged is no evidence of a fit
        return (f"{100 * unsure / read:.0f}% of the {read} code windows read pass through a "
                "fringe region that reads no one code: does the spec fit (method, period, "
                "projector size, levels, window)?")
    misread = info.get("unknown_regions", -(-unknown // spec.window))
    if unknown > UNKNOWN * windows and misread >= 2:
        return (f"{100 * unknown / windows:.0f}% of the {windows} code windows read are not "
                f"in the spec's code sequence: {fit}")
    contradicted = info.get("contradicted_windows", 0)
    if contradicted > max(CONTRADICTED * windows, spec.window + 2):
        return (f"{100 * contradicted / windows:.0f}% of the {windows} code windows read are "
                f"found in the spec's code sequence apart from their neighbours': {fit}")
    past = info.get("past_windows", 0)
    if past >= PAST:
        return (f"{past} of the {windows} code windows read run past the spec's "
                f"{spec.fringes} fringes: is the period (or the projector size) right?")
    return None


def levels_fit(theta: np.ndarray, fs: FringeSet, levels: int) -> tuple[float, float, int]:
    """How well the code phases sit on ``levels`` stair levels, and on the best other count.

    The misfit (:func:`bistair.core.checks.stair_misfit`, pass 0's sample: 0 on the levels,
    1 halfway between two) on ``levels`` and on every other count of 2 to 32 levels. With
    the right levels every other count fits worse (its grid either misses the codes or is
    finer, so the same noise is a larger share of its step: 3 levels per level on a grid
    three times as fine holds the same phases, three times the misfit).

    Parameters
    ----------
    theta : numpy.ndarray
        (H, W) code phase, radians (``code_phase`` of :func:`code_columns`).
    fs : FringeSet
        Stage 1: its sample and valid pixels.
    levels : int
        The spec's levels.

    Returns
    -------
    (misfit, other, other_levels) : tuple of float, float, int
        The misfit on ``levels``, the least misfit of another count and that count.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("lv", width=480, height=32, period=20)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> theta = code_columns(cols, spec, fs).maps["code_phase"]
    >>> misfit, other, count = levels_fit(theta, fs, 5)  # 4-level codes read as 5
    >>> round(misfit, 2), round(other, 2), count
    (0.5, 0.0, 4)
    """
    t, ok = stair_sample(fs.sample, theta, fs.valid)

    def misfit(count: int) -> float:
        return stair_misfit(t, ok, stair_level_phase(np.arange(count), count))

    others = {count: misfit(count) for count in range(2, 33) if count != levels}
    best = min(others, key=others.__getitem__)
    return misfit(levels), others[best], best


def _window_key(codes: np.ndarray, levels: int) -> np.ndarray:
    """One integer per row of window codes."""
    return (codes * levels ** np.arange(codes.shape[1] - 1, -1, -1)).sum(axis=1)


def code_columns(prepared: Prepared, spec: LvSpec, fs: FringeSet,
                 min_modulation: float | None = None) -> CodeMap:
    """Stage 2: each valid pixel's code level from the coded pair.

    Parameters
    ----------
    prepared : Prepared
        The method's frames in method order, column layout (coded axis along the image
        rows), as fractions of full scale.
    spec : LvSpec
        The spec of one coded axis.
    fs : FringeSet
        Stage 1: the valid pixels and the average the pair is read against.
    min_modulation : float, optional
        Not used (the code shares the fringes' validity).

    Returns
    -------
    CodeMap
        ``code``: (H, W) int32 code level, -1 where not valid; ``maps["code_phase"]``:
        (H, W) float32 code phase in [-pi, pi) radians; ``cycle``: ``levels``.

    Raises
    ------
    BistairError
        The code phases sit halfway between the levels (``code-cos`` and ``code-sin``
        swapped, or another number of levels than the patterns').

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("lv", width=480, height=32, period=20)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> code.code[0, 10::20].tolist() == list(spec.sequence), code.cycle
    (True, 4)
    >>> eight = spec.replace(levels=8)  # 4-level codes read as 8 levels
    >>> code_columns(cols, eight, fs)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the captures do not fit the spec: the code phases sit ...
    """
    theta, _, codes = read_stairs(prepared, spec.steps, spec.levels, fs.avg, fs.valid,
                                  fs.stair)
    if stair_misfit(*stair_sample(fs.sample, theta, fs.valid),
                    stair_level_phase(np.arange(spec.levels), spec.levels)) > 0.7:
        refuse("the code phases sit halfway between the code's levels: are code-cos and "
               "code-sin swapped (or levels wrong)?")
    return CodeMap(codes, {"code_phase": theta}, cycle=spec.levels)


def order_columns(fs: FringeSet, code: CodeMap, spec: LvSpec) -> Orders:
    """Stage 3: windows of adjacent fringe regions looked up in the code sequence.

    Each fringe region takes the code most of its pixels read; the windows of adjacent
    regions vote for orders (:func:`window_evidence`), checked across every wrap
    (:func:`bistair.core.resolve.orders_from_regions`).

    Parameters
    ----------
    fs : FringeSet
        Stage 1, column layout.
    code : CodeMap
        Stage 2 (:func:`code_columns`).
    spec : LvSpec
        The spec of one coded axis.

    Returns
    -------
    Orders
        (H, W) fringe order per pixel (-1 where invalid) and ``info``: the camera noise,
        the fringes, the code windows the spec check judges (``code_windows``) and the
        unknown among them (``unknown_windows``), the windows it leaves out (through a
        region whose code is split, ``unsure_windows``; across an edge of two surfaces,
        ``edge_windows``: see :func:`window_evidence`, :func:`edge_windows`), those
        contradicted by their neighbours and those past the spec's fringes
        (``contradicted_windows``, ``past_windows``), the code phases' misfit on the
        spec's levels and on the best other count (``code_misfit``, ``other_misfit``,
        ``other_levels``: :func:`levels_fit`), the region counts and the phase jumps
        across which the orders do not step by one.

    Raises
    ------
    BistairError
        The code windows say the spec does not fit (:func:`window_problem`: too many
        unknown to the sequence, past its last fringe, contradicted by their neighbours,
        or through regions of no one code), or the code phases fit another count of levels
        clearly better than the spec's (:func:`levels_fit`: a misfit over
        :data:`MISFIT_RATIO` times the other count's and over :data:`MISFIT_FLOOR`).

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("lv", width=480, height=32, period=20)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> orders = order_columns(fs, code_columns(cols, spec, fs), spec)
    >>> orders.order[0, ::20].tolist() == list(range(24)), orders.info["unknown_windows"]
    (True, 0)
    >>> five = spec.replace(levels=5)  # not the patterns' code
    >>> order_columns(fs, code_columns(cols, five, fs), five)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the captures do not fit the spec: 81% of the 21 code windows ...
    """
    codes = code.code
    labels, _ = fringe_regions(fs.phi, fs.valid, phase_noise=fs.phase_noise, links=fs.links)
    weight = core_weight(fs.phi)

    judged: list = []  # the judged windows of the last labelling, and its labels

    def evidence_of(labels: np.ndarray, n: int) -> tuple[np.ndarray, int, np.ndarray]:
        shares = code_evidence(labels, n, codes, spec.levels, weight)
        region_code = np.where(shares.max(axis=1) > 0, shares.argmax(axis=1), -1)
        region_code[0] = -1
        succ = _successors(region_links(fs.phi, labels), n)
        evidence = window_evidence(region_code, shares.max(axis=1), succ, spec, info,
                                   judged_out=judged)
        judged.append(labels)
        return labels, n, evidence

    sequence = np.asarray(spec.sequence, np.int32)

    def agrees(k: np.ndarray) -> np.ndarray:
        ok = np.empty(k.shape, bool)
        bands = row_bands(k.shape[0])
        for y0 in bands:  # a band at a time: the lookup's indices are 8 bytes a pixel
            rows = slice(y0, y0 + bands.step)
            np.equal(codes[rows], np.take(sequence, k[rows], mode="clip"), out=ok[rows])
        ok |= codes < 0  # (undecided orders, -1, are not judged)
        return ok

    info: dict = {"noise": fs.noise, "fringes": spec.fringes}
    order = orders_from_regions(fs.phi, fs.valid, labels, evidence_of, agrees, info)
    edges = 0  # windows across an edge of two surfaces are not judged
    if judged and len(judged[0]):
        chains, starts, contra, last = judged
        region_order = np.full(int(last.max()) + 1, -1, np.int64)
        region_order[last.ravel()] = order.ravel()  # every pixel of a region has its order
        region_order[0] = -1
        across = edge_windows(chains, region_order)
        edges = int((across & (starts < 0)).sum())
        info.update(unknown_regions=misread_regions(chains[(starts < 0) & ~across]),
                    contradicted_windows=int((contra & ~across).sum()),
                    past_windows=int((past_windows(chains, region_order, spec)
                                      & ~across).sum()))
    info.update(code_windows=info.get("code_windows", 0) - edges,
                unknown_windows=info.get("unknown_windows", 0) - edges, edge_windows=edges)
    misfit, other, other_levels = levels_fit(code.maps["code_phase"], fs, spec.levels)
    info.update(code_misfit=misfit, other_levels=other_levels, other_misfit=other)
    refuse(window_problem(info, spec))
    if misfit > MISFIT_RATIO * other and misfit > MISFIT_FLOOR:
        refuse(f"the code phases sit {misfit:.2f} of half a level step off the spec's "
               f"{spec.levels} levels, {other:.2f} off {other_levels}: are the levels "
               "(or the projector size) right?")
    return Orders(order, info)


def levels_for(fringes: int, window: int = 4) -> int:
    """The fewest stair levels (at least the paper's 4) whose windows can tell the fringes.

    Parameters
    ----------
    fringes : int
        Fringes across the coded axis.
    window : int, default 4
        Adjacent codes that fix an order.

    Returns
    -------
    int
        The levels: ``levels * (levels - 1) ** (window - 1) + window - 1 >= fringes``.

    Examples
    --------
    >>> levels_for(36), levels_for(200)
    (4, 5)
    """
    levels = 4
    while levels * (levels - 1) ** (window - 1) + window - 1 < fringes:
        levels += 1
    return levels


def comparable(width: int, height: int, period: int, steps: int) -> dict:
    """The same period with the fewest levels that tell its fringes apart.

    Parameters
    ----------
    width : int
        Projector width in pixels (the coded axis).
    height : int
        Projector height in pixels (not used).
    period : int
        Fringe period in projector pixels.
    steps : int
        Phase-shift steps N.

    Returns
    -------
    dict
        Spec parameters for :func:`~bistair.codecs.make_spec` (besides the size).

    Examples
    --------
    >>> comparable(1080, 1080, 30, 4), comparable(1920, 1080, 8, 4)["levels"]
    ({'period': 30, 'steps': 4, 'levels': 4}, 5)
    """
    return dict(period=period, steps=steps, levels=levels_for(-(-width // period)))


CODEC = Codec(
    name="lv",
    spec_class=LvSpec,
    summary="N phase shifts + a few-level code read over four adjacent fringes (after Lv 2019)",
    encode_columns=encode_columns,
    code_columns=code_columns,
    order_columns=order_columns,
    comparable=comparable,
)
