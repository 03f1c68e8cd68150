"""``bistair scan``: project a pattern set, grab it, write a capture folder (and decode it).

:func:`scan_folder` runs :func:`bistair.acquire.scan` and writes::

    OUT/00.png ...          one capture a pattern, 8 or 16 bit as the camera delivers
    OUT/spec.json           the spec, its frames named in capture order
    OUT/scan.json           devices, exposure, settle, the show and grab times of each frame
    OUT/decode/             with decode: what 'bistair decode' writes (coord.npy, ...);
                            with a calibration also cloud.ply, depth.npy and depth.png

``OUT`` is then a capture folder like any other for ``bistair decode``, ``reconstruct``,
``calibrate`` (one scan per board pose and orientation) and ``batch``. Every device string
and setting is checked before the devices open, the calibration before the scan; the
captures are written only once all are grabbed (into a temporary folder that replaces
``OUT`` as a whole), so a refusal, a failure or Ctrl-C leaves nothing half-written. A
decode that fails after the scan leaves the captures in place (they are complete) and says
so. :func:`measure_settle` is ``bistair scan --measure-latency``.

Examples
--------
>>> import tempfile, pathlib
>>> from bistair.codecs import make_spec
>>> spec = make_spec("graycode", width=1920, height=1080, period=30)
>>> with tempfile.TemporaryDirectory() as tmp:
...     report = scan_folder(spec, "none", "sim:plane:48x32", pathlib.Path(tmp) / "scan")
...     sorted(p.name for p in report.out.iterdir())[-3:]
['09.png', 'scan.json', 'spec.json']
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..acquire import Latency, Scan, measure_latency, parse_camera, parse_display, scan
from ..acquire.latency import default_latency_file, save_latency
from ..core.result import AxesResult, DecodeResult
from ..errors import BistairError
from ..geometry.calibration import CAMERA_PROJECTOR, Calibration, load_calibration
from ..geometry.triangulate import Reconstruction, check_depth_range, check_fit
from ..io.atomic import TEMP_PREFIX, check_output, replace_folder, write_image
from ..io.jsonfile import to_jsonable, write_json
from ..io.read import load_spec
from ..spec import BaseSpec
from .decode import decode_folder, reconstruct_folder

DECODE_FOLDER = "decode"


@dataclass
class ScanReport:
    """What a scan wrote: the folder, the scan and, if asked for, the decode and the
    reconstruction."""

    out: Path
    scan: Scan
    decoded: DecodeResult | AxesResult | None = None
    reconstruction: Reconstruction | None = None


def scan_folder(spec: BaseSpec | str | Path, display: str, camera: str, out: str | Path, *,
                decode: bool = False, calibration: Calibration | str | Path | None = None,
                depth_range: tuple[float, float] = (0.0, np.inf),
                progress: Callable[[str], None] | None = None, previews: bool = True,
                **options: Any) -> ScanReport:
    """Scan ``spec`` with ``display`` and ``camera`` into the folder ``out`` (see the
    module's description); ``options`` go to :func:`bistair.acquire.scan` (``settle_ms``,
    ``average``, ``drop``, ``exposure``, ``gain``, ``pixel_format``, ``latency_file``).
    ``decode`` writes ``OUT/decode/`` (``previews``: with its PNG previews); a
    ``calibration`` also reconstructs there (``depth_range``: ``(min, max)`` depth in mm)."""
    say = progress or (lambda text: None)
    out = check_output(out)
    check_out(out)
    if not isinstance(spec, BaseSpec):
        spec = load_spec(spec)
    cal = None
    if calibration is not None:
        check_depth_range(*depth_range)
        cal = calibration if isinstance(calibration, Calibration) else \
            load_calibration(calibration, CAMERA_PROJECTOR)
        check_fit(_blank(cal.camera.size, spec), cal, spec)  # before the work of scanning
    # devices parsed (every string and setting checked) before either opens
    devices = (parse_display(display), parse_camera(camera, options.pop("exposure", None),
                                                    options.pop("gain", None),
                                                    options.pop("pixel_format", None)))
    result = scan(spec, *devices, progress=say, **options)
    size = (result.frames.shape[2], result.frames.shape[1])
    if cal is not None and size != cal.camera.size:
        raise BistairError(f"calibration is for {cal.camera.width}x{cal.camera.height} camera "
                           f"images, {result.info['camera']['name']} delivered "
                           f"{size[0]}x{size[1]}")
    say("writing the captures")
    digits = max(2, len(str(len(result.frames) - 1)))
    files = [f"{i:0{digits}d}.png" for i in range(len(result.frames))]
    with replace_folder(out, prefix=f"{TEMP_PREFIX}{os.getpid()}-") as tmp:
        for name, image in zip(files, result.frames, strict=True):
            write_image(tmp / name, image)
        (tmp / "spec.json").write_text(spec.to_json())
        write_json(tmp / "scan.json", to_jsonable(result.to_dict(files)))
    report = ScanReport(out, result)
    if not (decode or cal is not None):
        return report
    where = out / DECODE_FOLDER
    try:
        report.decoded = decode_folder(out, where, previews=previews, progress=say)
        if cal is not None:
            report.reconstruction = reconstruct_folder(
                out, None, cal, where / "cloud.ply", depth_dir=where, min_depth=depth_range[0],
                max_depth=depth_range[1], decoded=report.decoded, progress=say)
    except BistairError as exc:
        raise BistairError(f"{exc} (the scan itself is complete in {out}: decode it with "
                           f"'bistair decode {out} --out RESULT')") from None
    return report


def check_out(out: Path) -> None:
    """Refuse an output that is a file, or a folder that holds anything but an earlier
    scan or series of scans (it is replaced as a whole)."""
    if out.exists() and not out.is_dir():
        raise BistairError(f"output {out} exists and is not a folder")
    if out.is_dir():
        items = [p for p in out.iterdir() if not p.name.startswith(TEMP_PREFIX)]
        if items and not any((out / name).is_file() for name in ("scan.json", "series.json")):
            raise BistairError(f"output folder {out} holds files and is not an earlier scan "
                               "(a scan replaces its folder as a whole): choose a new or "
                               "empty folder")


def _blank(size: tuple[int, int], spec: BaseSpec) -> DecodeResult | AxesResult:
    """An empty decode of a camera's size, for checking a calibration before the scan."""
    zeros = np.zeros((size[1], size[0]), np.float32)
    blank = DecodeResult(*(zeros,) * 8, period=1.0, method="")
    return AxesResult(blank, blank) if spec.orientation == "both" else blank


def measure_settle(display: str, camera: str, latency_file: str | Path | None = None,
                   trials: int = 6, progress: Callable[[str], None] | None = None,
                   **settings: Any) -> tuple[Latency, Path]:
    """``bistair scan --measure-latency``: time how long ``camera`` takes to see changes on
    ``display`` and save the settle time in the latency file (by default
    :func:`~bistair.acquire.latency.default_latency_file`); returns it and the file.
    ``settings``: the camera's ``exposure``, ``gain``, ``pixel_format``."""
    path = Path(latency_file) if latency_file is not None else default_latency_file()
    shown, seen = parse_display(display), parse_camera(camera, **settings)
    if not shown.drives:
        raise BistairError(f"display {shown.name} is not driven by bistair: there is no "
                           "latency to measure (the projector triggers the camera)")
    with shown, seen:
        seen.attach(shown)
        latency = measure_latency(shown, seen, trials=trials, progress=progress)
    save_latency(path, latency)
    return latency, path
