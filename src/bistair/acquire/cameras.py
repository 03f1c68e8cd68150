"""Cameras that grab what the projector shows.

- :class:`OpenCVCamera` (``opencv:INDEX|URL``): ``cv2.VideoCapture`` of a USB/UVC camera
  (``INDEX``), a stream, a video file or an image sequence (``URL``, e.g. ``f%03d.png``).
  Exposure and gain where the backend takes them (in the backend's own units).
- :class:`~bistair.acquire.genicam.GenicamCamera` (``genicam:PRODUCER.cti[:SERIAL]``), in
  :mod:`bistair.acquire.genicam`.
- :class:`ScreenCamera` (``screen[:MONITOR]``): screenshots of a monitor (mss), a camera
  that looks at the screen itself, for tests and demonstrations.
- :class:`SimCamera` (``sim[:SCENE[:WxH]][@FPS]``): the virtual rig (:mod:`bistair.sim`)
  renders what its camera sees of the pattern the display shows, with the imaging of
  ``bistair simulate``'s defaults, frame ``k`` with the noise of frame ``k`` of
  ``bistair simulate``; a preset scene or a calibration board in one of eight poses. At a
  frame rate (``@FPS``) it delivers a frame every ``1/FPS`` s, as a camera does, rendering
  each pattern once (:meth:`Camera.prepare`).

A camera is a context manager: leaving the ``with`` block (also by Ctrl-C or an error)
releases the device. :meth:`Camera.grab` returns one :class:`Frame`, 2-D grey in the
camera's own dtype (``uint8``; ``uint16`` for deeper pixel formats).

Examples
--------
>>> import numpy as np
>>> from bistair.acquire.displays import NoDisplay
>>> with NoDisplay() as display, SimCamera("plane", (32, 24)) as camera:
...     camera.attach(display)
...     _ = display.show(np.full((1080, 1920), 255, np.uint8))
...     frame = camera.grab()
>>> frame.image.shape, frame.image.dtype
((24, 32), dtype('uint8'))
"""

from __future__ import annotations

import time
import zlib
from typing import Any, NamedTuple

import cv2
import mss
import numpy as np

from ..errors import BistairError
from ..geometry.board import Board
from ..sim import Imaging, Rig, Scene, expose, preset, scene_names, trace
from ..sim.boards import POSES, board_plane
from .displays import Display

PIXEL_FORMATS = ("Mono8", "Mono12", "Mono16")
# the virtual camera's imaging: bistair simulate's defaults, so that a sim scan is its render
SIM_IMAGING = dict(read_noise=0.01, camera_blur=1.0, gamma=2.2, ambient=0.05, bits=8, seed=0)
FETCH_TIMEOUT = 5.0  # seconds a camera may take to deliver a frame
SIM_BOARD = Board("checkerboard", 9, 6, 20.0)  # the board of the sim:board-N scenes
MAX_FPS = 1000.0  # the sim camera's highest frame rate


class Frame(NamedTuple):
    """One grabbed frame: the image, ``time.monotonic()`` when the grab returned and the
    device's own timestamp in seconds (None where it has none)."""

    image: np.ndarray
    time: float
    stamp: float | None = None


class Camera:
    """What every camera does; subclasses open, grab and close."""

    kind = "camera"
    settings: tuple[str, ...] = ()  # the settings it takes: exposure, gain, pixel_format
    settle_ms: float | None = None  # its own settle time (None: measure it)

    def __init__(self, exposure: float | None = None, gain: float | None = None,
                 pixel_format: str | None = None) -> None:
        asked = {"exposure": exposure, "gain": gain, "pixel_format": pixel_format}
        for key, value in asked.items():
            if value is not None and key not in self.settings:
                raise BistairError(f"the {self.kind} camera has no {key.replace('_', ' ')} "
                                   f"setting ({_takes(self.kind)})")
        if pixel_format is not None and pixel_format not in PIXEL_FORMATS:
            raise BistairError(f"pixel format must be one of {', '.join(PIXEL_FORMATS)}, got "
                               f"{pixel_format!r}")
        self.exposure, self.gain, self.pixel_format = exposure, gain, pixel_format
        self.drop = 0  # frames a flush drops (set when open)
        self.grabs = 0

    @property
    def name(self) -> str:
        """The device string that opens this camera again."""
        return self.kind

    def __enter__(self) -> Camera:
        self.open()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def open(self) -> None:
        """Open the device and apply the settings."""

    def close(self) -> None:
        """Release the device; safe to call twice."""

    def attach(self, display: Display) -> None:
        """The display whose patterns the camera looks at (the simulated camera renders
        them)."""

    def check(self, width: int, height: int) -> None:
        """Refuse patterns of ``width x height`` the camera cannot see whole (before it
        opens)."""

    def prepare(self, patterns: np.ndarray) -> None:
        """The patterns the display will show, before the first (a camera that renders
        them, the simulated one at a frame rate, renders them here)."""

    def grab(self) -> Frame:
        """The next frame."""
        raise NotImplementedError

    def flush(self, count: int | None = None) -> int:
        """Drop the frames buffered before now (``count`` of them, or the camera's own
        number); returns how many were dropped."""
        count = self.drop if count is None else count
        for _ in range(count):
            self.grab()
        return count

    def describe(self) -> dict[str, Any]:
        """The camera as ``scan.json`` records it."""
        return {"kind": self.kind, "name": self.name, "exposure": self.exposure,
                "gain": self.gain, "pixel_format": self.pixel_format, "drop": self.drop}


def _takes(kind: str) -> str:
    return {"opencv": "opencv cameras take exposure and gain",
            "genicam": "genicam cameras take exposure, gain and pixel format",
            "sim": "the sim camera takes exposure, its response to white from 0 to 1"}.get(
        kind, "it takes none")


def grey(image: np.ndarray) -> np.ndarray:
    """A camera frame as 2-D grey in its own dtype: a colour frame (BGR or BGRA) whose
    channels agree gives one of them, else OpenCV's BGR-to-grey weights.

    Parameters
    ----------
    image : numpy.ndarray
        ``(H, W)``, ``(H, W, 1)``, ``(H, W, 3)`` BGR or ``(H, W, 4)`` BGRA.

    Returns
    -------
    numpy.ndarray
        ``(H, W)``, contiguous.

    Raises
    ------
    BistairError
        If the frame is not an image of those shapes.

    Examples
    --------
    >>> bgr = np.zeros((1, 2, 3), np.uint8); bgr[0, 1] = 200
    >>> grey(bgr).tolist()
    [[0, 200]]
    """
    image = np.asarray(image)
    if image.ndim == 3 and image.shape[2] == 1:
        image = image[:, :, 0]
    if image.ndim == 2:
        return np.ascontiguousarray(image)
    if image.ndim != 3 or image.shape[2] not in (3, 4):
        raise BistairError(f"the camera delivered an array of shape {image.shape}, not an "
                           "image")
    colour = image[:, :, :3]
    if (colour[:, :, 0] == colour[:, :, 1]).all() and (colour[:, :, 0] == colour[:, :, 2]).all():
        return np.ascontiguousarray(colour[:, :, 0])
    return cv2.cvtColor(np.ascontiguousarray(colour), cv2.COLOR_BGR2GRAY)


class OpenCVCamera(Camera):
    """``opencv:INDEX|URL``: ``cv2.VideoCapture``. A device (``INDEX``) drops its buffered
    frames after each pattern (the backend's buffer size, else 4); a file or stream none
    unless told."""

    kind = "opencv"
    settings = ("exposure", "gain")

    def __init__(self, source: int | str, **settings: Any) -> None:
        super().__init__(**settings)
        self.source = source
        self._cap: Any = None
        self.backend: str | None = None

    @property
    def name(self) -> str:
        return f"opencv:{self.source}"

    def open(self) -> None:
        level = cv2.utils.logging.getLogLevel()
        # OpenCV's own warnings would spoil the one-line error
        cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)
        try:
            cap = cv2.VideoCapture(self.source)
            opened = cap.isOpened()
        finally:
            cv2.utils.logging.setLogLevel(level)
        if not opened:
            cap.release()
            what = "no such device or it is busy" if isinstance(self.source, int) else \
                "no such file, or a stream or format OpenCV cannot read"
            raise BistairError(f"cannot open camera {self.name}: {what}")
        self._cap, self.backend = cap, cap.getBackendName()
        for key, prop in (("exposure", cv2.CAP_PROP_EXPOSURE), ("gain", cv2.CAP_PROP_GAIN)):
            value = getattr(self, key)
            if value is None:
                continue
            if key == "exposure":
                cap.set(cv2.CAP_PROP_AUTO_EXPOSURE, 0.25)  # manual, as V4L2 names it in OpenCV
            if not cap.set(prop, float(value)):
                self.close()
                raise BistairError(f"camera {self.name} does not take the {key} {value:g} "
                                   f"(its {self.backend} backend refused it)")
        if isinstance(self.source, int):
            buffered = cap.get(cv2.CAP_PROP_BUFFERSIZE)
            self.drop = int(buffered) if buffered > 0 else 4

    def close(self) -> None:
        if self._cap is not None:
            self._cap.release()
            self._cap = None

    def grab(self) -> Frame:
        ok, image = self._cap.read()
        now = time.monotonic()
        if not ok or image is None:
            raise BistairError(f"camera {self.name} delivered no frame after {self.grabs} "
                               "(end of the stream, or the device was disconnected)")
        self.grabs += 1
        position = self._cap.get(cv2.CAP_PROP_POS_MSEC)
        return Frame(grey(image), now, position / 1000.0 if position > 0 else None)

    def describe(self) -> dict[str, Any]:
        out = {**super().describe(), "backend": self.backend}
        if self._cap is not None:
            out["reported_exposure"] = self._cap.get(cv2.CAP_PROP_EXPOSURE)
            out["reported_gain"] = self._cap.get(cv2.CAP_PROP_GAIN)
        return out


class ScreenCamera(Camera):
    """``screen[:MONITOR]``: a screenshot of monitor ``MONITOR`` (from 0, as mss lists the
    monitors after the union of all of them) for every frame; 8-bit grey."""

    kind = "screen"

    def __init__(self, monitor: int = 0, **settings: Any) -> None:
        super().__init__(**settings)
        self.monitor = monitor
        self._shots: Any = None
        self._area: dict[str, int] | None = None

    @property
    def name(self) -> str:
        return f"screen:{self.monitor}"

    def open(self) -> None:
        try:
            shots = mss.MSS()
        except Exception as exc:  # mss raises ScreenShotError without a window system
            raise BistairError(f"cannot open camera {self.name}: {one_line(exc)}"
                               f"{'' if 'DISPLAY' in str(exc) else ' (is DISPLAY set?)'}") \
                from None
        monitors = shots.monitors[1:]
        if self.monitor >= len(monitors):
            shots.close()
            raise BistairError(f"cannot open camera {self.name}: there "
                               f"{'is' if len(monitors) == 1 else 'are'} {len(monitors)} "
                               f"monitor{'s' if len(monitors) != 1 else ''}")
        self._shots, self._area = shots, dict(monitors[self.monitor])

    def close(self) -> None:
        if self._shots is not None:
            self._shots.close()
            self._shots = None

    def grab(self) -> Frame:
        shot = np.asarray(self._shots.grab(self._area))
        self.grabs += 1
        return Frame(grey(shot), time.monotonic())

    def describe(self) -> dict[str, Any]:
        return {**super().describe(), "area": self._area}


class SimCamera(Camera):
    """``sim[:SCENE[:WxH]][@FPS]``: the virtual rig of a preset scene (``paper-sim`` by
    default; camera size ``WxH``, by default the preset's) renders the pattern the display
    shows, placed at the top-left of its projector as a screen shows it. ``board-N`` (N from
    0 to 7) is the 9 x 6 checkerboard of 20 mm of ``bistair simulate --scene calibration``
    in its pose N, on the default rig (1920 x 1080 projector). Exposure: the response to
    full white, above 0 and at most 1 (0.8 by default, :class:`~bistair.sim.Imaging`).

    ``fps``: a camera that delivers a frame every ``1/fps`` seconds from its first grab
    (a grab waits for the next frame; one asked for late is delivered at once, as from a
    camera's buffer). So that rendering costs no time between frames, it renders each
    pattern once, in :meth:`prepare` (pattern ``k`` with the noise of frame ``k``, as
    without a rate) or when first shown, and delivers that image whenever the pattern is
    shown again: a still scene scanned again and again gives the same images."""

    kind = "sim"
    settings = ("exposure",)
    settle_ms = 0.0  # it sees the pattern the moment it is shown

    def __init__(self, scene: str = "paper-sim", size: tuple[int, int] | None = None,
                 fps: float | None = None, **settings: Any) -> None:
        super().__init__(**settings)
        if self.exposure is not None and not 0 < self.exposure <= 1:  # (NaN too)
            raise BistairError(f"the sim camera's exposure is its response to white, above 0 "
                               f"and at most 1, got {self.exposure:g}")
        if fps is not None and (isinstance(fps, bool) or not isinstance(fps, int | float)
                                or not 0 < fps <= MAX_FPS):
            raise BistairError(f"the frame rate of the sim camera must be above 0 and at most "
                               f"{MAX_FPS:g} frames a second, got {fps!r}")
        self.fps = None if fps is None else float(fps)
        self._rendered: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {}
        self._next: float | None = None  # when the next frame is due (at a frame rate)
        boards = [f"board-{i}" for i in range(len(POSES))]
        if scene not in (*scene_names(), *boards):
            raise BistairError(f"unknown sim scene {scene!r} (known: "
                               f"{', '.join(scene_names())}, board-0 to {boards[-1]})")
        extra = {} if self.exposure is None else {"exposure": self.exposure}
        self.imaging = Imaging(**SIM_IMAGING, **extra)
        self.scene, self.size = scene, size
        # the rig and scene are quick to make; the ray casting waits for open()
        sized = {} if size is None else {"camera_size": size}
        if scene in boards:  # the board of 'bistair simulate --scene calibration' in a pose
            self._rig = Rig.default(**sized)
            self._geometry = Scene([board_plane(SIM_BOARD, *POSES[boards.index(scene)])])
        else:
            self._rig, self._geometry = preset(scene, **sized)
        self._trace: Any = None
        self._display: Display | None = None

    @property
    def name(self) -> str:
        return f"sim:{self.scene}" + (f":{self.size[0]}x{self.size[1]}" if self.size else "") \
            + (f"@{self.fps:g}" if self.fps is not None else "")

    def open(self) -> None:
        self._trace = trace(self._rig, self._geometry, self.imaging)
        self._rendered, self._next = {}, None

    def close(self) -> None:
        self._trace = None
        self._rendered = {}

    def prepare(self, patterns: np.ndarray) -> None:
        if self.fps is None:
            return
        top = 65535.0 if patterns.dtype == np.uint16 else 255.0
        for k, codes in enumerate(patterns):
            if self._cached(codes) is None:  # as a display holds it: fractions of full scale
                self._keep(codes, self._render(codes.astype(np.float32) / np.float32(top), k))

    def attach(self, display: Display) -> None:
        self._display = display

    def check(self, width: int, height: int) -> None:
        projector = self._rig.projector
        if width > projector.width or height > projector.height:
            raise BistairError(f"the spec's {width}x{height} patterns do not fit the "
                               f"{projector.width}x{projector.height} projector of "
                               f"{self.name}")

    def grab(self) -> Frame:
        codes = None if self._display is None else self._display.codes
        if codes is None:
            raise BistairError(f"camera {self.name} sees no pattern: nothing was shown")
        self.check(codes.shape[1], codes.shape[0])
        if self.fps is None:
            image = self._render(self._display.current, self.grabs)
        else:
            image = self._cached(codes)
            if image is None:
                image = self._keep(codes, self._render(self._display.current, self.grabs))
            now = time.monotonic()
            due = now if self._next is None else self._next
            if due > now:
                time.sleep(due - now)
            self._next = due + 1.0 / self.fps
        self.grabs += 1
        return Frame(image, time.monotonic())

    def _render(self, shown: np.ndarray, frame: int) -> np.ndarray:
        """The camera image of ``shown`` (fractions of full scale) with the noise of
        ``frame``."""
        projector = self._trace.rig.projector
        screen = np.zeros((projector.height, projector.width), np.float32)
        screen[:shown.shape[0], :shown.shape[1]] = shown
        return expose(self._trace, screen[None], self.imaging, first_frame=frame)[0]

    def _cached(self, codes: np.ndarray) -> np.ndarray | None:
        """The image rendered of a pattern of the same codes, if any."""
        codes = np.ascontiguousarray(codes)
        for pattern, image in self._rendered.get(zlib.crc32(codes), ()):
            if pattern.dtype == codes.dtype and np.array_equal(pattern, codes):
                return image
        return None

    def _keep(self, codes: np.ndarray, image: np.ndarray) -> np.ndarray:
        codes = np.ascontiguousarray(codes)
        image.setflags(write=False)  # handed out again and again
        self._rendered.setdefault(zlib.crc32(codes), []).append((codes.copy(), image))
        return image

    def describe(self) -> dict[str, Any]:
        camera = self._rig.camera
        return {**super().describe(), "scene": self.scene, "size": [camera.width, camera.height],
                "fps": self.fps, "imaging": {**SIM_IMAGING, "exposure": self.imaging.exposure}}


def one_line(exc: BaseException) -> str:
    """An exception's message on one line (its type's name if it has none)."""
    return " ".join(str(exc).split()) or type(exc).__name__
