"""Gray code plus N-step phase shifting: plain, complementary, shifted, or checked by a
second period.

Frames ``shift-n``; with ``second_period`` a second N-step set ``second-shift-n``; then
``gray-0 .. gray-(B-1)`` (most significant first, ``B`` bits for the levels the code needs),
with ``complementary`` one more, ``gray-B``, and with ``inverse`` each code pattern's
inverse ``gray-i-inv`` after them (``frames`` may put them in any order, e.g. OpenCV's
``GrayCodePattern``: each pattern followed by its inverse). A pattern is bright where its
bit is 1; the Gray code of level ``j`` is ``j ^ (j >> 1)``.

Plain: the code gives ``k = floor(x/T)`` directly; its edges sit exactly on the phase wraps,
so blur and noise read pixels beside every edge one order off (the method's known limit);
per pixel those are left out (see below).

Shifted (``gray_offset = 0.5``; Wu Z. et al., Opt. Express 27(16), 2019): the code's edges
sit half a period off the phase jumps, ``g = floor(x/T + 1/2)`` over ``fringes + 1``
levels; ``k = g`` where ``phi < pi`` and ``g - 1`` where ``phi >= pi``. Its misreads move
from the phase jumps to mid-fringe, where the phase is continuous: the region strategy
outvotes them, and per pixel they take their fringe region's order
(:mod:`~bistair.codecs.graycode_edges`). With ``gray_wrap = 1`` (SLMaster's
``SinusShiftGrayCodePattern``) the code wraps cyclically, ``g = floor(x/T + 1/2) mod
fringes`` in ``ceil(log2(fringes))`` bits: ``g - 1 = -1`` is the last fringe.

Second period (``second_period = T2``; the layout of kamino410/phase-shifting, with OpenCV's
Gray code): the order read from the code is checked against the phase of a second N-step
set. Next to a code edge the true order is the code's or its neighbour on the side the
wrapped phase says (``k + 1`` where ``phi < pi``, ``k - 1`` where ``phi >= pi``); the one
whose coordinate predicts the second phase best is kept, and a pixel where neither predicts
it within half their separation is invalid. ``T / T2`` must not be close to a whole number.

Complementary (Zhang Q. et al., Opt. Lasers Eng. 50(4), 2012): the ``B+1`` patterns form a
Gray code of half-period resolution whose last bit has its edges mid-fringe. With ``k1``
from the first ``B`` bits and ``k2 = floor((K2 + 1)/2)`` from all of them, the three-zone
rule picks the code whose edges are far from the pixel: ``k2`` where ``phi < pi/2``,
``k2 - 1`` where ``phi >= 3*pi/2``, ``k1`` in between.

Stage 3 takes each pixel's order from the code (``strategy="pixel"``, the classic decode) or
votes it over each fringe region, the pixels far from the code's edges counting most
(``strategy="region"``), which removes the misreads beside the edges of a plain or shifted
code. Per pixel, an order the pixel's own evidence cannot carry is left out, not guessed
(:func:`~bistair.codecs.graycode_jit.read_orders`: bits that do not clear their noise, or
read under half the pixel's code contrast, away from their edges; a phase within three
sigmas of a code edge whose edge bits say the cell's other end); by regions, only the
pixels whose evidence carries their order vote.

Bits are binarised against the fringes' average intensity, or against the inverse patterns
when the spec has them (robust to albedo and ambient light); with inverses, a pixel whose
pattern and inverse differ by less than twice the modulation threshold (median over the
bits) is in shadow and invalid.

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
import math
from typing import Literal

import numpy as np

from ..core.captures import Prepared
from ..core.checks import cell_steps, direction_problem, refuse
from ..core.measure import FringeSet, measure
from ..core.phase import TWO_PI, wrap
from ..core.regions import core_weight, fringe_regions
from ..core.resolve import code_evidence, orders_from_regions
from ..errors import BistairError
from ..spec import PeriodSpec, field
from .base import (
    Codec,
    CodeMap,
    Orders,
    along_columns,
    fringe_index,
    measure_shifts,
    shift_patterns,
)
from .graycode_alone import code_alone, measure_alone
from .graycode_edges import edge_orders
from .graycode_jit import code_bits, orders_fit, read_orders
from .graylevels import code_digits, level_patterns, levels_code, order_levels, validate_levels

# The per-pixel evidence a read order needs (:func:`~.graycode_jit.read_orders`; measured
# in docs/guide/checks.md): a bit clears the noise of its margin by CLEAR_NOISE sigmas (a
# bit read on the wrong side does so with probability under 0.14%) and reads over
# CLEAR_SHARE of the pixel's code contrast (its strongest bit), unless the phase puts its
# edge within EDGE_REACH fringes (a blur that leaves the fringes 5% of the code's contrast
# still leaves a bit half a fringe from its edge 0.8 of it); the phase clears its own noise
# by CLEAR_NOISE sigmas where the code's edge sits on it.
CLEAR_NOISE = 3.0
CLEAR_SHARE = 0.5
EDGE_REACH = 0.5
# A dim pixel (read, not carried) is kept where its fringe region's strong pixels settle
# its order: over SETTLED of at least MIN_STRONG of them read it (:func:`region_carry`)
SETTLED = 0.99
MIN_STRONG = 50
# A part detached from its fringe region for codes that deny the region's order is decoded
# on its own where at least PART_CARRIED of its read pixels carry their code
# (:func:`part_carried`)
PART_CARRIED = 0.1


def gray_to_binary(gray: np.ndarray) -> np.ndarray:
    """Decode reflected Gray code integers.

    Parameters
    ----------
    gray : numpy.ndarray
        Non-negative integers in reflected Gray code, any shape and integer dtype.

    Returns
    -------
    numpy.ndarray
        The binary values, a new array of the same shape and dtype.

    Examples
    --------
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
    shiftless = True  # steps = 0: the Gray code alone (see the module docstring)

    complementary: int = field(0, "add the complementary pattern (three-zone rule)",
                               choices=(0, 1))
    inverse: int = field(0, "also project each code pattern's inverse to binarise against",
                         choices=(0, 1))
    gray_offset: float = field(0.0, "where the code's edges sit, as a fraction of a period "
                               "after the phase jumps: 0, or 0.5 for the shifted Gray code",
                               choices=(0.0, 0.5))
    # a spec file may leave gray_wrap out (0): the specs written before it existed mean 0,
    # and read against cyclic captures 0 is never wrong (their last half fringe, code 0
    # past the phase's middle, reads order -1: left out) or refused by the frame count
    gray_wrap: int = field(0, "1: the shifted code wraps cyclically over the fringes (the first "
                           "half period and the last share code 0; SLMaster's "
                           "SinusShiftGrayCodePattern), with gray_offset 0.5",
                           later=True, choices=(0, 1))
    second_period: float = field(0.0, "period of a second N-step set that checks the code's "
                                 "orders next to its edges (0: none)")
    code_levels: int = field(2, "grey levels of the code: 2, the binary Gray code; L > 2, a "
                             "base-L reflected Gray code read against the fringes (4: the "
                             "quaternary code)", later=True)

    @property
    def levels(self) -> int:
        """Code levels: the fringes, one more for the shifted code (unless it wraps
        cyclically), twice for the complementary one."""
        if self.complementary:
            return 2 * self.fringes
        return self.fringes + (1 if self.gray_offset and not self.gray_wrap else 0)

    @property
    def code_bits(self) -> int:
        """Gray code bits of the fringe count (the complementary pattern adds one); with
        ``code_levels`` L > 2 the base-L digits of the fringe count."""
        if self.code_levels != 2:
            return code_digits(self.fringes, self.code_levels)
        return max(1, int(np.ceil(np.log2(self.levels if not self.complementary
                                          else self.fringes))))

    def method_frames(self) -> tuple[str, ...]:
        codes = tuple(f"gray-{i}" for i in range(self.code_bits + self.complementary))
        if self.steps == 0:  # OpenCV's GrayCodePattern order: each bit, then its inverse
            return tuple(n for c in codes for n in ((c, f"{c}-inv") if self.inverse else (c,)))
        inverse = tuple(f"{c}-inv" for c in codes) if self.inverse else ()
        second = tuple(f"second-{n}" for n in self.shift_frames()) if self.second_period else ()
        return (*self.shift_frames(), *second, *codes, *inverse)

    def extra_frames(self) -> tuple[str, ...]:
        """``white``, and for a Gray code alone ``black`` after it (the mid-level the bits
        are read against without inverses, and the shadow mask: OpenCV's layout)."""
        if self.steps == 0 and self.white:
            return ("white", "black")
        return super().extra_frames()

    def validate(self) -> None:
        validate_levels(self)
        super().validate()
        if self.steps == 0:
            self._validate_alone()
        for name in ("complementary", "inverse", "gray_wrap"):
            if getattr(self, name) not in (0, 1):
                raise BistairError(f"{name} must be 0 or 1, got {getattr(self, name)}")
        if self.gray_offset not in (0.0, 0.5):
            raise BistairError(f"gray_offset must be 0 or 0.5, got {self.gray_offset}")
        if self.gray_offset and self.complementary:
            raise BistairError("a shifted Gray code (gray_offset 0.5) cannot be complementary")
        if self.gray_wrap and self.gray_offset != 0.5:
            raise BistairError("gray_wrap 1 wraps the shifted Gray code: it needs gray_offset "
                               f"0.5, got {self.gray_offset}")
        if self.second_period:
            if not (math.isfinite(self.second_period) and self.second_period >= 4):
                raise BistairError(f"second_period must be 0 (none) or at least 4 projector "
                                   f"pixels, got {self.second_period}")
            turn = abs(((self.period / self.second_period) + 0.5) % 1.0 - 0.5)
            if turn < 0.2:
                raise BistairError(
                    f"period / second_period = {self.period / self.second_period:.3f} is too "
                    "close to a whole number: a period off would not show in the second phase")


    def frame_count_hint(self, count: int) -> str:
        """The field that would make this spec's frames ``count`` where a near spec does:
        a shifted code one frame over the captures is likely SLMaster's cyclic one
        (``gray_wrap 1``, a code bit fewer); ``""`` else.

        Examples
        --------
        >>> spec = GrayCodeSpec(width=1920, height=1080, period=60, gray_offset=0.5)
        >>> spec.frame_count, spec.frame_count_hint(9)
        (10, 'gray_wrap 1 gives 9 (the cyclic shifted code)')
        >>> spec.frame_count_hint(8)
        ''
        """
        if not self.gray_offset or self.gray_wrap or self.frame_order:
            return ""
        cyclic = self.replace(gray_wrap=1)
        return (f"gray_wrap 1 gives {count} (the cyclic shifted code)"
                if cyclic.frame_count == count else "")

    def half_period_reading(self) -> str:
        """The spec fields that read the same frames with the code's edges half a period
        over (shifted for a plain code, plain for a shifted one), which explains captures
        equally with the phase offset pi away; ``""`` where no such reading has this spec's
        frames (complementary, a second period, no phase shifts).

        Examples
        --------
        >>> spec = GrayCodeSpec(width=1920, height=1080, period=60)
        >>> spec.half_period_reading()  # 32 fringes: 5 frames only if the code wraps
        'gray_offset 0.5 and gray_wrap 1'
        >>> spec.replace(period=40).half_period_reading()  # 48 fringes, 49 shifted levels
        'gray_offset 0.5'
        >>> spec.replace(complementary=1).half_period_reading()
        ''
        >>> spec.replace(gray_offset=0.5, gray_wrap=1).half_period_reading()
        'gray_offset 0 (gray_wrap 0)'
        """
        if self.steps == 0 or self.complementary or self.second_period or \
                self.code_levels != 2:  # (a multi-level code has no shifted twin)
            return ""
        if self.gray_offset:
            plain = self.replace(gray_offset=0.0, gray_wrap=0, frame_order=())
            return ("" if plain.code_bits != self.code_bits else
                    "gray_offset 0" + (" (gray_wrap 0)" if self.gray_wrap else ""))
        for cyclic, text in ((0, "gray_offset 0.5"), (1, "gray_offset 0.5 and gray_wrap 1")):
            if self.replace(gray_offset=0.5, gray_wrap=cyclic, frame_order=()).code_bits \
                    == self.code_bits:
                return text
        return ""

    def _validate_alone(self) -> None:
        """A Gray code without phase shifts: no second period, no complementary or shifted
        code (they refine a phase), and something to read the bits against."""
        for name in ("complementary", "gray_offset", "second_period"):
            if getattr(self, name):
                raise BistairError(f"{name} needs phase shifts: a Gray code alone (steps 0) "
                                   "has none")
        if not self.inverse:
            if not self.white:
                raise BistairError("a Gray code alone (steps 0) needs inverse patterns "
                                   "(inverse 1) or white and black frames (white 1) to read "
                                   "its bits against")
            if self.frame_order and "black" not in self.frame_order:
                raise BistairError("a Gray code alone without inverse patterns needs a black "
                                   "frame: add 'black' to frames")

    @classmethod
    def defaults(cls, params: dict) -> dict:
        """Defaults that depend on other parameters: a Gray code alone has cells of one
        projector pixel (OpenCV's ``GrayCodePattern``) unless a period is given."""
        if params.get("steps") == 0 and "period" not in params:
            return {"period": 1.0}
        return {}


def encode_columns(spec: GrayCodeSpec) -> np.ndarray:
    """The patterns of a Gray-code spec in the column layout, in method-frame order.

    The N-step set, the second N-step set (with ``second_period``), the ``code_bits`` Gray
    code patterns most significant first (one more when complementary) and, with
    ``inverse``, their inverses. A code pattern is ``offset + amplitude`` where its bit is 1,
    ``offset - amplitude`` where it is 0.

    Parameters
    ----------
    spec : GrayCodeSpec
        The spec of one coded axis.

    Returns
    -------
    numpy.ndarray
        (frames, other_length, coded_length) float32 intensities (fractions of full scale),
        a read-only view whose rows are all the same.

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("graycode", width=240, height=32, period=30)
    >>> pats = encode_columns(spec)
    >>> pats.shape
    (7, 32, 240)
    >>> (pats[4:, 0, 15::30] > 0.5).astype(int).tolist()  # the bits of fringes 0..7
    [[0, 0, 0, 0, 1, 1, 1, 1], [0, 0, 1, 1, 1, 1, 0, 0], [0, 1, 1, 0, 0, 1, 1, 0]]
    """
    if spec.code_levels != 2:
        return along_columns(np.concatenate([shift_patterns(spec), level_patterns(spec)]), spec)
    shifts = shift_patterns(spec)
    second = shift_patterns(spec, spec.second_period) if spec.second_period else shifts[:0]
    n_bits = spec.code_bits + spec.complementary
    if spec.complementary:
        level = fringe_index(spec, spec.period / 2)
    else:
        level = np.floor(np.arange(spec.coded_length) / spec.period + spec.gray_offset
                         + 1e-9).astype(np.int64)
        if spec.gray_wrap:  # the last half fringe shares the first one's code
            level %= spec.fringes
    gray = level ^ (level >> 1)
    bits = (gray[None, :] >> np.arange(n_bits - 1, -1, -1)[:, None]) & 1
    codes = spec.offset + spec.amplitude * (2.0 * bits - 1.0)
    if spec.inverse and spec.steps == 0:  # each bit, then its inverse
        codes = np.stack([codes, 2 * spec.offset - codes], axis=1).reshape(-1, codes.shape[1])
    elif spec.inverse:
        codes = np.concatenate([codes, 2 * spec.offset - codes])
    return along_columns(np.concatenate([shifts, second, codes]), spec)


def code_columns(prepared: Prepared, spec: GrayCodeSpec, fs: FringeSet,
                 min_modulation: float | None = None) -> CodeMap:
    """Stage 2: the fringe order read from the Gray code (three-zone rule when
    complementary, half-period rule when shifted, checked by the second phase when there is
    one), -1 where the fringes are not valid, the pixel is in shadow or the code is out of
    range.

    ``edges`` is the code as read, whose steps sit at the code's own edges (at wrapped phase
    ``edge_phase``): the decode checks them against the phase.

    Parameters
    ----------
    prepared : Prepared
        The method's frames in method order, column layout (coded axis along the image
        rows), as fractions of full scale.
    spec : GrayCodeSpec
        The spec of one coded axis.
    fs : FringeSet
        Stage 1: the wrapped phase in [0, 2*pi), the average the bits are binarised against
        (without inverses) and the valid pixels.
    min_modulation : float, optional
        The modulation (fraction of full scale) a pixel of the second N-step set needs.

    Returns
    -------
    CodeMap
        ``code``: (H, W) int32 fringe order as read (checked by the second phase where
        there is one), -1 where not decoded; ``maps["carried"]`` where the pixel's own
        evidence carries it; ``maps["edges"]`` the code whose steps are the code's edges
        (-1 where invalid), ``maps["second_phase"]`` with a second period;
        ``edge_phase`` 0 (pi for the shifted code); ``beyond``, the valid pixels whose code
        names a fringe past the projector's last.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=240, height=32, period=30)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> code.code.dtype, code.code[0, ::30].tolist(), code.edge_phase, code.beyond
    (dtype('int32'), [0, 1, 2, 3, 4, 5, 6, 7], 0.0, 0)
    """
    if spec.steps == 0:
        return code_alone(prepared, fs, spec.code_bits, bool(spec.inverse), spec.fringes)
    if spec.code_levels != 2:
        return levels_code(prepared, spec, fs)
    n = spec.steps
    start = n * (2 if spec.second_period else 1)
    n_bits = spec.code_bits + spec.complementary
    valid = fs.valid
    if spec.inverse and fs.threshold is not None:
        code = prepared.frames[start:start + n_bits]
        ref = prepared.frames[start + n_bits:start + 2 * n_bits]
        valid = valid & (np.median(np.abs(code - ref), axis=0) >= 2.0 * fs.threshold)
        del code, ref
    maps: dict[str, np.ndarray] = {}
    mode = 1 if spec.complementary else (3 if spec.gray_wrap else 2) if spec.gray_offset else 0
    # the noise of a bit's margin (frame minus inverse, or minus the average of n frames),
    # and of the phase times the modulation
    evidence = (fs.noise * math.sqrt(2.0 if spec.inverse else 1.0 + 1.0 / n),
                fs.noise / math.sqrt(n / 2), CLEAR_NOISE, CLEAR_SHARE, EDGE_REACH)
    if not spec.second_period:  # per pixel in one pass, with the evidence of each order
        code, maps["edges"], maps["carried"], beyond = read_orders(
            prepared.raw, start, n_bits, prepared.scale, fs.avg, bool(spec.inverse), fs.phi,
            fs.mod, valid, mode, spec.fringes, *evidence)
        return CodeMap(code, maps, edge_phase=np.pi if mode >= 2 else 0.0, beyond=beyond)
    # each bit: the code frame brighter than the average (or its inverse), in one pass
    gray = code_bits(prepared.raw, start, n_bits, prepared.scale, fs.avg, bool(spec.inverse))
    if spec.complementary:
        k1 = gray_to_binary(gray >> 1)
        k2 = (gray_to_binary(gray) + 1) // 2
        k = np.where(fs.phi < np.pi / 2, k2, np.where(fs.phi >= 1.5 * np.pi, k2 - 1, k1))
        edges, edge_phase = k1, 0.0
    elif spec.gray_offset:
        g = gray_to_binary(gray)
        k = np.where(fs.phi < np.pi, g, g - 1)
        if spec.gray_wrap:  # code 0 past the phase's middle: the last fringe
            k = np.where(g >= spec.fringes, spec.fringes, np.where(k < 0, spec.fringes - 1, k))
        edges, edge_phase = g, np.pi
    else:
        k = edges = gray_to_binary(gray)
        edge_phase = 0.0
    second = measure(prepared, n, n, min_modulation, check=False,
                     shift_sign=spec.shift_sign, phase_offset=spec.phase_offset)
    k, agree = _second_period_check(k, fs, second, spec)
    valid = valid & second.valid & agree
    maps["second_phase"] = second.phi
    ok = valid & (k >= 0) & (k < spec.fringes)
    maps["edges"] = np.where(valid, edges, -1).astype(np.int32)
    beyond = int(np.count_nonzero(valid & (k >= spec.fringes)))
    code = np.where(ok, k, -1).astype(np.int32)
    # where the order the second phase chose fits the code's own evidence
    maps["carried"] = orders_fit(prepared.raw, start, n_bits, prepared.scale, fs.avg,
                                 bool(spec.inverse), fs.phi, fs.mod, code, mode, spec.fringes,
                                 *evidence)
    return CodeMap(code, maps, edge_phase=edge_phase, beyond=beyond)


def _second_period_check(k: np.ndarray, fs: FringeSet, second: FringeSet,
                         spec: GrayCodeSpec) -> tuple[np.ndarray, np.ndarray]:
    """The order (the code's, or its neighbour on the phase's side) that predicts the second
    phase best, and where that prediction is within half the candidates' separation and
    the two phases' noise (``CLEAR_NOISE`` sigmas of the prediction's) is under half of
    it: where the second phase tells the two apart."""
    ratio = spec.period / spec.second_period
    phi, phi2 = fs.phi, second.phi
    side = np.where(phi < np.pi, 1, -1)
    errs = []
    for cand in (k, k + side):
        pred = (cand + phi / TWO_PI) * (TWO_PI * ratio)
        errs.append(np.abs(wrap(pred - phi2)))
    best = np.where(errs[1] < errs[0], k + side, k)
    best_err = np.minimum(errs[0], errs[1])
    separation = abs(wrap(np.array(TWO_PI * ratio)))
    sigma = np.hypot(ratio * fs.phase_noise, second.phase_noise)
    return best, (best_err < 0.5 * separation) & (CLEAR_NOISE * sigma < 0.5 * separation)


def order_columns(fs: FringeSet, code: CodeMap, spec: GrayCodeSpec, *,
                  strategy: Literal["pixel", "region"] = "pixel") -> Orders:
    """Stage 3: the code is the order, per pixel (``pixel``, the classic decode; -1 where
    the pixel's own evidence does not carry it, ``code.maps["carried"]``), or voted per
    fringe region with the pixels far from the code's edges counting most (``region``: a
    code misread beside its edges is outvoted by the rest of its fringe).

    Parameters
    ----------
    fs : FringeSet
        Stage 1, column layout.
    code : CodeMap
        Stage 2 (:func:`code_columns`).
    spec : GrayCodeSpec
        The spec of one coded axis.
    strategy : {"pixel", "region"}
        Per-pixel orders (the classic decode) or one order per fringe region.

    Returns
    -------
    Orders
        (H, W) fringe order per pixel (-1 where invalid) and ``info``: the strategy, the
        camera noise, the code bits, the pixels read but left out (``left_out``), and for
        ``region`` the region counts and the phase jumps across which the orders do not
        step by one; per pixel, ``read``: the orders as read, which the checks judge.

    Raises
    ------
    BistairError
        ``strategy`` is neither ``"pixel"`` nor ``"region"``.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=240, height=32, period=30)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> orders = order_columns(fs, code, spec, strategy="region")
    >>> orders.order[0, ::30].tolist(), orders.info["regions"], orders.info["jump_violations"]
    ([0, 1, 2, 3, 4, 5, 6, 7], 8, 0)
    >>> order_columns(fs, code, spec, strategy="mode")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: unknown strategy 'mode' (use 'pixel' or 'region')
    """
    if strategy not in ("pixel", "region"):
        raise BistairError(f"unknown strategy {strategy!r} (use 'pixel' or 'region')")
    if strategy == "region" and spec.steps == 0:
        raise BistairError("strategy 'region' needs phase shifts: a Gray code alone (steps 0) "
                           "decodes per pixel")
    info = {"strategy": strategy, "noise": fs.noise,
            "bits": spec.code_bits + spec.complementary}
    read = code.code
    if strategy == "pixel" and spec.code_levels != 2:
        return order_levels(fs, code, spec, info)
    if strategy == "pixel":
        # the orders the pixels' own evidence carries (all read ones where it is not judged)
        carried = code.maps.get("carried")
        k = read if carried is None else np.where(carried, read, -1)
        if carried is not None and spec.steps:
            regions = fringe_regions(fs.phi, fs.valid & (read >= 0),
                                     phase_noise=fs.phase_noise, links=fs.links)
            k, info["region_carried"] = region_carry(fs, read, k, spec.fringes,
                                                     regions=regions)
            if spec.gray_offset:  # beside the shifted code's edges: the region's order
                k, info["edge_orders"] = edge_orders(fs, read, k, spec.fringes,
                                                     bool(spec.gray_wrap), regions)
        if carried is not None:
            info["left_out"] = int(np.count_nonzero(read >= 0)) - int(np.count_nonzero(k >= 0))
        if spec.steps == 0:  # no phase to check the cells against: their direction
            against, steps = cell_steps(k)
            info.update(cell_steps=steps, cell_steps_against=against)
            refuse(direction_problem(against, steps))
        return Orders(k, info, read=None if carried is None else read)
    # every pixel read votes (votes from only the pixels whose evidence carries their order
    # leave regions without votes to their neighbours: on the rendered presets 0.03-0.3% of
    # the pixels wrong became 0.06-4%)
    labels, _ = fringe_regions(fs.phi, fs.valid & (read >= 0), phase_noise=fs.phase_noise,
                               links=fs.links)
    weight = core_weight((fs.phi - np.float32(code.edge_phase)) % np.float32(TWO_PI))

    carried = code.maps.get("carried")
    first = int(labels.max())

    def evidence_of(labels: np.ndarray, n: int) -> tuple[np.ndarray, int, np.ndarray]:
        evidence = code_evidence(labels, n, read, spec.fringes, weight)
        if n > first and carried is not None:
            evidence[first + 1:][~part_carried(labels, first, n, read, carried)] = 0.0
        return labels, n, evidence

    def agrees(order: np.ndarray) -> np.ndarray:
        return (read == order) | (read < 0)

    order = orders_from_regions(fs.phi, fs.valid & (read >= 0), labels, evidence_of, agrees,
                                info)
    return Orders(order, info)


def part_carried(labels: np.ndarray, first: int, n: int, read: np.ndarray,
                 carried: np.ndarray, share: float = PART_CARRIED) -> np.ndarray:
    """Which parts detached from their regions (labels ``first + 1 .. n``) have codes their
    own pixels' evidence carries: at least ``share`` of the part's read pixels carried.

    A part is detached where its codes deny its region's order (two surfaces in one
    region); where that denial rests on codes no pixel's evidence carries, the part is a
    misread, not a surface, and is left undecided rather than decoded on it.

    Parameters
    ----------
    labels : (H, W) int array
        Fringe regions, the detached parts numbered from ``first + 1``.
    first : int
        The highest label before any part was detached.
    n : int
        The highest label.
    read : (H, W) int array
        The order each pixel's code reads, negative where it reads none.
    carried : (H, W) bool array
        Where the pixel's own evidence carries its read order.
    share : float
        The share of a part's read pixels that must carry their code.

    Returns
    -------
    (n - first,) bool array
        Per part (label ``first + 1`` first), whether it is carried.

    Examples
    --------
    >>> labels = np.array([[1, 1, 2, 2, 3, 3]])
    >>> read = np.array([[0, 0, 1, 1, 1, 1]])
    >>> carried = np.array([[1, 1, 1, 0, 0, 0]], bool)
    >>> part_carried(labels, 1, 3, read, carried).tolist()
    [True, False]
    """
    parts = labels > first
    index = labels[parts] - (first + 1)
    reads = np.bincount(index, weights=read[parts] >= 0, minlength=n - first)
    strong = np.bincount(index, weights=carried[parts] & (read[parts] >= 0), minlength=n - first)
    return strong >= share * np.maximum(reads, 1)


def region_carry(fs: FringeSet, read: np.ndarray, carried: np.ndarray, fringes: int,
                 settled: float = SETTLED, min_strong: int = MIN_STRONG,
                 regions: tuple[np.ndarray, int] | None = None
                 ) -> tuple[np.ndarray, int]:
    """Keep the orders read where the pixel's own evidence does not carry them but its
    fringe region's strong pixels settle the same order.

    A fringe region (between phase wraps) holds one order; where at least ``min_strong``
    of its pixels carry their orders and over ``settled`` of them read the same one, a dim
    pixel of the region (read, not carried) that reads that order is kept.

    Parameters
    ----------
    fs : FringeSet
        Stage 1: the phase, validity and phase noise the regions are cut by.
    read : numpy.ndarray
        (H, W) int32 orders as read (-1 where none).
    carried : numpy.ndarray
        (H, W) int32 orders the pixels' own evidence carries (-1 elsewhere).
    fringes : int
        Fringes across the coded axis (the orders' range).
    settled : float, default SETTLED
        Share of a region's strong pixels that must read one order.
    min_strong : int, default MIN_STRONG
        Strong pixels a region needs.
    regions : tuple of (numpy.ndarray, int), optional
        The fringe regions of ``fs`` over the pixels read, if already cut.

    Returns
    -------
    orders : numpy.ndarray
        (H, W) int32, ``carried`` with the kept dim pixels' orders.
    kept : int
        The dim pixels kept.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=240, height=32, period=30, complementary=1)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> read = code_columns(cols, spec, fs).code
    >>> carried = read.copy()
    >>> carried[:, 40:50] = -1  # dim pixels in fringe 1
    >>> read[:16, 40:50] = 2  # half of them read another order than their region's
    >>> orders, kept = region_carry(fs, read, carried, spec.fringes)
    >>> kept, int(orders[16:, 40:50].min()), int(orders[:16, 40:50].max())
    (160, 1, -1)
    """
    read_any = read >= 0
    dim = np.flatnonzero(read_any & (carried < 0))
    if not dim.size:
        return carried, 0
    labels, n = regions or fringe_regions(fs.phi, fs.valid & read_any,
                                          phase_noise=fs.phase_noise, links=fs.links)
    shares = code_evidence(labels, n, carried, fringes)
    strong = np.bincount(labels[carried >= 0], minlength=n + 1)
    order = np.where((shares.max(axis=1) > settled) & (strong >= min_strong),
                     shares.argmax(axis=1), -1)
    order[0] = -1
    kept = dim[read.ravel()[dim] == order[labels.ravel()[dim]]]
    out = np.array(carried, dtype=np.int32, order="C")  # a copy
    out.ravel()[kept] = read.ravel()[kept]
    return out, int(kept.size)


def measure_columns(prepared: Prepared, spec: GrayCodeSpec,
                    min_modulation: float | None = None) -> FringeSet:
    """Stage 1: the N-step set (:func:`~bistair.codecs.base.measure_shifts`), or for a Gray
    code alone the contrast and validity of its bits
    (:func:`~bistair.codecs.graycode_alone.measure_alone`).

    Parameters
    ----------
    prepared : Prepared
        The method's frames in method order, column layout.
    spec : GrayCodeSpec
        The spec of one coded axis.
    min_modulation : float, optional
        The modulation (fraction of full scale) a valid pixel needs.

    Returns
    -------
    FringeSet
        The stage-1 maps (see the two functions).

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=64, height=16, steps=0, inverse=1)
    >>> measure_columns(prepare(encode(spec), spec.frame_count, "graycode"), spec).steps
    0
    """
    if spec.steps == 0:
        return measure_alone(prepared, spec.code_bits, bool(spec.inverse), spec.period,
                             min_modulation)
    return measure_shifts(prepared, spec, min_modulation)


def comparable(width: int, height: int, period: int, steps: int) -> dict:
    """The complementary Gray code at the same period.

    Parameters
    ----------
    width, height : int
        Projector size in pixels (not used: the code covers any width).
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
    {'period': 30, 'complementary': 1, 'steps': 4}
    """
    return dict(period=period, complementary=1, steps=steps)


CODEC = Codec(
    name="graycode",
    spec_class=GrayCodeSpec,
    summary="N phase shifts + Gray code (complementary, shifted, with inverses, or checked "
            "by a second period)",
    encode_columns=encode_columns,
    code_columns=code_columns,
    order_columns=order_columns,
    measure_columns=measure_columns,
    comparable=comparable,
)
