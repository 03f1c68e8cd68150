"""A command killed while it writes leaves nothing behind (issue 14, defect 5); a signal
that arrives while a compiled kernel runs stops the command as the signal should (issue 31)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import PATIENCE

import bistair
from bistair.app.patterns import save_patterns
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


# -- a signal while a compiled kernel runs (QA of issue 31, defect 9) --------------------------
# A signal is handled at the next Python step, which can be numba's own call back into Python
# as a kernel hands its arrays over; a handler that raised there made the kernel's call fail
# with "SystemError: CPUDispatcher(...) returned a result with an exception set" (a 70-line
# traceback, exit 1), or, on its first call in a process, lost the exception and left a hole
# (NULL) in the results. The kernel below sends the signal to its own process from inside
# the compiled code, so the signal always arrives there, whatever the timing.
SIGNAL_KERNEL = '''
import ctypes

from bistair.core.jit import kernel

_raise = ctypes.CDLL(None)["raise"]
_raise.argtypes = [ctypes.c_int]
_raise.restype = ctypes.c_int


@kernel()
def signal_self(sig, values):
    """Raise ``sig`` in this process from compiled code (0: none), then return two arrays."""
    if sig:
        _raise(sig)
    out = values * 2.0
    return out, out + 1.0
'''


def _signal_kernel(folder: Path, name: str):
    """A new module ``name`` in ``folder`` with the kernel, imported (not yet compiled)."""
    (folder / f"{name}.py").write_text(SIGNAL_KERNEL)
    sys.path.insert(0, str(folder))
    try:
        return __import__(name).signal_self  # (kept in sys.modules: numba compiles it later)
    finally:
        sys.path.remove(str(folder))


@pytest.mark.parametrize(("sig", "handler", "warm"), [
    (signal.SIGTERM, "_terminated", False),  # the command line's, on the kernel's first call
    (signal.SIGINT, "_interrupted", False),
    (signal.SIGINT, "default_int_handler", True),  # Python's own (a notebook), compiled
], ids=["SIGTERM-cli", "SIGINT-cli", "SIGINT-python"])
def test_a_signal_inside_a_kernel_stops_as_the_signal(tmp_path, sig, handler, warm):
    """The handler's SystemExit (143) or KeyboardInterrupt comes out of the kernel's call as
    itself: not as a SystemError, and not lost."""
    from bistair.app import cli

    signal_self = _signal_kernel(tmp_path, f"signal_kernel_{tmp_path.name}")
    if warm:
        assert signal_self(0, np.ones(2))[1].tolist() == [3.0, 3.0]
    old = signal.signal(sig, getattr(cli if hasattr(cli, handler) else signal, handler))
    try:
        with pytest.raises(SystemExit if sig == signal.SIGTERM else KeyboardInterrupt) as got:
            signal_self(int(sig), np.zeros(3))
    finally:
        signal.signal(sig, old)
    if sig == signal.SIGTERM:
        assert got.value.code == 143


def test_a_signal_while_a_kernel_compiles_is_not_held_back():
    """Only a signal handled inside numba's call back from compiled code waits for the
    kernel to return; one handled while numba compiles it (a minute or two, the first time)
    stops the command at once."""
    from bistair.core import jit

    jit._SIGNALS["depth"] += 1  # as inside a kernel's call, in numba's compiler
    try:
        with pytest.raises(KeyboardInterrupt):
            jit.interrupt(KeyboardInterrupt(), sys._getframe())
    finally:
        jit._SIGNALS["depth"] -= 1
    assert jit._SIGNALS["pending"] is None


@pytest.mark.parametrize(("sig", "code", "last"), [(signal.SIGTERM, 143, None),
                                                   (signal.SIGINT, 1, "Aborted.")])
def test_a_command_signalled_inside_a_kernel_stops_cleanly(tmp_path, sig, code, last):
    """``bistair decode`` whose decode meets the signal inside a kernel: the exit code of the
    signal (143, or 1 and 'Aborted.' for Ctrl-C as the command line documents), no
    traceback, nothing written."""
    folder = tmp_path / "kernel"
    folder.mkdir()
    (folder / "signal_kernel.py").write_text(SIGNAL_KERNEL)
    pats = tmp_path / "pats"
    save_patterns(bistair.make_spec("graycode", width=64, height=48, period=16), pats)
    script = (f"import sys; sys.path.insert(0, {str(folder)!r})\n"
              "import numpy as np\n"
              "import bistair.app.decode as job\n"
              "from signal_kernel import signal_self\n"
              "def decode(stack, spec, **options):\n"
              f"    signal_self({int(sig)}, np.zeros(3))\n"
              "job.decode = decode\n"
              "from bistair.app.cli import main\n"
              "main()\n")
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-c", script, "decode", str(pats), "--out", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == code, proc.stderr
    assert "Traceback" not in proc.stderr and "SystemError" not in proc.stderr, proc.stderr
    lines = [line for line in proc.stderr.splitlines()  # not the compile notes
             if line.strip() and not line.startswith("bistair: ") and "NumbaWarning" not in line
             and "@kernel" not in line]
    assert lines[-1:] == ([] if last is None else [last]), proc.stderr
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["kernel", "pats"]
