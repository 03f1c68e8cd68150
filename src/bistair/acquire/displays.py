"""Displays that put a pattern in front of the camera.

- :class:`WindowDisplay` (``window[:SCREEN]``): a borderless full-screen window on the
  projector's screen, through SDL2 (pygame). The pattern is drawn pixel for pixel at the
  screen's top-left corner, the rest of the screen black: no scaling, no colour management
  (SDL applies none), grey levels as 8-bit codes on all three channels. The mouse pointer
  is hidden; Esc or closing the window stops a scan like Ctrl-C.
- :class:`NoDisplay` (``none``): a projector that holds the patterns itself and triggers
  the camera. Nothing is shown; the display only remembers which pattern is due, so that
  a simulated camera can render it.

A display is a context manager: leaving the ``with`` block (also by Ctrl-C or an error)
closes the window. ``current`` is the pattern last shown, as fractions of full scale
(made when first asked for), ``codes`` the same as it was given (8- or 16-bit codes).

Examples
--------
>>> import numpy as np
>>> with NoDisplay() as shown:
...     _ = shown.show(np.array([[0, 255]], np.uint8))
...     shown.current.tolist(), shown.describe()["kind"]
([[0.0, 1.0]], 'none')
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")  # pygame greets on stdout otherwise

import numpy as np  # noqa: E402
import pygame  # noqa: E402

from ..errors import BistairError  # noqa: E402

# SDL's defaults that would spoil a scan: a full-screen window minimised when another
# window (the terminal on the other screen) takes the focus
_SDL_HINTS = {"SDL_VIDEO_MINIMIZE_ON_FOCUS_LOSS": "0"}
_NO_SCREEN = ("dummy", "offscreen")  # SDL's drivers that show nothing
_SETTLE_WINDOW = 2.0  # seconds a new window may take to be shown


class Display:
    """What every display does; subclasses open, show and close."""

    kind = "display"
    drives = True  # shows each pattern when told (``none``: the projector runs the sequence)

    def __init__(self) -> None:
        self.codes: np.ndarray | None = None  # the pattern last shown, as given
        self._current: np.ndarray | None = None
        self.size: tuple[int, int] | None = None  # the screen's (width, height) when open
        self.shown = 0

    @property
    def name(self) -> str:
        """The device string that opens this display again."""
        return self.kind

    def __enter__(self) -> Display:
        self.open()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def open(self) -> None:
        """Open the window (nothing for ``none``)."""

    def close(self) -> None:
        """Close the window; safe to call twice."""

    def check(self, width: int, height: int) -> None:
        """Refuse patterns of ``width x height`` that the screen cannot show whole."""
        if self.size is None:
            return
        if width > self.size[0] or height > self.size[1]:
            raise BistairError(f"the spec's {width}x{height} patterns do not fit {self.name} "
                               f"({self.size[0]}x{self.size[1]}): the patterns are shown pixel "
                               "for pixel, never scaled")

    def show(self, image: np.ndarray) -> float:
        """Show ``image`` (2-D 8- or 16-bit codes); returns the ``time.monotonic()`` at which
        it is up (for a window: drawn and handed to the window system)."""
        self.codes, self._current = np.asarray(image), None
        self.shown += 1
        self._draw(image)
        return time.monotonic()

    @property
    def current(self) -> np.ndarray | None:
        """The pattern last shown as fractions of full scale (float32), or None."""
        if self._current is None and self.codes is not None:
            top = 65535.0 if self.codes.dtype == np.uint16 else 255.0
            self._current = self.codes.astype(np.float32) / np.float32(top)
        return self._current

    def _draw(self, image: np.ndarray) -> None:
        """Put the image on the screen."""

    def wait(self, until: float) -> None:
        """Sleep until ``time.monotonic()`` reaches ``until``, keeping the window alive."""
        while (left := until - time.monotonic()) > 0:
            time.sleep(min(left, 0.01))
            self.poll()

    def poll(self) -> bool:
        """Handle the window system's events, so that the window stays alive (Esc or a
        closed window: KeyboardInterrupt)."""
        return False

    def describe(self) -> dict[str, Any]:
        """The display as ``scan.json`` records it."""
        return {"kind": self.kind, "name": self.name,
                "size": list(self.size) if self.size else None}


class NoDisplay(Display):
    """``none``: the projector shows the sequence itself and triggers the camera."""

    kind = "none"
    drives = False


class WindowDisplay(Display):
    """``window[:SCREEN]``: a borderless full-screen window on screen ``SCREEN`` (from 0, in
    the window system's order), through SDL2 (pygame)."""

    kind = "window"

    def __init__(self, screen: int = 0) -> None:
        super().__init__()
        self.screen = screen
        self._surface: Any = None
        self.driver: str | None = None

    @property
    def name(self) -> str:
        return f"window:{self.screen}"

    def open(self) -> None:
        chosen = os.environ.get("SDL_VIDEODRIVER")  # e.g. kmsdrm on a box without X
        if sys.platform.startswith("linux") and not chosen and not (
                os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            raise BistairError(f"cannot open display {self.name}: no window system (DISPLAY "
                               "and WAYLAND_DISPLAY are not set)")
        for key, value in _SDL_HINTS.items():
            os.environ.setdefault(key, value)
        try:
            pygame.display.init()
            sizes = pygame.display.get_desktop_sizes()
            driver = pygame.display.get_driver()
        except pygame.error as exc:
            pygame.display.quit()
            raise BistairError(f"cannot open display {self.name}: {_sdl_message(exc)}") from None
        if driver in _NO_SCREEN and driver != chosen:
            pygame.display.quit()
            raise BistairError(f"cannot open display {self.name}: SDL found no window system "
                               f"(only its {driver} driver, which shows nothing)")
        if self.screen >= len(sizes):
            pygame.display.quit()
            known = "window:0" + (f" to window:{len(sizes) - 1}" if len(sizes) > 1 else "")
            raise BistairError(f"cannot open display {self.name}: the window system has "
                               f"{len(sizes)} screen{'s' if len(sizes) != 1 else ''} ({known})")
        size = tuple(sizes[self.screen])
        try:
            # at the screen's own size SDL makes a "desktop" full-screen window: no mode change
            surface = pygame.display.set_mode(size, pygame.FULLSCREEN, display=self.screen)
        except pygame.error as exc:
            pygame.display.quit()
            raise BistairError(f"cannot open display {self.name}: {_sdl_message(exc)}") from None
        if surface.get_size() != size:
            pygame.display.quit()
            raise BistairError(f"display {self.name} gave a {surface.get_width()}x"
                               f"{surface.get_height()} window on a {size[0]}x{size[1]} screen "
                               "(scaled desktop?): set the screen's scaling to 100%")
        self._surface, self.size = surface, (int(size[0]), int(size[1]))
        self.driver = driver
        pygame.display.set_caption("bistair scan")
        pygame.mouse.set_visible(False)
        surface.fill((0, 0, 0))
        pygame.display.flip()
        # the window system maps, resizes and exposes a new window for a moment
        deadline, exposed = time.monotonic() + _SETTLE_WINDOW, False
        while not exposed and time.monotonic() < deadline:
            exposed = self.poll()
            time.sleep(0.01)

    def close(self) -> None:
        if self._surface is not None:
            self._surface = None
            pygame.display.quit()

    @property
    def current(self) -> np.ndarray | None:
        """The pattern last shown as fractions of full scale (float32), or None."""
        if self._current is None and self.codes is not None:
            top = 65535.0 if self.codes.dtype == np.uint16 else 255.0
            self._current = self.codes.astype(np.float32) / np.float32(top)
        return self._current

    def _draw(self, image: np.ndarray) -> None:
        if self._surface is None:
            raise BistairError(f"display {self.name} is not open")
        codes = image if image.dtype == np.uint8 else _to_8_bits(image)
        height, width = codes.shape
        rgb = np.repeat(codes[:, :, None], 3, axis=2)
        picture = pygame.image.frombuffer(rgb.tobytes(), (width, height), "RGB")
        self._surface.fill((0, 0, 0))
        self._surface.blit(picture, (0, 0))
        pygame.display.flip()
        self.poll()

    def poll(self) -> bool:
        """Also draws the pattern again where the window system lost it (an exposed
        window); returns whether it did."""
        if self._surface is None:
            return False
        exposed = False
        for event in pygame.event.get():
            if event.type == pygame.QUIT or (event.type == pygame.KEYDOWN
                                             and event.key == pygame.K_ESCAPE):
                raise KeyboardInterrupt
            exposed |= event.type in (pygame.VIDEOEXPOSE, pygame.WINDOWEXPOSED)
        if exposed:
            pygame.display.flip()
        return exposed

    def describe(self) -> dict[str, Any]:
        return {**super().describe(), "screen": self.screen, "driver": self.driver,
                "bits": 8}


def _to_8_bits(image: np.ndarray) -> np.ndarray:
    """16-bit codes as the nearest 8-bit ones (a window shows 8 bits a channel)."""
    return np.round(image.astype(np.float64) / 257.0).astype(np.uint8)


def _sdl_message(exc: Exception) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    if "video device" in text.lower() or "x11" in text.lower():
        text += " (no window system: is DISPLAY set?)"
    return text
