"""The pattern jobs behind the command line: write a method's pattern set
(``bistair patterns NAME``), a gamma ramp (``bistair patterns gamma``) and measure the
projector's gamma from its captures (``bistair gamma``).

Each job writes its outputs atomically (a temporary folder or file moved in at the end), so
a failed job leaves nothing behind.

Examples
--------
>>> import tempfile, pathlib
>>> from bistair.codecs import make_spec
>>> spec = make_spec("bidirectional", width=240, height=60, period=20, partitions=2)
>>> with tempfile.TemporaryDirectory() as tmp:
...     out = save_patterns(spec, pathlib.Path(tmp) / "pats")
...     sorted(p.name for p in out.iterdir())
['00.png', '01.png', '02.png', '03.png', '04.png', '05.png', 'spec.json']
"""

from __future__ import annotations

import contextlib
import re
from pathlib import Path

import numpy as np

from ..codecs import encode
from ..core.captures import full_scale_of, to_bit_depth
from ..core.response import Response, estimate_response, ramp_levels
from ..errors import BistairError
from ..io.atomic import output_file, output_folder, write_image
from ..io.jsonfile import read_json, write_json
from ..io.read import Captures, capture_files, read_captures
from ..spec import BaseSpec


def save_patterns(spec: BaseSpec, out: str | Path) -> Path:
    """Write ``00.png`` ... and ``spec.json`` into ``out``; returns ``out``. Numbered
    images an earlier pattern set left there (``06.png`` of a set of 7 after one of 6)
    are removed, so that the folder holds exactly the frames to project."""
    images = to_bit_depth(encode(spec), spec.bits)
    width = max(2, len(str(len(images) - 1)))
    with output_folder(out) as tmp:
        for i, img in enumerate(images):
            write_image(tmp / f"{i:0{width}d}.png", img)
        (tmp / "spec.json").write_text(spec.to_json())
        written = {p.name for p in tmp.iterdir()}
    for old in Path(out).iterdir():
        if old.name not in written and re.fullmatch(r"\d+\.(png|tiff?|bmp)", old.name):
            with contextlib.suppress(OSError):
                old.unlink()
    return Path(out)

def save_ramp(width: int, height: int, levels: int, bits: int, out: str | Path) -> Path:
    """Write a gamma ramp: ``levels`` uniform frames from black to white (``NN.png``) and
    ``ramp.json`` (their pattern values), for :func:`measure_gamma`."""
    if width < 8 or height < 8:
        raise BistairError(f"projector size {width}x{height} is too small (8x8 at least)")
    values = ramp_levels(levels)
    digits = max(2, len(str(levels - 1)))
    with output_folder(out) as tmp:
        for i, v in enumerate(values):
            write_image(tmp / f"{i:0{digits}d}.png",
                        to_bit_depth(np.full((height, width), v), bits))
        write_json(tmp / "ramp.json", {"format": "bistair-gamma-ramp", "version": 1,
                                       "width": width, "height": height, "bits": bits,
                                       "levels": values.tolist()})
    return Path(out)

def measure_gamma(captures: Captures, out: str | Path,
                  ramp: str | Path | None = None) -> Response:
    """Fit the projector's gamma to captures of a ramp (:func:`save_ramp`) and write
    ``gamma.json`` atomically; ``ramp`` defaults to ``ramp.json`` in the captures' folder."""
    files = capture_files(captures)
    if ramp is None:
        first = Path(captures if isinstance(captures, str | Path) else captures[0])
        ramp = (first if first.is_dir() else files[0].parent) / "ramp.json"
    data = read_json(ramp, "gamma ramp")
    levels = data.get("levels") if isinstance(data, dict) else None
    if not isinstance(levels, list) or not all(isinstance(v, int | float) for v in levels):
        raise BistairError(f"gamma ramp {ramp} has no list of 'levels'")
    stack = read_captures(files)
    if len(stack) != len(levels):
        raise BistairError(f"the gamma ramp has {len(levels)} levels, the captures have "
                           f"{len(stack)} frames")
    fit = estimate_response(stack, np.asarray(levels, float), full_scale_of(stack))
    with output_file(out) as tmp:
        write_json(tmp, fit.to_dict())
    return fit

def read_gamma(path: str | Path) -> float:
    """The fitted gamma of a ``gamma.json`` written by :func:`measure_gamma`."""
    data = read_json(path, "gamma file")
    value = data.get("gamma") if isinstance(data, dict) else None
    if not isinstance(value, int | float) or not 0.2 <= value <= 5.0:
        raise BistairError(f"gamma file {path} has no gamma in [0.2, 5]")
    return float(value)
