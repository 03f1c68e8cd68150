"""Pattern-set specifications: validated, serialisable parameters shared by encode and decode.

A spec names the method, every parameter and the frame order. It is written next to the
patterns as ``spec.json`` and read back to decode the captures, so the set that was projected
is the set that is decoded.

The spec classes live with their codecs (:mod:`bistair.codecs`), which also keep the one
registry of methods; this module holds what every spec shares: the base classes, field
metadata for the command line, and the checks of a spec read from JSON.

Examples
--------
>>> from bistair.codecs import spec_from_dict
>>> spec = spec_from_dict({"method": "bidirectional", "width": 1080, "height": 1080,
...                        "period": 30})
>>> spec.frames[:2], spec.frame_count
(('shift-0', 'shift-1'), 6)
>>> spec_from_dict(spec.to_dict()) == spec
True
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping
from typing import Any, ClassVar

from .errors import BistairError

SPEC_VERSION = 1


def field(default: Any, help: str, **cli: Any) -> Any:  # noqa: A002 - mirrors click's name
    """A spec field with its help text (used by the CLI) and optional CLI settings."""
    return dataclasses.field(default=default, metadata={"help": help, **cli})


@dataclasses.dataclass(frozen=True, kw_only=True)
class BaseSpec:
    """Parameters every method shares.

    The coded axis is the projector's x (``orientation="columns"``: vertical fringes, phase
    along the column index) or its y (``orientation="rows"``: horizontal fringes).
    """

    method: ClassVar[str] = ""
    required: ClassVar[tuple[str, ...]] = ()

    width: int = field(1080, "projector width in pixels")
    height: int = field(1080, "projector height in pixels")
    steps: int = field(4, "phase-shift steps N (N >= 3)")
    bits: int = field(8, "bit depth of the pattern images (8 or 16)", choices=(8, 16))
    offset: float = field(0.5, "pattern mean a, as a fraction of full scale")
    amplitude: float = field(0.5, "pattern modulation b, as a fraction of full scale")
    gamma: float = field(1.0, "projector gamma to pre-compensate (1 = none)")
    orientation: str = field(
        "columns", "coded axis: columns (vertical fringes) or rows", choices=("columns", "rows")
    )
    white: int = field(0, "append a fully lit frame (1) for texture and board detection",
                       choices=(0, 1))
    frame_order: tuple[str, ...] = field((), "frame names in capture order", cli=False)

    # -- derived ---------------------------------------------------------------------------
    @property
    def coded_length(self) -> int:
        """Projector pixels along the coded axis."""
        return self.width if self.orientation == "columns" else self.height

    @property
    def other_length(self) -> int:
        """Projector pixels across the coded axis."""
        return self.height if self.orientation == "columns" else self.width

    @property
    def frames(self) -> tuple[str, ...]:
        """Frame names in projection (and capture) order."""
        return self.frame_order or self.default_frames()

    def default_frames(self) -> tuple[str, ...]:
        """The method's frames, then the white frame if asked for."""
        return self.method_frames() + (("white",) if self.white else ())

    @property
    def frame_count(self) -> int:
        return len(self.frames)

    def method_frames(self) -> tuple[str, ...]:
        """The frames the method decodes, in its own order (without extra frames)."""
        raise NotImplementedError

    # -- validation ------------------------------------------------------------------------
    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> None:
        """Raise :class:`BistairError` with a one-line reason if the parameters cannot work."""
        if self.width < 8 or self.height < 8:
            raise BistairError(f"projector size {self.width}x{self.height} is too small")
        if self.steps < 3:
            raise BistairError(f"steps must be at least 3, got {self.steps}")
        if self.bits not in (8, 16):
            raise BistairError(f"bits must be 8 or 16, got {self.bits}")
        if self.orientation not in ("columns", "rows"):
            raise BistairError(f"orientation must be 'columns' or 'rows', got {self.orientation!r}")
        if not (0 < self.amplitude <= self.offset and self.offset + self.amplitude <= 1.0):
            raise BistairError(
                f"offset {self.offset} and amplitude {self.amplitude} must satisfy "
                "0 < amplitude <= offset and offset + amplitude <= 1"
            )
        if not 0.2 <= self.gamma <= 5.0:
            raise BistairError(f"gamma must lie in [0.2, 5], got {self.gamma}")
        if self.white not in (0, 1):
            raise BistairError(f"white must be 0 or 1, got {self.white}")
        if self.frame_order and sorted(self.frame_order) != sorted(self.default_frames()):
            raise BistairError(
                f"spec field 'frames' must list the frames {list(self.default_frames())} "
                "in any order"
            )

    # -- serialisation ---------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        data: dict[str, Any] = {"method": self.method, "version": SPEC_VERSION}
        data.update(dataclasses.asdict(self))
        del data["frame_order"]
        data["frames"] = list(self.frames)
        return data

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2) + "\n"

    def replace(self, **changes: Any) -> BaseSpec:
        return dataclasses.replace(self, **changes)

    def frame_index(self, name: str) -> int:
        return self.frames.index(name)


@dataclasses.dataclass(frozen=True, kw_only=True)
class PeriodSpec(BaseSpec):
    """A spec with one fringe period T and an N-step set ``shift-0 .. shift-(N-1)``."""

    required: ClassVar[tuple[str, ...]] = ("period",)

    period: int = field(30, "fringe period T in projector pixels")

    @property
    def fringes(self) -> int:
        """Fringes across the coded axis, ``ceil(coded_length / period)``."""
        return -(-self.coded_length // self.period)

    def shift_frames(self) -> tuple[str, ...]:
        return tuple(f"shift-{n}" for n in range(self.steps))

    def validate(self) -> None:
        super().validate()
        if self.period < 4:
            raise BistairError(f"period must be at least 4 projector pixels, got {self.period}")


def _coerce(name: str, value: Any, kind: type) -> Any:
    if kind is int:
        if isinstance(value, bool) or not isinstance(value, int | float) or int(value) != value:
            raise BistairError(f"spec field '{name}' must be an integer, got {value!r}")
        return int(value)
    if kind is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise BistairError(f"spec field '{name}' must be a number, got {value!r}")
        return float(value)
    if kind is str:
        if not isinstance(value, str):
            raise BistairError(f"spec field '{name}' must be a string, got {value!r}")
        return value
    if kind is tuple:  # tuple[int, ...] or tuple[str, ...]
        if not isinstance(value, list | tuple) or not value:
            raise BistairError(f"spec field '{name}' must be a non-empty list, got {value!r}")
        item = str if all(isinstance(v, str) for v in value) else int
        return tuple(_coerce(name, v, item) for v in value)
    raise TypeError(kind)  # pragma: no cover


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

    Field values are checked for type, unknown fields and fields the class requires are
    refused with one line; ``frames`` becomes the capture order.
    """
    version = data.get("version", SPEC_VERSION)
    if version != SPEC_VERSION:
        raise BistairError(f"spec version {version!r} is not supported (expected {SPEC_VERSION})")
    data = dict(data)
    if "frames" in data:
        data["frame_order"] = data.pop("frames")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = set(data) - set(fields) - {"method", "version"}
    if unknown:
        raise BistairError(f"spec has unknown field(s): {', '.join(sorted(unknown))}")
    required = [name for name in ("width", "height", *cls.required) if name not in data]
    if required:
        raise BistairError(f"spec misses field(s): {', '.join(required)}")
    kwargs = {name: _coerce(name, data[name], field_kind(f)) for name, f in fields.items()
              if name in data}
    spec = cls(**kwargs)
    if spec.frame_order == spec.default_frames():
        spec = dataclasses.replace(spec, frame_order=())
    return spec
