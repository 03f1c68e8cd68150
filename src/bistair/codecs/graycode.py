"""Gray code plus N-step phase shifting, plain or complementary.

Frames ``shift-n``, then ``gray-0 .. gray-(B-1)`` (most significant first, ``B`` bits for
the fringe count), with ``complementary`` one more, ``gray-B``, and with ``inverse`` each
code pattern's inverse ``gray-i-inv`` after them.

Plain: the code gives ``k = floor(x/T)`` directly; its edges sit exactly on the phase wraps,
so blur and noise put pixels beside every edge one order off (the method's known limit).

Complementary (Zhang Q. et al., Opt. Lasers Eng. 50(4), 2012): the ``B+1`` patterns form a
Gray code of half-period resolution whose last bit has its edges mid-fringe. With ``k1``
from the first ``B`` bits and ``k2 = floor((K2 + 1)/2)`` from all of them, the three-zone
rule picks the code whose edges are far from the pixel: ``k2`` where ``phi < pi/2``,
``k2 - 1`` where ``phi >= 3*pi/2``, ``k1`` in between.

Bits are binarised against the fringes' average intensity, or against the inverse patterns
when the spec has them (robust to albedo and ambient light).

Examples
--------
>>> import numpy as np
>>> from bistair import decode, encode, make_spec
>>> spec = make_spec("graycode", width=480, height=40, period=30, complementary=1)
>>> spec.code_bits, spec.frames[4:]
(4, ('gray-0', 'gray-1', 'gray-2', 'gray-3', 'gray-4'))
>>> res = decode(encode(spec), spec)
>>> bool(np.abs(res.coord - np.arange(480)).max() < 1e-3)
True
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..core.captures import Prepared
from ..core.measure import FringeSet
from ..core.phase import TWO_PI, phase_shift_patterns
from ..errors import BistairError
from ..spec import PeriodSpec, field
from .base import Codec, CodeMap, Orders, along_columns


def gray_to_binary(gray: np.ndarray) -> np.ndarray:
    """Decode reflected Gray code integers.

    >>> gray_to_binary(np.array([0, 1, 3, 2, 6, 7, 5, 4])).tolist()
    [0, 1, 2, 3, 4, 5, 6, 7]
    """
    binary = np.array(gray, copy=True)
    shift, top = 1, int(np.max(binary, initial=0)).bit_length()
    while shift < top:
        binary ^= binary >> shift
        shift <<= 1
    return binary


@dataclasses.dataclass(frozen=True, kw_only=True)
class GrayCodeSpec(PeriodSpec):
    method = "graycode"

    complementary: int = field(0, "add the complementary pattern (three-zone rule)",
                               choices=(0, 1))
    inverse: int = field(0, "also project each code pattern's inverse to binarise against",
                         choices=(0, 1))

    @property
    def code_bits(self) -> int:
        """Gray code bits for the fringe count (the complementary pattern adds one)."""
        return max(1, int(np.ceil(np.log2(self.fringes))))

    def method_frames(self) -> tuple[str, ...]:
        codes = tuple(f"gray-{i}" for i in range(self.code_bits + self.complementary))
        inverse = tuple(f"{c}-inv" for c in codes) if self.inverse else ()
        return (*self.shift_frames(), *codes, *inverse)

    def validate(self) -> None:
        super().validate()
        if self.complementary not in (0, 1) or self.inverse not in (0, 1):
            raise BistairError("complementary and inverse must be 0 or 1")


def encode_columns(spec: GrayCodeSpec) -> np.ndarray:
    x = np.arange(spec.coded_length)
    shifts = phase_shift_patterns(x, spec.period, spec.steps, spec.offset, spec.amplitude)
    n_bits = spec.code_bits + spec.complementary
    level = (2 * x) // spec.period if spec.complementary else x // spec.period
    gray = level ^ (level >> 1)
    bits = (gray[None, :] >> np.arange(n_bits - 1, -1, -1)[:, None]) & 1
    codes = spec.offset + spec.amplitude * (2.0 * bits - 1.0)
    if spec.inverse:
        codes = np.concatenate([codes, 2 * spec.offset - codes])
    return along_columns(np.concatenate([shifts, codes]), spec)


def code_columns(prepared: Prepared, spec: GrayCodeSpec, fs: FringeSet,
                 min_modulation: float | None = None) -> CodeMap:
    """Stage 2: the fringe order read from the Gray code (three-zone rule when
    complementary), -1 where the fringes are not valid or the code is out of range."""
    n_bits = spec.code_bits + spec.complementary
    code = prepared.frames[spec.steps:spec.steps + n_bits]
    ref = prepared.frames[spec.steps + n_bits:] if spec.inverse else fs.avg[None]
    gray = np.zeros(fs.phi.shape, np.int32)
    for frame, against in zip(code, np.broadcast_to(ref, code.shape), strict=True):
        gray <<= 1
        gray |= frame > against
    if spec.complementary:
        k1 = gray_to_binary(gray >> 1)
        k2 = (gray_to_binary(gray) + 1) // 2
        k = np.where(fs.phi < np.pi / 2, k2, np.where(fs.phi >= 1.5 * np.pi, k2 - 1, k1))
    else:
        k = gray_to_binary(gray)
    ok = fs.valid & (k >= 0) & (k < spec.fringes)
    return CodeMap(np.where(ok, k, -1).astype(np.int32))


def order_columns(fs: FringeSet, code: CodeMap, spec: GrayCodeSpec) -> Orders:
    """Stage 3: the code is the order."""
    abs_phase = np.where(code.code >= 0, fs.phi + TWO_PI * code.code, np.nan)
    return Orders(abs_phase, {"noise": fs.noise, "bits": spec.code_bits + spec.complementary})


def comparable(width: int, height: int, period: int, steps: int) -> dict:
    """The complementary Gray code at the same period."""
    return dict(period=period, complementary=1, steps=steps)


CODEC = Codec(
    name="graycode",
    spec_class=GrayCodeSpec,
    summary="N phase shifts + Gray code (optionally complementary, optionally with inverses)",
    encode_columns=encode_columns,
    code_columns=code_columns,
    order_columns=order_columns,
    comparable=comparable,
)
