"""The interface every method implements, and the plumbing all methods share.

A codec is a spec class and four functions on the coded axis laid out along image columns
(captures of the rows orientation are decoded transposed):

====================================================  =========================================
``encode_columns(spec)``                              ``(F, other, coded)`` patterns in [0, 1]
``measure_columns(prepared, spec, min_mod)``          stage 1, the phase map: a
                                                      :class:`~bistair.core.measure.FringeSet`
``code_columns(prepared, spec, fringes, min_mod)``    stage 2, the code map: a :class:`CodeMap`
``order_columns(fringes, code, spec, **options)``     stage 3, the orders: an :class:`Orders`
====================================================  =========================================

:class:`Codec` wraps them with what every capture goes through (frame count, scaling, frame
order, orientation, projector gamma, bit depth) and exposes the stages like OpenCV's
structured-light decoders (``computePhaseMap``, ``computeFloorMap``): :meth:`Codec.phase_map`,
:meth:`Codec.code_map` and :meth:`Codec.decode`, each in camera image axes.

Examples
--------
>>> import numpy as np
>>> from bistair.codecs import get_codec, make_spec
>>> spec = make_spec("graycode", width=240, height=32, period=30)
>>> codec = get_codec("graycode")
>>> patterns = codec.encode(spec)
>>> fringes = codec.phase_map(patterns, spec)
>>> code = codec.code_map(patterns, spec)
>>> code.code[0, ::30].tolist(), codec.options
([0, 1, 2, 3, 4, 5, 6, 7], ('min_modulation', 'force', 'strategy'))
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, Literal, get_args, get_origin

import numpy as np

from ..core.captures import Prepared, check_min_modulation, prepare
from ..core.checks import EdgeCheck, Judge, forcing, sample_checks
from ..core.checks import shift_order_problem as shift_order_problem  # (its old place)
from ..core.measure import FringeSet, measure
from ..core.phase import phase_shift_patterns
from ..core.result import (
    AxesResult,
    DecodeResult,
    narrow_code,
    result_from_orders,
    transpose_own,
)
from ..errors import BistairError
from ..spec import AXES, BaseSpec, PeriodSpec, fringe_count


@dataclass
class CodeMap:
    """Stage 2 of a decode: the method's code word per pixel and the maps it came from.

    Attributes
    ----------
    code : int32, the code word (``k_s`` for the stair methods, the Gray-code order, the
        order from the coarser phases for multi-frequency), -1 where not decoded.
    maps : named method-specific maps of the same shape (e.g. ``stair_phase``). ``edges``,
        if present, is the code as read from its own patterns (else ``code`` is), whose
        steps sit where the wrapped phase is ``edge_phase`` (0: at the phase jumps).
    edge_phase : the wrapped phase at the code's edges.
    cycle : the code repeats every ``cycle`` values (a stair), or ``None``.
    check : a codec's own check of the phase convention, where its code says nothing of
        it (multi-frequency: the code comes from the phases themselves).
    beyond : valid pixels whose code names a fringe beyond the projector's last (counted
        with the coordinates outside the projector).
    """

    code: np.ndarray
    maps: dict[str, np.ndarray] = field(default_factory=dict)
    edge_phase: float = 0.0
    cycle: int | None = None  # the code repeats every ``cycle`` values (a stair)
    check: EdgeCheck | None = None  # a codec's own check of the phase convention
    beyond: int = 0  # pixels whose code names a fringe beyond the projector's last

    @property
    def edges(self) -> np.ndarray:
        """The code whose steps are the code's own edges (see the attributes)."""
        return self.maps.get("edges", self.code)

    def transposed(self) -> CodeMap:
        """The same maps with image axes swapped (for the rows orientation)."""
        return CodeMap(np.ascontiguousarray(self.code.T),
                       {k: np.ascontiguousarray(v.T) for k, v in self.maps.items()},
                       self.edge_phase, self.cycle, self.check, self.beyond)


@dataclass
class Orders:
    """Stage 3 of a decode: the fringe order per pixel (int, -1 where invalid) and figures
    about it; ``read``, where a per-pixel decoder left out pixels whose own evidence cannot
    carry their order, the orders as its code read them, which the checks of the whole
    decode judge (without those pixels the orders can step by one across every wrap of a
    code read wrong: the pixels at the wraps, where code and phase disagree, are the ones
    left out)."""

    order: np.ndarray
    info: dict[str, Any] = field(default_factory=dict)
    read: np.ndarray | None = None


MeasureFn = Callable[[Prepared, Any, float | None], FringeSet]
CodeFn = Callable[[Prepared, Any, FringeSet, float | None], CodeMap]
OrderFn = Callable[..., Orders]


def measure_shifts(prepared: Prepared, spec: PeriodSpec,
                   min_modulation: float | None = None) -> FringeSet:
    """Stage 1 of the single-period methods: their N-step set, the first ``steps`` frames,
    in the spec's phase convention.

    Parameters
    ----------
    prepared : Prepared
        The method's frames in method order, column layout (coded axis along the image
        rows), as fractions of full scale.
    spec : PeriodSpec
        The spec: ``steps``, ``shift_sign`` and ``phase_offset`` are used.
    min_modulation : float, optional
        The modulation (fraction of full scale) a valid pixel needs; by default a threshold
        from the measured camera noise.

    Returns
    -------
    FringeSet
        (H, W) float32 wrapped phase in [0, 2*pi) (radians), average and modulation
        (fractions of full scale), the validity mask and the camera noise; for a method
        with a cos/sin code pair right after the set (:func:`pair_frame`), its phase and
        modulation (``stair``), read in the same pass.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=240, height=32, period=30)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> fs.phi.shape, int(fs.valid.sum())
    ((32, 240), 7680)
    >>> (fs.phi[0, 7:30:7] * 30 / (2 * np.pi)).round(2).tolist()  # projector pixels
    [7.0, 14.0, 21.0, 28.0]
    """
    return measure(prepared, 0, spec.steps, min_modulation, shift_sign=spec.shift_sign,
                   phase_offset=spec.phase_offset, pair=pair_frame(spec))


def pair_frame(spec: BaseSpec) -> int | None:
    """The index of a cos/sin pair of code frames right after the N-step set (frames named
    ``...-cos`` and ``...-sin``: the stair or code pair of bidirectional, lv and
    phase-coding), which the phase stage reads in its own pass; ``None`` without one.

    Parameters
    ----------
    spec : BaseSpec
        The spec of one coded axis.

    Returns
    -------
    int or None

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> pair_frame(make_spec("lv", width=240, height=32, period=20))
    4
    >>> pair_frame(make_spec("graycode", width=240, height=32, period=30)) is None
    True
    """
    names = spec.method_frames()
    n = getattr(spec, "steps", 0)
    if len(names) >= n + 2 and names[n].endswith("-cos") and names[n + 1].endswith("-sin"):
        return n
    return None


@dataclass(frozen=True)
class Codec:
    """A method: its name, spec class and the functions of its stages (column layout).

    ``comparable(width, height, period, steps)`` gives the spec parameters of the method's
    pattern set that compares with the others on a projector (for the benchmark and the
    simulator); ``variants`` names decoder options worth comparing too (label -> options).
    ``aligned``: the decoder needs the coded axis to run along the image's rows of the
    column layout (bands of a code down the image), so captures whose phase changes more
    across that axis are refused; for the others it is a warning (a camera turned against
    the projector, as on a rig rolled by 90 degrees, decodes right with a per-pixel code).
    """

    name: str
    spec_class: type[BaseSpec]
    summary: str
    encode_columns: Callable[[Any], np.ndarray]
    order_columns: OrderFn
    code_columns: CodeFn
    measure_columns: MeasureFn = measure_shifts
    comparable: Callable[[int, int, int, int], dict[str, Any]] | None = None
    variants: dict[str, dict[str, Any]] = field(default_factory=dict)
    aligned: bool = False

    @property
    def options(self) -> tuple[str, ...]:
        """Decode keyword options: ``min_modulation``, ``force`` and those of the order
        stage."""
        params = inspect.signature(self.order_columns).parameters.values()
        return ("min_modulation", "force",
                *(p.name for p in params if p.kind is p.KEYWORD_ONLY))

    @property
    def choices(self) -> dict[str, tuple[Any, ...]]:
        """The values of each order-stage option declared as a ``Literal``, the default
        first (e.g. ``{"strategy": ("region", "paper")}``), for the command line's help."""
        params = inspect.signature(self.order_columns, eval_str=True).parameters.values()
        out = {}
        for p in params:
            if p.kind is p.KEYWORD_ONLY and get_origin(p.annotation) is Literal:
                values = get_args(p.annotation)
                out[p.name] = (p.default, *(v for v in values if v != p.default))
        return out

    # -- encoding ----------------------------------------------------------------------------
    def encode(self, spec: BaseSpec) -> np.ndarray:
        """Patterns as float32 in [0, 1], shape (frames, height, width), in the order of
        ``spec.frames``, gamma pre-compensated; ``black`` and ``ignore`` frames are dark."""
        by_name: dict[str, np.ndarray] = {}
        for axis, sub in spec.axes():
            pats = np.clip(np.asarray(self.encode_columns(sub), dtype=np.float64), 0.0, 1.0)
            if axis == "rows":
                pats = pats.transpose(0, 2, 1)
            tag = f"{AXES[axis]}/" if spec.orientation == "both" else ""
            by_name.update((tag + name, p) for name, p in zip(sub.method_frames(), pats,
                                                              strict=True))
        lit = np.ones((spec.height, spec.width))
        dark = np.zeros((spec.height, spec.width))
        pats = np.stack([by_name.get(n, lit if n == "white" else dark) for n in spec.frames])
        if spec.gamma != 1.0:
            pats = pats ** (1.0 / spec.gamma)
        return np.ascontiguousarray(pats, dtype=np.float32)

    # -- decoding stages ---------------------------------------------------------------------
    def _columns(self, images: np.ndarray, spec: BaseSpec) -> tuple[Prepared, Prepared]:
        """The checked, scaled stack and its method frames in method order, coded axis along
        the columns (white and black frames kept beside them)."""
        if spec.method != self.name:
            raise BistairError(f"a {spec.method} spec cannot be decoded by the {self.name} codec")
        if spec.orientation == "both":
            raise BistairError("a spec of both axes decodes with decode(), axis by axis")
        if np.ndim(images) == 3 and len(images) != spec.frame_count:
            raise frame_count_error(spec, len(images))
        frames = spec.frames
        roles = {role: frames.index(role) if role in frames else None
                 for role in ("white", "black")}
        prepared = prepare(images, spec.frame_count, self.name,
                           select=[frames.index(name) for name in spec.method_frames()],
                           **roles)
        if spec.orientation == "rows":
            return prepared, prepared.transposed()
        return prepared, prepared

    def phase_map(self, images: np.ndarray, spec: BaseSpec,
                  min_modulation: float | None = None) -> FringeSet:
        """Stage 1: wrapped phase, average, modulation and validity of the captures."""
        _, cols = self._columns(images, spec)
        fs = self.measure_columns(cols, spec, min_modulation)
        return fs.transposed() if spec.orientation == "rows" else fs

    def code_map(self, images: np.ndarray, spec: BaseSpec,
                 min_modulation: float | None = None) -> CodeMap:
        """Stage 2: the method's code word per pixel (-1 where not decoded)."""
        _, cols = self._columns(images, spec)
        fs = self.measure_columns(cols, spec, min_modulation)
        code = self.code_columns(cols, spec, fs, min_modulation)
        return code.transposed() if spec.orientation == "rows" else code

    def decode(self, images: np.ndarray, spec: BaseSpec,
               **options: Any) -> DecodeResult | AxesResult:
        """All stages: absolute phase, projector coordinate and fringe order per pixel.

        A spec of both axes gives an :class:`~bistair.core.result.AxesResult` (one decode
        per axis), any other a :class:`~bistair.core.result.DecodeResult`. With
        ``force=True``, the thresholded checks that would refuse the captures (the shares
        of :mod:`bistair.core.checks` and the codecs' own) are reported instead: their
        reasons in ``info["forced"]`` and as warnings; hard errors (frame count, no valid
        pixel) still raise.
        """
        unknown = set(options) - set(self.options)
        if unknown:
            raise BistairError(
                f"the {self.name} decoder has no option(s) {', '.join(sorted(unknown))}"
            )
        check_min_modulation(options.get("min_modulation"))
        if spec.orientation == "both":
            x, y = (self.decode(images, axis_spec, **options) for _, axis_spec in spec.axes())
            return AxesResult(x, y, spec=spec)
        force = bool(options.pop("force", False))
        with forcing(force) as forced:
            result = self._decode(images, spec, **options)
        if forced:  # decoded where thresholded checks would have refused
            result.info["forced"] = list(forced)
            result.info["warnings"] = [*result.info.get("warnings", []),
                                       *(f"forced past a check: {p}" for p in forced)]
        result.spec = spec  # for the reconstruction: the coded axis, the projector's size
        return result

    def _decode(self, images: np.ndarray, spec: BaseSpec, **options: Any) -> DecodeResult:
        """One axis of :meth:`decode` (the thresholded checks through
        :func:`~bistair.core.checks.refuse`)."""
        min_modulation = options.pop("min_modulation", None)
        prepared, cols = self._columns(images, spec)
        judge = Judge(spec, aligned=self.aligned)
        with sample_checks(judge):  # the frame order and the axis, on pass 0's sample
            fs = self.measure_columns(cols, spec, min_modulation)
        code = self.code_columns(cols, spec, fs, min_modulation)
        del cols
        fs = replace(fs, stair=None)  # (the code's maps hold the pair: let go with them)
        judge.convention(fs, code.check, code.edges, code.edge_phase, code.cycle)
        orders = self.order_columns(fs, code, spec, **options)
        # the code's maps let go with it once the orders are made (the words narrowed for the
        # result: int8 for up to 127 fringes), the phase noise and the sample too
        words, beyond = narrow_code(code.code, most_code(spec, code.cycle)), code.beyond
        edge_phase = code.edge_phase
        read_top = int(code.edges.max()) if beyond else -1  # codes past the projector's end
        del code
        fs = replace(fs, sigma=None, sample=None)
        orders.info.update(judge.seen)
        if judge.warnings:
            orders.info["warnings"] = [*orders.info.get("warnings", []), *judge.warnings]
        judge.blocks(fs, orders)
        judge.edges(fs, orders, edge_phase)
        judge.steps(orders)
        orders.info.setdefault("valid_modulation", judge.sparse(fs, orders.order))
        orders.read = None  # (judged: let go before the result's arrays are made)
        # pass 2: the orders and the wrapped phase become the result's, written over where
        # nothing else (the result's other arrays, the captures) shares their memory; the
        # phase and the mask are the only new arrays
        order = orders.order
        # the top coordinate read, for a hint of the other orientation
        top = (max(read_top, int(order.max()) if order.size else -1) + 1) * spec.period
        kept = [a for a in (fs.mod, fs.avg, fs.valid, words, images, prepared.raw,
                            prepared.white) if isinstance(a, np.ndarray)]
        reuse = not np.may_share_memory(fs.phi, order) and not any(
            np.may_share_memory(a, b) for a in (fs.phi, order) for b in kept)
        result = result_from_orders(self.name, fs, order, spec.period, code=words,
                                    info=orders.info, length=spec.coded_length, reuse=reuse)
        del fs, orders, order, kept, words
        if beyond:
            result.info["outside_projector"] = (result.info.get("outside_projector", 0)
                                                + beyond)
        decoded = int(np.count_nonzero(result.mask))
        judge.outside(result.info, decoded, top)
        result.info["valid_pixels"] = decoded
        result.info.setdefault("full_scale", prepared.full_scale)
        if spec.orientation == "rows":  # (only this function holds the result: turned array
            result = transpose_own(result)  # by array, not copied whole)
        result.texture = prepared.white
        return result


def frame_count_error(spec: BaseSpec, count: int) -> BistairError:
    """The error for ``count`` captures where ``spec`` needs another number of frames, with
    the spec's hint of a near spec that needs ``count`` (``frame_count_hint``) if it has
    one.

    Parameters
    ----------
    spec : BaseSpec
        The spec the captures were given with.
    count : int
        The frames captured.

    Returns
    -------
    BistairError

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("graycode", width=1920, height=1080, period=60, gray_offset=0.5)
    >>> print(frame_count_error(spec, 9))  # doctest: +NORMALIZE_WHITESPACE
    the graycode spec needs 10 frames, the captures have 9: gray_wrap 1 gives 9
    (the cyclic shifted code)
    """
    hint = getattr(spec, "frame_count_hint", lambda count: "")(count)
    return BistairError(f"the {spec.method} spec needs {spec.frame_count} frames, the captures "
                        f"have {count}" + (f": {hint}" if hint else ""))


def most_code(spec: BaseSpec, cycle: int | None = None) -> int:
    """The largest code word a decode of ``spec`` can write: every word of a binary code
    over its fringes (``2**bits - 1`` for the bits that count them, a fringe past the last
    included), or a stair's ``cycle`` if that is more; the result's code is kept in the
    smallest integer dtype that holds it (:func:`~bistair.core.result.narrow_code`).

    Parameters
    ----------
    spec : BaseSpec
        The spec of one axis (its coded length and period).
    cycle : int, optional
        The code's cycle (:class:`CodeMap`), if it repeats.

    Returns
    -------
    int

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> most_code(make_spec("graycode", width=1920, height=1080, period=30))  # 64 fringes
    127
    """
    fringes = fringe_count(spec.coded_length, spec.period)
    return max((1 << fringes.bit_length()) - 1, cycle or 0)


def check_convention(fs: FringeSet, code: CodeMap, spec: BaseSpec) -> list[str]:
    """Refuse captures whose code steps do not sit where the spec's phase convention puts
    them (:mod:`bistair.core.checks`); returns the warnings worth a line.

    Parameters
    ----------
    fs : FringeSet
        Stage 1, column layout.
    code : CodeMap
        Stage 2, column layout; its own ``check`` is used if it has one, else its ``edges``
        are aligned against the wrapped phase (at ``edge_phase``, every ``cycle`` values).
    spec : BaseSpec
        The spec whose ``phase_offset`` and ``shift_sign`` the captures should follow.

    Returns
    -------
    list of str
        Warnings (empty when the code's steps sit where they should).

    Raises
    ------
    BistairError
        The code's steps sit clearly elsewhere than the convention puts them (another
        ``phase_offset`` or ``shift_sign``).

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=240, height=32, period=30)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> from bistair.codecs.graycode import code_columns
    >>> fs = measure_shifts(cols, spec)
    >>> check_convention(fs, code_columns(cols, spec, fs), spec)
    []
    >>> other = spec.replace(phase_offset=1.0)  # not how the patterns were made
    >>> fs = measure_shifts(cols, other)
    >>> check_convention(fs, code_columns(cols, other, fs), other)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the captures do not fit the spec: the code steps where ...
    """
    return Judge(spec).convention(fs, code.check, code.edges, code.edge_phase, code.cycle)


def fringe_index(spec: BaseSpec, period: float | None = None) -> np.ndarray:
    """``floor(x / period)`` for every projector pixel ``x`` along the coded axis (int64; the
    spec's period by default). A hair of tolerance keeps pixels that sit exactly on a
    fringe edge of a fractional period (``1920/58``) in the fringe their phase says.

    Parameters
    ----------
    spec : BaseSpec
        The spec: ``coded_length`` and (by default) ``period`` are used.
    period : float, optional
        The period in projector pixels, instead of the spec's.

    Returns
    -------
    numpy.ndarray
        (coded_length,) int64, the fringe order of every projector pixel.

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> fringe_index(make_spec("graycode", width=120, height=16, period=30))[28:32].tolist()
    [0, 0, 1, 1]
    """
    x = np.arange(spec.coded_length, dtype=np.float64)
    return np.floor(x / (spec.period if period is None else period) + 1e-9).astype(np.int64)


def shift_patterns(spec: BaseSpec, period: float | None = None) -> np.ndarray:
    """The N-step fringe patterns along the coded axis, ``(steps, coded_length)``, in the
    spec's phase convention (``phase_offset``, ``shift_sign``).

    Parameters
    ----------
    spec : BaseSpec
        The spec: ``coded_length``, ``steps``, ``offset``, ``amplitude``, ``phase_offset``,
        ``shift_sign`` and (by default) ``period`` are used.
    period : float, optional
        The period in projector pixels, instead of the spec's.

    Returns
    -------
    numpy.ndarray
        (steps, coded_length) float64 intensities, ``offset + amplitude * cos(...)``
        (fractions of full scale).

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("graycode", width=240, height=32, period=30)
    >>> pats = shift_patterns(spec)
    >>> pats.shape, pats[:, 0].round(2).tolist(), pats[:, 15].round(2).tolist()
    ((4, 240), [1.0, 0.5, 0.0, 0.5], [0.0, 0.5, 1.0, 0.5])
    """
    x = np.arange(spec.coded_length)
    return phase_shift_patterns(x, spec.period if period is None else period, spec.steps,
                                spec.offset, spec.amplitude, spec.phase_offset,
                                spec.shift_sign)


def along_columns(profiles: np.ndarray, spec: BaseSpec) -> np.ndarray:
    """Patterns that vary along the coded axis only: (frames, coded) -> (frames, other, coded).

    Parameters
    ----------
    profiles : numpy.ndarray
        (frames, coded_length) intensities along the coded axis.
    spec : BaseSpec
        The spec whose ``other_length`` is the number of pattern rows.

    Returns
    -------
    numpy.ndarray
        (frames, other_length, coded_length) float32, a read-only broadcast view that
        repeats each profile on every row (column layout).

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("graycode", width=120, height=16, period=30)
    >>> pats = along_columns(shift_patterns(spec), spec)
    >>> pats.shape, pats.dtype, bool((pats[:, 0] == pats[:, 15]).all())
    ((4, 16, 120), dtype('float32'), True)
    """
    rows = np.asarray(profiles, dtype=np.float32)[:, None, :]
    return np.broadcast_to(rows, (rows.shape[0], spec.other_length, rows.shape[2]))
