"""The jobs on folders behind the command line: write a pattern set, decode a capture folder,
reconstruct, measure height against a reference plane, import an OpenCV calibration (the
calibration from board captures is :mod:`bistair.app.calibrate`); and the parsers of their
option strings (``WxH``, ``MIN:MAX``, ``NAME=KEY,...``).

Each job reads its inputs, works in memory and writes its outputs atomically (a temporary
folder or file moved in at the end), so a failed job leaves nothing behind.

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
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..codecs import decode, encode
from ..core.captures import full_scale_of, to_bit_depth
from ..core.response import Response, estimate_response, ramp_levels
from ..core.result import AxesResult, DecodeResult
from ..errors import BistairError
from ..geometry.calibration import (
    CAMERA_PROJECTOR,
    Calibration,
    StereoCalibration,
    load_calibration,
    save_calibration,
)
from ..geometry.height import HeightModel
from ..geometry.opencv import read_opencv_calibration
from ..geometry.projection_matrices import (
    default_origin,
    import_matrices,
    save_matrix_calibration,
)
from ..geometry.triangulate import Reconstruction, check_depth_range, check_fit, reconstruct
from ..io.atomic import check_output, output_file, output_folder, write_image
from ..io.jsonfile import read_json, write_json
from ..io.previews import colorize
from ..io.read import (
    Captures,
    capture_files,
    find_spec,
    read_captures,
    read_with_spec,
)
from ..io.writers import save_result, write_depth, write_ply
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


def decode_folder(captures: Captures, out: str | Path, spec: BaseSpec | str | Path | None = None,
                  previews: bool = True, progress: Say | None = None,
                  **options: Any) -> DecodeResult | AxesResult:
    """Decode captures (folders, files, glob patterns or a ``.npy`` stack; see
    :func:`~bistair.io.read.capture_files`) and write the result into the folder ``out``.

    ``spec`` defaults to ``spec.json`` in the captures' folder. A decode with no valid pixel
    is refused. ``progress`` is called with each stage's name as it starts.
    """
    say = progress or _silent
    check_output(out, captures)
    say("reading the captures")
    stack, spec = read_with_spec(captures, spec)
    say(_decoding(stack, spec))
    result = require_valid(decode(stack, spec, **options))
    say("writing " + ("outputs and previews" if previews else "outputs"))
    save_result(result, out, previews=previews)
    return result


Say = Callable[[str], None]


def _silent(stage: str) -> None:
    """The progress callback of a job nobody watches."""


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
    say = progress or _silent
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
    say = progress or _silent
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


# -- calibration ---------------------------------------------------------------------------


def import_calibration(files: Sequence[str | Path], out: str | Path,
                       projector_size: tuple[int, int] | str | None,
                       camera_size: tuple[int, int] | str | None = None,
                       keys: Mapping[str, str] | str | None = None) -> Calibration:
    """Read an OpenCV FileStorage calibration (YAML or XML, keys of several files merged)
    and write it as a bistair calibration file ``out`` (atomically).

    Sizes are ``(width, height)`` or ``"WxH"``, or ``None`` to read them from the files;
    ``keys`` renames parts (a mapping or ``"camera=M1,T=T"``), see
    :func:`~bistair.geometry.opencv.read_opencv_calibration`.
    Nothing is written on error.
    """
    if isinstance(projector_size, str):
        projector_size = parse_size(projector_size, "--projector-size")
    if isinstance(camera_size, str):
        camera_size = parse_size(camera_size, "--camera-size")
    if isinstance(keys, str):
        keys = parse_keys(keys)
    cal = read_opencv_calibration(list(files), projector_size, camera_size, keys)
    save_calibration(cal, out)
    return cal


def import_projection_matrices(files: Sequence[str | Path] | str, out: str | Path,
                               camera_size: tuple[int, int] | str | None,
                               projector_size: tuple[int, int] | str | None,
                               pixel_origin: int | None = None
                               ) -> tuple[StereoCalibration, int]:
    """Read three 3x4 projection matrices (left camera, right camera, projector: ``.npy``,
    ``.txt`` or ``.mat``, one world frame) and write the two-camera-and-projector
    calibration ``out`` in the left camera's frame
    (:mod:`~bistair.geometry.projection_matrices`), recording the cameras' pixel origin
    (``pixel_origin``: 0 or 1, by default 1 for ``.mat`` files, 0 otherwise). ``files``
    may be ``"L,R,P"``. Returns the calibration and the origin used. Nothing is written on
    error."""
    if isinstance(files, str):
        files = [f.strip() for f in files.split(",")]
    sizes = []
    for size, name in ((camera_size, "--camera-size"), (projector_size, "--projector-size")):
        if size is None:
            raise BistairError(f"--projection-matrices needs {name} WxH (a matrix does not "
                               "hold the image size)")
        sizes.append(parse_size(size, name) if isinstance(size, str) else size)
    cal = import_matrices(tuple(files), *sizes, pixel_origin=pixel_origin)
    origin = default_origin(files) if pixel_origin is None else int(pixel_origin)
    save_matrix_calibration(cal, origin, out)
    return cal, origin


# -- option strings --------------------------------------------------------------------------
def parse_size(text: str, name: str = "size") -> tuple[int, int]:
    """``"WxH"`` as ``(width, height)``, positive integers.

    Raises
    ------
    BistairError
        If ``text`` is not two positive whole numbers joined by ``x``.

    Examples
    --------
    >>> parse_size("1920x1080")
    (1920, 1080)
    >>> parse_size("1920")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: size must be WIDTHxHEIGHT in pixels, e.g. 1920x1080, got '1920'
    """
    parts = text.strip().lower().split("x")
    if len(parts) != 2 or not all(p.strip().isdigit() and int(p) > 0 for p in parts):
        raise BistairError(f"{name} must be WIDTHxHEIGHT in pixels, e.g. 1920x1080, got "
                           f"{text!r}")
    return int(parts[0]), int(parts[1])


def parse_keys(text: str) -> dict[str, str]:
    """``"NAME=KEY,NAME=KEY"`` as a dictionary (names checked by the reader).

    Raises
    ------
    BistairError
        If an item is not ``NAME=KEY`` or a name repeats.

    Examples
    --------
    >>> parse_keys("camera=K_cam, T=translation")
    {'camera': 'K_cam', 'T': 'translation'}
    """
    out: dict[str, str] = {}
    for item in text.split(","):
        name, sep, key = (part.strip() for part in item.partition("="))
        if not sep or not name or not key:
            raise BistairError(f"--keys must be NAME=KEY items joined by commas, e.g. "
                               f"camera=M1,T=T; got {item.strip()!r}")
        if name in out:
            raise BistairError(f"--keys names {name} twice")
        out[name] = key
    return out


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
