"""Multi-frequency temporal phase unwrapping: one N-step set per period, frames period by period.

Frames ``T{period}-shift-{n}`` in the order the periods are listed. Two rules:

``hierarchical``
    Coarse to fine (the paper's three-frequency twelve-step reference: 1080/180/30 on a
    1080-wide projector, 1920/240/30 in its third experiment). The longest period must cover
    the coded axis, so its phase is absolute; each finer phase takes the order that brings
    it nearest the coarser one scaled by the period ratio.
``heterodyne``
    For sets whose longest period does not cover the projector: the phase differences of
    neighbouring periods are the phases of their beat periods ``Ta*Tb/|Tb-Ta|``, and of
    those beats again, until one beat covers the coded axis; the phases are then unwrapped
    back down (e.g. 42/45/48: beats 630 and 720, and 5040 above them).

``phase.npy`` and ``order.npy`` refer to the shortest period; ``coord.npy`` is the projector
column. At every unwrapping step the coarser phase, scaled to the finer period, must land
within a quarter fringe of the finer phase; a pixel where any step misses is invalid
(``info["period_agreement"]`` is the share of well-modulated pixels where all steps agree).

Examples
--------
>>> import numpy as np
>>> from bistair import decode, encode, make_spec
>>> spec = make_spec("multifreq", width=300, height=40, periods=(42, 45, 48), steps=4)
>>> spec.unwrap, spec.frame_count
('heterodyne', 12)
>>> res = decode(encode(spec), spec)
>>> bool(np.abs(res.coord - np.arange(300)).max() < 1e-3), res.period
(True, 42.0)
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..core.captures import Prepared
from ..core.checks import refuse
from ..core.measure import FringeSet, measure
from ..core.phase import TWO_PI, order_from_reference
from ..errors import BistairError
from ..spec import BaseSpec, field, format_period
from .base import Codec, CodeMap, Orders, along_columns, shift_patterns
from .beats import ambiguous, beat, beat_tree, check_beat, covers
from .multifreq_jit import agreed_orders, unwrap_chain

# An unwrapping step's order is carried where the next order fits the step's miss worse by
# CLEAR_NOISE**2 sigmas squared of its noise: odds of exp(-4.5), 1.1%, at the most
CLEAR_NOISE = 3.0


def miss_peak(worst: np.ndarray, valid: np.ndarray) -> float:
    """How peaked at zero the unwrapping misses are: of the valid pixels missing their
    fringe by under a quarter (every fourth row and column), the share missing it by under
    an eighth. Misses spread evenly (periods that do not fit the captures) give 0.5; a
    right decode about 1, down to 0.5-0.6 under heavy noise.

    Parameters
    ----------
    worst : numpy.ndarray
        (H, W) the largest miss of any unwrapping step, fringes.
    valid : numpy.ndarray
        (H, W) bool, the pixels whose every period is well modulated.

    Returns
    -------
    float
        The share (1.0 with no miss under a quarter).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> even = rng.uniform(0, 0.5, (64, 64))
    >>> peak = np.abs(rng.normal(0, 0.03, (64, 64)))
    >>> ok = np.ones((64, 64), bool)
    >>> round(miss_peak(even, ok), 1), round(miss_peak(peak, ok), 2)
    (0.5, 1.0)
    """
    w = np.abs(np.asarray(worst)[::4, ::4])[np.asarray(valid)[::4, ::4]]
    quarter = int(np.count_nonzero(w < 0.25))
    return float(np.count_nonzero(w < 0.125) / quarter) if quarter else 1.0


@dataclasses.dataclass(frozen=True, kw_only=True)
class MultiFreqSpec(BaseSpec):
    method = "multifreq"

    periods: tuple[float, ...] = field((1080, 180, 30), "fringe periods in projector pixels, "
                                       "projected in this order")
    unwrap: str = field("auto", "hierarchical, heterodyne, or auto (hierarchical when the "
                        "longest period covers the axis)", shapes=False,
                        choices=("auto", "hierarchical", "heterodyne"))

    def __post_init__(self) -> None:
        if (self.unwrap == "auto" and self.periods and self.orientation != "both"
                and all(math.isfinite(t) for t in self.periods) and not self.single_period):
            rule = "hierarchical" if covers(max(self.periods), self.coded_length) \
                else "heterodyne"
            object.__setattr__(self, "unwrap", rule)
        super().__post_init__()

    def method_frames(self) -> tuple[str, ...]:
        return tuple(f"T{format_period(t)}-shift-{n}" for t in self.periods
                     for n in range(self.steps))

    def validate(self) -> None:
        super().validate()
        if not self.periods or not all(math.isfinite(t) and t >= 4 for t in self.periods):
            shown = ", ".join(format_period(t) for t in self.periods)
            raise BistairError(f"periods must be finite and at least 4 projector pixels, got "
                               f"({shown})")
        if len(set(self.periods)) != len(self.periods):
            raise BistairError(f"periods must differ, got {self.periods}")
        if self.single_period and self.unwrap == "auto":
            return  # a stream's set or stereo's: nothing to unwrap (see single_period)
        if self.unwrap not in ("hierarchical", "heterodyne"):
            raise BistairError(f"unwrap must be hierarchical or heterodyne, got {self.unwrap!r}")
        if self.unwrap == "hierarchical" and not covers(max(self.periods), self.coded_length):
            raise BistairError(
                f"hierarchical unwrapping needs a period covering the {self.coded_length}-px "
                f"axis; the longest is {max(self.periods)} (use heterodyne)"
            )
        if self.unwrap == "heterodyne":
            check_beat(self.periods, self.coded_length)

    @property
    def period(self) -> float:
        """The shortest period, which ``phase`` and ``order`` refer to."""
        return min(self.periods)

    @property
    def single_period(self) -> bool:
        """One period narrower than the coded axis (``unwrap`` stays ``auto``): a set that
        gives the wrapped phase and no fringe order, for a stream (``decode --window``) or
        two cameras (``stereo --depth-range``); :func:`measure_columns` refuses it alone.

        Examples
        --------
        >>> from bistair.codecs import make_spec
        >>> spec = make_spec("multifreq", width=300, height=32, periods=(30,))
        >>> spec.single_period, spec.unwrap, spec.frame_count
        (True, 'auto', 4)
        """
        return (len(self.periods) == 1 and self.orientation != "both"
                and math.isfinite(self.periods[0])
                and not covers(self.periods[0], self.coded_length))


def single_period_refusal(spec: MultiFreqSpec) -> str:
    """Why a single-period spec does not decode alone, and what to use instead.

    Parameters
    ----------
    spec : MultiFreqSpec
        A spec of one period narrower than its coded axis.

    Returns
    -------
    str
        The one-line reason, naming the period, the axis and the commands that decode it.

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> print(single_period_refusal(make_spec("multifreq", width=300, height=32,
    ...                                       periods=(30,))))  # doctest: +ELLIPSIS
    one period (30 px on the 300-px coded axis) gives no fringe order: decode a stream ...
    """
    return (f"one period ({format_period(spec.periods[0])} px on the {spec.coded_length}-px "
            f"coded axis) gives no fringe order: decode a stream of it with 'decode --window "
            f"N' (the wrapped phase), or two cameras' with 'stereo --depth-range'")


def encode_columns(spec: MultiFreqSpec) -> np.ndarray:
    """The patterns of a multi-frequency spec in the column layout: one N-step set per
    period, in the order the periods are listed.

    Parameters
    ----------
    spec : MultiFreqSpec
        The spec of one coded axis.

    Returns
    -------
    numpy.ndarray
        (len(periods) * steps, other_length, coded_length) float32 intensities (fractions
        of full scale), a read-only view whose rows are all the same.

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("multifreq", width=300, height=32, periods=(42, 45, 48))
    >>> pats = encode_columns(spec)
    >>> pats.shape, pats[4:8, 0, 45].round(2).tolist()  # the 45-px set at x = 45
    ((12, 32, 300), [1.0, 0.5, 0.0, 0.5])
    """
    sets = [shift_patterns(spec, t) for t in spec.periods]
    return along_columns(np.concatenate(sets), spec)


class _Unwrapper:
    """Unwraps a phase from a coarser absolute one, keeping the worst residual per pixel
    and the signed residual (in fringes) of the last step."""

    def __init__(self) -> None:
        self.worst: np.ndarray | float = 0.0
        self.last: np.ndarray | float = 0.0

    def __call__(self, phi: np.ndarray, coarse: np.ndarray, ratio: float) -> np.ndarray:
        ref = coarse * ratio
        k = order_from_reference(phi, ref)
        self.last = (ref - phi) / TWO_PI - k
        self.worst = np.maximum(self.worst, np.abs(self.last))
        return phi + TWO_PI * k


def top_phase(phi: np.ndarray, period: float, length: int) -> np.ndarray:
    """The absolute phase of the coarsest period (or beat), which covers the coded axis.

    Coordinates between the axis's end and the period's are impossible; the upper half of
    them are pixels at the start of the axis whose phase noise crossed the wrap, so they are
    moved one period down (to small negative coordinates, which the finer periods bring
    back): without this, a pixel at column 1 of a 1920-px projector decoded with beats of
    5040 px lands at 5041.

    Parameters
    ----------
    phi : numpy.ndarray
        Wrapped phase of the coarsest period (or beat) in [0, 2*pi), radians.
    period : float
        That period in projector pixels, at least ``length``.
    length : int
        Projector pixels along the coded axis.

    Returns
    -------
    numpy.ndarray
        The absolute phase in radians: ``phi``, less ``2*pi`` where it would put the pixel
        past the middle of the impossible coordinates.

    Examples
    --------
    >>> top_phase(np.array([0.1, 6.28]), 5040.0, 1920).round(3).tolist()
    [0.1, -0.003]
    """
    x = phi * (period / TWO_PI)
    fold = x >= 0.5 * (length + period)
    return np.where(fold, phi - TWO_PI, phi)


def measure_columns(prepared: Prepared, spec: MultiFreqSpec,
                    min_modulation: float | None = None) -> FringeSet:
    """Stage 1: the N-step set of the shortest period (the phase the result refers to).

    Parameters
    ----------
    prepared : Prepared
        The method's frames in method order, column layout (coded axis along the image
        rows), as fractions of full scale.
    spec : MultiFreqSpec
        The spec of one coded axis.
    min_modulation : float, optional
        The modulation (fraction of full scale) a valid pixel needs; by default a threshold
        from the measured camera noise.

    Returns
    -------
    FringeSet
        (H, W) float32 wrapped phase of the shortest period in [0, 2*pi) (radians), average
        and modulation (fractions of full scale), the validity mask and the camera noise.

    Raises
    ------
    BistairError
        A single-period spec (one period narrower than the coded axis,
        :func:`single_period_refusal`): it gives no fringe order alone.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("multifreq", width=300, height=32, periods=(42, 45, 48))
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_columns(cols, spec)
    >>> fs.phi.shape, round(float(fs.phi[0, 21]), 3)  # half of the 42-px period
    ((32, 300), 3.142)
    """
    if spec.single_period:
        raise BistairError(single_period_refusal(spec))
    i = spec.periods.index(min(spec.periods))
    return measure(prepared, i * spec.steps, spec.steps, min_modulation,
                   shift_sign=spec.shift_sign, phase_offset=spec.phase_offset)


def code_columns(prepared: Prepared, spec: MultiFreqSpec, fs: FringeSet,
                 min_modulation: float | None = None) -> CodeMap:
    """Stage 2: the shortest period's order from the longer periods (or their beats).

    ``maps["worst"]`` is the largest miss, in fringes, of any unwrapping step,
    ``maps["spread"]`` the largest noise of a step's miss (:func:`unwrap_spread`) and
    ``maps["valid"]`` where every period is well modulated.

    Parameters
    ----------
    prepared : Prepared
        The method's frames in method order, column layout (coded axis along the image
        rows), as fractions of full scale.
    spec : MultiFreqSpec
        The spec of one coded axis (``unwrap`` chooses the rule).
    fs : FringeSet
        Stage 1, the shortest period's set (:func:`measure_columns`).
    min_modulation : float, optional
        The modulation (fraction of full scale) a pixel of the other periods needs.

    Returns
    -------
    CodeMap
        ``code``: (H, W) int32 order of the shortest period, -1 where some period is not
        valid; ``maps``: ``worst`` (fringes), ``spread`` (float32 fringes), ``valid`` (bool)
        and ``residual`` (the last step's signed miss, fringes), all (H, W). The
        hierarchical rule unwraps in float64 and stores float32 (``worst`` rounded toward
        zero: below 0.25 exactly where the float64 miss is); the heterodyne rule keeps
        float64.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("multifreq", width=300, height=32, periods=(42, 45, 48))
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_columns(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> code.code[0, ::42].tolist(), sorted(code.maps), bool(code.maps["worst"].max() < 0.01)
    ([0, 1, 2, 3, 4, 5, 6, 7], ['residual', 'spread', 'valid', 'worst'], True)
    """
    n = spec.steps
    shortest = float(spec.period)
    sets = {}  # period: (phase, valid); the other maps of a set are let go at once
    noise = {}  # period: its phase noise (radians)
    for i, t in enumerate(spec.periods):
        s = fs if float(t) == shortest else measure(
            prepared, i * n, n, min_modulation, check=False, shift_sign=spec.shift_sign,
            phase_offset=spec.phase_offset)
        sets[float(t)] = (s.phi, s.valid)
        noise[float(t)] = s.phase_noise
        del s
    valid = np.logical_and.reduce([v for _, v in sets.values()])
    spread = unwrap_spread(noise, spec)
    del noise
    if spec.unwrap == "hierarchical" and len(sets) > 1:  # per pixel in one pass
        chain = sorted(sets, reverse=True)
        code, worst, last = unwrap_chain(tuple(sets[t][0] for t in chain), tuple(chain),
                                         spec.coded_length, fs.phi, valid)
        return CodeMap(code, {"worst": np.broadcast_to(worst, valid.shape), "valid": valid,
                              "residual": np.broadcast_to(last, valid.shape),
                              "spread": spread})
    phase_of = {t: phi.astype(np.float64) for t, (phi, _) in sets.items()}
    unwrap = _Unwrapper()
    if spec.unwrap == "hierarchical":
        chain = sorted(phase_of, reverse=True)
        absolute = {chain[0]: top_phase(phase_of[chain[0]], chain[0], spec.coded_length)}
        for coarse, fine in zip(chain[:-1], chain[1:], strict=True):
            absolute[fine] = unwrap(phase_of[fine], absolute[coarse], coarse / fine)
    else:
        levels = beat_tree(tuple(phase_of))
        for low in levels[:-1]:  # the beats' phases, level by level up
            for a, b in zip(low[:-1], low[1:], strict=True):
                phase_of[beat(a, b)] = (phase_of[a] - phase_of[b]) % TWO_PI
        top = levels[-1][0]
        absolute = {top: top_phase(phase_of[top], top, spec.coded_length)}
        for low in levels[-2::-1]:  # each period from a beat it makes with a neighbour
            for i, t in enumerate(low):
                j = min(i, len(low) - 2)
                parent = beat(low[j], low[j + 1])
                absolute[t] = unwrap(phase_of[t], absolute[parent], parent / t)
    order = order_from_reference(fs.phi, absolute[shortest])
    if spec.unwrap == "heterodyne":  # pixels a top beat read across its wrap can move
        twice = ambiguous(absolute[shortest] * (shortest / TWO_PI), spec.periods,
                          spec.coded_length)
        if twice is not None:
            order[twice] = np.nan
    code = np.where(valid & np.isfinite(order), order, -1).astype(np.int32)
    return CodeMap(code, {"worst": np.broadcast_to(unwrap.worst, valid.shape), "valid": valid,
                          "residual": np.broadcast_to(unwrap.last, valid.shape),
                          "spread": spread})


def unwrap_spread(noise: dict[float, np.ndarray], spec: MultiFreqSpec) -> np.ndarray:
    """The noise of the unwrapping steps' misses: per pixel, the largest standard
    deviation, in fringes of the finer period, of any step's miss (the coarser phase,
    scaled by the periods' ratio, less the finer one; a beat's phase noise is its two
    periods' together).

    Parameters
    ----------
    noise : dict of float to (H, W) float32 array
        Each period's phase noise in radians (:attr:`~bistair.core.measure.FringeSet.phase_noise`).
    spec : MultiFreqSpec
        The spec of one coded axis (``unwrap`` chooses the rule).

    Returns
    -------
    (H, W) float32 array
        The largest step's noise, in fringes (0 with a single period).

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("multifreq", width=300, height=40, periods=(42, 45, 48), steps=4)
    >>> sigma = {t: np.full((1, 1), 0.01, np.float32) for t in (42.0, 45.0, 48.0)}
    >>> round(float(unwrap_spread(sigma, spec)[0, 0]), 4)  # 720 -> 45: 16 x 0.014 rad / 2 pi
    0.036
    """
    two_pi = np.float32(TWO_PI)
    spread = np.zeros(next(iter(noise.values())).shape, np.float32)
    if len(noise) < 2:
        return spread
    sigma = dict(noise)
    if spec.unwrap == "hierarchical":
        steps = list(zip(sorted(sigma, reverse=True)[:-1], sorted(sigma, reverse=True)[1:],
                         strict=True))
    else:
        levels = beat_tree(tuple(sigma))
        for low in levels[:-1]:
            for a, b in zip(low[:-1], low[1:], strict=True):
                sigma[beat(a, b)] = np.hypot(sigma[a], sigma[b])
        steps = []
        for low in levels[-2::-1]:
            for i, t in enumerate(low):
                j = min(i, len(low) - 2)
                steps.append((beat(low[j], low[j + 1]), t))
    for coarse, fine in steps:
        step = np.hypot(np.float32(coarse / fine) * sigma[coarse], sigma[fine]) / two_pi
        np.maximum(spread, step, out=spread)
    return spread


def order_columns(fs: FringeSet, code: CodeMap, spec: MultiFreqSpec) -> Orders:
    """Stage 3: keep the pixels where every unwrapping step lands within a quarter fringe
    and whose phases carry their order: the next order fits the worst step's miss ``m``
    worse by ``CLEAR_NOISE**2`` of that miss's variance (``1 - 2|m| >= (3 sigma)**2``,
    ``sigma`` from :func:`unwrap_spread`); the others are left out (``info["left_out"]``).

    Captures where the periods agree on under half of the well-modulated pixels do not fit
    the spec (periods, frame order or phase convention) and are refused; a coordinate that
    falls along the image axis is worth a warning (the projector is mirrored, or the shifts
    run the other way: the captures alone cannot tell).

    Parameters
    ----------
    fs : FringeSet
        Stage 1, column layout.
    code : CodeMap
        Stage 2 (:func:`code_columns`).
    spec : MultiFreqSpec
        The spec of one coded axis.

    Returns
    -------
    Orders
        (H, W) int32 order of the shortest period per pixel (-1 where invalid) and
        ``info``: the unwrap rule, the camera noise, the pixels left out (``left_out``), the
        well-modulated pixels (``valid_modulation``), the share where every step agrees
        (``period_agreement``) and any ``warnings``.

    Raises
    ------
    BistairError
        With 500 or more well-modulated pixels, the periods agree on fewer than half.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("multifreq", width=300, height=32, periods=(42, 45, 48))
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_columns(cols, spec)
    >>> orders = order_columns(fs, code_columns(cols, spec, fs), spec)
    >>> orders.order[0, ::42].tolist(), orders.info["period_agreement"]
    ([0, 1, 2, 3, 4, 5, 6, 7], 1.0)
    >>> swapped = spec.replace(periods=(45, 42, 48))  # not the frame order
    >>> fs = measure_columns(cols, swapped)
    >>> order_columns(fs, code_columns(cols, swapped, fs), swapped)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the captures do not fit the spec: the periods agree on 13% ...
    """
    valid = code.maps["valid"]
    # the kept orders, the counts and the sign of the phase's slope along the rows at once
    order, lit, agreeing, falling = agreed_orders(code.code, code.maps["worst"], valid,
                                                  fs.phi, 0.25, 4)
    share = float(np.int64(agreeing) / max(lit, 1))
    peaked = miss_peak(code.maps["worst"], valid)
    # a pixel whose phases do not carry its order: at its worst step the next order, whose
    # miss is 1 - |m| away, fits not CLEAR_NOISE**2 sigmas squared worse than its own,
    # |m| away: (1 - |m|)**2 - m**2 = 1 - 2|m| under (CLEAR_NOISE * sigma)**2
    worst, spread = code.maps["worst"], code.maps["spread"]
    doubtful = (order >= 0) & ~(1.0 - 2.0 * worst >= (CLEAR_NOISE * spread) ** 2)
    order[doubtful] = -1
    info = {"unwrap": spec.unwrap, "noise": fs.noise, "left_out": int(doubtful.sum()),
            "valid_modulation": int(lit), "period_agreement": share,
            "miss_peak": round(peaked, 3)}
    # periods that do not fit miss their fringes at random: about half the pixels "agree"
    # (a miss under a quarter fringe) and the misses spread evenly (half of those under an
    # eighth); noise alone keeps them peaked at 0
    if lit >= 500 and (share < 0.5 or (share < 0.7 and peaked < 0.55)):
        residual = code.maps["residual"][valid]
        turn = float(np.angle(np.exp(-2j * np.pi * residual).mean()))
        hint = ""
        if spec.unwrap == "heterodyne" and abs(turn) > 0.5:
            hint = f"; the shortest period is {turn:+.2f} rad off its beats: phase_offset " \
                   f"{(spec.phase_offset + turn + np.pi) % TWO_PI - np.pi:.3f}?"
        refuse(
            f"the periods agree on {100 * share:.0f}% of "
            f"the modulated pixels (check the periods, the frame order, phase_offset and "
            f"shift_sign{hint})")
    if falling:
        info["warnings"] = ["the projector coordinate falls along the image's coded axis: "
                            "if the projector is not mirrored, is shift_sign "
                            f"{-spec.shift_sign:+d}?"]
    return Orders(order, info)


def comparable(width: int, height: int, period: int, steps: int) -> dict:
    """The paper's three-frequency twelve-step reference: the width, about
    ``sqrt(width * period)`` and the period (1080/180/30, 1920/240/30).

    Parameters
    ----------
    width : int
        Projector width in pixels (the coded axis), the longest period.
    height : int
        Projector height in pixels (not used).
    period : int
        The shortest fringe period in projector pixels.
    steps : int
        Not used: the reference has twelve steps per period.

    Returns
    -------
    dict
        Spec parameters for :func:`~bistair.codecs.make_spec` (besides the size).

    Examples
    --------
    >>> comparable(1080, 1080, 30, 4), comparable(1920, 1080, 30, 4)["periods"]
    ({'periods': (1080, 180, 30), 'steps': 12}, (1920, 240, 30))
    """
    middle = int(round(math.sqrt(width * period) / period)) * period
    return dict(periods=(width, middle, period), steps=12)


CODEC = Codec(
    name="multifreq",
    spec_class=MultiFreqSpec,
    summary="N-step sets at several periods, unwrapped hierarchically or by heterodyne beats",
    encode_columns=encode_columns,
    measure_columns=measure_columns,
    code_columns=code_columns,
    order_columns=order_columns,
    comparable=comparable,
)
