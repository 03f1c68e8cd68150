"""Conventional stair phase coding (Wang and Zhang, Optics Letters 37(11), 2012).

One stair level per fringe: the code phase steps by ``2*pi/K`` every fringe, ``K`` the
number of fringes across the coded axis, so the levels get closer as fringes are added.
Level ``k`` sits at ``-pi + pi/K + 2*pi*k/K`` (the bin centres of :mod:`bistair.stair`).

Forms:

``pair`` (paper-comparable, 6 frames for N = 4)
    N phase shifts plus the coded pair ``a + b*cos(code)``, ``a + b*sin(code)`` decoded with
    the fringes' average, as in the bidirectional method. Frames ``shift-n``, ``code-cos``,
    ``code-sin``.
``shifted`` (the original, 2N frames)
    N phase shifts plus the code phase shifted N times, ``a + b*cos(code + 2*pi*n/N)``.
    Frames ``shift-n``, ``code-n``.

Strategies: ``region`` (default) votes the code over each fringe region and checks orders
step by one across wraps (:func:`bistair.core.resolve.orders_from_regions`); ``pixel`` is the
classic per-pixel ``k = code``, which misorders pixels where the code and the wrapped phase
change together.

Examples
--------
>>> import numpy as np
>>> from bistair import decode, encode, make_spec
>>> spec = make_spec("phase-coding", width=480, height=40, period=30)
>>> spec.levels, spec.frames[-2:]
(16, ('code-cos', 'code-sin'))
>>> res = decode(encode(spec), spec)
>>> bool(np.abs(res.coord - np.arange(480)).max() < 1e-3)
True
"""

from __future__ import annotations

import dataclasses
from typing import Literal

import numpy as np

from ..core.captures import Prepared
from ..core.measure import FringeSet
from ..core.phase import shifts_of, wrapped_phase
from ..core.regions import core_weight, fringe_regions
from ..core.resolve import code_evidence, orders_from_regions
from ..core.stair import read_stairs, stair_level_phase, stair_levels, stair_pair
from ..errors import BistairError
from ..spec import PeriodSpec, field, format_period
from .base import Codec, CodeMap, Orders, along_columns, fringe_index, shift_patterns


@dataclasses.dataclass(frozen=True, kw_only=True)
class PhaseCodingSpec(PeriodSpec):
    method = "phase-coding"

    form: str = field("pair", "pair: a cos/sin coded pair; shifted: N-step coded patterns",
                      choices=("pair", "shifted"))

    @property
    def levels(self) -> int:
        """Stair levels: one per fringe across the coded axis."""
        return self.fringes

    def method_frames(self) -> tuple[str, ...]:
        shifts = self.shift_frames()
        if self.form == "pair":
            return (*shifts, "code-cos", "code-sin")
        return (*shifts, *(f"code-{n}" for n in range(self.steps)))

    def validate(self) -> None:
        super().validate()
        if self.form not in ("pair", "shifted"):
            raise BistairError(f"form must be pair or shifted, got {self.form!r}")
        if self.levels < 2:
            raise BistairError(f"a {format_period(self.period)}-px period leaves fewer than 2 "
                               f"fringes across the {self.coded_length}-px coded axis")


def encode_columns(spec: PhaseCodingSpec) -> np.ndarray:
    """The patterns of a phase-coding spec in the column layout, in method-frame order.

    The N-step set, then the code phase of fringe ``k`` (stair level ``k`` of ``levels``,
    one per fringe) as the ``pair`` ``offset + amplitude * cos / sin(code)``, or
    ``shifted`` N times like the fringes.

    Parameters
    ----------
    spec : PhaseCodingSpec
        The spec of one coded axis.

    Returns
    -------
    numpy.ndarray
        (frames, other_length, coded_length) float32 intensities (fractions of full scale),
        a read-only view whose rows are all the same.

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("phase-coding", width=240, height=32, period=30)
    >>> pats = encode_columns(spec)
    >>> pats.shape
    (6, 32, 240)
    >>> code = np.arctan2(pats[5, 0] - 0.5, pats[4, 0] - 0.5)  # the code phase, radians
    >>> (code[15::30] / (2 * np.pi / spec.levels)).round(2).tolist()  # in level steps
    [-3.5, -2.5, -1.5, -0.5, 0.5, 1.5, 2.5, 3.5]
    """
    shifts = shift_patterns(spec)
    code = stair_level_phase(fringe_index(spec), spec.levels)
    if spec.form == "pair":
        coded = stair_pair(code, spec.offset, spec.amplitude)
    else:
        steps = shifts_of(spec.steps, spec.shift_sign)[:, None]
        coded = spec.offset + spec.amplitude * np.cos(code[None, :] + steps)
    return along_columns(np.concatenate([shifts, coded]), spec)


def code_columns(prepared: Prepared, spec: PhaseCodingSpec, fs: FringeSet,
                 min_modulation: float | None = None) -> CodeMap:
    """Stage 2: the code phase of either form and its stair level on the valid pixels.

    Parameters
    ----------
    prepared : Prepared
        The method's frames in method order, column layout (coded axis along the image
        rows), as fractions of full scale.
    spec : PhaseCodingSpec
        The spec of one coded axis.
    fs : FringeSet
        Stage 1: the valid pixels, and the average the ``pair`` is read against.
    min_modulation : float, optional
        Not used (the code shares the fringes' validity).

    Returns
    -------
    CodeMap
        ``code``: (H, W) int32 stair level (the fringe order it codes), -1 where not
        valid; ``maps["code_phase"]``: (H, W) float32 code phase in radians, in [-pi, pi)
        for the pair, [0, 2*pi) for the shifted form (the levels are read modulo 2*pi).

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("phase-coding", width=240, height=32, period=30)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> code.code[0, ::30].tolist(), sorted(code.maps)
    ([0, 1, 2, 3, 4, 5, 6, 7], ['code_phase'])
    """
    if spec.form == "pair":
        theta, _, codes = read_stairs(prepared, spec.steps, spec.levels, fs.avg, fs.valid,
                                      fs.stair)
    else:
        theta = wrapped_phase(prepared.frames[spec.steps:], spec.shift_sign)[0]
        codes = stair_levels(theta, spec.levels, fs.valid)
    return CodeMap(codes, {"code_phase": theta})


def order_columns(fs: FringeSet, code: CodeMap, spec: PhaseCodingSpec, *,
                  strategy: Literal["region", "pixel"] = "region") -> Orders:
    """Stage 3: the code per pixel (``pixel``) or voted per fringe region (``region``).

    Parameters
    ----------
    fs : FringeSet
        Stage 1, column layout.
    code : CodeMap
        Stage 2 (:func:`code_columns`).
    spec : PhaseCodingSpec
        The spec of one coded axis.
    strategy : {"region", "pixel"}
        One order per fringe region, checked across the wraps, or the code per pixel.

    Returns
    -------
    Orders
        (H, W) fringe order per pixel (-1 where invalid) and ``info``: the strategy, the
        camera noise, the levels, and for ``region`` the region counts and the phase jumps
        across which the orders do not step by one.

    Raises
    ------
    BistairError
        ``strategy`` is neither ``"region"`` nor ``"pixel"``.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("phase-coding", width=240, height=32, period=30)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> orders = order_columns(fs, code, spec)
    >>> orders.order[0, ::30].tolist(), orders.info["strategy"], orders.info["regions"]
    ([0, 1, 2, 3, 4, 5, 6, 7], 'region', 8)
    >>> order_columns(fs, code, spec, strategy="mode")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: unknown strategy 'mode' (use 'region' or 'pixel')
    """
    if strategy not in ("region", "pixel"):
        raise BistairError(f"unknown strategy {strategy!r} (use 'region' or 'pixel')")
    codes = code.code
    info = {"strategy": strategy, "noise": fs.noise, "levels": spec.levels}
    if strategy == "pixel":
        return Orders(codes, info)
    labels, _ = fringe_regions(fs.phi, fs.valid, phase_noise=fs.phase_noise, links=fs.links)
    weight = core_weight(fs.phi)

    def evidence_of(labels: np.ndarray, n: int) -> tuple[np.ndarray, int, np.ndarray]:
        return labels, n, code_evidence(labels, n, codes, spec.levels, weight)

    def agrees(k: np.ndarray) -> np.ndarray:
        """Noise moves a code a level or so; another surface's fringe moves it more."""
        off = np.subtract(codes, k, dtype=np.int32)  # in place from here: few temporaries
        np.abs(off, out=off)
        off %= spec.levels
        ok = off <= 1  # min(off, levels - off) <= 1
        ok |= off >= spec.levels - 1
        del off
        ok |= codes < 0
        return ok

    return Orders(orders_from_regions(fs.phi, fs.valid, labels, evidence_of, agrees, info),
                  info)


def comparable(width: int, height: int, period: int, steps: int) -> dict:
    """One level per fringe at the same period.

    Parameters
    ----------
    width, height : int
        Projector size in pixels (not used: the levels follow the fringes).
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
    {'period': 30, 'steps': 4}
    """
    return dict(period=period, steps=steps)


CODEC = Codec(
    name="phase-coding",
    spec_class=PhaseCodingSpec,
    summary="N phase shifts + a stair code with one level per fringe (Wang and Zhang 2012)",
    encode_columns=encode_columns,
    code_columns=code_columns,
    order_columns=order_columns,
    comparable=comparable,
)
