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

import numpy as np

from ..core.captures import Prepared
from ..core.measure import FringeSet
from ..core.phase import shifts_of, wrapped_phase
from ..core.regions import core_weight, fringe_regions
from ..core.resolve import code_evidence, orders_from_regions
from ..core.stair import quantize, stair_level_phase, stair_pair, stair_phase
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
    """Stage 2: the code phase of either form and its stair level on the valid pixels."""
    frames = prepared.frames[spec.steps:]
    if spec.form == "pair":
        theta = stair_phase(frames[0], frames[1], fs.avg)[0]
    else:
        theta = wrapped_phase(frames, spec.shift_sign)[0]
    codes = np.where(fs.valid, quantize(theta, spec.levels), -1).astype(np.int32)
    return CodeMap(codes, {"code_phase": theta})


def order_columns(fs: FringeSet, code: CodeMap, spec: PhaseCodingSpec, *,
                  strategy: str = "region") -> Orders:
    """Stage 3: the code per pixel (``pixel``) or voted per fringe region (``region``)."""
    if strategy not in ("region", "pixel"):
        raise BistairError(f"unknown strategy {strategy!r} (use 'region' or 'pixel')")
    codes = code.code
    info = {"strategy": strategy, "noise": fs.noise, "levels": spec.levels}
    if strategy == "pixel":
        return Orders(codes, info)
    labels, _ = fringe_regions(fs.phi, fs.valid, phase_noise=fs.phase_noise)
    weight = core_weight(fs.phi)

    def evidence_of(labels: np.ndarray, n: int) -> tuple[np.ndarray, int, np.ndarray]:
        return labels, n, code_evidence(labels, n, codes, spec.levels, weight)

    def agrees(k: np.ndarray) -> np.ndarray:
        """Noise moves a code a level or so; another surface's fringe moves it more."""
        off = np.abs(codes - k) % spec.levels
        return (np.minimum(off, spec.levels - off) <= 1) | (codes < 0)

    return Orders(orders_from_regions(fs.phi, fs.valid, labels, evidence_of, agrees, info),
                  info)


def comparable(width: int, height: int, period: int, steps: int) -> dict:
    """One level per fringe at the same period."""
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
