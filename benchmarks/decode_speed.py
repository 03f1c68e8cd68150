"""Decoding speed of every codec against the OpenCV floor of a 4-step decode, in the same run,
and where the default decode's time goes.

For 1.3 MP (1280 x 1024) and 12 MP (4000 x 3000) captures, 8-bit, of the speed scene
(:mod:`bistair.evaluation.speed`, which ``bistair bench`` times too), each codec's warm
decode time (median of several runs; the first decode, which loads the kernels, not timed)
is printed next to the least work any 4-step decode must do on the same frames: two frame
differences, their phase and magnitude (``cv2.subtract`` into float32, ``cv2.phase``,
``cv2.magnitude``), timed after each decode (the machine is shared and noisy: the ratio
decode / floor, the median of the runs' own ratios, is the figure; issue 32's targets: at
most 15 at 1.3 MP and 12 at 12 MP for the default decoder, every other codec within 1.3
times the default's ratio). Also printed: megapixels and scans (one capture set) per
second, each codec's ratio against the default decoder's, the peak memory of a decode in a
fresh process per camera pixel beyond the input stack, and two cold starts in fresh
processes with an empty numba cache (``NUMBA_CACHE_DIR``): the first call with the kernels
compiled at install time (``bistair/_kernels``, see ``setup.py``; ``-`` if this checkout has
none: ``python -m bistair.app.kernels src/bistair/_kernels`` makes them) and the compile of
a first call without them (``BISTAIR_KERNELS=none``: first call less a warm one).
``numpy.show_runtime()`` says which vector units NumPy uses. If comimag's ``fringes``
package is installed, its three-frequency decode is timed too.

Where the time goes: the default decode with every function of ``bistair.core`` and
``bistair.codecs`` timed (``stage_times.py``), its stages grouped into five rows; the
fastest of ``--runs`` instrumented decodes, beside the same decode not instrumented.

The decodes are timed as the command line runs them, with freed memory kept for the next
arrays (:func:`bistair.core.memory.keep_freed_memory`); the default decoder is also timed
with glibc's default allocator settings (``system malloc``), which is what
``bistair.decode`` from Python gets unless asked. The memory figure is always measured
with the default settings. ``--markdown docs/results/speed.md`` writes the page of the
documentation's results: both tables, then what the script printed.

    python benchmarks/decode_speed.py [--runs 5] [--sizes 1.3,12] [--threads N] [--no-memory]
                                      [--no-compile] [--codecs 0,2]
                                      [--markdown docs/results/speed.md]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from importlib.metadata import version
from pathlib import Path

import cv2
import numpy as np
from markdown_page import markdown_page
from stage_times import STAGES, stage_times

import bistair
from bistair.core.jit import prebuilt_folder, set_threads
from bistair.core.memory import keep_freed_memory
from bistair.evaluation.speed import CASES, Timing, machine, speed_captures, time_case

SIZES = {"1.3": (1024, 1280), "12": (3000, 4000)}
TITLE = "Decode speed"
ABOUT = ("Every codec's warm decode against the least work any 4-step decode does (OpenCV's "
         "4-step pass on the same frames, timed after each decode), and where the default "
         "decode's time goes. `bistair bench` measures the first table on your machine.")


def timed(func, runs: int) -> float:
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        func()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


# Peak memory of the second (warm) decode, from /proc/self/status: VmHWM reset (clear_refs
# 5) just before it and VmRSS read then; ru_maxrss would start at the parent's peak
# (inherited over fork) and the first decode also loads the modules and kernels.
_CHILD = """
import json, sys, time
import numpy as np
import bistair
def status(key):
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith(key + ":"))
frames = np.load(sys.argv[1])
spec = bistair.spec_from_dict(json.loads(sys.argv[2]))
options = json.loads(sys.argv[3])
t0 = time.perf_counter()
bistair.decode(frames, spec, **options)
first = time.perf_counter() - t0
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")
before = status("VmRSS")
t0 = time.perf_counter()
bistair.decode(frames, spec, **options)
warm = time.perf_counter() - t0
peak = status("VmHWM")
print(json.dumps({"first": first, "warm": warm, "peak_kb": peak - before}))
"""


def fresh_process(frames: np.ndarray, spec, options: dict, cache: str | None,
                  prebuilt: bool = True) -> dict:
    """First-call time, warm time and peak resident memory growth of one decode in a new
    process (``cache``: a numba cache folder, empty for a cold start; ``prebuilt``: the
    kernels compiled at install time are read)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "frames.npy"
        np.save(path, frames)
        # a fixed mmap threshold: freed arrays leave the resident set, so the warm decode's
        # peak is its own and not hidden in memory glibc kept from the first
        env = {**os.environ, "MALLOC_MMAP_THRESHOLD_": "131072",
               "MALLOC_TRIM_THRESHOLD_": "131072"}
        if cache is not None:
            env["NUMBA_CACHE_DIR"] = cache
        if not prebuilt:
            env["BISTAIR_KERNELS"] = "none"
        out = subprocess.run([sys.executable, "-c", _CHILD, str(path), spec.to_json(),
                              json.dumps(options)], capture_output=True, text=True, env=env,
                             check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def fringes_three_frequency(size: tuple[int, int], runs: int) -> str:
    try:
        import fringes  # comimag/Fringes, optional
    except ImportError:
        return "comimag fringes: not installed (pip install fringes to compare)"
    f = fringes.Fringes()
    f.X, f.Y = size[1], size[0]
    f.K = 3
    f.N = 8
    I = f.encode()  # noqa: E741 - their name
    t = timed(lambda: f.decode(I), runs)
    return f"comimag fringes 3 frequencies x 8 steps: {1e3 * t:.0f} ms"


def _ms(seconds: float) -> str:
    return f"{seconds:.2f} s" if seconds >= 1 else f"{1e3 * seconds:.0f} ms" \
        if seconds >= 0.01 else f"{1e3 * seconds:.1f} ms"


def speed_table(found: dict[str, dict]) -> list[str]:
    """The page's table of every codec: per size its time and ratio, the ratios to the
    default decoder's, scans/s, peak memory and the first decode in a fresh process."""
    keys = list(found)
    head = ["codec"]
    for key in keys:
        head += [f"{key} MP", "/ floor"]
    both = ", ".join(f"{k} MP" for k in keys)
    head += [f"/ default ({both})", f"scans/s ({both})", f"peak memory ({both})",
             f"first decode ({both})"]
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    labels = [label for label in found[keys[0]]["timings"]]
    for label in labels:
        cells = [label + (" (the default)" if label == CASES[0].label else "")]
        for key in keys:
            t: Timing = found[key]["timings"][label]
            cells += [_ms(t.decode_s), f"{t.ratio:.1f}"]
        default = [found[k]["timings"].get(CASES[0].label) for k in keys]
        cells.append(", ".join(f"{found[k]['timings'][label].ratio / d.ratio:.2f}" if d else "-"
                               for k, d in zip(keys, default, strict=True)))
        cells.append(", ".join(f"{found[k]['timings'][label].scans_per_s:.1f}" for k in keys))
        cells.append(", ".join(found[k]["memory"].get(label) or "-" for k in keys))
        cells.append(", ".join(found[k]["first"].get(label) or "-" for k in keys))
        lines.append("| " + " | ".join(cells) + " |")
    floor = ["the floor (OpenCV 4-step pass)"]
    for key in keys:
        floors = [t.floor_s for t in found[key]["timings"].values()]
        floor += [f"{_ms(min(floors))} to {_ms(max(floors))}", "1"]
    lines.append("| " + " | ".join(floor + [""] * 4) + " |")
    return lines


def stage_table(found: dict[str, dict]) -> list[str]:
    """The page's five rows of where the default decode's time goes, per size."""
    keys = [k for k in found if found[k].get("stages")]
    if not keys:
        return []
    head = ["stage"] + [c for k in keys for c in (f"{k} MP", "share")]
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for stage in STAGES:
        cells = [stage]
        for key in keys:
            seconds, total = found[key]["stages"][stage], found[key]["stage_total"]
            cells += [_ms(seconds), f"{100 * seconds / total:.0f}%"]
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("| " + " | ".join(["the five, instrumented"] + [
        c for k in keys for c in (_ms(found[k]["stage_total"]), "100%")]) + " |")
    lines.append("| " + " | ".join(["the same decode, not instrumented (median)"] + [
        c for k in keys for c in (_ms(found[k]["timings"][CASES[0].label].decode_s), "")])
        + " |")
    return lines


def page_sections(found: dict[str, dict], runs: int) -> list[str]:
    lines = ["## Every codec", "", *speed_table(found), "",
             "`/ floor`: the median of the runs' own decode / floor ratios; `/ default`: the "
             "codec's ratio divided by the default decoder's; scans/s: capture sets decoded "
             "per second one after the other; peak memory: growth of the resident set during "
             "a warm decode in a fresh process, per camera pixel, beyond the input stack; first "
             "decode: in a fresh process with an empty numba cache, the kernels compiled at "
             "install time read (`-`: none in this checkout, or not measured)."]
    stages = stage_table(found)
    if stages:
        lines += ["", "## Where the time goes", "",
                  f"The default decode ({CASES[0].label}) with every function of "
                  "`bistair.core` and `bistair.codecs` timed (`benchmarks/stage_times.py`): "
                  "each function's own time, less the timed functions it calls, counted in the "
                  "stage its module and name belong to; the compiled kernels timed as single "
                  f"calls. The fastest of {runs} instrumented decodes.", "", *stages]
    return lines


def machine_line() -> str:
    m = machine()
    return (f"{m['cpu']} ({m['cores']} cores, {m['threads']} kernel threads, numba threading "
            f"layer {m['threading_layer']}; load average {m['load']} at the end), numba "
            f"{version('numba')}, NumPy {np.__version__}, OpenCV {cv2.__version__},")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--sizes", default="1.3,12")
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--no-memory", action="store_true", help="skip the fresh processes")
    parser.add_argument("--no-compile", action="store_true",
                        help="skip the fresh processes that compile every kernel (minutes)")
    parser.add_argument("--codecs", default=None,
                        help="comma-separated indices of the codecs to time, 0 the default "
                             "(default: all)")
    parser.add_argument("--markdown", type=Path, default=None,
                        help="also write the page of the results (e.g. docs/results/speed.md)")
    args = parser.parse_args()
    if args.codecs is not None and not all(
            i.strip().isdigit() and int(i) < len(CASES) for i in args.codecs.split(",")):
        parser.error(f"--codecs takes indices 0-{len(CASES) - 1} of: "
                     + ", ".join(case.label for case in CASES))
    found: dict[str, dict] = {}
    with markdown_page(args.markdown, TITLE, ABOUT, lambda: page_sections(found, args.runs),
                       machine_line):
        run(args, found)


def run(args: argparse.Namespace, found: dict[str, dict]) -> None:
    threads = set_threads(args.threads)
    np.show_runtime()
    kept = keep_freed_memory()
    folder = prebuilt_folder()
    have = folder is not None and any(folder.glob("*.nbi"))
    print(f"\nnumba threads: {threads}; OpenCV threads: {cv2.getNumThreads()}; cores: "
          f"{os.cpu_count()}; freed memory kept for the next arrays: "
          f"{'yes' if kept else 'no (not glibc)'}; kernels compiled at install time: "
          f"{folder if have else 'none'}; load average {os.getloadavg()[0]:.1f}")
    picked = (range(len(CASES)) if args.codecs is None
              else [int(i) for i in args.codecs.split(",")])
    for key in args.sizes.split(","):
        size = SIZES[key]
        mpix = size[0] * size[1] / 1e6
        runs = args.runs if mpix < 5 else max(2, args.runs // 2)
        found[key] = entry = {"timings": {}, "memory": {}, "first": {}}
        print(f"\ncaptures {size[1]}x{size[0]} ({mpix:.1f} MP), 8 bit, median of {runs} runs "
              "(the first decode not timed); floor: OpenCV's 4-step pass on the same frames, "
              "timed after each decode")
        print(f"{'codec':<28} {'decode':>8} {'floor':>7} {'ratio':>6} {'(range)':>8} "
              f"{'MP/s':>5} {'scans/s':>7} {'/default':>8} {'B/px':>5} {'first':>7} "
              f"{'compile':>7}")
        default = None
        for i in picked:
            case = CASES[i]
            spec = case.spec()
            frames = speed_captures(spec, size)
            t = time_case(case, frames, runs)
            entry["timings"][case.label] = t
            if i == 0:
                default = t.ratio
            mem = first = compile_s = ""
            if not args.no_memory:
                with tempfile.TemporaryDirectory() as cache:
                    cold = fresh_process(frames, spec, case.options, cache)
                mem = f"{1024 * cold['peak_kb'] / (size[0] * size[1]):5.1f}"
                first = f"{cold['first']:6.2f}s" if have else "-"
                if not args.no_compile:
                    with tempfile.TemporaryDirectory() as cache:
                        jit = fresh_process(frames, spec, case.options, cache, prebuilt=False)
                    compile_s = f"{jit['first'] - jit['warm']:6.1f}s"
                entry["memory"][case.label] = f"{mem.strip()} B/px"
                entry["first"][case.label] = _ms(cold["first"]) if have else None
            against = f"{t.ratio / default:8.2f}" if default else f"{'':8s}"
            print(f"{case.label:<28} {1e3 * t.decode_s:6.0f}ms {1e3 * t.floor_s:5.1f}ms "
                  f"{t.ratio:6.1f} {f'{min(t.ratios):.0f}-{max(t.ratios):.0f}':>8} "
                  f"{t.mpix_per_s:5.1f} {t.scans_per_s:7.1f} {against} {mem:>5} {first:>7} "
                  f"{compile_s:>7}", flush=True)
            if i == 0 and kept:
                keep_freed_memory(False)
                sys_t = time_case(case, frames, runs)
                keep_freed_memory(True)
                print(f"{'  the same, system malloc':<28} {1e3 * sys_t.decode_s:6.0f}ms "
                      f"{'':7s} {sys_t.ratio:6.1f}", flush=True)
            if i == 0:
                seconds, total, unassigned = stage_times(bistair.codecs.decode, frames, spec,
                                                         case.options, runs)
                entry["stages"], entry["stage_total"] = seconds, total
                print("  where its time goes (fastest of "
                      f"{runs} instrumented decodes, {1e3 * total:.0f} ms): " + "; ".join(
                          f"{stage.split(':')[0]} {1e3 * s:.0f} ms"
                          for stage, s in seconds.items()), flush=True)
                if unassigned:
                    print(f"  (counted with the orders, no pattern names them: "
                          f"{', '.join(unassigned)})")
        print(fringes_three_frequency(size, args.runs))


if __name__ == "__main__":
    main()
