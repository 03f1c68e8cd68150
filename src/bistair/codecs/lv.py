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
from ..core.stair import stair_level_phase, stair_pair
from ..core.stair_jit import pair_phase, quantize32
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
                    unknown: list | None = None) -> np.ndarray:
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
    unknown : list, optional
        Receives (in place of its contents) the (u, window) int64 regions of the ``u``
        judged windows the sequence does not hold, in chain order.

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
    if info is not None:
        judged = ok & (confidence[safe].min(axis=1) >= sure)
        info.update(code_windows=int(judged.sum()),
                    unknown_windows=int((judged & (start < 0)).sum()),
                    unsure_windows=int((ok & ~judged).sum()))
        if unknown is not None:
            unknown[:] = [chain[judged & (start < 0)]]
    ok &= start >= 0
    pred = np.full(n_reg + 1, -1, np.int64)
    has_succ = succ >= 0
    pred[succ[has_succ]] = np.flatnonzero(has_succ)
    after = np.where(succ >= 0, start[np.maximum(succ, 0)], -1)
    before = np.where(pred >= 0, start[np.maximum(pred, 0)], -1)
    contradicted = ((after >= 0) & (after != start + 1)) | ((before >= 0) & (before != start - 1))
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
    theta = (fs.stair if fs.stair is not None else
             pair_phase(prepared.raw, spec.steps, prepared.scale, fs.avg))[0]
    codes = quantize32(theta, spec.levels, fs.valid)
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
        ``edge_windows``: see :func:`window_evidence`, :func:`edge_windows`), the region
        counts and the phase jumps across which the orders do not step by one.

    Raises
    ------
    BistairError
        Of 20 or more code windows judged, over 15% are not in the spec's sequence, or of
        20 or more read, over half pass through a region that reads no one code
        (:data:`UNSURE`): the spec does not fit the captures.

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
    labels, _ = fringe_regions(fs.phi, fs.valid, phase_noise=fs.phase_noise)
    weight = core_weight(fs.phi)

    unknown: list = []  # the last labels and the chains of their unknown windows

    def evidence_of(labels: np.ndarray, n: int) -> tuple[np.ndarray, int, np.ndarray]:
        shares = code_evidence(labels, n, codes, spec.levels, weight)
        region_code = np.where(shares.max(axis=1) > 0, shares.argmax(axis=1), -1)
        region_code[0] = -1
        succ = _successors(region_links(fs.phi, labels), n)
        evidence = window_evidence(region_code, shares.max(axis=1), succ, spec, info,
                                   unknown=unknown)
        unknown.append(labels)
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
    if unknown and len(unknown[0]):
        chains, last = unknown
        region_order = np.full(int(last.max()) + 1, -1, np.int64)
        region_order[last.ravel()] = order.ravel()  # every pixel of a region has its order
        region_order[0] = -1
        edges = int(edge_windows(chains, region_order).sum())
    info.update(code_windows=info.get("code_windows", 0) - edges,
                unknown_windows=info.get("unknown_windows", 0) - edges, edge_windows=edges)
    windows, unknown_count = info.get("code_windows", 0), info.get("unknown_windows", 0)
    read = windows + info.get("unsure_windows", 0)
    if read >= 20 and info.get("unsure_windows", 0) > UNSURE * read:
        refuse(  # no window judged is no evidence that the spec fits
            f"{100 * info['unsure_windows'] / read:.0f}% of the {read} code windows read "
            "pass through a fringe region that reads no one code: does the spec fit "
            "(method, period, projector size, levels, window)?")
    if windows >= 20 and unknown_count > 0.15 * windows:
        refuse(
            f"{100 * unknown_count / windows:.0f}% of the "
            f"{windows} code windows read are not in the spec's code sequence: does the spec "
            "fit (period, projector size, levels, window)?")
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
