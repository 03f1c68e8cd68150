"""Batch speed: scans per second of ``bistair batch`` on 1 and 2 workers against a plain loop.

Renders (once, kept in ``--data``) 20 scenes of 1280 x 1024 (1.3 MP) with
``bistair simulate --count`` (bidirectional, optics, objects and pose varied), then decodes
them, in rounds, three ways: a plain loop of :func:`bistair.app.jobs.decode_folder` in this
process (what a loop over ``bistair decode`` does, without its start-up), and
:func:`bistair.app.batch.run_batch` on a local cluster of 1 and of 2 workers (wall time
from the call to its return: cluster start and stop, every set, ``batch.csv``). Each writes
the same files (previews included). The machine is shared and its speed varies from minute
to minute, so the three are interleaved in each round and the figures printed are the
median and the best of the rounds and each round's ratios to its own plain loop; the load
average is printed alongside.

    python benchmarks/batch_speed.py [--sets 20] [--rounds 3] [--data bench-out/batch-data]

Targets (issue 12): overhead per set at most 10% of the loop's time per set; near-linear
in workers (2 workers close to twice the scans per second of 1, given 2 free cores).
"""

from __future__ import annotations

import argparse
import csv
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bistair.app.batch import run_batch
from bistair.app.engine import dask_client
from bistair.app.jobs import decode_folder
from bistair.app.simulate import simulate_many

CAMERA = (1280, 1024)
METHOD = "bidirectional"


def data_set(folder: Path, sets: int) -> list[Path]:
    """The capture folders of ``sets`` simulated scenes (rendered unless already there)."""
    index = folder / "index.csv"
    if index.exists():
        with index.open() as fh:
            rows = list(csv.DictReader(fh))
        if len(rows) >= sets and all((folder / r["captures"]).is_dir() for r in rows):
            return [folder / r["captures"] for r in rows[:sets]]
    print(f"rendering {sets} scenes of {CAMERA[0]}x{CAMERA[1]} into {folder} (once) ...",
          flush=True)
    report = simulate_many(sets, [METHOD], folder, seed=0, vary=("optics", "objects", "pose"),
                           camera_size=CAMERA)
    if report.failed:
        raise SystemExit(f"rendering failed: {report.failed}")
    print(f"  {report.seconds:.0f} s on {report.workers} workers", flush=True)
    return [folder / r["captures"] for r in report.rows]


def plain_loop(captures: list[Path], out: Path) -> float:
    start = time.perf_counter()
    for folder in captures:
        decode_folder(folder, out / folder.parent.name)
    return time.perf_counter() - start


def batch(manifest: Path, out: Path, workers: int) -> float:
    start = time.perf_counter()
    report = run_batch(manifest, out, workers=workers)
    seconds = time.perf_counter() - start
    if report.failed:
        raise SystemExit(f"batch failed: {report.failed[0]}")
    return seconds


PROBE = """
import time
import numpy as np
from scipy import ndimage
a = np.random.default_rng(0).random((1024, 1280), np.float32)
start = time.perf_counter()
for _ in range(30):
    ndimage.gaussian_filter(a, 1.0)
print(time.perf_counter() - start)
"""


def free_cores() -> float:
    """How many cores two processes got just now: two copies of a fixed NumPy workload run
    at once against one alone (2.0: two free cores; 1.0: the two shared one)."""
    def run(copies: int) -> float:
        procs = [subprocess.Popen([sys.executable, "-c", PROBE], stdout=subprocess.PIPE,
                                  text=True) for _ in range(copies)]
        return statistics.mean(float(p.communicate()[0]) for p in procs)

    alone = run(1)
    return 2 * alone / run(2)


def cluster_start_stop(workers: int) -> float:
    start = time.perf_counter()
    with dask_client(workers):
        pass
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--data", type=Path, default=Path("bench-out/batch-data"))
    args = parser.parse_args()
    captures = data_set(args.data, args.sets)
    n = len(captures)
    work = Path(tempfile.mkdtemp(prefix="batch-speed-"))
    manifest = work / "sets.csv"
    manifest.write_text("captures,out\n" + "".join(f"{c.absolute()},{c.parent.name}\n"
                                                   for c in captures))
    times: dict[str, list[float]] = {k: [] for k in ("loop", "1", "2", "start1", "start2")}
    cores: list[float] = []
    loads = [os.getloadavg()[0]]
    try:
        for r in range(args.rounds):
            for key in ("loop", "1", "2"):
                out = work / f"out-{key}"
                shutil.rmtree(out, ignore_errors=True)
                t = plain_loop(captures, out) if key == "loop" else batch(manifest, out,
                                                                          int(key))
                times[key].append(t)
                print(f"round {r + 1}: {'plain loop' if key == 'loop' else key + ' worker(s)'}"
                      f" {t:.1f} s", flush=True)
            for w in (1, 2):
                times[f"start{w}"].append(cluster_start_stop(w))
            cores.append(free_cores())
            loads.append(os.getloadavg()[0])
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print()
    print(f"{n} sets of {CAMERA[0]}x{CAMERA[1]} ({CAMERA[0] * CAMERA[1] / 1e6:.1f} MP), "
          f"{METHOD}, previews written; {args.rounds} interleaved round(s); "
          f"{os.cpu_count()} CPUs, load average {min(loads):.1f}-{max(loads):.1f} during the "
          "run (other work on the machine slows every figure)")
    for label, pick in (("median", statistics.median), ("best", min)):
        report(label, {k: pick(v) for k, v in times.items()}, n)
    print()
    print("per round, against that round's plain loop: 1 worker " + ", ".join(
        f"{lp / t:.2f}" for lp, t in zip(times["loop"], times["1"], strict=True))
          + "; 2 workers " + ", ".join(
        f"{lp / t:.2f}" for lp, t in zip(times["loop"], times["2"], strict=True)))
    print("2 workers against 1, per round: " + ", ".join(
        f"{a / b:.2f}" for a, b in zip(times["1"], times["2"], strict=True))
          + "; the cores two processes got at the end of each round (a NumPy probe, 2.00 = "
          "two free cores): " + ", ".join(f"{c:.2f}" for c in cores))


def report(label: str, med: dict[str, float], n: int) -> None:
    """The table and the two targets for one pick of the rounds (median or best)."""
    loop = med["loop"]
    print()
    print(f"{label} of the rounds{'':8s}{'wall s':>8s}{'scans/s':>10s}{'vs loop':>9s}")
    print(f"{'plain loop':30s}{loop:8.1f}{n / loop:10.3f}{1.0:9.2f}")
    for w in (1, 2):
        t = med[str(w)]
        print(f"{f'batch, {w} worker' + ('s' if w > 1 else ''):30s}{t:8.1f}{n / t:10.3f}"
              f"{loop / t:9.2f}")
    per_set = loop / n
    over = (med["1"] - loop) / n
    fixed = med["start1"]
    print(f"overhead per set, 1 worker against the plain loop: {over:+.3f} s = "
          f"{100 * over / per_set:+.1f}% of the loop's {per_set:.2f} s per set "
          f"(target <= 10%); of it the cluster's start and stop, {fixed:.1f} s once, is "
          f"{fixed / n:.3f} s per set over {n} sets; the rest "
          f"{100 * (over - fixed / n) / per_set:+.1f}%")
    print(f"2 workers against 1: {med['1'] / med['2']:.2f} times the scans per second "
          f"(linear: 2.00; cluster start and stop {med['start2']:.1f} s)")


if __name__ == "__main__":
    main()
