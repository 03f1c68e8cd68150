"""The scan loop: show each pattern, let it settle, drop stale frames, grab and average.

::

    for each pattern of the spec, in its frame order:
        display.show(pattern)                 up at t_show (a window: drawn and flushed)
        wait until t_show + settle            the camera's latency (--measure-latency)
        camera.flush()                        drop frames buffered before the pattern was up
        grab `average` frames, average them   -> captures[n], 8 or 16 bit as delivered

With the display ``none`` the projector runs the sequence and triggers the camera: the loop
neither waits nor drops, it grabs ``average`` frames per pattern in order.

Examples
--------
>>> from bistair.codecs import make_spec
>>> spec = make_spec("graycode", width=1920, height=1080, period=30)
>>> result = scan(spec, "none", "sim:plane:48x32")
>>> result.frames.shape, result.frames.dtype, result.info["settle_source"]
((10, 32, 48), dtype('uint8'), 'none')
"""

from __future__ import annotations

import contextlib
import itertools
import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from ..codecs import encode
from ..core.captures import to_bit_depth
from ..errors import BistairError
from ..io.read import load_spec
from ..spec import BaseSpec
from .cameras import Camera, Frame
from .devices import parse_camera, parse_display
from .displays import Display
from .latency import default_latency_file, read_settle

DEFAULT_SETTLE_MS = 250.0  # a display and camera whose latency was never measured
MAX_AVERAGE = 1000


@dataclass
class Scan:
    """A scan: the captures ``(frames, height, width)`` in the camera's dtype, the spec,
    one record a frame (``shown``, ``settled``, ``grabbed``: seconds from the start of the
    loop; ``dropped``; the camera's own ``stamps``) and what was used (``info``: display,
    camera, settle, average, start time, warnings)."""

    frames: np.ndarray
    spec: BaseSpec
    records: list[dict[str, Any]]
    info: dict[str, Any] = field(default_factory=dict)

    def to_dict(self, files: list[str] | None = None) -> dict[str, Any]:
        """What ``scan.json`` holds (``files``: the frame files, in order)."""
        records = [dict(r) for r in self.records]
        for record, name in zip(records, files or [], strict=False):
            record["file"] = name
        return {"format": "bistair-scan", "version": 1, **self.info,
                "frame_size": [int(self.frames.shape[2]), int(self.frames.shape[1])],
                "frame_dtype": str(self.frames.dtype), "frames": records}


def pattern_images(spec: BaseSpec) -> np.ndarray:
    """The spec's patterns as the images ``bistair patterns`` writes (8 or 16 bit)."""
    return to_bit_depth(encode(spec), spec.bits)


def settle_time(display: Display, camera: Camera, settle_ms: float | None = None,
                latency_file: str | Path | None = None) -> tuple[float, str]:
    """The settle time (ms) and where it comes from: ``option`` (``settle_ms``), ``none``
    (the display ``none``), ``camera`` (a camera with its own, the simulated one: 0),
    ``measured`` (the latency file) or ``default`` (:data:`DEFAULT_SETTLE_MS`)."""
    if settle_ms is not None:
        if not (isinstance(settle_ms, int | float) and math.isfinite(settle_ms)
                and 0 <= settle_ms <= 60000):
            raise BistairError(f"--settle-ms must be from 0 to 60000 ms, got {settle_ms!r}")
        return float(settle_ms), "option"
    if not display.drives:
        return 0.0, "none"
    if camera.settle_ms is not None:
        return float(camera.settle_ms), "camera"
    measured = read_settle(latency_file or default_latency_file(), display.name, camera.name)
    if measured is not None:
        return measured, "measured"
    return DEFAULT_SETTLE_MS, "default"


def scan(spec: BaseSpec | str | Path, display: Display | str, camera: Camera | str, *,
         settle_ms: float | None = None, average: int = 1, drop: int | None = None,
         exposure: float | None = None, gain: float | None = None,
         pixel_format: str | None = None, latency_file: str | Path | None = None,
         progress: Callable[[str], None] | None = None) -> Scan:
    """Show the spec's patterns on ``display`` and grab them with ``camera``.

    ``display`` and ``camera`` are device strings (see :mod:`bistair.acquire.devices`) or
    device objects (not yet open: they are opened and closed here). ``settle_ms``: wait
    after showing each pattern (default: see :func:`settle_time`); ``drop``: frames to drop
    after the wait (default: the camera's own, e.g. a GenICam camera's whole buffer);
    ``average``: frames grabbed and averaged per pattern. ``exposure``, ``gain`` and
    ``pixel_format`` apply to a camera given as a string. ``progress`` is called with each
    stage's name.

    Raises :class:`BistairError` (one line) for bad devices or settings, patterns that do
    not fit the screen, a camera that delivers no frame or frames of changing size; the
    devices are closed on every way out, Ctrl-C included.
    """
    with contextlib.closing(scans(spec, display, camera, 1, settle_ms=settle_ms,
                                  average=average, drop=drop, exposure=exposure, gain=gain,
                                  pixel_format=pixel_format, latency_file=latency_file,
                                  progress=progress)) as each:
        return next(each)


def scans(spec: BaseSpec | str | Path, display: Display | str, camera: Camera | str,
          count: int | None = 1, *, settle_ms: float | None = None, average: int = 1,
          drop: int | None = None, exposure: float | None = None, gain: float | None = None,
          pixel_format: str | None = None, latency_file: str | Path | None = None,
          progress: Callable[[str], None] | None = None) -> Iterator[Scan]:
    """Scan the pattern set ``count`` times in a row (``None``: until the caller stops),
    the devices open throughout: each :class:`Scan` is yielded as soon as its last frame is
    grabbed, and the next begins when the caller asks for it.

    The arguments are those of :func:`scan`; everything is checked before the devices
    open, and they are closed when the iterator ends or is closed (``contextlib.closing``),
    Ctrl-C included. The camera is told the patterns first (:meth:`Camera.prepare`).

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> spec = make_spec("graycode", width=1920, height=1080, period=30)
    >>> each = scans(spec, "none", "sim:plane:48x32@1000", 3)
    >>> [s.frames.shape for s in each]
    [(10, 32, 48), (10, 32, 48), (10, 32, 48)]
    """
    if not isinstance(spec, BaseSpec):
        spec = load_spec(spec)
    if isinstance(average, bool) or not isinstance(average, int) or \
            not 1 <= average <= MAX_AVERAGE:
        raise BistairError(f"--average must be a whole number from 1 to {MAX_AVERAGE}, got "
                           f"{average!r}")
    if drop is not None and (isinstance(drop, bool) or not isinstance(drop, int) or drop < 0):
        raise BistairError(f"--drop must be a whole number of frames from 0, got {drop!r}")
    if isinstance(display, str):
        display = parse_display(display)
    if isinstance(camera, str):
        camera = parse_camera(camera, exposure, gain, pixel_format)
    say = progress or (lambda text: None)
    patterns = pattern_images(spec)
    settle, source = settle_time(display, camera, settle_ms, latency_file)
    camera.check(spec.width, spec.height)
    say(f"opening {display.name} and {camera.name}")
    with display:
        display.check(spec.width, spec.height)  # its size is known once it is open
        with camera:
            camera.attach(display)
            camera.prepare(patterns)
            for n in itertools.count() if count is None else range(count):
                if count != 1:  # a stage a scan, not a pattern
                    say(f"scan {n + 1}" + ("" if count is None else f" of {count}"))
                yield _run(spec, display, camera, patterns, settle, source, drop, average,
                           say if count == 1 else _quiet)


def _quiet(text: str) -> None:
    """The progress of each pattern of a scan among many: not told."""


def _run(spec: BaseSpec, display: Display, camera: Camera, patterns: np.ndarray,
         settle: float, source: str, drop: int | None, average: int,
         say: Callable[[str], None]) -> Scan:
    """The loop over the patterns, with both devices open."""
    started = datetime.now(UTC).isoformat(timespec="milliseconds")
    start = time.monotonic()
    frames, records = [], []
    for index, (name, pattern) in enumerate(zip(spec.frames, patterns, strict=True)):
        say(f"pattern {index + 1} of {len(patterns)} ({name})")
        image, record = _one_pattern(display, camera, pattern, settle, drop, average,
                                     frames[0] if frames else None)
        frames.append(image)
        records.append({"index": index, "name": name,
                        **{k: _since(v, start) if k in _TIMES else v
                           for k, v in record.items()}})
    seconds = time.monotonic() - start
    info = {"started": started, "seconds": round(seconds, 3),
            "display": display.describe(), "camera": camera.describe(),
            "settle_ms": settle, "settle_source": source, "average": average,
            "drop": drop, "warnings": _warnings(display, camera, source, settle)}
    return Scan(np.stack(frames), spec, records, info)


def _one_pattern(display: Display, camera: Camera, pattern: np.ndarray, settle: float,
                 drop: int | None, average: int, first: np.ndarray | None
                 ) -> tuple[np.ndarray, dict[str, Any]]:
    """Show one pattern and grab its frame (see the module's description)."""
    shown = display.show(pattern)
    dropped = 0
    if display.drives:
        display.wait(shown + settle / 1000.0)
        settled = time.monotonic()
        dropped = camera.flush(drop)
    else:
        settled = shown
    grabs: list[Frame] = []
    for _ in range(average):
        frame = camera.grab()
        display.poll()  # a window answers its window system while the camera works
        _check_frame(camera, frame.image, first if first is not None else
                     (grabs[0].image if grabs else None))
        grabs.append(frame)
    if average == 1:
        image = grabs[0].image
    else:
        mean = np.mean([g.image for g in grabs], axis=0, dtype=np.float64)
        image = np.round(mean).astype(grabs[0].image.dtype)
    record = {"shown": shown, "settled": settled, "dropped": dropped,
              "grabbed": [g.time for g in grabs],
              "stamps": [g.stamp for g in grabs] if any(g.stamp is not None for g in grabs)
              else None}
    return image, record


def _check_frame(camera: Camera, image: np.ndarray, first: np.ndarray | None) -> None:
    if image.ndim != 2 or image.dtype not in (np.uint8, np.uint16):
        raise BistairError(f"camera {camera.name} delivered {image.dtype} frames of shape "
                           f"{image.shape}: 8- or 16-bit grey frames are needed")
    if first is None:
        return
    if image.shape != first.shape:
        raise BistairError(f"camera {camera.name} delivered a {image.shape[1]}x{image.shape[0]} "
                           f"frame after {first.shape[1]}x{first.shape[0]} ones: frames of "
                           "changing size cannot be decoded")
    if image.dtype != first.dtype:
        raise BistairError(f"camera {camera.name} delivered {image.dtype} frames after "
                           f"{first.dtype} ones: frames of changing depth cannot be decoded")


_TIMES = ("shown", "settled", "grabbed")  # the records' monotonic times


def _since(value: float | list[float], start: float) -> float | list[float]:
    """Monotonic times as seconds from the start, rounded to 0.1 ms (lists too)."""
    if isinstance(value, list):
        return [round(v - start, 4) for v in value]
    return round(value - start, 4)


def _warnings(display: Display, camera: Camera, source: str, settle: float) -> list[str]:
    if source != "default":
        return []
    return [f"no latency measured for {display.name} and {camera.name}: each pattern "
            f"settled {settle:g} ms (measure it with 'bistair scan --measure-latency "
            f"--display {display.name} --camera {camera.name}', or give --settle-ms)"]
