"""How long a camera takes to see what a display shows, and the settle time it asks for.

:func:`measure_latency` flashes the screen black and white and times, for each change, when
a grabbed frame has gone 90% of the way to the new level: the time from showing a pattern
to the first frame that shows it (display lag, camera exposure, transfer and buffering
together). The settle time is the longest of them plus a quarter. :func:`save_latency`
keeps it per display and camera in a small JSON file (by default
``~/.config/bistair/latency.json``, or ``$BISTAIR_LATENCY_FILE``), where ``bistair scan``
finds it when no ``--settle-ms`` is given.

Examples
--------
>>> import tempfile, pathlib
>>> with tempfile.TemporaryDirectory() as tmp:
...     path = pathlib.Path(tmp) / "latency.json"
...     save_latency(path, Latency("window:0", "opencv:0", [80.0, 120.0], 0.02, 0.9))
...     read_settle(path, "window:0", "opencv:0")
150.0
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import asdict, dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import BistairError
from ..io.atomic import output_file
from ..io.jsonfile import read_json, write_json
from .cameras import Camera
from .displays import Display

LATENCY_FORMAT = "bistair-latency"
MIN_CONTRAST = 0.02  # white minus black the camera must see, fraction of full scale
TIMEOUT = 5.0  # seconds to wait for a change to show


@dataclass
class Latency:
    """The measured latencies (ms) of a display and camera, and the levels the camera saw
    (mean of the frame, fraction of full scale) on black and white."""

    display: str
    camera: str
    latencies_ms: list[float]
    black: float
    white: float
    measured: str = ""

    @property
    def settle_ms(self) -> float:
        """The longest latency plus a quarter, rounded up to a millisecond."""
        return float(math.ceil(max(self.latencies_ms) * 1.25))


def default_latency_file() -> Path:
    """``$BISTAIR_LATENCY_FILE``, else ``bistair/latency.json`` in ``$XDG_CONFIG_HOME``
    (``~/.config``)."""
    if os.environ.get("BISTAIR_LATENCY_FILE"):
        return Path(os.environ["BISTAIR_LATENCY_FILE"])
    base = os.environ.get("XDG_CONFIG_HOME") or Path.home() / ".config"
    return Path(base) / "bistair" / "latency.json"


def _key(display: str, camera: str) -> str:
    return f"{display} {camera}"


def read_settle(path: str | Path, display: str, camera: str) -> float | None:
    """The settle time (ms) measured for a display and camera, or None if never measured
    (or no file)."""
    path = Path(path)
    if not path.exists():
        return None
    data = read_json(path, "latency file", state=True)
    entry = data.get("pairs", {}).get(_key(display, camera)) if isinstance(data, dict) else None
    value = entry.get("settle_ms") if isinstance(entry, dict) else None
    if not isinstance(value, int | float) or not 0 <= value < 60000:
        return None
    return float(value)


def save_latency(path: str | Path, latency: Latency) -> None:
    """Add (or replace) a measurement in the latency file, written atomically."""
    path = Path(path)
    data = read_json(path, "latency file", state=True) if path.exists() else {}
    if not isinstance(data, dict) or data.get("format") != LATENCY_FORMAT:
        data = {"format": LATENCY_FORMAT, "version": 1, "pairs": {}}
    data.setdefault("pairs", {})[_key(latency.display, latency.camera)] = {
        **asdict(latency), "settle_ms": latency.settle_ms}
    with output_file(path) as tmp:
        write_json(tmp, data)


def _level(image: np.ndarray) -> float:
    top = 65535.0 if image.dtype == np.uint16 else 255.0
    return float(image.mean(dtype=np.float64)) / top


def measure_latency(display: Display, camera: Camera, trials: int = 6,
                    progress: Any = None) -> Latency:
    """Flash ``trials`` changes between black and white on the open ``display`` and time
    when ``camera`` (open, attached) sees each; see the module's description.

    Raises :class:`BistairError` for a display that bistair does not drive (``none``), a
    camera that sees less than 2% of full scale between black and white, or a change not
    seen within 5 s.
    """
    if not display.drives or display.size is None:
        raise BistairError(f"display {display.name} is not driven by bistair: there is no "
                           "latency to measure (the projector triggers the camera)")
    say = progress or (lambda text: None)
    width, height = display.size
    screens = {0: np.zeros((height, width), np.uint8), 1: np.full((height, width), 255, np.uint8)}

    def steady(which: int) -> float:
        display.wait(display.show(screens[which]) + 1.0)
        camera.flush()
        return float(np.mean([_level(camera.grab().image) for _ in range(3)]))

    say("measuring the camera's levels on black and white")
    black, white = steady(0), steady(1)
    if white - black < MIN_CONTRAST:
        raise BistairError(f"camera {camera.name} sees {100 * (white - black):.1f}% of full "
                           f"scale between black and white on {display.name} (black "
                           f"{100 * black:.1f}%, white {100 * white:.1f}%): does it look at the "
                           "projected image, is its exposure right?")
    times, now = [], 1
    for trial in range(trials):
        say(f"timing change {trial + 1} of {trials}")
        now = 1 - now
        goal = black + (0.9 if now == 1 else 0.1) * (white - black)  # 90% of the way there
        shown = display.show(screens[now])
        while True:
            frame = camera.grab()
            level = _level(frame.image)
            if (level >= goal) if now == 1 else (level <= goal):
                times.append(1000.0 * (frame.time - shown))
                break
            if frame.time - shown > TIMEOUT:
                raise BistairError(f"camera {camera.name} did not see {display.name} turn "
                                   f"{'white' if now else 'black'} within {TIMEOUT:g} s")
        display.wait(time.monotonic() + 0.2)
    stamp = datetime.now(UTC).isoformat(timespec="seconds")
    return Latency(display.name, camera.name, [round(t, 2) for t in times], round(black, 4),
                   round(white, 4), stamp)
