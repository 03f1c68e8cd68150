"""``bistair bench``: how fast every codec decodes on this machine, against the OpenCV floor
timed in the same run (:mod:`bistair.evaluation.speed`).

For each codec it renders the speed scene at the camera size, decodes it once (not timed:
that decode loads the kernels), then times ``runs`` decodes, each followed by the floor on
the same frames. The default decoder is always timed, since every ratio is also given
against its own.

Examples
--------
>>> report = run_bench((256, 192), ["graycode"], runs=1)
>>> [timing.case.label for timing in report.timings]
['bidirectional 8x8 (region)', 'graycode complementary']
>>> lines = bench_lines(report)
>>> lines[1].split()[:3], lines[2].split()[0], lines[-1].split()[0]
(['codec', 'decoded', 'ms/decode'], 'bidirectional', 'machine:')
"""

from __future__ import annotations

import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import BistairError
from ..evaluation.speed import (
    CASES,
    Timing,
    check_size,
    machine,
    speed_captures,
    speed_cases,
    time_case,
)
from ..io.atomic import check_output, output_file
from ..io.jsonfile import write_json

MAX_RUNS = 1000


@dataclass
class BenchReport:
    """What ``bistair bench`` measured: the camera size ``(width, height)``, the runs, each
    codec's :class:`~bistair.evaluation.speed.Timing` (the default decoder first), the
    floor's seconds (the median of the codecs' medians) and the machine."""

    size: tuple[int, int]
    runs: int
    timings: list[Timing]
    floor_s: float
    machine: dict[str, Any] = field(default_factory=dict)

    @property
    def default(self) -> Timing:
        """The default decoder's timing."""
        return self.timings[0]

    def to_dict(self) -> dict[str, Any]:
        """The figures as ``--json`` writes them."""
        return {"format": "bistair-bench", "version": 1, "camera": list(self.size),
                "runs": self.runs, "first_decode_timed": False,
                "floor_ms": 1e3 * self.floor_s, "machine": self.machine,
                "codecs": [{"label": t.case.label, "method": t.case.method,
                            "options": t.case.options, "decoded": t.valid,
                            "ms": 1e3 * t.decode_s, "floor_ms": 1e3 * t.floor_s,
                            "scans_per_s": t.scans_per_s, "mpix_per_s": t.mpix_per_s,
                            "ratio": t.ratio, "ratios": t.ratios,
                            "to_default": t.ratio / self.default.ratio}
                           for t in self.timings]}


def run_bench(size: tuple[int, int], picked: Sequence[str] | None = None, runs: int = 5,
              progress: Callable[[str], None] | None = None) -> BenchReport:
    """Time the warm decodes of the picked methods (every codec when ``None``) and the
    floor at camera ``size`` = ``(width, height)``.

    Raises :class:`~bistair.errors.BistairError` for an unknown method, a camera size the
    scene is not made for, or a count of runs outside 1 to :data:`MAX_RUNS`.
    """
    say = progress or (lambda text: None)
    if isinstance(runs, bool) or not isinstance(runs, int) or not 1 <= runs <= MAX_RUNS:
        raise BistairError(f"--runs must be a whole number from 1 to {MAX_RUNS}, got {runs!r}")
    width, height = size
    check_size((height, width))
    cases = speed_cases(picked)
    if CASES[0] not in cases:
        cases.insert(0, CASES[0])  # the ratios' reference
    timings = []
    for case in cases:
        say(f"rendering the {case.label} captures at {width}x{height}")
        frames = speed_captures(case.spec(), (height, width))
        say(f"decoding {case.label}: {runs} timed decodes after a first one")
        timings.append(time_case(case, frames, runs))
    floor = float(statistics.median(t.floor_s for t in timings))
    return BenchReport((width, height), runs, timings, floor, machine())


def bench_lines(report: BenchReport) -> list[str]:
    """The table ``bistair bench`` prints: a heading, a row per codec, the floor's row and
    the machine's line."""
    width, height = report.size
    mp = width * height / 1e6
    lines = [f"warm decodes of {width}x{height} 8-bit captures ({mp:.1f} MP), median of "
             f"{report.runs} run{'s' if report.runs != 1 else ''} (each codec's first decode, "
             "which loads its kernels, not timed); floor: OpenCV's 4-step pass on the same "
             "frames after each decode",
             f"{'codec':<28} {'decoded':>7} {'ms/decode':>9} {'scans/s':>7} {'MP/s':>6} "
             f"{'/ floor':>7} {'/ default':>9}"]
    for t in report.timings:
        lines.append(f"{t.case.label:<28} {100 * t.valid:6.1f}% {1e3 * t.decode_s:9.1f} "
                     f"{t.scans_per_s:7.1f} {t.mpix_per_s:6.1f} {t.ratio:7.1f} "
                     f"{t.ratio / report.default.ratio:9.2f}")
    floor = report.floor_s
    lines.append(f"{'floor (OpenCV 4-step pass)':<28} {'':7} {1e3 * floor:9.2f} "
                 f"{1 / floor:7.0f} {mp / floor:6.0f} {1:7.1f}")
    m = report.machine
    load = "" if m.get("load") is None else f"; load average {m['load']:.1f}"
    lines.append(f"machine: {m['cores']} cores, {m['threads']} kernel threads, "
                 f"{m['opencv_threads']} OpenCV threads; {m['cpu']}; numba threading layer "
                 f"{m['threading_layer']}{load}")
    return lines


def check_json_path(path: str | Path) -> Path:
    """Refuse, before any work, a ``--json`` path that cannot be a file: empty, a folder, or
    below a file."""
    path = check_output(path)
    if path.is_dir():
        raise BistairError(f"--json {path} is a folder: name a file")
    for folder in path.parents:
        if folder.exists():
            if not folder.is_dir():
                raise BistairError(f"--json {path}: {folder} is a file, not a folder")
            break
    return path


def write_bench_json(report: BenchReport, path: str | Path) -> Path:
    """Write the figures (:meth:`BenchReport.to_dict`) to ``path`` atomically."""
    path = check_json_path(path)
    with output_file(path) as tmp:
        write_json(tmp, report.to_dict())
    return path
