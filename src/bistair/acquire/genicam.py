"""GenICam cameras (``genicam:PRODUCER.cti[:SERIAL]``) through ``harvesters`` and the
vendor's GenTL producer: ``pip install 'bistair[genicam]'``. Exposure (``ExposureTime``,
microseconds), gain (``Gain``) and pixel format (``Mono8``, ``Mono12``, ``Mono16``); frames
as 8 or 16 bit; after each pattern every frame already delivered is dropped.

Without harvesters the module still imports; opening a camera then says which extra to
install. The tests run the grab loop against a stand-in with the harvesters API's shape
(``tests/support/scan_devices.py``); no real camera has been tried.

Examples
--------
>>> camera = GenicamCamera(__file__, "S1")  # not opened: any file passes for a producer here
>>> camera.name.endswith("genicam.py:S1"), camera.settings
(True, ('exposure', 'gain', 'pixel_format'))
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import BistairError
from .cameras import FETCH_TIMEOUT, Camera, Frame, one_line

try:  # the optional extra bistair[genicam]
    from harvesters.core import Harvester
except ImportError:
    Harvester = None

GENICAM_EXTRA = "pip install 'bistair[genicam]'"


class GenicamCamera(Camera):
    """``genicam:PRODUCER.cti[:SERIAL]``: the first camera the GenTL producer finds, or
    the one with that serial number, through harvesters. Calls used: ``Harvester()``,
    ``add_file(path, check_existence=True, check_validity=True)``, ``update()``,
    ``device_info_list`` (``property_dict["serial_number"]``), ``create(index)``,
    ``remote_device.node_map.<Node>.value``, ``start()``, ``try_fetch(timeout=)`` (a buffer
    or None; ``payload.components[0]`` with ``data``, ``width``, ``height``; the buffer's
    ``timestamp_ns``; ``queue()``), ``stop()``, ``destroy()`` and ``reset()``."""

    kind = "genicam"
    settings = ("exposure", "gain", "pixel_format")

    def __init__(self, producer: str | Path, serial: str | None = None,
                 **settings: Any) -> None:
        super().__init__(**settings)
        self.producer, self.serial = Path(producer), serial
        self._harvester: Any = None
        self._acquirer: Any = None
        self.model: str | None = None

    @property
    def name(self) -> str:
        return f"genicam:{self.producer}" + (f":{self.serial}" if self.serial else "")

    def open(self) -> None:
        if Harvester is None:
            raise BistairError(f"genicam cameras need harvesters: {GENICAM_EXTRA}")
        if not self.producer.is_file():
            raise BistairError(f"GenTL producer file {self.producer} not found")
        harvester = Harvester()
        self._harvester = harvester
        try:
            harvester.add_file(str(self.producer), check_existence=True, check_validity=True)
            harvester.update()
        except (OSError, FileNotFoundError) as exc:
            self.close()
            raise BistairError(f"cannot load GenTL producer {self.producer}: "
                               f"{one_line(exc)}") from None
        infos = [dict(getattr(info, "property_dict", {}) or {})
                 for info in harvester.device_info_list]
        serials = [str(info.get("serial_number")) for info in infos]
        if not infos:
            self.close()
            raise BistairError(f"no GenICam camera found through {self.producer}")
        index = 0
        if self.serial is not None:
            if self.serial not in serials:
                self.close()
                raise BistairError(f"no GenICam camera with serial {self.serial} through "
                                   f"{self.producer} (found: {', '.join(serials)})")
            index = serials.index(self.serial)
        try:
            self._acquirer = harvester.create(index)
        except Exception as exc:  # harvesters raises GenTL's own exceptions
            self.close()
            raise BistairError(f"cannot open camera {self.name}: {one_line(exc)}") from None
        self.model = infos[index].get("model")
        self.serial = self.serial or serials[index]
        nodes = self._acquirer.remote_device.node_map
        for names, value in ((("PixelFormat",), self.pixel_format),
                             (("ExposureTime", "ExposureTimeAbs"), self.exposure),
                             (("Gain", "GainRaw"), self.gain)):
            if value is not None:
                self._set(nodes, names, value)
        self._acquirer.start()

    def _set(self, nodes: Any, names: tuple[str, ...], value: Any) -> None:
        for name in names:
            node = getattr(nodes, name, None)
            if node is None:
                continue
            try:
                node.value = value
            except Exception as exc:  # GenApi's own exceptions: out of range, not writable
                self.close()
                raise BistairError(f"camera {self.name} refused {name} = {value}: "
                                   f"{one_line(exc)}") from None
            return
        self.close()
        raise BistairError(f"camera {self.name} has no {' or '.join(names)} node")

    def close(self) -> None:
        acquirer, harvester = self._acquirer, self._harvester
        self._acquirer = self._harvester = None
        if acquirer is not None:
            acquirer.stop()
            acquirer.destroy()
        if harvester is not None:
            harvester.reset()

    def _fetch(self, timeout: float) -> Frame | None:
        buffer = self._acquirer.try_fetch(timeout=timeout)
        now = time.monotonic()
        if buffer is None:
            return None
        try:
            part = buffer.payload.components[0]
            image = np.array(part.data, copy=True).reshape(int(part.height), int(part.width))
            stamp = getattr(buffer, "timestamp_ns", None)
        finally:
            buffer.queue()
        return Frame(image, now, stamp * 1e-9 if stamp else None)

    def grab(self) -> Frame:
        frame = self._fetch(FETCH_TIMEOUT)
        if frame is None:
            raise BistairError(f"camera {self.name} delivered no frame within "
                               f"{FETCH_TIMEOUT:g} s (is it waiting for a trigger?)")
        self.grabs += 1
        return frame

    def flush(self, count: int | None = None) -> int:
        """Drop every frame already delivered (or ``count`` frames)."""
        if count is not None:
            return super().flush(count)
        dropped = 0
        while self._fetch(0.001) is not None:
            dropped += 1
        return dropped

    def describe(self) -> dict[str, Any]:
        return {**super().describe(), "producer": str(self.producer), "serial": self.serial,
                "model": self.model}
