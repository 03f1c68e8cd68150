"""Acquisition: show the patterns on a display, grab them with a camera (``bistair scan``).

:mod:`~bistair.acquire.displays` (a full-screen window through SDL2, or ``none``),
:mod:`~bistair.acquire.cameras` (OpenCV, screenshots, the virtual rig),
:mod:`~bistair.acquire.genicam` (GenICam through harvesters),
:mod:`~bistair.acquire.devices` (the device strings, parsed in one place),
:mod:`~bistair.acquire.loop` (show, settle, drop, grab, average: :func:`scan`) and
:mod:`~bistair.acquire.latency` (how long the camera takes to see a change). This layer sits
above the simulator (the ``sim`` camera renders with it) and below the jobs of
:mod:`bistair.app`, which write the scan folder.
"""

from .devices import parse_camera, parse_display
from .latency import Latency, measure_latency
from .loop import Scan, scan

__all__ = ["Latency", "Scan", "measure_latency", "parse_camera", "parse_display", "scan"]
