"""Bidirectional stair-phase coding (Qi, Zhou et al.): N phase shifts plus one coded pair.

Frames: ``shift-0 .. shift-(N-1)`` (Eq. 1-4) and ``stair-cos``, ``stair-sin`` (Eq. 15-16).
Along x the pair carries two stairs: a local stair of ``S`` levels that steps every fringe
(``k mod S``, Eq. 13) and a partition stair of ``P`` levels that steps every ``S`` fringes
(``k // S``, Eq. 14). Down the pattern the two alternate in groups of ``group_rows`` rows,
the first ``local_rows`` carrying the local stair and the rest the partition stair, so every
small region of the image holds both and ``k = k_s1 + S * k_s2`` (Eq. 22).

Decoding strategies:

``"region"`` (default)
    Fringe regions (2-D areas between wrapped-phase jumps, :mod:`bistair.core.regions`)
    each hold one order. The stair phase is averaged along each row of a region, the bands
    of the resulting profile are told apart by their lengths (:mod:`.bands`), and every
    region gets one order, checked against its neighbours across each wrap, where orders
    must step by exactly one (:func:`bistair.core.resolve.resolve_regions`).
``"paper"``
    The paper's decoder (:mod:`.paper`): ``k_s`` by Eq. 19-20, a column scan of run lengths
    ``C`` whose increases mark group starts, ``k = k_s1 + S*k_s2`` per group (``k_s1 *
    (S+1)`` where the runs merge), then each fringe (a 2-D stripe between two phase jumps)
    takes the mode.

Examples
--------
>>> import numpy as np
>>> from bistair import decode, encode, make_spec
>>> spec = make_spec("bidirectional", width=360, height=120, period=20, partitions=3,
...                  stairs=6)
>>> pats = encode(spec)
>>> pats.shape
(6, 120, 360)
>>> res = decode(pats, spec)
>>> x = np.arange(360)
>>> bool(np.allclose(res.coord[60], x, atol=1e-3)), res.order[60, ::60].tolist()
(True, [0, 3, 6, 9, 12, 15])
"""

from __future__ import annotations

import dataclasses
import math
from typing import Literal

import numpy as np

from ...core.captures import Prepared
from ...core.checks import refuse, stair_misfit, stair_sample, wrap_steps
from ...core.measure import FringeSet
from ...core.regions import (
    core_weight,
    fringe_direction,
    fringe_regions,
    kept_regions,
    label_fringes,
)
from ...core.resolve import orders_from_regions
from ...core.stair import (
    fit_level_response,
    level_readings,
    read_stairs,
    stair_level_phase,
    stair_pair,
)
from ...errors import BistairError
from ...spec import PeriodSpec, field, format_period
from ..base import Codec, CodeMap, Orders, fringe_index, shift_patterns
from .bands import row_runs, union_levels
from .evidence import (
    BandLayout,
    band_splits,
    edge_rows,
    group_heights,
    region_evidence,
    split_profiles,
    split_regions,
)
from .paper import paper_orders
from .profiles import (
    RowProfiles,
    profile_centroids,
    relabel_stair_profiles,
    row_profiles,
    stair_row_profiles,
    stair_values,
)
from .response import (
    LEVEL_DOUBT,
    UNREADABLE,
    doubtful_regions,
    level_offsets,
    linear_stair,
)
from .stairs import stair_agreement, stair_edges, stair_fit, stair_noise


@dataclasses.dataclass(frozen=True, kw_only=True)
class BidirectionalSpec(PeriodSpec):
    method = "bidirectional"

    partitions: int = field(6, "partition stair levels P")
    stairs: int = field(6, "local stair levels S (fringes per partition)")
    group_rows: int = field(30, "projector rows per group (local + partition rows)")
    local_rows: int = field(20, "rows of each group that carry the local stair")

    def method_frames(self) -> tuple[str, ...]:
        return (*self.shift_frames(), "stair-cos", "stair-sin")

    def validate(self) -> None:
        """Each int field's own range first, then how the fields fit together."""
        super().validate()
        if self.stairs < 2:
            raise BistairError(f"stairs must be at least 2, got {self.stairs}")
        if self.partitions < 2:
            raise BistairError(
                f"partitions must be at least 2 (use phase-coding for one stair), got "
                f"{self.partitions}"
            )
        for name in ("stairs", "partitions"):
            if getattr(self, name) > 32:
                raise BistairError(f"{name} must be at most 32 (more levels leave too little "
                                   f"phase per level), got {getattr(self, name)}")
        if not 3 <= self.group_rows <= self.other_length:
            raise BistairError(
                f"group rows must lie in 3..{self.other_length} (the projector's "
                f"{'width' if self.orientation == 'rows' else 'height'}), got {self.group_rows}"
            )
        if not 1 <= self.local_rows < self.group_rows:
            raise BistairError(
                f"local rows must lie in 1..{self.group_rows - 1} (fewer than the "
                f"{self.group_rows} group rows), got {self.local_rows}"
            )
        if 2 * self.local_rows == self.group_rows:
            raise BistairError(
                f"local rows ({self.local_rows}) equal partition rows "
                f"({self.group_rows - self.local_rows}): the bands could not be told apart"
            )
        span = self.partitions * self.stairs * self.period
        if span < self.coded_length:
            raise BistairError(
                f"partitions*stairs*period = {self.partitions}*{self.stairs}*"
                f"{format_period(self.period)} = {format_period(span)} px is narrower than the "
                f"{self.coded_length}-px coded axis"
            )


def encode_columns(spec: BidirectionalSpec) -> np.ndarray:
    """The N phase-shift patterns and the bidirectional pair, vertical fringes.

    On fringe ``k`` the pair ``offset + amplitude * cos / sin(theta)`` carries the local
    stair level ``k % stairs`` on the first ``local_rows`` of every ``group_rows`` pattern
    rows and the partition stair level ``k // stairs`` on the rest.

    Parameters
    ----------
    spec : BidirectionalSpec
        The spec of one coded axis.

    Returns
    -------
    numpy.ndarray
        (steps + 2, other_length, coded_length) float32 intensities (fractions of full
        scale), column layout: ``shift-0 .. shift-(N-1)``, ``stair-cos``, ``stair-sin``.

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> from bistair.core.stair import quantize
    >>> spec = make_spec("bidirectional", width=240, height=64, period=20, partitions=3,
    ...                  stairs=4, group_rows=16, local_rows=10)
    >>> pats = encode_columns(spec)
    >>> pats.shape, pats.dtype
    ((6, 64, 240), dtype('float32'))
    >>> theta = np.arctan2(pats[5] - 0.5, pats[4] - 0.5)  # the stair phase, radians
    >>> quantize(theta[0, 10::20], 4).tolist()  # a local row: k % S
    [0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3]
    >>> quantize(theta[12, 10::20], 3).tolist()  # a partition row: k // S
    [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2]
    """
    x = np.arange(spec.coded_length)
    y = np.arange(spec.other_length)
    k = fringe_index(spec)
    shifts = shift_patterns(spec)
    local = stair_level_phase(k % spec.stairs, spec.stairs)
    partition = stair_level_phase(k // spec.stairs, spec.partitions)
    is_local = (y % spec.group_rows) < spec.local_rows
    theta = np.where(is_local[:, None], local[None, :], partition[None, :])
    pair = stair_pair(theta, spec.offset, spec.amplitude)
    rows = np.broadcast_to(shifts[:, None, :], (spec.steps, y.size, x.size))
    return np.concatenate([rows, pair]).astype(np.float32)


def code_columns(prepared: Prepared, spec: BidirectionalSpec, fs: FringeSet,
                 min_modulation: float | None = None) -> CodeMap:
    """Stage 2: the stair phase of the coded pair (Eq. 19), its modulation and ``k_s`` (Eq. 20)
    on the valid pixels.

    Parameters
    ----------
    prepared : Prepared
        The method's frames in method order, column layout (coded axis along the image
        rows), as fractions of full scale.
    spec : BidirectionalSpec
        The spec of one coded axis.
    fs : FringeSet
        Stage 1: the valid pixels and the average the pair is read against.
    min_modulation : float, optional
        Not used (the code shares the fringes' validity).

    Returns
    -------
    CodeMap
        ``code``: (H, W) int32 ``k_s``, the stair phase quantised to ``stairs`` levels (-1
        where not valid); ``maps``: ``stair_phase`` (float32 radians in [-pi, pi)) and
        ``stair_modulation`` (fraction of full scale); ``cycle``: ``stairs``.

    Raises
    ------
    BistairError
        The stair phases sit halfway between the code's levels (``stair-cos`` and
        ``stair-sin`` swapped, or other partitions and stairs than the patterns').

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("bidirectional", width=240, height=64, period=20, partitions=3,
    ...                  stairs=4, group_rows=16, local_rows=10)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> code.code[0, 10::20].tolist(), code.cycle, sorted(code.maps)
    ([0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3], 4, ['stair_modulation', 'stair_phase'])
    >>> other = spec.replace(stairs=5)
    >>> code_columns(cols, other, fs)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the captures do not fit the spec: the stair phases sit ...
    """
    theta, stair_mod, ks = read_stairs(prepared, spec.steps, spec.stairs, fs.avg, fs.valid,
                                       fs.stair)
    if _misfit(*stair_sample(fs.sample, theta, fs.valid), spec) > MISFIT:
        refuse("the stair phases sit halfway between the levels of the code: are stair-cos "
               "and stair-sin swapped (or partitions and stairs wrong)?")
    return CodeMap(ks, {"stair_phase": theta, "stair_modulation": stair_mod}, cycle=spec.stairs)


MISFIT = 0.7  # stair phases this far from the levels (1: halfway) do not fit the code


def _misfit(theta: np.ndarray, ok: np.ndarray, spec: BidirectionalSpec) -> float:
    """The stair misfit of a sample against the code's levels, or, where over
    :data:`MISFIT`, against where they read through the response exponent that fits the
    sample best (:func:`~bistair.core.stair.fit_level_response`): an uncompensated gamma
    moves 12 x 12 levels 0.70 of the way to halfway at 2.2 and 8 x 8 levels 0.79 at 2.8
    (0.01 from where they read), which the region decoder reads right."""
    levels = union_levels(spec.partitions, spec.stairs)
    misfit = stair_misfit(theta, ok, levels)
    if misfit <= MISFIT or not ok.any():
        return misfit
    exponent, _ = fit_level_response(theta[ok], levels, spec.offset, spec.amplitude)
    return min(misfit, stair_misfit(theta, ok, level_readings(levels, exponent, spec.offset,
                                                               spec.amplitude)))


def order_columns(fs: FringeSet, code: CodeMap, spec: BidirectionalSpec, *,
                  strategy: Literal["region", "paper"] = "region") -> Orders:
    """Stage 3: one fringe order per pixel by the ``region`` (default) or ``paper`` strategy.

    The region strategy reads the stair levels where this capture's response puts them
    (:func:`~.response.linear_stair`). The orders are then checked against the stair phase
    (:func:`stair_fit`).

    Parameters
    ----------
    fs : FringeSet
        Stage 1, column layout.
    code : CodeMap
        Stage 2 (:func:`code_columns`).
    spec : BidirectionalSpec
        The spec of one coded axis.
    strategy : {"region", "paper"}
        The band analysis per fringe region (:mod:`.bands`) or the paper's column scan
        (:func:`~bistair.codecs.bidirectional.paper.paper_orders`).

    Returns
    -------
    Orders
        (H, W) int32 fringe order per pixel (-1 where invalid) and ``info``: the strategy,
        the camera noise, the well-modulated pixels, the phase jumps across which the
        orders do not step by one, ``stair_misfit``, for the region strategy how far the
        band rows read from their levels (``level_offset``, ``worst_level_offset``), the
        levels too far to decide a region (``doubtful_levels``) and the response exponent
        the levels were read through (``stair_response``, :mod:`.response`), and any
        ``warnings``.

    Raises
    ------
    BistairError
        ``strategy`` is neither ``"region"`` nor ``"paper"``, over 10% of the decoded
        pixels' stair phases contradict their orders (the spec does not fit), or the band
        rows read as far from the levels as at random (``level_offset`` at least
        ``UNREADABLE``).

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("bidirectional", width=240, height=64, period=20, partitions=3,
    ...                  stairs=4, group_rows=16, local_rows=10)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> orders = order_columns(fs, code, spec)
    >>> orders.order[0, ::20].tolist(), orders.info["stair_misfit"]
    ([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11], 0.0)
    >>> order_columns(fs, code, spec, strategy="paper").order[0, ::20].tolist()
    [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]
    >>> order_columns(fs, code, spec, strategy="mode")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: unknown strategy 'mode' (use 'region' or 'paper')
    """
    if strategy not in ("region", "paper"):
        raise BistairError(f"unknown strategy {strategy!r} (use 'region' or 'paper')")
    theta, ks, stair_mod = code.maps["stair_phase"], code.code, code.maps["stair_modulation"]
    info = {"strategy": strategy, "noise": fs.noise, "valid_modulation": int(fs.valid.sum())}
    readings = None
    if strategy == "paper":
        order = paper_orders(ks, theta, fs, spec).astype(np.int32)
        # the published decoder as published: its orders are judged by the same limit as
        # the region decoder's (10% of the phase jumps), and reported, not corrected
        bad, big, links = wrap_steps(fs.phi, order, fs.valid)
        info.update(jump_violations=bad, jump_links=links, block_jumps=big)
        if links and bad > 0.005 * links:
            info["warnings"] = [f"the paper decoder's orders do not step by one across "
                                f"{100 * bad / links:.1f}% of the phase jumps"]
    else:  # read the levels where this capture's response puts them
        lin = linear_stair(fs, theta, stair_mod, ks, spec)
        if lin.readings is not None:
            info["stair_response"] = round(lin.exponent, 2)
        order = _region_orders(fs, lin.theta, stair_mod, lin.ks, spec, info)
        readings = lin.readings
    misfit = stair_fit(fs, theta, stair_mod, order, spec, readings=readings)
    info["stair_misfit"] = round(misfit, 4)
    band = info.get("group_height", spec.group_rows) * (1 - spec.local_rows / spec.group_rows)
    if band < MIN_BAND_PX:
        info["warnings"] = [*info.get("warnings", []), (
            f"the partition bands are {band:.1f} camera pixels tall: at this resolution blur "
            "mixes them with the local bands and some regions can read a wrong partition "
            "(more group_rows, a longer period or a closer camera give thicker bands)")]
    if "stair_response" in info:
        info["warnings"] = [*info.get("warnings", []), (
            f"the stair levels read where a projector response of exponent "
            f"{info['stair_response']:g} puts them and were read there: is the projector's "
            "gamma compensated (spec field gamma, 'bistair gamma')? It also ripples the "
            "fringes' phase")]
    if "doubtful_levels" in info:
        info["warnings"] = [*info.get("warnings", []), (
            f"{info['doubtful_levels']} of the {len(union_levels(spec.partitions, spec.stairs))} "
            f"stair levels read at least {100 * LEVEL_DOUBT:.0f}% of the way to halfway to the "
            "next (median of their band rows): the regions that read one take their orders "
            "from their neighbours or stay undecided")]
    if info.get("level_offset", 0.0) >= UNREADABLE:
        refuse(f"the band rows read {100 * info['level_offset']:.0f}% of the way to halfway "
               "between two stair levels (median; 50% at random): the levels cannot be told "
               f"apart (too much noise or blur for {spec.partitions} x {spec.stairs} levels, "
               "or a projector response the decoder cannot undo: compensate its gamma, spec "
               "field gamma, 'bistair gamma')")
    if misfit > 0.1:
        refuse(
            f"at {100 * misfit:.0f}% of the decoded pixels "
            "the stair phase is nearer a level other than the local or partition level of the "
            "decoded order: are partitions, stairs and period right, and stair-cos and "
            "stair-sin in the spec's order?")
    return Orders(order, info)


def _region_orders(fs: FringeSet, theta: np.ndarray, stair_mod: np.ndarray, ks: np.ndarray,
                  spec: BidirectionalSpec, info: dict) -> np.ndarray:
    # stair phase noise: the pair's two frames against the fringes' average
    noise_scale = fs.noise * np.sqrt(2.0)
    maps = (fs.phi, theta, stair_mod, fs.mod)
    compiled = np.ndim(noise_scale) == 0 and all(m.dtype == np.float32 for m in maps)
    gathered: list[tuple[np.ndarray, RowProfiles]] = []  # the labelling's own sums, once
    if compiled:
        def profiles(labels: np.ndarray) -> RowProfiles:  # values summed, never stored
            if gathered and gathered[0][0] is labels:
                return gathered.pop()[1]
            gathered.clear()
            return stair_row_profiles(labels, fs.phi, theta, stair_mod, fs.mod)

        def stair_noise_map() -> np.ndarray:
            return stair_noise(stair_mod, float(noise_scale))
    else:  # the same in NumPy
        ratio = np.clip(stair_mod / np.maximum(fs.mod, 1e-6), 0.0, 2.0)
        values = stair_values(theta, core_weight(fs.phi) * np.minimum(ratio, 1.0), ratio)

        def profiles(labels: np.ndarray) -> RowProfiles:
            return row_profiles(labels, values)

        def stair_noise_map() -> np.ndarray:
            return noise_scale / np.maximum(stair_mod, 1e-6)

    # the phase noise and the fringes' direction, once for the regions and their orders
    phase_noise = fs.phase_noise
    direction = fringe_direction(fs.phi, fs.valid)

    def regions() -> np.ndarray:
        """Fringe regions, cut where the stair code says two surfaces meet."""
        edges = stair_edges(fs.phi, theta, fs.valid, stair_noise_map(), spec.stairs, 12)
        if not (compiled and GATHER):
            return fringe_regions(fs.phi, fs.valid, phase_noise=phase_noise,
                                  boundaries=edges, sign=direction, links=fs.links)[0]
        # the final numbering writes the labels and sums the stair values per (region,
        # row) in one scan: the first evidence reads those sums
        lab = label_fringes(fs.phi, fs.valid, phase_noise=phase_noise, boundaries=edges,
                            sign=direction, links=fs.links)
        remap, n = kept_regions(lab)
        gathered.append((lab.labels, relabel_stair_profiles(
            lab.labels, lab.roots, remap, fs.phi, theta, stair_mod, fs.mod, n)))
        return lab.labels

    levels = union_levels(spec.partitions, spec.stairs)
    doubt = np.zeros(levels.size, bool)  # the levels whose rows read too far from them

    def evidence_of(labels: np.ndarray, n: int) -> tuple[np.ndarray, int, np.ndarray]:
        prof = profiles(labels)
        if "level_offset" not in info:  # how far the band rows read from the levels
            offset, per_level = level_offsets(prof, levels)
            info.update(level_offset=round(offset, 3),
                        worst_level_offset=round(float(per_level.max()), 3))
            doubt[:] = per_level >= LEVEL_DOUBT
            if doubt.any():
                info["doubtful_levels"] = int(doubt.sum())
        runs = row_runs(prof, levels)
        heights = group_heights(runs, n, profile_centroids(prof, n))
        splits = edge_rows(runs, band_splits(runs, heights, spec.local_rows / spec.group_rows))
        if splits:  # surfaces stacked in one fringe region: decode them apart
            prof = split_profiles(prof, n, splits)
            labels, n = split_regions(labels, n, splits, in_place=True)  # the decode's own
            runs = row_runs(prof, levels)
        heights = group_heights(runs, n, profile_centroids(prof, n))
        default = float(np.nanmedian(heights)) if np.isfinite(heights).any() else spec.group_rows
        layout = BandLayout(spec.stairs, spec.partitions, spec.local_rows / spec.group_rows,
                            default)
        info.update(region_splits=info.get("region_splits", 0) + len(splits),
                    group_height=default)
        evidence = thin_band_doubt(region_evidence(runs, n, heights, layout), default, spec)
        if doubt.any():  # regions that read a level too far from its place: faint
            evidence[doubtful_regions(runs, n, doubt)] *= THIN_DOUBT
        return labels, n, evidence

    def agrees(k: np.ndarray) -> np.ndarray:
        """A pixel reads its order's local or partition level (its row decides which)."""
        return stair_agreement(ks, theta, k, spec.stairs, spec.partitions)

    # the labels are passed on, not kept here: the decode replaces them as it splits regions
    return orders_from_regions(fs.phi, fs.valid, regions(), evidence_of, agrees, info,
                               phase_noise=phase_noise, direction=direction)


def thin_band_doubt(evidence: np.ndarray, group_height: float,
                    spec: BidirectionalSpec) -> np.ndarray:
    """The band evidence, the orders whose two stairs read one level (``k = j*(S+1)``,
    local and partition level both ``j``) made faint (scaled by ``THIN_DOUBT``) while the
    partition bands are thinner than ``MIN_BAND_PX`` camera pixels.

    Blur mixes a band that thin with the local bands either side: its rows lose the
    modulation of a band and are skipped as transitions, so a region whose partition level
    differs from its local level seems to read one level throughout, which only such an
    order explains (a small object at 320 x 256, its partition bands 3 px tall and read 4,
    its local bands 6: decoded as order 54 = 6*(8+1) rather than 38, by two partitions).
    Those regions then take their orders from neighbours that decide themselves, or stay
    undecided (:func:`bistair.core.resolve.settle`).

    Parameters
    ----------
    evidence : numpy.ndarray
        (n+1, K) band evidence per region.
    group_height : float
        The median band group height, camera pixels.
    spec : BidirectionalSpec
        The spec (stairs, partitions, local and group rows).

    Returns
    -------
    numpy.ndarray
        The evidence, those orders' columns scaled where the bands are thin.

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("bidirectional", width=240, height=64, period=20, partitions=3,
    ...                  stairs=4, group_rows=16, local_rows=10)
    >>> ev = np.ones((2, 12))
    >>> thin_band_doubt(ev, 8.0, spec)[1].tolist()  # 3-px partition bands
    [0.4, 1.0, 1.0, 1.0, 1.0, 0.4, 1.0, 1.0, 1.0, 1.0, 0.4, 1.0]
    >>> bool((thin_band_doubt(ev, 16.0, spec) == ev).all())  # 6 px: read as they are
    True
    """
    band = group_height * (1.0 - spec.local_rows / spec.group_rows)
    if not band < MIN_BAND_PX:
        return evidence
    merged = np.arange(min(spec.stairs, spec.partitions)) * (spec.stairs + 1)
    merged = merged[merged < evidence.shape[1]]
    out = np.array(evidence, copy=True)
    out[:, merged] *= THIN_DOUBT
    return out


# the first evidence reads the (region, row) stair sums gathered in the labelling's final
# scan (:func:`.profiles.relabel_stair_profiles`), not in a scan of their own (the same
# sums; False: as bistair did before, for the tests' comparison)
GATHER = True
MIN_BAND_PX = 4.0  # partition bands thinner than this (camera pixels) are read with doubt
THIN_DOUBT = 0.4  # below the resolve stage's min_score: faint


def stairs_for(fringes: int) -> tuple[int, int]:
    """Partitions and stairs (P, S) with P*S >= fringes, as square as possible.

    Parameters
    ----------
    fringes : int
        Fringes across the coded axis.

    Returns
    -------
    tuple of int
        ``(P, S)``: ``S = ceil(sqrt(fringes))`` and ``P = ceil(fringes / S)``.

    Examples
    --------
    >>> stairs_for(36), stairs_for(64), stairs_for(121)
    ((6, 6), (8, 8), (11, 11))
    """
    stairs = math.ceil(math.sqrt(fringes))
    return math.ceil(fringes / stairs), stairs


def comparable(width: int, height: int, period: int, steps: int) -> dict:
    """The squarest P x S covering the width at this period (6 x 6 on 1080 px at 30 px).

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
    >>> comparable(1080, 1080, 30, 4)
    {'period': 30, 'partitions': 6, 'stairs': 6, 'steps': 4}
    """
    parts, stairs = stairs_for(math.ceil(width / period))
    return dict(period=period, partitions=parts, stairs=stairs, steps=steps)


CODEC = Codec(
    name="bidirectional",
    spec_class=BidirectionalSpec,
    summary="N phase shifts + a bidirectional stair-phase pair (Qi, Zhou et al.)",
    encode_columns=encode_columns,
    code_columns=code_columns,
    order_columns=order_columns,
    comparable=comparable,
    variants={"paper decoder": {"strategy": "paper"}},
    aligned=True,
)
