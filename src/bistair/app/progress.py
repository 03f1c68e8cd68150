"""What a long command is doing, on stderr.

A job reports each stage it starts by calling its ``progress`` callback with a short text
(``"decoding 1280x1024 (bidirectional)"``). :class:`Progress` turns those calls into:

- on a terminal, one live line ``bistair: <stage> ... 12 s`` rewritten in place (``\\r``)
  with the elapsed time, erased when the command ends;
- elsewhere (a log, a pipe), plain lines ``bistair: <stage> (12.3 s)``, no ``\\r``;
- nothing with ``--quiet``.

Short work prints nothing: the first line appears once the command has run ``delay``
seconds (1 s on a terminal, 5 s elsewhere, or the environment variable
``BISTAIR_PROGRESS_DELAY``); from then on every stage is reported as it starts, and in a
log a stage that runs long is repeated every 30 s.
Errors and warnings are printed whatever the setting. When a compiled kernel is not found
in a cache and has to be compiled (:func:`bistair.core.jit.on_compile`), one line says so
at once (:data:`COMPILE_NOTICE`), unless quiet.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Callable
from types import TracebackType
from typing import IO

from ..core.jit import on_compile

Say = Callable[[str], None]  # a job's progress callback: called with each stage as it starts


def silent(stage: str) -> None:
    """The progress callback of a job nobody watches: says nothing.

    Parameters
    ----------
    stage : str
        The stage the job starts.

    Examples
    --------
    >>> silent("decoding")
    """


COMPILE_NOTICE = ("compiling the decode kernels for this machine: a minute or two, once "
                  "(they are kept; an install from source compiles them beforehand)")
_ACTIVE: list[Progress] = []  # the open Progress that prints the compile notice


def _delay(live: bool) -> float:
    default = 1.0 if live else 5.0
    try:
        return max(0.0, float(os.environ.get("BISTAIR_PROGRESS_DELAY", default)))
    except ValueError:
        return default


class Progress:
    """Stage reports for one command; call with a stage's text, use as a context manager.

    >>> import io
    >>> log = io.StringIO()
    >>> with Progress(stream=log, delay=0.0) as say:
    ...     say("reading 6 captures")
    >>> log.getvalue().startswith("bistair: reading 6 captures (")
    True
    >>> with Progress(quiet=True, stream=log) as say:
    ...     say("not shown")
    >>> "not shown" in log.getvalue()
    False
    """

    REPEAT = 30.0

    def __init__(self, quiet: bool = False, stream: IO[str] | None = None,
                 delay: float | None = None) -> None:
        self.quiet = quiet
        self.stream = stream if stream is not None else sys.stderr
        try:
            self.live = bool(self.stream.isatty())
        except (AttributeError, OSError, ValueError):  # no stream, or a closed one
            self.live = False
        self.delay = _delay(self.live) if delay is None else delay
        self.start = time.monotonic()
        self.stage = ""
        self.shown = False  # anything printed yet (the delay has passed)
        self.printed_at = 0.0
        self.width = 0
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def __call__(self, stage: str) -> None:
        if self.quiet:
            return
        with self._lock:
            self.stage = stage
            if self.shown or time.monotonic() - self.start >= self.delay:
                self.shown = True
                self._show(new=True)

    def __enter__(self) -> Progress:
        if not self.quiet:
            self._thread = threading.Thread(target=self._tick, daemon=True)
            self._thread.start()
        if not _ACTIVE:
            on_compile(_compile_notice)  # once per process (the first kernel compiled)
        _ACTIVE.append(self)
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def close(self) -> None:
        """Stop the clock and erase the live line (before the result or an error is printed)."""
        if self in _ACTIVE:
            _ACTIVE.remove(self)
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        with self._lock:
            if self.live and self.shown and self.width:
                self._write("\r" + " " * self.width + "\r")
                self.width = 0

    def warn(self, message: str) -> None:
        """Print one warning line now, also when quiet (above the live line, which the clock
        draws again)."""
        self._line(f"Warning: {message}")

    def note(self, message: str) -> None:
        """Print one line ``bistair: <message>`` now, unless quiet (above the live line)."""
        if not self.quiet:
            self._line(f"bistair: {message}")

    def _line(self, text: str) -> None:
        with self._lock:
            if self.live and self.width:
                self._write("\r" + " " * self.width + "\r")
                self.width = 0
            try:
                self.stream.write(text + "\n")
                self.stream.flush()
            except (OSError, ValueError):
                pass

    def _tick(self) -> None:
        period = 0.25 if self.live else 0.1
        while not self._stop.wait(period):
            with self._lock:
                elapsed = time.monotonic() - self.start
                if not self.stage or elapsed < self.delay:
                    continue
                if not self.shown:
                    self.shown = True
                    self._show(new=True)
                elif self.live or elapsed - self.printed_at >= self.REPEAT:
                    self._show(new=False)

    def _show(self, new: bool) -> None:
        elapsed = time.monotonic() - self.start
        self.printed_at = elapsed
        if self.live:
            line = f"bistair: {self.stage} ... {elapsed:.0f} s"
            pad = max(0, self.width - len(line))
            self._write("\r" + line + " " * pad)
            self.width = len(line)
        else:
            still = "" if new else "still "
            self._write(f"bistair: {still}{self.stage} ({elapsed:.1f} s)\n")

    def _write(self, text: str) -> None:
        try:
            self.stream.write(text)
            self.stream.flush()
        except (OSError, ValueError):  # a closed pipe: progress is not worth failing for
            self.quiet = True


def _compile_notice() -> None:
    """The first kernel of the process is being compiled: one line from the open Progress
    (the innermost), if any."""
    if _ACTIVE:
        _ACTIVE[-1].note(COMPILE_NOTICE)
