"""The interface every method implements, and the plumbing all methods share.

A codec is a spec class and four functions on the coded axis laid out along image columns
(captures of the rows orientation are decoded transposed):

================================================  =========================================
``encode_columns(spec)``                          ``(F, other, coded)`` patterns in [0, 1]
``measure_columns(prepared, spec, min_mod)``      stage 1, the phase map: a
                                                  :class:`~bistair.core.measure.FringeSet`
``code_columns(prepared, spec, fringes, min_mod)``  stage 2, the code map: a :class:`CodeMap`
``order_columns(fringes, code, spec, **options)`` stage 3, the orders: an :class:`Orders`
================================================  =========================================

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
([0, 1, 2, 3, 4, 5, 6, 7], ('min_modulation', 'strategy'))
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.captures import Prepared, check_min_modulation, prepare
from ..core.checks import (
    EdgeCheck,
    axis_problem,
    convention_problem,
    edge_alignment,
    jump_problem,
    outside_problem,
)
from ..core.measure import FringeSet, measure
from ..core.phase import phase_shift_patterns
from ..core.result import AxesResult, DecodeResult, result_from_orders
from ..errors import BistairError
from ..spec import AXES, BaseSpec, PeriodSpec


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
    """

    code: np.ndarray
    maps: dict[str, np.ndarray] = field(default_factory=dict)
    edge_phase: float = 0.0
    cycle: int | None = None  # the code repeats every ``cycle`` values (a stair)
    check: EdgeCheck | None = None  # a codec's own check of the phase convention

    @property
    def edges(self) -> np.ndarray:
        """The code whose steps are the code's own edges (see the attributes)."""
        return self.maps.get("edges", self.code)

    def transposed(self) -> CodeMap:
        """The same maps with image axes swapped (for the rows orientation)."""
        return CodeMap(np.ascontiguousarray(self.code.T),
                       {k: np.ascontiguousarray(v.T) for k, v in self.maps.items()},
                       self.edge_phase, self.cycle, self.check)


@dataclass
class Orders:
    """Stage 3 of a decode: the fringe order per pixel (int, -1 where invalid) and figures
    about it."""

    order: np.ndarray
    info: dict[str, Any] = field(default_factory=dict)


MeasureFn = Callable[[Prepared, Any, float | None], FringeSet]
CodeFn = Callable[[Prepared, Any, FringeSet, float | None], CodeMap]
OrderFn = Callable[..., Orders]


def measure_shifts(prepared: Prepared, spec: PeriodSpec,
                   min_modulation: float | None = None) -> FringeSet:
    """Stage 1 of the single-period methods: their N-step set, the first ``steps`` frames,
    in the spec's phase convention."""
    return measure(prepared, 0, spec.steps, min_modulation, shift_sign=spec.shift_sign,
                   phase_offset=spec.phase_offset)


@dataclass(frozen=True)
class Codec:
    """A method: its name, spec class and the functions of its stages (column layout).

    ``comparable(width, height, period, steps)`` gives the spec parameters of the method's
    pattern set that compares with the others on a projector (for the benchmark and the
    simulator); ``variants`` names decoder options worth comparing too (label -> options).
    ``aligned``: the decoder needs the coded axis to run along the image's rows of the
    column layout (bands of a code down the image), so captures whose phase changes more
    across that axis are refused; for the others it is a warning.
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
        """Decode keyword options: ``min_modulation`` and those of the order stage."""
        params = inspect.signature(self.order_columns).parameters.values()
        return ("min_modulation", *(p.name for p in params if p.kind is p.KEYWORD_ONLY))

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
        per axis), any other a :class:`~bistair.core.result.DecodeResult`.
        """
        unknown = set(options) - set(self.options)
        if unknown:
            raise BistairError(
                f"the {self.name} decoder has no option(s) {', '.join(sorted(unknown))}"
            )
        check_min_modulation(options.get("min_modulation"))
        if spec.orientation == "both":
            x, y = (self.decode(images, axis_spec, **options) for _, axis_spec in spec.axes())
            return AxesResult(x, y)
        min_modulation = options.pop("min_modulation", None)
        prepared, cols = self._columns(images, spec)
        fs = self.measure_columns(cols, spec, min_modulation)
        turned = axis_problem(fs.phi, fs.valid, spec.orientation)
        if self.aligned:
            _refuse(turned)
        code = self.code_columns(cols, spec, fs, min_modulation)
        warnings = check_convention(fs, code, spec) + ([turned] if turned else [])
        orders = self.order_columns(fs, code, spec, **options)
        if warnings:
            orders.info["warnings"] = [*orders.info.get("warnings", []), *warnings]
        _refuse(jump_problem(orders.info.get("jump_violations", 0),
                             orders.info.get("jump_links", 0)))
        result = result_from_orders(self.name, fs, orders.order, spec.period,
                                   code=code.code, info=orders.info, length=spec.coded_length)
        _refuse(outside_problem(int(result.mask.sum()), result.info.get("outside_projector", 0),
                                spec.coded_length))
        result.info["valid_pixels"] = int(result.mask.sum())
        result.info.setdefault("full_scale", prepared.full_scale)
        if spec.orientation == "rows":
            result = result.transposed()
        result.texture = prepared.white
        return result


def _refuse(problem: str | None) -> None:
    if problem is not None:
        raise BistairError(f"the captures do not fit the spec: {problem}")


def check_convention(fs: FringeSet, code: CodeMap, spec: BaseSpec) -> list[str]:
    """Refuse captures whose code steps do not sit where the spec's phase convention puts
    them (:mod:`bistair.core.checks`); returns the warnings worth a line."""
    check = code.check or edge_alignment(fs.phi, code.edges, fs.valid, code.edge_phase,
                                         code.cycle)
    problem = convention_problem(check, spec.phase_offset, spec.shift_sign, code.edge_phase)
    if problem is None:
        return []
    kind, message = problem
    if kind == "refuse":
        raise BistairError(f"the captures do not fit the spec: {message}")
    return [message]


def fringe_index(spec: BaseSpec, period: float | None = None) -> np.ndarray:
    """``floor(x / period)`` for every projector pixel ``x`` along the coded axis (int64; the
    spec's period by default). A hair of tolerance keeps pixels that sit exactly on a
    fringe edge of a fractional period (``1920/58``) in the fringe their phase says.

    >>> from bistair.codecs import make_spec
    >>> fringe_index(make_spec("graycode", width=120, height=16, period=30))[28:32].tolist()
    [0, 0, 1, 1]
    """
    x = np.arange(spec.coded_length, dtype=np.float64)
    return np.floor(x / (spec.period if period is None else period) + 1e-9).astype(np.int64)


def shift_patterns(spec: BaseSpec, period: float | None = None) -> np.ndarray:
    """The N-step fringe patterns along the coded axis, ``(steps, coded_length)``, in the
    spec's phase convention (``phase_offset``, ``shift_sign``)."""
    x = np.arange(spec.coded_length)
    return phase_shift_patterns(x, spec.period if period is None else period, spec.steps,
                                spec.offset, spec.amplitude, spec.phase_offset,
                                spec.shift_sign)


def along_columns(profiles: np.ndarray, spec: BaseSpec) -> np.ndarray:
    """Patterns that vary along the coded axis only: (frames, coded) -> (frames, other, coded)."""
    rows = np.asarray(profiles, dtype=np.float32)[:, None, :]
    return np.broadcast_to(rows, (rows.shape[0], spec.other_length, rows.shape[2]))
