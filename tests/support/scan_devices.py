"""Stand-ins for the scan tests: a display bistair drives that shows nothing (so the loop
waits and drops frames without a window system), and a GenICam camera with the shape of the
harvesters API (the calls :class:`bistair.acquire.genicam.GenicamCamera` makes).

The stand-in camera looks at a :class:`Screen`: every frame it delivers shows the pattern
last shown, as 16-bit codes (``Mono16``: code * 257, ``Mono8``: the code) plus an
alternating noise of +-``noise`` codes (so two frames average to the pattern exactly), and
each time the screen changes it queues ``stale`` frames of the pattern before, as a camera
buffers frames exposed before the pattern was up.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np

from bistair.acquire.displays import Display


class Screen(Display):
    """A display of ``size`` that bistair drives, showing nothing; it tells the cameras
    watching it (``watchers``) when the pattern changes."""

    kind = "test-screen"

    def __init__(self, size: tuple[int, int]) -> None:
        super().__init__()
        self._size = size
        self.watchers: list[Any] = []
        self.opened = self.closed = 0

    def open(self) -> None:
        self.size = self._size
        self.opened += 1

    def close(self) -> None:
        self.closed += 1

    def _draw(self, image: np.ndarray) -> None:
        for watcher in self.watchers:
            watcher.changed()


class Node:
    """A GenApi node: ``value``, refusing values outside ``allowed`` like GenApi does."""

    def __init__(self, value: Any, allowed: Any = None) -> None:
        self._value, self.allowed = value, allowed

    @property
    def value(self) -> Any:
        return self._value

    @value.setter
    def value(self, new: Any) -> None:
        if self.allowed is not None and not self.allowed(new):
            raise ValueError(f"OutOfRangeException: value {new} is out of range")
        self._value = new


class Acquirer:
    """An ImageAcquirer: ``remote_device.node_map``, ``start``, ``try_fetch``, ``stop``,
    ``destroy``."""

    def __init__(self, owner: Harvester) -> None:
        self.owner = owner
        nodes = {"PixelFormat": Node("Mono8", lambda v: v in ("Mono8", "Mono12", "Mono16")),
                 "ExposureTime": Node(10000.0, lambda v: 10 <= v <= 1e6),
                 "Gain": Node(0.0, lambda v: 0 <= v <= 24)}
        for missing in owner.missing_nodes:
            nodes.pop(missing)
        self.nodes = nodes
        self.remote_device = SimpleNamespace(node_map=SimpleNamespace(**nodes))
        self.queue: list[np.ndarray] = []
        self.last: np.ndarray | None = None
        self.delivered = 0
        self.started = self.stopped = self.destroyed = False
        self.queued_back = 0

    def start(self) -> None:
        self.started = True

    def stop(self) -> None:
        self.stopped = True

    def destroy(self) -> None:
        self.destroyed = True

    def changed(self) -> None:
        """The screen shows a new pattern: frames of the old one are still buffered."""
        if self.last is not None:
            self.queue.extend([self._picture(self.last)] * self.owner.stale)

    def _picture(self, shown: np.ndarray) -> np.ndarray:
        if self.nodes["PixelFormat"].value == "Mono8":
            return np.round(shown * 255).astype(np.uint8)
        return np.round(shown * 65535).astype(np.uint16)

    def try_fetch(self, *, timeout: float) -> Any:
        if self.owner.interrupt_after is not None and \
                self.delivered >= self.owner.interrupt_after:
            raise KeyboardInterrupt
        if self.queue:
            image = self.queue.pop(0)
        elif timeout < 0.01:  # nothing buffered: a short wait finds nothing
            return None
        else:
            shown = self.owner.screen.current
            self.last = shown
            clean = self._picture(shown)
            size, top = self.owner.noise, np.iinfo(clean.dtype).max
            noise = np.where((clean >= size) & (clean <= top - size),  # never clipped
                             size if self.delivered % 2 == 0 else -size, 0)
            image = (clean.astype(np.int64) + noise).astype(clean.dtype)
        self.delivered += 1
        if self.owner.grow_after is not None and self.delivered > self.owner.grow_after:
            image = np.pad(image, ((0, 2), (0, 0)))
        component = SimpleNamespace(data=image.ravel(), width=image.shape[1],
                                    height=image.shape[0])
        return SimpleNamespace(payload=SimpleNamespace(components=[component]),
                               timestamp_ns=1_000_000 * self.delivered, queue=self._queued)

    def _queued(self) -> None:
        self.queued_back += 1


class Harvester:
    """The ``harvesters.core.Harvester`` calls bistair makes, against a :class:`Screen`.

    Class attributes set the scene: ``devices`` (serial numbers found), ``stale`` (frames
    buffered per pattern change), ``noise``, ``missing_nodes``, ``grow_after`` (frames after
    which the frames grow by two rows), ``interrupt_after`` (frames after which a fetch
    raises KeyboardInterrupt, as Ctrl-C does)."""

    screen: Screen
    devices: tuple[str, ...] = ("S1",)
    stale = 3
    noise = 2
    missing_nodes: tuple[str, ...] = ()
    grow_after: int | None = None
    interrupt_after: int | None = None
    made: list[Harvester] = []

    def __init__(self) -> None:
        self.files: list[str] = []
        self.acquirers: list[Acquirer] = []
        self.was_reset = False
        type(self).made.append(self)

    def add_file(self, file_path: str, check_existence: bool = False,
                 check_validity: bool = False) -> None:
        self.files.append(file_path)

    def update(self) -> None:
        self.device_info_list = [SimpleNamespace(property_dict={
            "serial_number": serial, "model": "Stand-in", "vendor": "tests"})
            for serial in (self.devices if self.files else ())]

    def create(self, search_key: int = 0) -> Acquirer:
        acquirer = Acquirer(self)
        self.acquirers.append(acquirer)
        self.screen.watchers.append(acquirer)
        return acquirer

    def reset(self) -> None:
        self.was_reset = True
