"""A command killed while it writes leaves nothing behind (issue 14, defect 5)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import PATIENCE

from bistair.io.atomic import output_folder, remove_stale

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")


def _start(out: Path) -> subprocess.Popen:
    cmd = [sys.executable, "-c", "from bistair.app.cli import main; main()", "simulate",
           "--scene", "plane", "--method", "all", "--camera", "1280x1024", "--out", str(out)]
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def _wait_for_temp(parent: Path, proc: subprocess.Popen) -> Path:
    deadline = time.monotonic() + PATIENCE
    while time.monotonic() < deadline and proc.poll() is None:
        found = list(parent.glob(f".bistair-{proc.pid}-*"))
        if found and any(found[0].rglob("*.png")):
            return found[0]
        time.sleep(0.02)
    pytest.fail("the command never started writing")


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_signal_while_writing_leaves_nothing(tmp_path: Path, sig: signal.Signals) -> None:
    out = tmp_path / "scans"
    proc = _start(out)
    temp = _wait_for_temp(tmp_path, proc)
    # frozen while the signal is sent: it cannot finish writing in between, so an exit code
    # of 0 can only mean a handler that swallowed the signal
    proc.send_signal(signal.SIGSTOP)
    writing = temp.exists()
    proc.send_signal(sig)
    proc.send_signal(signal.SIGCONT)
    _, err = proc.communicate(timeout=PATIENCE)
    if not writing:
        pytest.skip("the command finished writing before it was stopped (busy machine)")
    assert proc.returncode != 0, "the signal was swallowed: the command went on and exited 0"
    assert list(tmp_path.iterdir()) == [], "temporary output left behind"
    assert "Traceback" not in err


def test_sigkill_leftovers_are_removed_by_the_next_run(tmp_path: Path) -> None:
    """SIGKILL cannot be caught: the next write into the same folder removes the dead
    process's temporary output (named after its pid) and leaves live ones alone."""
    out = tmp_path / "scans"
    proc = _start(out)
    _wait_for_temp(tmp_path, proc)
    proc.kill()
    proc.wait(timeout=60)
    assert [p.name.startswith(f".bistair-{proc.pid}-") for p in tmp_path.iterdir()] == [True]
    live = tmp_path / f".bistair-{os.getpid()}-mine"
    live.mkdir()
    with output_folder(tmp_path / "next") as tmp:
        (tmp / "a.txt").write_text("x")
    assert sorted(p.name for p in tmp_path.iterdir()) == [live.name, "next"]
    assert remove_stale(tmp_path) == 0
