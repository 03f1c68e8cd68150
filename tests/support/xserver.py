"""An X server of the tests' own: Xvfb on a display number it finds free itself.

- ``-displayfd``: Xvfb takes the first display number no other server holds (its lock file)
  and writes it to a pipe once it accepts connections; never a fixed ``:0`` or ``:99``, and
  never the user's ``DISPLAY``, so another X server on the machine (a desktop, another test
  run) is neither used nor in the way.
- ``-noreset``: by default an X server resets when its last client disconnects, and a client
  connecting during the reset is refused ("Cannot connect to display"). The tests open and
  close windows and screenshot connections one after the other, so without it about one
  connection in three failed (measured: 62 of 200 mss connections in a row).
"""

from __future__ import annotations

import os
import select
import shutil
import subprocess
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager

import pytest

START_TIMEOUT = 120.0  # seconds Xvfb may take to start on a loaded machine


@contextmanager
def own_xvfb(size: tuple[int, int] = (1920, 1080), depth: int = 24) -> Iterator[str]:
    """Run an Xvfb with one ``size`` screen for the duration; yields its display (``:N``).

    Skips the calling test (saying why) where none can be started: no Xvfb, or it fails.
    """
    exe = shutil.which("Xvfb")
    if exe is None:
        pytest.skip("no X server can be started: Xvfb is not installed (.ci/run installs the "
                    "xvfb package with apt)")
    read, write = os.pipe()
    log = tempfile.TemporaryFile()
    proc = subprocess.Popen([exe, "-displayfd", str(write), "-screen", "0",
                             f"{size[0]}x{size[1]}x{depth}", "-nolisten", "tcp", "-noreset"],
                            pass_fds=(write,), stdout=subprocess.DEVNULL, stderr=log)
    os.close(write)
    try:
        number, deadline = b"", time.monotonic() + START_TIMEOUT
        while not number.endswith(b"\n") and time.monotonic() < deadline \
                and proc.poll() is None:
            if select.select([read], [], [], 0.2)[0]:
                chunk = os.read(read, 16)
                if not chunk:
                    break
                number += chunk
        os.close(read)
        if not number.strip().isdigit():
            proc.kill()
            proc.wait()
            log.seek(0)
            lines = log.read().decode(errors="replace").strip().splitlines()
            why = (lines or ["no message"])[-1]
            pytest.skip(f"no X server can be started: Xvfb failed ({why})")
        yield f":{number.decode().strip()}"
    finally:
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        log.close()
