"""The decoding jobs behind the command line: decode a capture folder (``bistair
decode``), reconstruct with a calibration (``bistair reconstruct``) and measure height
against a reference plane (``bistair height``); and the parser of ``--depth-range``.

Each job reads its inputs, works in memory and writes its outputs atomically (a temporary
folder or file moved in at the end), so a failed job leaves nothing behind.

Examples
--------
>>> import tempfile, pathlib
>>> from bistair.codecs import make_spec
>>> from bistair.app.patterns import save_patterns
>>> spec = make_spec("graycode", width=64, height=48, period=16)
>>> with tempfile.TemporaryDirectory() as tmp:
...     pats = save_patterns(spec, pathlib.Path(tmp) / "pats")
...     result = decode_folder(pats, pathlib.Path(tmp) / "out")
...     result.method, bool(result.mask.all())
('graycode', True)
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..codecs import decode
from ..core.result import AxesResult, DecodeResult
from ..errors import BistairError
from ..geometry.calibration import (
    CAMERA_PROJECTOR,
    Calibration,
    load_calibration,
)
from ..geometry.height import HeightModel
from ..geometry.triangulate import Reconstruction, check_depth_range, check_fit, reconstruct
from ..io.atomic import check_output, output_folder, write_image
from ..io.previews import colorize
from ..io.read import (
    Captures,
    find_spec,
    read_captures,
    read_with_spec,
)
from ..io.writers import save_result, write_depth, write_ply
from ..spec import BaseSpec
from .progress import Say, silent


def decode_folder(captures: Captures, out: str | Path, spec: BaseSpec | str | Path | None = None,
                  previews: bool = True, progress: Say | None = None,
                  **options: Any) -> DecodeResult | AxesResult:
    """Decode captures (folders, files, glob patterns or a ``.npy`` stack; see
    :func:`~bistair.io.read.capture_files`) and write the result into the folder ``out``.

    ``spec`` defaults to ``spec.json`` in the captures' folder. A decode with no valid pixel
    is refused. ``progress`` is called with each stage's name as it starts.
    """
    say = progress or silent
    check_output(out, captures)
    say("reading the captures")
    stack, spec = read_with_spec(captures, spec)
    say(_decoding(stack, spec))
    result = require_valid(decode(stack, spec, **options))
    say("writing " + ("outputs and previews" if previews else "outputs"))
    save_result(result, out, previews=previews)
    return result

def _decoding(stack: np.ndarray, spec: BaseSpec) -> str:
    return (f"decoding {len(stack)} frames of {stack.shape[2]}x{stack.shape[1]} "
            f"({spec.method})")

def require_valid(result: DecodeResult | AxesResult) -> DecodeResult | AxesResult:
    """Refuse a decode that has no valid pixel (an answer of nothing is not an answer)."""
    for tag, res in ((("", result),) if isinstance(result, DecodeResult)
                     else (("x: ", result.x), ("y: ", result.y))):
        if res.mask.any():
            continue
        outside = res.info.get("outside_projector", 0)
        why = (f"{outside} pixels decode outside the projector" if outside
               else f"{res.info.get('valid_modulation', 0)} pixels have fringes")
        raise BistairError(f"{tag}no pixel decoded ({why}): does the spec fit the captures "
                           "(method, periods, frame order, phase_offset, shift_sign)?")
    return result

def height_folder(captures: str | Path, reference: str | Path, out: str | Path,
                  spec: BaseSpec | str | Path | None = None, planes: tuple[str, ...] = (),
                  geometry: str | None = None, progress: Say | None = None) -> np.ndarray:
    """Height above a reference plane (mm) from the captures of the object, of the plane and
    either of planes at known heights (``"FOLDER:HEIGHT"``, two or more) or of the geometry
    (``"DISTANCE,BASELINE,FREQUENCY"``); writes ``height.npy`` and ``height.png``.
    ``progress`` is called with each stage's name as it starts."""
    say = progress or silent
    say("reading the captures")
    stack, spec = read_with_spec(captures, spec)
    if bool(planes) == bool(geometry):
        raise BistairError("give either two or more --plane FOLDER:HEIGHT or --geometry")

    def coord(folder: str | Path) -> np.ndarray:
        say(f"decoding {folder}")
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
    say(_decoding(stack, spec))
    obj = decode(stack, spec).coord.astype(np.float64)
    if obj.shape != ref.shape:
        raise BistairError(f"captures are {obj.shape[1]}x{obj.shape[0]}, the reference "
                           f"{ref.shape[1]}x{ref.shape[0]}")
    heights = model.height(obj).astype(np.float32)
    say("writing height.npy and height.png")
    with output_folder(out) as tmp:
        np.save(tmp / "height.npy", heights)
        write_image(tmp / "height.png", colorize(heights, "viridis", unit="mm"))
    return heights

def reconstruct_folder(captures: str | Path, spec: BaseSpec | str | Path | None,
                       calibration: Calibration | str | Path, out_ply: str | Path,
                       depth_dir: str | Path | None = None, orientation: str | None = None,
                       min_depth: float = 0.0, max_depth: float = np.inf,
                       epipolar_tolerance: float = 1.5,
                       decoded: DecodeResult | AxesResult | None = None,
                       progress: Say | None = None,
                       **options: Any) -> Reconstruction:
    """Decode a capture folder (or ``.npy`` stack), triangulate it and write the PLY (and
    ``depth.npy``, ``depth.png`` into ``depth_dir``). ``spec`` defaults to
    ``CAPTURES/spec.json``; ``options`` go to the decoder. A spec of both axes triangulates
    with both projector coordinates (``epipolar_tolerance``: see
    :func:`~bistair.geometry.triangulate.reconstruct`). ``decoded``: the decode of these
    captures if already made (by :func:`decode_folder`), triangulated without reading or
    decoding them again. Nothing is written on error. ``progress`` is called with each
    stage's name as it starts."""
    say = progress or silent
    check_depth_range(min_depth, max_depth)
    if not epipolar_tolerance > 0:
        raise BistairError(f"the epipolar tolerance must be positive, got {epipolar_tolerance}")
    stack = None
    if decoded is None:
        say("reading the captures")
        stack, spec = read_with_spec(captures, spec)
        shape = stack.shape[1:]
    else:
        spec, shape = find_spec(captures, spec), decoded.mask.shape
    if not isinstance(calibration, Calibration):
        calibration = load_calibration(calibration, CAMERA_PROJECTOR)
    blank: DecodeResult | AxesResult = DecodeResult(*(np.zeros(shape),) * 8,
                                                    period=1.0, method="")
    if spec.orientation == "both":
        blank = AxesResult(blank, blank)
    check_fit(blank, calibration, spec, orientation)  # before the work of decoding
    if decoded is None:
        say(_decoding(stack, spec))
        decoded = decode(stack, spec, **options)
    say("triangulating")
    rec = reconstruct(decoded, calibration, spec, orientation, min_depth, max_depth,
                      epipolar_tolerance)
    infos = [decoded.x.info, decoded.y.info] if isinstance(decoded, AxesResult) \
        else [decoded.info]
    for key in ("warnings", "forced"):  # the decode's, passed on to the caller
        found = [m for info in infos for m in info.get(key, [])]
        if found:
            rec.info[key] = found
    pts, cols = rec.cloud()
    say(f"writing {len(pts)} points")
    if depth_dir is None:
        write_ply(out_ply, pts, cols)
        return rec
    with output_folder(depth_dir) as tmp:
        write_depth(rec.depth, tmp)
        write_ply(out_ply, pts, cols)
    return rec

def parse_depth_range(text: str) -> tuple[float, float]:
    """``"MIN:MAX"`` (mm) as ``(min, max)`` with ``0 <= min < max`` (``max`` may be ``inf``).

    Raises
    ------
    BistairError
        If the text is not two numbers joined by ``:`` or they are not an interval of
        depths.

    Examples
    --------
    >>> parse_depth_range("400:650.5")
    (400.0, 650.5)
    >>> parse_depth_range("650:400")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: --depth-range MIN:MAX needs MIN < MAX, got 650:400
    """
    low, sep, high = text.partition(":")
    try:
        if not sep:
            raise ValueError
        lo, hi = float(low), float(high)
    except ValueError:
        raise BistairError(f"--depth-range must be MIN:MAX in mm, e.g. 400:800, got "
                           f"{text!r}") from None
    if not lo < hi:  # also refuses NaN
        raise BistairError(f"--depth-range MIN:MAX needs MIN < MAX, got {text}")
    if not 0 <= lo < np.inf:
        raise BistairError(f"--depth-range MIN must be a depth of 0 mm or more, got {text}")
    return lo, hi
