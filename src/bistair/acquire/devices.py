"""The device strings of ``bistair scan --display`` and ``--camera``, parsed in one place.

Displays: ``window[:SCREEN]`` (default screen 0), ``none``. Cameras:
``opencv:INDEX|URL``, ``genicam:PRODUCER.cti[:SERIAL]``, ``screen[:MONITOR]`` (default 0),
``sim[:SCENE[:WxH]][@FPS]`` (default ``paper-sim`` at the preset's camera size, frames as
fast as it renders them; ``@FPS``: a frame every ``1/FPS`` s). A string that
names no known kind, a bad number or a producer file that is not there is refused with one
line, before anything is opened.

Examples
--------
>>> parse_display("window:1").name, parse_display("none").name
('window:1', 'none')
>>> parse_camera("opencv:0").name, parse_camera("sim:plane:64x48").name
('opencv:0', 'sim:plane:64x48')
>>> parse_camera("sim:plane:64x48@60").fps, parse_camera("sim@7.5").name
(60.0, 'sim:paper-sim@7.5')
>>> parse_camera("webcam")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
bistair.errors.BistairError: unknown camera 'webcam' (known: opencv:INDEX|URL, ...)
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import BistairError
from .cameras import Camera, OpenCVCamera, ScreenCamera, SimCamera
from .displays import Display, NoDisplay, WindowDisplay
from .genicam import GenicamCamera

DISPLAYS = "window[:SCREEN], none"
CAMERAS = ("opencv:INDEX|URL, genicam:PRODUCER.cti[:SERIAL], screen[:MONITOR], "
           "sim[:SCENE[:WxH]][@FPS]")


def parse_display(text: str) -> Display:
    """The display a device string names (not opened yet).

    Parameters
    ----------
    text : str
        ``window``, ``window:SCREEN`` (a screen number from 0) or ``none``.

    Returns
    -------
    Display
        A :class:`~bistair.acquire.displays.WindowDisplay` or
        :class:`~bistair.acquire.displays.NoDisplay`; open it with ``with``.

    Raises
    ------
    BistairError
        An unknown kind or a screen that is not a whole number.

    Examples
    --------
    >>> parse_display("window").screen
    0
    >>> parse_display("window:x")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the screen of display 'window:x' must be a number from 0, got 'x'
    """
    kind, _, rest = text.strip().partition(":")
    if kind == "none" and not rest:
        return NoDisplay()
    if kind == "window":
        return WindowDisplay(_index(rest, 0, f"the screen of display {text!r}"))
    raise BistairError(f"unknown display {text!r} (known: {DISPLAYS})")


def parse_camera(text: str, exposure: float | None = None, gain: float | None = None,
                 pixel_format: str | None = None) -> Camera:
    """The camera a device string names, with its settings (not opened yet).

    Parameters
    ----------
    text : str
        ``opencv:INDEX`` (a device number) or ``opencv:URL`` (a stream, video file or
        image sequence such as ``caps/f%03d.png``), ``genicam:PRODUCER.cti`` or
        ``genicam:PRODUCER.cti:SERIAL``, ``screen`` or ``screen:MONITOR``, ``sim``,
        ``sim:SCENE`` or ``sim:SCENE:WxH``, each with ``@FPS`` (a frame rate) or without.
    exposure, gain : float, optional
        In the camera's own units (genicam: ``ExposureTime`` in microseconds; opencv: the
        backend's; sim: the response to full white).
    pixel_format : str, optional
        genicam: ``Mono8``, ``Mono12`` or ``Mono16``.

    Returns
    -------
    Camera
        The camera; open it with ``with``.

    Raises
    ------
    BistairError
        An unknown kind, a bad index or size, a missing producer file, an unknown sim
        scene, or a setting the camera does not take.

    Examples
    --------
    >>> parse_camera("genicam:/nowhere/producer.cti")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: GenTL producer file /nowhere/producer.cti not found
    >>> parse_camera("screen", exposure=10)
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the screen camera has no exposure setting (it takes none)
    """
    text = text.strip()
    kind, _, rest = text.partition(":")
    settings: dict[str, Any] = {"exposure": exposure, "gain": gain,
                                "pixel_format": pixel_format}
    if kind == "opencv":
        if not rest:
            raise BistairError("camera opencv needs a device number or a URL: opencv:0, "
                               "opencv:rtsp://..., opencv:caps/f%03d.png")
        source: int | str = int(rest) if rest.isdigit() else rest
        return OpenCVCamera(source, **settings)
    if kind == "genicam":
        producer, serial = _producer(rest, text)
        return GenicamCamera(producer, serial, **settings)
    if kind == "screen":
        return ScreenCamera(_index(rest, 0, f"the monitor of camera {text!r}"), **settings)
    if kind.partition("@")[0] == "sim":
        rest, fps = _rate(text.partition(":")[2] if ":" in text else "", text)
        scene, _, size = rest.partition(":")
        return SimCamera(scene or "paper-sim", _size(size, text) if size else None, fps,
                         **settings)
    raise BistairError(f"unknown camera {text!r} (known: {CAMERAS})")


def _index(text: str, default: int, what: str) -> int:
    if not text:
        return default
    if not text.isdigit():
        raise BistairError(f"{what} must be a number from 0, got {text!r}")
    return int(text)


def _producer(rest: str, text: str) -> tuple[Path, str | None]:
    """``PRODUCER.cti`` or ``PRODUCER.cti:SERIAL`` (the path may hold colons itself)."""
    if rest.lower().endswith(".cti"):
        path, serial = rest, None
    else:
        path, _, serial = rest.rpartition(":")
    if not path.lower().endswith(".cti"):
        raise BistairError(f"camera {text!r} must be genicam:PRODUCER.cti or "
                           "genicam:PRODUCER.cti:SERIAL (the GenTL producer file of the "
                           "camera's vendor)")
    if not Path(path).is_file():
        raise BistairError(f"GenTL producer file {path} not found")
    return Path(path), serial or None


def _rate(rest: str, device: str) -> tuple[str, float | None]:
    """``REST@FPS`` as ``(REST, FPS)`` (``None`` without ``@``); the whole device string
    ``sim@FPS`` too."""
    if "@" not in device:
        return rest, None
    rest = rest.rpartition("@")[0] if "@" in rest else ""
    value = device.rpartition("@")[2]
    try:
        fps = float(value)
    except ValueError:
        fps = None
    if fps is None or not fps > 0:
        raise BistairError(f"the frame rate of camera {device!r} must be a number of frames "
                           f"a second above 0, e.g. @60, got {value!r}")
    return rest, fps


def _size(text: str, device: str) -> tuple[int, int]:
    parts = text.lower().split("x")
    if len(parts) != 2 or not all(p.isdigit() and 8 <= int(p) <= 8192 for p in parts):
        raise BistairError(f"the camera size of {device!r} must be WIDTHxHEIGHT from 8 to "
                           f"8192 pixels a side, e.g. 640x512, got {text!r}")
    return int(parts[0]), int(parts[1])
