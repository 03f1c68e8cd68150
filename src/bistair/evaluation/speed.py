"""Decode speed against the least work any 4-step decode does, timed in the same run: the
scene, the codecs' cases, the OpenCV floor and the timing that ``bistair bench`` and
``benchmarks/decode_speed.py`` share.

The floor is OpenCV's 4-step pass on the same frames: two frame differences into float32
(``cv2.subtract``), their phase (``cv2.phase``) and magnitude (``cv2.magnitude``). A machine
shared with other work changes its speed from minute to minute, so every decode is followed
by the floor and the figure to compare is the ratio decode / floor of each run (its
median), not a time across runs. A codec's first decode (which loads or compiles its
kernels and warms the allocator) is never timed.

Examples
--------
>>> case = speed_cases(["graycode"])[0]
>>> case.label, case.method
('graycode complementary', 'graycode')
>>> frames = speed_captures(case.spec(), (192, 256))
>>> frames.shape, frames.dtype.name
((11, 192, 256), 'uint8')
>>> timing = time_case(case, frames, runs=2)
>>> len(timing.ratios), timing.decode_s > 0, timing.floor_s > 0, 0.4 < timing.valid < 0.7
(2, True, True, True)
"""

from __future__ import annotations

import os
import platform
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ..codecs import decode, make_spec, methods
from ..core.jit import thread_count, threading_layer
from ..errors import BistairError
from ..sim.warp import Blob, WarpScene, render_warp
from ..spec import BaseSpec


@dataclass(frozen=True)
class SpeedCase:
    """One codec as the speed figures time it: a label, the spec's parameters (the method
    among them) and the decode's options."""

    label: str
    params: dict[str, Any]
    options: dict[str, Any] = field(default_factory=dict)

    @property
    def method(self) -> str:
        """The method's registered name."""
        return str(self.params["method"])

    def spec(self) -> BaseSpec:
        """The spec of the patterns (a 1920 x 1080 projector)."""
        params = dict(self.params)
        return make_spec(params.pop("method"), **params)


_PROJECTOR = dict(width=1920, height=1080)
# the default decoder first: the others' ratios are divided by its own
CASES = (
    SpeedCase("bidirectional 8x8 (region)", dict(method="bidirectional", **_PROJECTOR,
                                                 period=30, partitions=8, stairs=8)),
    SpeedCase("bidirectional 8x8 (paper)", dict(method="bidirectional", **_PROJECTOR,
                                                period=30, partitions=8, stairs=8),
              {"strategy": "paper"}),
    SpeedCase("multifreq 1920/240/30 x4", dict(method="multifreq", **_PROJECTOR,
                                               periods=(1920, 240, 30))),
    SpeedCase("phase-coding 64 levels", dict(method="phase-coding", **_PROJECTOR, period=30)),
    SpeedCase("lv 64 fringes", dict(method="lv", **_PROJECTOR, period=30)),
    SpeedCase("graycode complementary", dict(method="graycode", **_PROJECTOR, period=30,
                                             complementary=1)),
)
MIN_SIDE, MAX_PIXELS = 192, 64_000_000  # the scene's smallest side; memory for the largest


def speed_cases(picked: Sequence[str] | None = None) -> list[SpeedCase]:
    """The cases of the given methods (every registered one when ``None``), in
    :data:`CASES` order; a registered method :data:`CASES` does not name is timed with its
    spec's defaults on the same projector.

    Parameters
    ----------
    picked : sequence of str, optional
        Method names (``bidirectional`` gives both of its strategies).

    Returns
    -------
    list of SpeedCase

    Raises
    ------
    BistairError
        A name that is no registered method (the message lists them).

    Examples
    --------
    >>> [case.label for case in speed_cases(["lv", "bidirectional"])]
    ['bidirectional 8x8 (region)', 'bidirectional 8x8 (paper)', 'lv 64 fringes']
    >>> speed_cases(["lw"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: unknown method 'lw' (known: bidirectional, lv, ...)
    """
    known = methods()
    for name in picked or ():
        if name not in known:
            raise BistairError(f"unknown method {name!r} (known: {', '.join(known)})")
    wanted = known if picked is None else list(picked)
    cases = [case for case in CASES if case.method in wanted]
    named = {case.method for case in CASES}
    cases += [SpeedCase(f"{name} (defaults)", dict(method=name, **_PROJECTOR))
              for name in known if name in wanted and name not in named]
    return cases


def check_size(size: tuple[int, int]) -> None:
    """Refuse a camera size the scene is not made for, in one line.

    Parameters
    ----------
    size : (int, int)
        ``(height, width)`` in pixels.

    Raises
    ------
    BistairError
        A side under :data:`MIN_SIDE` or more than :data:`MAX_PIXELS` pixels.

    Examples
    --------
    >>> check_size((1024, 1280))
    >>> check_size((48, 64))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: camera 64x48 is too small for the speed scene: ...
    """
    h, w = size
    if min(h, w) < MIN_SIDE:
        raise BistairError(f"camera {w}x{h} is too small for the speed scene: at least "
                           f"{MIN_SIDE} pixels a side")
    if h * w > MAX_PIXELS:
        raise BistairError(f"camera {w}x{h} is too large for the speed scene: at most "
                           f"{MAX_PIXELS // 1_000_000} MP")


def speed_captures(spec: BaseSpec, size: tuple[int, int]) -> np.ndarray:
    """8-bit captures of the speed scene: a dome-shaped object and two small ones on a dark
    field, seen with a stretch, a vertical scale and a slight roll (the warp renderer,
    :mod:`bistair.sim.warp`).

    From 1280 pixels wide up the camera sees the same part of the projector at every size
    (the figures of 1.3 and 12 MP); a narrower camera sees a narrower part of it with
    fringes as wide as at 1280 (so that every codec still decodes half the image).

    Parameters
    ----------
    spec : BaseSpec
        The patterns (the 1920 x 1080 projector of :data:`CASES`).
    size : (int, int)
        ``(height, width)``, each side at least :data:`MIN_SIDE`.

    Returns
    -------
    (F, H, W) uint8 array
        The captures in the spec's frame order.

    Examples
    --------
    >>> spec = speed_cases(["lv"])[0].spec()
    >>> speed_captures(spec, (192, 256)).shape
    (6, 192, 256)
    """
    check_size(size)
    h, w = size
    g = w / 1280  # the objects' size
    k = max(g, 1.0)  # projector pixels per camera pixel: 1.4 / k
    scene = WarpScene(size=size, stretch=1.4 / k, offset=20.0, scale_top=0.8 / k,
                      scale_bottom=1.3 / k, roll_deg=1.0, blur=1.0, noise=0.01, seed=0,
                      supersample=1, bits=None,
                      blobs=(Blob(450 * g, 500 * g, 380 * g, 450 * g, dome=40, albedo=0.8),
                             Blob(1000 * g, 300 * g, 100 * g, 120 * g, shift=30, dome=5,
                                  albedo=0.7),
                             Blob(1050 * g, 750 * g, 150 * g, 200 * g, shift=-80, dome=20,
                                  albedo=0.6)))
    images, _ = render_warp(spec, scene)
    return np.round(np.clip(images, 0, 1) * 255).astype(np.uint8)


def opencv_floor(frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The least work a 4-step decode does, in OpenCV: two frame differences into float32,
    their phase and magnitude.

    Parameters
    ----------
    frames : (F, H, W) array
        Captures; the first four are the phase shifts.

    Returns
    -------
    phase, magnitude : (H, W) float32 arrays

    Examples
    --------
    >>> frames = np.array([[[9]], [[5]], [[1]], [[5]]], np.uint8)  # phase 0
    >>> phase, magnitude = opencv_floor(frames)
    >>> float(phase[0, 0]), float(magnitude[0, 0])
    (0.0, 8.0)
    """
    b = cv2.subtract(frames[3], frames[1], dtype=cv2.CV_32F)
    a = cv2.subtract(frames[0], frames[2], dtype=cv2.CV_32F)
    return cv2.phase(a, b), cv2.magnitude(a, b)


def floor_time(frames: np.ndarray, repeats: int = 5) -> float:
    """Seconds of the fastest of ``repeats`` floor passes (:func:`opencv_floor`): a pass of
    a few ms that one busy moment of the machine would spoil.

    Examples
    --------
    >>> floor_time(np.zeros((4, 64, 64), np.uint8)) > 0
    True
    """
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        opencv_floor(frames)
        best = min(best, time.perf_counter() - t0)
    return float(best)


@dataclass
class Timing:
    """A codec's warm decodes, each followed by the floor on the same frames: the medians of
    the decode's and the floor's seconds, each run's ratio and the share of pixels the
    decode answered for."""

    case: SpeedCase
    pixels: int
    decode_s: float
    floor_s: float
    ratios: list[float]
    valid: float

    @property
    def ratio(self) -> float:
        """The median of the runs' decode / floor ratios."""
        return float(statistics.median(self.ratios))

    @property
    def scans_per_s(self) -> float:
        """Capture sets decoded per second (one after the other)."""
        return 1.0 / self.decode_s

    @property
    def mpix_per_s(self) -> float:
        """Camera megapixels decoded per second."""
        return self.pixels / 1e6 / self.decode_s


def time_case(case: SpeedCase, frames: np.ndarray, runs: int,
              decoder: Callable[..., Any] = decode) -> Timing:
    """Time ``runs`` warm decodes of ``frames``, each followed by the floor.

    The first decode (kernels loaded or compiled, the allocator warmed) is not timed; a
    decode that refuses the scene raises.

    Parameters
    ----------
    case : SpeedCase
        The codec, its spec and options.
    frames : (F, H, W) array
        Its captures (:func:`speed_captures`).
    runs : int
        Timed decodes (1 or more).
    decoder : callable, optional
        ``decoder(frames, spec, **options)``; :func:`bistair.codecs.decode` by default.

    Returns
    -------
    Timing

    Examples
    --------
    >>> case = speed_cases(["lv"])[0]
    >>> timing = time_case(case, speed_captures(case.spec(), (192, 256)), runs=1)
    >>> timing.pixels, len(timing.ratios), timing.scans_per_s > 0
    (49152, 1, True)
    """
    spec = case.spec()
    try:
        first = decoder(frames, spec, **case.options)
    except BistairError as exc:
        raise BistairError(f"{case.label} refused the speed scene at {frames.shape[2]}x"
                           f"{frames.shape[1]}: {exc}") from None
    valid = float(np.mean(first.mask))
    decodes, floors, ratios = [], [], []
    for _ in range(max(1, int(runs))):
        t0 = time.perf_counter()
        decoder(frames, spec, **case.options)
        seconds = time.perf_counter() - t0
        floor = floor_time(frames)
        decodes.append(seconds)
        floors.append(floor)
        ratios.append(seconds / floor)
    return Timing(case, frames.shape[1] * frames.shape[2], float(statistics.median(decodes)),
                  float(statistics.median(floors)), ratios, valid)


def machine() -> dict[str, Any]:
    """What the figures were measured on: cores, the kernels' and OpenCV's threads, the CPU
    model, numba's threading layer (``not started`` before the first parallel kernel) and
    the load average.

    Examples
    --------
    >>> sorted(machine())
    ['cores', 'cpu', 'load', 'opencv_threads', 'threading_layer', 'threads']
    """
    return {"cores": os.cpu_count() or 1, "threads": thread_count(),
            "opencv_threads": cv2.getNumThreads(), "cpu": cpu_model(),
            "threading_layer": threading_layer(),
            "load": round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None}


def cpu_model() -> str:
    """The CPU's model name (Linux: ``/proc/cpuinfo``; else what the platform says).

    Examples
    --------
    >>> isinstance(cpu_model(), str) and cpu_model() != ""
    True
    """
    info = Path("/proc/cpuinfo")
    if info.is_file():
        for line in info.read_text(errors="replace").splitlines():
            key, _, value = line.partition(":")
            if key.strip() in ("model name", "Model", "cpu model") and value.strip():
                return value.strip()
    return platform.processor() or platform.machine() or "unknown"
