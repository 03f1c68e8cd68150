"""Batch speed: scans per second of ``bistair batch`` on 1 and 2 workers against a plain loop.

Renders (once, kept in ``--data``) 20 scenes of 1280 x 1024 (1.3 MP) with
``bistair simulate --count`` (bidirectional, optics, objects and pose varied), then decodes
them, in rounds, three ways, each in a new Python process as a user runs them: a plain loop
of :func:`bistair.app.decode.decode_folder` (a script's loop over the sets), and
:func:`bistair.app.batch.run_batch` (what ``bistair batch`` runs) on a local cluster of 1
and of 2 workers. Each is timed from after its imports to its end: the loop pays the
kernels' loading in its first decode, the batch its cluster's start and stop, its workers'
start and the kernels' loading in them, every set and ``batch.csv``. Each writes the same
files, with the previews and again without them (``--no-previews``). The machine is shared
and its speed varies from minute to minute, so the ways are interleaved in each round and
the figures printed are the median and the best of the rounds and each round's ratios to
its own plain loop; the load average and a probe of the free cores are printed alongside.

    python benchmarks/batch_speed.py [--sets 20] [--rounds 3] [--data bench-out/batch-data]
                                     [--markdown docs/results/batch.md]

``--markdown docs/results/batch.md`` writes the page of the documentation's results: the
medians' table, then what the script printed.

Targets (issue 23): overhead per set at most 10% of the loop's time per set (1 worker
against the loop); 2 workers at least 1.6 times the plain loop's scans per second.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from markdown_page import markdown_page

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


# Each way runs in a new process: its imports first, then the timed work; it prints
# {"seconds": ...} last.
LOOP = """
import json, sys, time
from pathlib import Path
from bistair.app.decode import decode_folder
from bistair.core.memory import keep_freed_memory
keep_freed_memory()  # as the command line and each batch task do
folders, out, previews = json.loads(sys.argv[1]), Path(sys.argv[2]), sys.argv[3] == "1"
start = time.perf_counter()
for folder in folders:
    decode_folder(folder, out / Path(folder).parent.name, previews=previews)
print(json.dumps({"seconds": time.perf_counter() - start}))
"""
BATCH = """
import json, sys, time
from bistair.app.batch import run_batch
from bistair.core.memory import keep_freed_memory
keep_freed_memory()  # as the command line does
manifest, out, previews, workers = sys.argv[1], sys.argv[2], sys.argv[3] == "1", int(sys.argv[4])
start = time.perf_counter()
report = run_batch(manifest, out, workers=workers, previews=previews)
seconds = time.perf_counter() - start
if report.failed:
    raise SystemExit(f"batch failed: {report.failed[0]}")
print(json.dumps({"seconds": seconds}))
"""


def timed(code: str, *args: str) -> float:
    done = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"failed:\n{done.stdout}\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])["seconds"]


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


WAYS = ("loop", "1", "2")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--data", type=Path, default=Path("bench-out/batch-data"))
    parser.add_argument("--previews", choices=("both", "yes", "no"), default="both")
    parser.add_argument("--markdown", type=Path, default=None,
                        help="also write the page of the results (e.g. docs/results/batch.md)")
    args = parser.parse_args()
    found: dict[str, object] = {}
    with markdown_page(args.markdown, TITLE, ABOUT, lambda: page_sections(found)):
        run(args, found)


TITLE = "Batch speed"
ABOUT = ("Scans per second of `bistair batch` on a local cluster of 1 and 2 workers against a "
         "plain loop of the same decodes (`decode_folder` per set), each way in a new process "
         "as a user runs it, interleaved in rounds, with the previews and without them. "
         "The many-scans guide says what a batch is for.")


def page_sections(found: dict[str, object]) -> list[str]:
    """The page's table: the median of the rounds for each way, with and without previews,
    and what the loop, 1 worker and 2 workers compare to."""
    times = found.get("times")
    if not isinstance(times, dict):
        return []
    n = found["sets"]
    kinds = sorted({previews for previews, _ in times}, reverse=True)
    head = ["| |"]
    for previews in kinds:
        on = "previews" if previews else "no previews"
        head.append(f" {on}: wall time | scans/s | against the loop |")
    lines = ["## The median of the rounds", "", "".join(head),
             "| --- |" + " --- | --- | --- |" * len(kinds)]
    names = {"loop": "plain loop", "1": "batch, 1 worker", "2": "batch, 2 workers"}
    for way in WAYS:
        row = f"| {names[way]} |"
        for previews in kinds:
            t = statistics.median(times[(previews, way)])
            loop = statistics.median(times[(previews, "loop")])
            row += f" {t:.1f} s | {n / t:.2f} | {loop / t:.2f} |"
        lines.append(row)
    lines += ["", f"{n} sets of {CAMERA[0]} x {CAMERA[1]}, {METHOD}, {found['rounds']} "
              f"round(s), load average {found['loads']} during the run; `against the loop`: "
              "the loop's wall time over the way's (above 1: faster than the loop). Issue "
              "23's targets: 1 worker's overhead per set at most 10% of the loop's time per "
              "set; 2 workers at least 1.6 times the loop's scans per second."]
    return lines


def run(args: argparse.Namespace, found: dict[str, object]) -> None:
    """Render the sets (once), time the three ways in rounds, print the tables; keep the
    times in ``found`` for the page."""
    captures = data_set(args.data, args.sets)
    n = len(captures)
    work = Path(tempfile.mkdtemp(prefix="batch-speed-"))
    manifest = work / "sets.csv"
    manifest.write_text("captures,out\n" + "".join(f"{c.absolute()},{c.parent.name}\n"
                                                   for c in captures))
    folders = json.dumps([str(c.absolute()) for c in captures])
    kinds = {"both": (True, False), "yes": (True,), "no": (False,)}[args.previews]
    times: dict[tuple[bool, str], list[float]] = {(p, w): [] for p in kinds for w in WAYS}
    cores: list[float] = []
    loads = [os.getloadavg()[0]]
    try:
        for r in range(args.rounds):
            for previews in kinds:
                for way in WAYS:
                    out = work / "out"
                    shutil.rmtree(out, ignore_errors=True)
                    flag = "1" if previews else "0"
                    t = (timed(LOOP, folders, str(out), flag) if way == "loop"
                         else timed(BATCH, str(manifest), str(out), flag, way))
                    times[(previews, way)].append(t)
                    print(f"round {r + 1}, previews {'on' if previews else 'off'}: "
                          f"{'plain loop' if way == 'loop' else way + ' worker(s)'} {t:.1f} s",
                          flush=True)
            cores.append(free_cores())
            loads.append(os.getloadavg()[0])
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print()
    print(f"{n} sets of {CAMERA[0]}x{CAMERA[1]} ({CAMERA[0] * CAMERA[1] / 1e6:.1f} MP), "
          f"{METHOD}; {args.rounds} interleaved round(s), each way in a new process; "
          f"{os.cpu_count()} CPUs, load average {min(loads):.1f}-{max(loads):.1f} during the "
          "run (other work on the machine slows every figure)")
    for previews in kinds:
        for label, pick in (("median", statistics.median), ("best", min)):
            report(f"{label} of the rounds, previews {'on' if previews else 'off'}",
                   {w: pick(times[(previews, w)]) for w in WAYS}, n)
        loop = times[(previews, "loop")]
        print("per round, against that round's plain loop: 1 worker " + ", ".join(
            f"{a / b:.2f}" for a, b in zip(loop, times[(previews, "1")], strict=True))
              + "; 2 workers " + ", ".join(
            f"{a / b:.2f}" for a, b in zip(loop, times[(previews, "2")], strict=True)))
    found.update(times=times, sets=n, rounds=args.rounds,
                 loads=f"{min(loads):.1f}-{max(loads):.1f}")
    print("\nthe cores two processes got at the end of each round (a NumPy probe, 2.00 = "
          "two free cores): " + ", ".join(f"{c:.2f}" for c in cores))


def report(label: str, med: dict[str, float], n: int) -> None:
    """The table and the two targets for one pick of the rounds (median or best)."""
    loop = med["loop"]
    print()
    print(f"{label:<42}{'wall s':>8s}{'scans/s':>10s}{'vs loop':>9s}")
    print(f"{'plain loop':42s}{loop:8.1f}{n / loop:10.3f}{1.0:9.2f}")
    for w in ("1", "2"):
        t = med[w]
        name = f"batch, {w} worker" + ("s" if w != "1" else "")
        print(f"{name:42s}{t:8.1f}{n / t:10.3f}{loop / t:9.2f}")
    per_set = loop / n
    over = (med["1"] - loop) / n
    print(f"overhead per set, 1 worker against the plain loop: {over:+.3f} s = "
          f"{100 * over / per_set:+.1f}% of the loop's {per_set:.2f} s per set "
          f"(target <= 10%); 2 workers: {loop / med['2']:.2f} times the loop's scans per "
          f"second (target >= 1.6), {med['1'] / med['2']:.2f} times 1 worker's")


if __name__ == "__main__":
    main()
