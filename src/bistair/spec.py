"""Pattern-set specifications: validated, serialisable parameters shared by encode and decode.

A spec names the method, every parameter and the frame order. It is written next to the
patterns as ``spec.json`` and read back to decode the captures, so the set that was projected
is the set that is decoded.

The spec classes live with their codecs (:mod:`bistair.codecs`), which also keep the one
registry of methods; this module holds what every spec shares: the base classes, field
metadata for the command line, and the checks of a spec read from JSON.

Examples
--------
>>> from bistair.codecs import make_spec, spec_from_dict
>>> spec = make_spec("bidirectional", width=1080, height=1080, period=30)
>>> spec.frames[:2], spec.frame_count
(('shift-0', 'shift-1'), 6)
>>> spec_from_dict(spec.to_dict()) == spec
True
>>> spec_from_dict({"method": "bidirectional", "width": 1080, "height": 1080, "period": 30})
... # doctest: +ELLIPSIS
Traceback (most recent call last):
...
bistair.errors.BistairError: spec misses field(s): steps, orientation, phase_offset, ...
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from collections.abc import Mapping
from typing import Any, ClassVar

from .errors import BistairError

SPEC_VERSION = 2
# Version 1 specs predate these fields; their patterns used the defaults.
_V1_DEFAULTS = {"phase_offset": 0.0, "shift_sign": 1}
ROLES = ("white", "black", "ignore")
AXES = {"columns": "x", "rows": "y"}


def field(default: Any, help: str, shapes: bool = True, **cli: Any) -> Any:  # noqa: A002
    """A spec field with its help text (used by the CLI) and optional CLI settings.

    ``shapes``: the field decides where the patterns' fringes and codes fall, so a spec read
    from a file must name it (defaults serve only when making new patterns); fields of
    intensity only (offset, amplitude, gamma, bit depth) may be left out. ``later=True``
    (among the settings): a field added after spec files were written, whose default is
    what those files meant: written only when it is not the default, read as the default
    where a file does not name it.
    """
    return dataclasses.field(default=default, metadata={"help": help, "shapes": shapes, **cli})


@dataclasses.dataclass(frozen=True, kw_only=True)
class BaseSpec:
    """Parameters every method shares.

    The coded axis is the projector's x (``orientation="columns"``: vertical fringes, phase
    along the column index), its y (``orientation="rows"``: horizontal fringes) or both
    (``"both"``: the method's frames twice, named ``x/NAME`` and ``y/NAME``, decoded into
    both projector coordinates).

    Phase shifts follow ``I = a + b*cos(2*pi*x/T + phase_offset + shift_sign*2*pi*n/N)`` for
    frame ``n`` of an ``N``-step set. ``frames`` may hold, besides the method's frame names,
    the roles ``white`` (a fully lit frame), ``black`` (a dark frame) and ``ignore`` (any
    number of frames that are not decoded).
    """

    method: ClassVar[str] = ""
    # a method that can decode without phase shifts (a Gray code alone) allows steps = 0
    shiftless: ClassVar[bool] = False

    width: int = field(1080, "projector width in pixels")
    height: int = field(1080, "projector height in pixels")
    steps: int = field(4, "phase-shift steps N (N >= 3; 0 for a Gray code alone)")
    bits: int = field(8, "bit depth of the pattern images (8 or 16)", shapes=False,
                      choices=(8, 16))
    offset: float = field(0.5, "pattern mean a, as a fraction of full scale", shapes=False)
    amplitude: float = field(0.5, "pattern modulation b, as a fraction of full scale",
                             shapes=False)
    gamma: float = field(1.0, "projector gamma to pre-compensate (1 = none)", shapes=False)
    orientation: str = field(
        "columns", "coded axis: columns (vertical fringes), rows, or both (x/ and y/ frames)",
        choices=("columns", "rows", "both"))
    phase_offset: float = field(0.0, "phase at projector coordinate 0 in radians: "
                                "I = a + b*cos(2*pi*x/T + phase_offset + shift_sign*2*pi*n/N)")
    shift_sign: int = field(1, "direction of the phase shifts, +1 or -1", choices=(1, -1))
    white: int = field(0, "append a fully lit frame (1) for texture and board detection",
                       shapes=False, choices=(0, 1))
    frame_order: tuple[str, ...] = field((), "frame names in capture order", cli=False)

    # -- derived ---------------------------------------------------------------------------
    @property
    def coded_length(self) -> int:
        """Projector pixels along the coded axis (the columns axis for ``"both"``)."""
        return self.height if self.orientation == "rows" else self.width

    @property
    def other_length(self) -> int:
        """Projector pixels across the coded axis."""
        return self.width if self.orientation == "rows" else self.height

    @property
    def frames(self) -> tuple[str, ...]:
        """Frame names in projection (and capture) order."""
        return self.frame_order or self.default_frames()

    def default_frames(self) -> tuple[str, ...]:
        """The method's frames, then the white frame (and others, see
        :meth:`extra_frames`) if asked for."""
        if self.orientation == "both":
            own = tuple(f"{tag}/{name}" for axis, tag in AXES.items() for name in
                        dataclasses.replace(self, orientation=axis, frame_order=())
                        .method_frames())
        else:
            own = self.method_frames()
        return own + self.extra_frames()

    @classmethod
    def defaults(cls, params: dict) -> dict:
        """Defaults that depend on the other parameters given (none here; a method's spec
        may have some), applied by :func:`bistair.codecs.make_spec` and the command line to
        the fields left out."""
        return {}

    def extra_frames(self) -> tuple[str, ...]:
        """The role frames appended after the method's own: ``white`` when asked for."""
        return ("white",) if self.white else ()

    @property
    def frame_count(self) -> int:
        return len(self.frames)

    def method_frames(self) -> tuple[str, ...]:
        """The frames the method decodes, in its own order (without extra frames)."""
        raise NotImplementedError

    def axes(self) -> tuple[tuple[str, BaseSpec], ...]:
        """``(orientation, spec)`` per coded axis: one for columns or rows, two for both.

        An axis spec of a ``"both"`` spec keeps the frame order: the other axis's frames
        become ``ignore`` and the ``x/`` or ``y/`` prefix is dropped.
        """
        if self.orientation != "both":
            return ((self.orientation, self),)
        out = []
        for axis, tag in AXES.items():
            order = tuple(n[2:] if n.startswith(f"{tag}/") else
                          (n if n in ROLES else "ignore") for n in self.frames)
            out.append((axis, dataclasses.replace(self, orientation=axis, frame_order=order)))
        return tuple(out)

    # -- validation ------------------------------------------------------------------------
    def __post_init__(self) -> None:
        if self.orientation == "both":
            self._validate_common()
            self.axes()  # each axis spec validates itself
            self._validate_frames()
        else:
            self.validate()

    def _validate_common(self) -> None:
        if self.width < 8 or self.height < 8:
            raise BistairError(f"projector size {self.width}x{self.height} is too small (at "
                               "least 8x8)")
        if self.steps < 3 and not (self.shiftless and self.steps == 0):
            alone = " (or 0 for a Gray code alone)" if self.shiftless else ""
            raise BistairError(f"steps must be at least 3{alone}, got {self.steps}")
        if self.bits not in (8, 16):
            raise BistairError(f"bits must be 8 or 16, got {self.bits}")
        if self.orientation not in ("columns", "rows", "both"):
            raise BistairError(f"orientation must be 'columns', 'rows' or 'both', got "
                               f"{self.orientation!r}")
        if not (0 < self.amplitude <= self.offset and self.offset + self.amplitude <= 1.0):
            raise BistairError(
                f"offset {self.offset} and amplitude {self.amplitude} must satisfy "
                "0 < amplitude <= offset and offset + amplitude <= 1"
            )
        if not 0.2 <= self.gamma <= 5.0:
            raise BistairError(f"gamma must lie in [0.2, 5], got {self.gamma}")
        if self.white not in (0, 1):
            raise BistairError(f"white must be 0 or 1, got {self.white}")
        if self.shift_sign not in (1, -1):
            raise BistairError(f"shift_sign must be +1 or -1, got {self.shift_sign}")
        if not math.isfinite(self.phase_offset):
            raise BistairError(f"phase_offset must be a finite number, got {self.phase_offset}")

    def _validate_frames(self) -> None:
        if not self.frame_order:
            return
        own = [n for n in self.frame_order if n not in ROLES]
        want = [n for n in self.default_frames() if n != "black"]
        if "white" in self.frame_order and not self.white:
            raise BistairError("spec field 'frames' lists a white frame but 'white' is 0 "
                               "(set \"white\": 1)")
        if self.frame_order.count("black") > 1:
            raise BistairError("spec field 'frames' lists 'black' more than once")
        if sorted(own + ["white"] * self.frame_order.count("white")) != sorted(want):
            missing = [n for n in want if n not in self.frame_order]
            extra = sorted({n for n in own if n not in want or own.count(n) > 1})
            what = (f"misses {missing}" if missing else f"has unknown or repeated {extra}")
            raise BistairError(
                f"spec field 'frames' {what}: it must list each of {list(want)} once, in "
                f"capture order, with 'black' and any number of 'ignore' besides"
            )

    def validate(self) -> None:
        """Raise :class:`BistairError` with a one-line reason if the parameters cannot work."""
        self._validate_common()
        self._validate_frames()

    # -- serialisation ---------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        data: dict[str, Any] = {"method": self.method, "version": SPEC_VERSION}
        data.update(dataclasses.asdict(self))
        del data["frame_order"]
        for f in dataclasses.fields(self):  # (files written before a later field existed)
            if f.metadata.get("later") and data[f.name] == f.default:
                del data[f.name]
        for key, value in data.items():
            if isinstance(value, float) and value.is_integer():
                data[key] = int(value)  # 30, not 30.0
            elif isinstance(value, tuple):
                data[key] = [int(v) if isinstance(v, float) and v.is_integer() else v
                             for v in value]
        data["frames"] = list(self.frames)
        return data

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2) + "\n"

    def replace(self, **changes: Any) -> BaseSpec:
        return dataclasses.replace(self, **changes)

    def frame_index(self, name: str) -> int:
        return self.frames.index(name)


def format_period(period: float) -> str:
    """A period as it reads in frame names: ``30``, ``33.1034``.

    >>> format_period(30.0), format_period(1920 / 58)
    ('30', '33.1034')
    """
    return f"{period:g}"


def fringe_count(length: int, period: float) -> int:
    """Fringes across ``length`` projector pixels: ``ceil(length / period)``, exact for
    periods like ``1920/58`` that float rounding puts a hair off.

    >>> fringe_count(1080, 30), fringe_count(1920, 1920 / 58), fringe_count(1081, 30)
    (36, 58, 37)
    """
    return math.ceil(length / period - 1e-9)


@dataclasses.dataclass(frozen=True, kw_only=True)
class PeriodSpec(BaseSpec):
    """A spec with one fringe period T and an N-step set ``shift-0 .. shift-(N-1)``."""

    period: float = field(30.0, "fringe period T in projector pixels (may be a fraction such "
                          "as 1920/58)")

    @property
    def fringes(self) -> int:
        """Fringes across the coded axis, ``ceil(coded_length / period)``."""
        return fringe_count(self.coded_length, self.period)

    def shift_frames(self) -> tuple[str, ...]:
        return tuple(f"shift-{n}" for n in range(self.steps))

    def validate(self) -> None:
        super().validate()
        if self.steps == 0:  # a code alone: its cells may be a pixel wide
            if not (math.isfinite(self.period) and self.period >= 1):
                raise BistairError(f"period (the code's cell) must be at least 1 projector "
                                   f"pixel, got {self.period}")
        elif not (math.isfinite(self.period) and self.period >= 4):
            raise BistairError(f"period must be at least 4 projector pixels, got {self.period}")


_EXPRESSION = re.compile(r"^[0-9.eE+\-*/() ]*(pi[0-9.eE+\-*/() ]*)*$")


def parse_number(name: str, value: Any) -> float:
    """A number, or a string of one written with ``+ - * /``, brackets and ``pi``:
    ``"1920/58"``, ``"-2*pi/3"``.

    >>> parse_number("period", "1920/58") == 1920 / 58, parse_number("period", 30)
    (True, 30.0)
    >>> round(parse_number("phase_offset", "-2*pi/3"), 6), parse_number("phase_offset", "-pi")
    (-2.094395, -3.141592653589793)
    """
    if isinstance(value, str):
        text = value.strip()
        if text and _EXPRESSION.match(text) and "**" not in text:
            try:
                number = eval(text, {"__builtins__": {}}, {"pi": math.pi})  # noqa: S307
                if isinstance(number, int | float) and math.isfinite(number):
                    return float(number)
            except (SyntaxError, ZeroDivisionError, TypeError, ValueError):
                pass
    elif isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    raise BistairError(f"spec field '{name}' must be a number, got {value!r}")


def _coerce(name: str, value: Any, kind: str) -> Any:
    if kind == "int":
        if isinstance(value, str) and re.fullmatch(r"\s*[+-]?[0-9]+\s*", value):
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, int | float) or int(value) != value:
            raise BistairError(f"spec field '{name}' must be an integer, got {value!r}")
        return int(value)
    if kind == "float":
        return parse_number(name, value)
    if kind == "str":
        if not isinstance(value, str):
            raise BistairError(f"spec field '{name}' must be a string, got {value!r}")
        return value
    if kind.startswith("tuple"):
        if not isinstance(value, list | tuple) or not value:
            raise BistairError(f"spec field '{name}' must be a non-empty list, got {value!r}")
        item = kind[len("tuple["):].split(",")[0]
        return tuple(_coerce(name, v, item) for v in value)
    raise TypeError(kind)  # pragma: no cover


def coerce_field(f: dataclasses.Field, value: Any) -> Any:
    """A value for spec field ``f`` from JSON or from the command line (strings: integers,
    numbers as in :func:`parse_number`, comma-separated lists); one-line
    :class:`BistairError` if it is not one.

    >>> import dataclasses
    >>> period = {f.name: f for f in dataclasses.fields(PeriodSpec)}["period"]
    >>> coerce_field(period, "1920/58") == 1920 / 58
    True
    """
    kind = str(f.type)
    if isinstance(value, str) and kind.startswith("tuple"):
        value = [v.strip() for v in value.split(",") if v.strip()]
    return _coerce(f.name, value, kind)


def field_kind(f: dataclasses.Field) -> type:
    """The Python type of a spec field: int, float, str or tuple."""
    text = str(f.type)
    for kind in (int, float, str):
        if text == kind.__name__:
            return kind
    if text.startswith("tuple"):
        return tuple
    raise TypeError(f"unsupported spec field type {text}")  # pragma: no cover


def check_fields(cls: type[BaseSpec], data: Mapping[str, Any]) -> BaseSpec:
    """Build and validate a spec of class ``cls`` from its dictionary (as in ``spec.json``).

    Unknown fields, values of the wrong type and missing fields that shape the patterns are
    refused with one line (a version-1 spec, written before ``phase_offset`` and
    ``shift_sign`` existed, takes their defaults); ``frames`` becomes the capture order.
    """
    version = data.get("version", SPEC_VERSION)
    if version not in (1, SPEC_VERSION):
        raise BistairError(f"spec version {version!r} is not supported (expected {SPEC_VERSION})")
    data = dict(data)
    if version == 1:
        data = {**_V1_DEFAULTS, **data}
    data = {**{f.name: f.default for f in dataclasses.fields(cls) if f.metadata.get("later")},
            **data}
    if "frames" in data:
        data["frame_order"] = data.pop("frames")
        if isinstance(data["frame_order"], list) and "white" in data["frame_order"]:
            data.setdefault("white", 1)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = set(data) - set(fields) - {"method", "version"}
    if unknown:
        raise BistairError(f"spec has unknown field(s): {', '.join(sorted(unknown))}")
    required = [name for name, f in fields.items()
                if f.metadata.get("shapes", True) and f.metadata.get("cli", True) is not False
                and name not in data]
    if required:
        raise BistairError(f"spec misses field(s): {', '.join(required)} (a spec read from a "
                           "file must name every field that shapes its patterns)")
    kwargs = {name: _coerce(name, data[name], str(f.type)) for name, f in fields.items()
              if name in data}
    spec = cls(**kwargs)
    if spec.frame_order == spec.default_frames():
        spec = dataclasses.replace(spec, frame_order=())
    return spec
