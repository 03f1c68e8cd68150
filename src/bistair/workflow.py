"""The file-level jobs behind the CLI: write a pattern set, decode a capture folder.

Examples
--------
>>> import tempfile, pathlib
>>> from bistair import make_spec
>>> spec = make_spec("bidirectional", width=240, height=60, period=20, partitions=2)
>>> with tempfile.TemporaryDirectory() as tmp:
...     out = save_patterns(spec, pathlib.Path(tmp) / "pats")
...     sorted(p.name for p in out.iterdir())
['00.png', '01.png', '02.png', '03.png', '04.png', '05.png', 'spec.json']
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from . import decode, encode
from .codecs.base import quantize_patterns
from .errors import BistairError
from .io import output_folder, read_captures, write_image
from .result import DecodeResult
from .spec import BaseSpec, load_spec


def save_patterns(spec: BaseSpec, out: str | Path) -> Path:
    """Write ``00.png`` ... and ``spec.json`` into ``out``; returns ``out``."""
    images = quantize_patterns(encode(spec), spec.bits)
    width = max(2, len(str(len(images) - 1)))
    with output_folder(out) as tmp:
        for i, img in enumerate(images):
            write_image(tmp / f"{i:0{width}d}.png", img)
        (tmp / "spec.json").write_text(spec.to_json())
    return Path(out)


def decode_folder(captures: str | Path, out: str | Path, spec: BaseSpec | str | Path | None = None,
                  previews: bool = True, **options: Any) -> DecodeResult:
    """Decode a capture folder (or ``.npy`` stack) and write the result arrays into ``out``.

    ``spec`` defaults to ``CAPTURES/spec.json``.
    """
    stack, spec = read_with_spec(captures, spec)
    result = decode(stack, spec, **options)
    with output_folder(out) as tmp:
        result.save(tmp, previews=previews)
        (tmp / "info.json").write_text(json.dumps(_jsonable(result.info), indent=2) + "\n")
    return result


def read_with_spec(captures: str | Path, spec: BaseSpec | str | Path | None
                   ) -> tuple[np.ndarray, BaseSpec]:
    """The capture stack and its spec (``CAPTURES/spec.json``, or beside a ``.npy`` stack,
    unless given)."""
    captures = Path(captures)
    if not captures.exists():
        raise BistairError(f"captures {captures} not found")
    if spec is None:
        spec = captures / "spec.json" if captures.is_dir() else captures.with_name("spec.json")
    if not isinstance(spec, BaseSpec):
        spec = load_spec(spec)
    return read_captures(captures), spec


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def height_folder(captures: str | Path, reference: str | Path, out: str | Path,
                  spec: BaseSpec | str | Path | None = None, planes: tuple[str, ...] = (),
                  geometry: str | None = None) -> np.ndarray:
    """Height above a reference plane (mm) from the captures of the object, of the plane and
    either of planes at known heights (``"FOLDER:HEIGHT"``, two or more) or of the geometry
    (``"DISTANCE,BASELINE,FREQUENCY"``); writes ``height.npy`` and ``height.png``."""
    from .preview import colorize
    from .reconstruct import HeightModel

    stack, spec = read_with_spec(captures, spec)
    if bool(planes) == bool(geometry):
        raise BistairError("give either two or more --plane FOLDER:HEIGHT or --geometry")

    def coord(folder: str | Path) -> np.ndarray:
        return decode(read_captures(folder), spec).coord.astype(np.float64)

    ref = coord(reference)
    if geometry:
        try:
            distance, baseline, frequency = (float(v) for v in geometry.split(","))
        except ValueError:
            raise BistairError(f"--geometry must be DISTANCE,BASELINE,FREQUENCY, got "
                               f"{geometry!r}") from None
        model = HeightModel.classical(ref, distance, baseline, frequency, spec.period)
    else:
        pairs = []
        for item in planes:
            folder, _, value = item.rpartition(":")
            try:
                pairs.append((coord(folder), float(value)))
            except ValueError:
                raise BistairError(f"--plane must be FOLDER:HEIGHT, got {item!r}") from None
        model = HeightModel.fit(ref, [p for p, _ in pairs], [h for _, h in pairs])
    obj = decode(stack, spec).coord.astype(np.float64)
    if obj.shape != ref.shape:
        raise BistairError(f"captures are {obj.shape[1]}x{obj.shape[0]}, the reference "
                           f"{ref.shape[1]}x{ref.shape[0]}")
    heights = model.height(obj).astype(np.float32)
    with output_folder(out) as tmp:
        np.save(tmp / "height.npy", heights)
        write_image(tmp / "height.png", colorize(heights, "viridis"))
    return heights
