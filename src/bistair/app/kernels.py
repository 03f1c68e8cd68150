"""The compiled kernels made at install time, so that a first decode does not wait for them.

numba compiles a kernel on its first call: some fifty kernels and a minute on two cores for
the default decode, two or three minutes for every codec, paid again in every new
environment. ``pip install`` (``setup.py``) runs this module once the package is built::

    python -m bistair.app.kernels FOLDER [--jobs N]

It compiles every kernel for every argument type listed in ``kernels.txt`` (beside this
module) into ``FOLDER`` (the package's ``_kernels``), where :mod:`bistair.core.jit` looks
first. The list is what the test suite's processes compile
(``BISTAIR_RECORD_KERNELS=FILE pytest``, then ``python -m bistair.app.kernels --record
FILE``); ``tests/test_kernels.py`` checks that the decodes of every codec need nothing
else. Only numpy and numba are needed: the kernel modules are loaded without their
packages' ``__init__`` (which import scipy and OpenCV), so the build environment stays
small.

Compiled code is tied to the numba version, the Python version and the CPU it was compiled
on; a kernel whose sources, numba or CPU differ is compiled on its first call as before
(and kept in numba's own cache).
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import subprocess
import sys
import time
import types
from pathlib import Path
from typing import Any

from ..core import jit

SIGNATURES = Path(__file__).resolve().with_name("kernels.txt")
PACKAGE = Path(__file__).resolve().parents[1]


def type_name(numba_type: Any) -> str:
    """The text of a kernel argument type in ``kernels.txt`` (numba's own name)."""
    return str(numba_type)


def parse_type(text: str) -> Any:
    """A numba type from its name: arrays (``readonly array(float32, 2d, C)``), scalars,
    ``none`` (an argument given as None), ``UniTuple(T x N)`` and ``Tuple(T, ...)``."""
    found, rest = _parse(text.strip())
    if rest.strip():
        raise ValueError(f"cannot read the type {text!r}")
    return found


def _parse(text: str) -> tuple[Any, str]:
    import numba
    import numpy as np

    readonly = text.startswith("readonly ")
    if readonly:
        text = text[len("readonly "):]
    for head in ("array", "UniTuple", "Tuple"):
        if text.startswith(head + "("):
            inner, rest = _group(text[len(head):])
            if head == "array":
                dtype, ndim, layout = (part.strip() for part in inner.split(","))
                return numba.types.Array(numba.from_dtype(np.dtype(dtype)), int(ndim[:-1]),
                                         layout, readonly=readonly), rest
            if head == "UniTuple":
                elem, count = inner.rsplit(" x ", 1)
                return numba.types.UniTuple(parse_type(elem), int(count)), rest
            return numba.types.Tuple([parse_type(p) for p in _split(inner)]), rest
    match = re.match(r"[a-z][a-z0-9_]*", text)
    if match is None or readonly:
        raise ValueError(f"cannot read the type {text!r}")
    if match.group(0) == "none":  # (an argument passed as None: a kernel's optional input)
        return numba.types.none, text[match.end():]
    return numba.from_dtype(np.dtype(match.group(0))), text[match.end():]


def _group(text: str) -> tuple[str, str]:
    """``(inner, rest)`` of a text starting with ``(``, up to its matching ``)``."""
    depth = 0
    for i, char in enumerate(text):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if depth == 0:
            return text[1:i], text[i + 1:]
    raise ValueError(f"unbalanced parentheses in {text!r}")


def _split(text: str) -> list[str]:
    """The comma-separated parts of ``text`` outside parentheses."""
    parts, depth, start = [], 0, 0
    for i, char in enumerate(text):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if char == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    tail = text[start:].strip()
    return [p.strip() for p in parts] + ([tail] if tail else [])


def read_signatures(path: Path = SIGNATURES) -> dict[str, list[tuple[str, ...]]]:
    """``module.function`` -> the argument type names of each signature, from a list (or
    from the lines a recording process adds: the same format)."""
    out: dict[str, list[tuple[str, ...]]] = {}
    for line in path.read_text().splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        key, _, args = line.partition(" ")
        inner, rest = _group(args.strip())
        if rest.strip():
            raise ValueError(f"cannot read the line {line!r}")
        sig = tuple(_split(inner))
        if sig not in out.setdefault(key, []):
            out[key].append(sig)
    return out


def write_signatures(found: dict[str, list[tuple[str, ...]]], path: Path = SIGNATURES) -> int:
    """Write the list, sorted, every type checked to read back; returns its length."""
    lines = sorted({f"{key} ({', '.join(sig)})" for key, sigs in found.items() for sig in sigs})
    for sigs in found.values():
        for sig in sigs:
            for name in sig:
                if type_name(parse_type(name)) != name:
                    raise ValueError(f"the type {name!r} does not read back")
    header = ("# The kernels compiled at install time and their argument types "
              "(bistair.app.kernels):\n# what the test suite's processes compiled, recorded "
              "with python -m bistair.app.kernels --record\n")
    path.write_text(header + "".join(line + "\n" for line in lines))
    return len(lines)


def with_every_stack_type(found: dict[str, list[tuple[str, ...]]]
                          ) -> dict[str, list[tuple[str, ...]]]:
    """The list, and for every kernel that takes a capture stack (a 3-d array first) the
    stack types :func:`bistair.core.jit.kernel_frames` passes: uint8, uint16 and float32,
    writeable or read-only (a ``.npy`` file is read as a read-only map)."""
    out = {key: list(sigs) for key, sigs in found.items()}
    for key, sigs in found.items():
        for sig in sigs:
            if sig and re.fullmatch(r"(readonly )?array\(\w+, 3d, C\)", sig[0]):
                for ro in ("", "readonly "):
                    for dtype in ("uint8", "uint16", "float32"):
                        new = (f"{ro}array({dtype}, 3d, C)", *sig[1:])
                        if new not in out[key]:
                            out[key].append(new)
                out[key] = [s for s in out[key] if not re.fullmatch(
                    r"(readonly )?array\((?!uint8|uint16|float32)\w+, 3d, C\)", s[0])]
    return out


def load_listed(prefixes: tuple[str, ...] = ("bistair.",)) -> tuple[int, int]:
    """Load every listed kernel (of the modules whose names start with one of ``prefixes``)
    from the caches into this process, compiling nothing (:func:`bistair.core.jit.load_cached`);
    returns (loaded, listed)."""
    loaded = listed = 0
    for key, sigs in read_signatures().items():
        module_name, _, func_name = key.rpartition(".")
        if not module_name.startswith(prefixes):
            continue
        func = getattr(importlib.import_module(module_name), func_name)
        listed += len(sigs)
        loaded += jit.load_cached(func, [tuple(parse_type(t) for t in sig) for sig in sigs])
    return loaded, listed


def load_module(name: str) -> types.ModuleType:
    """Import a kernel module without running the ``__init__`` of packages not imported yet
    (they import scipy and OpenCV, which the build environment lacks): those packages get
    a bare module that only knows its folder. For the build process only."""
    parts = name.split(".")
    for i in range(2, len(parts)):
        package = ".".join(parts[:i])
        if package not in sys.modules:
            stub = types.ModuleType(package)
            stub.__path__ = [str(PACKAGE.joinpath(*parts[1:i]))]
            sys.modules[package] = stub
    return importlib.import_module(name)


def build(folder: Path, only: set[str] | None = None) -> tuple[int, int]:
    """Compile the listed kernels (of the modules in ``only``, else all) into ``folder``;
    returns (signatures compiled, signatures that failed)."""
    import numba

    folder.mkdir(parents=True, exist_ok=True)
    jit._STATE["building"] = folder
    done = failed = 0
    for key, sigs in read_signatures().items():
        module_name, _, func_name = key.rpartition(".")
        if only is not None and module_name not in only:
            continue
        func = getattr(load_module(module_name), func_name)
        compiled = jit.dispatcher(func)
        for sig in sigs:
            try:
                compiled.compile(tuple(parse_type(t) for t in sig))
                done += 1
            except (numba.core.errors.NumbaError, ValueError) as exc:
                failed += 1
                print(f"bistair kernels: {key}{sig}: {exc}", file=sys.stderr)
    return done, failed


def _groups(jobs: int) -> list[set[str]]:
    """The kernel modules in ``jobs`` groups of about equal signature counts."""
    count: dict[str, int] = {}
    for key, sigs in read_signatures().items():
        module = key.rpartition(".")[0]
        count[module] = count.get(module, 0) + len(sigs)
    groups: list[tuple[int, set[str]]] = [(0, set()) for _ in range(jobs)]
    for module in sorted(count, key=lambda m: -count[m]):
        total, members = min(groups, key=lambda g: g[0])
        groups.remove((total, members))
        groups.append((total + count[module], members | {module}))
    return [members for _, members in groups if members]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path, nargs="?",
                        help="where to compile the kernels (the package's _kernels)")
    parser.add_argument("--record", type=Path, default=None,
                        help="write kernels.txt from the lines processes added to this file "
                             "(BISTAIR_RECORD_KERNELS=FILE pytest)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                        help="processes that compile at once (default: the cores)")
    parser.add_argument("--only", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.record is not None:
        # the package's kernels only (tests compile kernels of their own, in temporary modules)
        found = {key: sigs for key, sigs in read_signatures(args.record).items()
                 if key.startswith("bistair.")}
        count = write_signatures(with_every_stack_type(found))
        print(f"bistair: {count} kernel signatures written to {SIGNATURES}")
        return 0
    if args.folder is None:
        parser.error("name the folder to compile the kernels into")
    start = time.perf_counter()
    if args.only is not None:
        done, failed = build(args.folder, set(args.only.split(",")))
        return 1 if failed else 0
    procs = [subprocess.Popen([sys.executable, "-m", __spec__.name, str(args.folder),
                               "--only", ",".join(sorted(group))])
             for group in _groups(max(1, args.jobs))]
    codes = [p.wait() for p in procs]
    total = sum(len(s) for s in read_signatures().values())
    print(f"bistair: compiled {total} kernel signatures into {args.folder} in "
          f"{time.perf_counter() - start:.0f} s ({len(procs)} processes)"
          + ("" if not any(codes) else "; some failed: they compile on first use"))
    return 1 if any(codes) else 0


if __name__ == "__main__":
    sys.exit(main())
