"""Shared fixtures: specs, warped scenes with isolated objects, ground-truth scoring."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import numpy as np
import pytest

import bistair
from bistair.app.progress import COMPILE_NOTICE
from bistair.evaluation.metrics import score as score_of
from bistair.sim.warp import Blob, WarpScene, render_warp

SHARED = Path(__file__).resolve().parents[1].parent / "shared"

# The tests that interrupt a command (Ctrl-C: SIGINT) need it to reach the command's Python.
# pytest-xdist's workers (`make test` runs them) ignore SIGINT, and an ignored signal stays
# ignored in the processes they start, whose Python then never raises KeyboardInterrupt; a
# handler here is reset to the default in those processes, so they get Python's own.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
CFPE = SHARED / "data" / "cfpe"
# seconds a test waits for a command it started (to start writing, to end after a signal,
# to finish) before calling it hung: a guard against hangs only, so long enough for a
# loaded two-core machine (issue 31: six test runs at once ran a minute's work in several)
PATIENCE = 600.0


@pytest.fixture(scope="session", autouse=True)
def no_progress_lines():
    """No progress lines on stderr unless a test asks for them (``BISTAIR_PROGRESS_DELAY``
    set by the test itself): a command prints them once it has run 5 s in a log, so whether
    they appear before a result or an error depends on the machine's load, not the code.
    Session-wide, so that the fixtures of wider scope see it too."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("BISTAIR_PROGRESS_DELAY", "3600")
        yield


def isolated_blobs(seed: int, stretch: float, period: float = 30.0) -> tuple[Blob, ...]:
    """One large object and six small, well separated ones, some 1-2 fringes wide and about
    one group tall (seeded)."""
    rng = np.random.default_rng(seed)
    fringe = period / stretch  # camera pixels per fringe
    blobs = [Blob(rng.uniform(180, 230), rng.uniform(220, 260), rng.uniform(110, 140),
                  rng.uniform(150, 190), shift=rng.uniform(-50, 50), dome=rng.uniform(0, 40),
                  albedo=rng.uniform(0.5, 0.8))]
    for i in range(6):
        half_w = rng.uniform(0.5, 1.0) * fringe if i < 3 else rng.uniform(1.0, 1.6) * fringe
        half_h = rng.uniform(0.5, 0.75) * period if i < 3 else rng.uniform(1.0, 1.8) * period
        cx = 440 + (i % 2) * 120 + rng.uniform(-10, 10)
        cy = 50 + (i // 2) * 150 + rng.uniform(-10, 10)
        blobs.append(Blob(cx, cy, half_w, min(half_h, 60.0), shift=rng.uniform(-300, 300),
                          dome=rng.uniform(0, 4), albedo=rng.uniform(0.3, 0.8)))
    return tuple(blobs)


def warped_scene(seed: int, noise: float, blur: float, **overrides) -> WarpScene:
    """A seeded warp: stretch, offset, vertical scale giving groups of 20-45 rows, roll."""
    rng = np.random.default_rng(1000 + seed)
    stretch = rng.uniform(1.0, 1.5)
    top, bottom = rng.uniform(0.67, 0.9), rng.uniform(1.1, 1.5)
    if rng.random() < 0.5:
        top, bottom = bottom, top
    params = dict(size=(480, 640), blobs=isolated_blobs(seed, stretch), stretch=stretch,
                  offset=rng.uniform(0, 150), scale_top=top, scale_bottom=bottom,
                  row_offset=rng.uniform(0, 30), roll_deg=rng.uniform(-2, 2), blur=blur,
                  noise=noise, seed=seed, albedo_texture=0.15)
    params.update(overrides)
    return WarpScene(**params)


def score(spec, scene, **decode_options):
    images, truth = render_warp(spec, scene)
    result = bistair.decode(images, spec, **decode_options)
    return result, truth, score_of(result, truth.coord(spec), truth.mask, truth.object_id)


@pytest.fixture(scope="session")
def spec36():
    return bistair.make_spec("bidirectional", width=1080, height=1080, period=30)


def cli_run(monkeypatch, capsys, *args) -> tuple[int, str, str]:
    """Run the ``bistair`` entry point in-process: (exit code, stdout, stderr without the
    kernels' compile notice)."""
    from bistair.app.cli import main

    monkeypatch.setattr(sys, "argv", ["bistair", *map(str, args)])
    code = 0
    try:
        main()
    except SystemExit as exc:
        code = exc.code or 0
    out = capsys.readouterr()
    # a kernel compiled in this process (a cold numba cache: a checkout whose prebuilt
    # kernels do not match its sources) says so once on stderr; what the tests read is the
    # rest (test_kernels.py tests the notice itself)
    err = "".join(line for line in out.err.splitlines(keepends=True)
                  if line.rstrip("\n") != f"bistair: {COMPILE_NOTICE}")
    return code, out.out, err
