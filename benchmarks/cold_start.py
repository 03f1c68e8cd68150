"""The first decode after a fresh install against a warm one, as a new user meets them.

Installs bistair from this checkout into a new virtual environment (``pip install REPO``,
not editable: the build compiles the kernels, see ``setup.py``), with empty caches
(``NUMBA_CACHE_DIR`` a new folder, no ``__pycache__`` from an earlier run), renders one
320 x 256 scene of every method with ``bistair simulate`` and then, per method, times
``bistair decode`` as a whole process: the first run after the install, then three more
(warm: the median). The ratio first / warm is the figure (target: at most 8). With
``--no-prebuild`` the install skips the kernels (``BISTAIR_NO_PREBUILD=1``), which shows
what numba's compile on first call costs. The install's own time (and of it the kernels')
is printed too: what installing from source costs.

    python benchmarks/cold_start.py [--keep DIR] [--no-prebuild] [--python python3.11]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
METHODS = ("bidirectional", "multifreq", "phase-coding", "lv", "graycode")


def run(cmd: list[str], env: dict[str, str], cwd: Path) -> tuple[float, str]:
    start = time.perf_counter()
    done = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{done.stdout}\n{done.stderr}")
    return seconds, done.stdout + done.stderr


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--python", default=sys.executable,
                        help="the interpreter of the new environment")
    parser.add_argument("--no-prebuild", action="store_true",
                        help="install without compiling the kernels")
    parser.add_argument("--keep", type=Path, default=None,
                        help="work in this folder and keep it (default: a temporary one)")
    parser.add_argument("--warm", type=int, default=3, help="warm runs per method")
    args = parser.parse_args()
    work = args.keep or Path(tempfile.mkdtemp(prefix="bistair-cold-"))
    work.mkdir(parents=True, exist_ok=True)
    venv = work / "venv"
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "NUMBA_CACHE_DIR", "BISTAIR_KERNELS")}
    env["NUMBA_CACHE_DIR"] = str(work / "numba-cache")  # empty: nothing compiled before
    env["BISTAIR_PROGRESS_DELAY"] = "1000"  # only the compile notice, if any
    if args.no_prebuild:
        env["BISTAIR_NO_PREBUILD"] = "1"
    try:
        shutil.rmtree(venv, ignore_errors=True)
        shutil.rmtree(work / "numba-cache", ignore_errors=True)
        # a copy without caches of earlier runs (the repository's own __pycache__)
        source = work / "source"
        shutil.rmtree(source, ignore_errors=True)
        shutil.copytree(REPO, source, ignore=shutil.ignore_patterns(
            "__pycache__", ".venv", "_kernels", "*.egg-info", "build", ".git", "bench-out",
            "demo-out", "docs"))
        subprocess.run([args.python, "-m", "venv", str(venv)], check=True)
        py = str(venv / "bin" / "python")
        t_install, log = run([py, "-m", "pip", "install", "--no-cache-dir", "--quiet",
                              str(source)], env, work)
        kernels = [line for line in log.splitlines() if "kernel signatures" in line]
        print(f"install (pip install {'with BISTAIR_NO_PREBUILD=1 ' if args.no_prebuild else ''}"
              f"from source, dependencies from the package index): {t_install:.0f} s"
              + (f"; {kernels[0].strip()}" if kernels else ""), flush=True)
        bistair = str(venv / "bin" / "bistair")
        scenes = work / "scenes"
        shutil.rmtree(scenes, ignore_errors=True)
        # rendered with a cache of its own: the decodes' cache stays empty
        t_sim, _ = run([bistair, "simulate", "--scene", "paper-sim", "--method", "all",
                        "--camera", "320x256", "--out", str(scenes), "-q"],
                       {**env, "NUMBA_CACHE_DIR": str(work / "numba-cache-sim")}, work)
        print(f"rendering the 320x256 scenes (its own first call included): {t_sim:.1f} s")
        print(f"\n{'method':<16}{'first s':>9}{'warm s':>9}{'ratio':>7}  notice")
        ratios = []
        for method in METHODS:
            cmd = [bistair, "decode", str(scenes / method), "--out", str(work / "out" / method)]
            first, text = run(cmd, env, work)
            warm = statistics.median(run(cmd, env, work)[0] for _ in range(args.warm))
            noticed = "compiling" in text
            ratios.append(first / warm)
            print(f"{method:<16}{first:9.2f}{warm:9.2f}{first / warm:7.1f}  "
                  f"{'yes' if noticed else 'no'}", flush=True)
        print(f"\nfirst / warm: {min(ratios):.1f}-{max(ratios):.1f} (target: at most 8); "
              f"load average {os.getloadavg()[0]:.1f}")
    finally:
        if args.keep is None:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
