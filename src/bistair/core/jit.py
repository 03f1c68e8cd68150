"""The numba decorator, thread control and the compiled helpers several passes share.

The compiled passes of a concept module ``X.py`` live beside it in ``X_jit.py``
(:mod:`.phase_jit`, :mod:`.measure_jit`, :mod:`.stair_jit`, :mod:`.regions_jit`,
:mod:`.resolve_jit`, :mod:`.checks_jit`, :mod:`.result_jit`); a pass that one codec alone
uses lives beside that codec. Every pass is plain Python over arrays, marked with
:func:`kernel` and compiled with numba on its first call (``cache=True``: once per machine,
kept in ``__pycache__``); numba itself is imported only then, so importing bistair or
starting the command line does not pay for it. Passes that loop over image rows or chunks
run them on every core (``prange``); :func:`set_threads` limits that. Each pass gives, bit
for bit, what the NumPy it replaced gives (the exceptions say so in their docstrings).

Examples
--------
>>> chunk_count(1280 * 1024)  # a flat pass over 1.3 MP runs in 64 chunks
64
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from functools import wraps
from typing import Any

import numpy as np

prange = range  # numba's prange once the first kernel compiles
_COMPILED: dict[str, Any] = {}


def kernel(parallel: bool = False) -> Callable[[Callable], Callable]:
    """Compile the decorated function with ``numba.njit`` on its first call.

    The compiled function is kept per function (module and name) and cached on disk
    (``cache=True``); the plain Python function stays available as the wrapper's
    ``py_func``. Helpers marked for inlining are compiled into the kernels when the first
    kernel of their module compiles (and ``prange`` becomes numba's there).

    Parameters
    ----------
    parallel : bool
        Compile with ``parallel=True``, so that loops over ``prange`` run on every core.

    Returns
    -------
    callable
        A decorator: it takes the kernel's Python function and returns a wrapper with the
        same name and signature (positional arguments only).

    Examples
    --------
    >>> def total(a):
    ...     return a.sum()
    >>> compiled = kernel()(total)  # nothing is compiled until the first call
    >>> compiled.__name__, compiled.py_func is total
    ('total', True)
    """

    def wrap(fn: Callable) -> Callable:
        key = f"{fn.__module__}.{fn.__qualname__}"

        @wraps(fn)
        def call(*args: Any) -> Any:
            compiled = _COMPILED.get(key)
            if compiled is None:
                numba = _numba()  # heavy: imported when the first kernel runs
                module = fn.__globals__  # the kernel's own module (a *_jit.py)
                if module.get("prange") is range:  # its first kernel: helpers compiled once
                    module["prange"] = numba.prange
                    for name, value in list(module.items()):
                        how = getattr(value, "_inline", None)
                        if how is not None:
                            module[name] = numba.njit(cache=True, inline=how)(value)
                compiled = numba.njit(cache=True, parallel=parallel, fastmath=False,
                                      error_model="numpy")(fn)
                _COMPILED[key] = compiled
            return compiled(*args)

        call.py_func = fn  # type: ignore[attr-defined]
        return call

    return wrap


def set_threads(count: int | None) -> int:
    """Use ``count`` threads in the kernels (all cores when ``None``); returns the count.

    Parameters
    ----------
    count : int or None
        Threads for the parallel kernels, capped at numba's ``NUMBA_NUM_THREADS``; ``None``
        (or 0) for every core.

    Returns
    -------
    int
        The number of threads numba now uses.

    Examples
    --------
    >>> set_threads(1)
    1
    >>> set_threads(None) >= 1  # back to every core
    True
    """
    numba = _numba()
    count = count or os.cpu_count() or 1
    numba.set_num_threads(max(1, min(int(count), numba.config.NUMBA_NUM_THREADS)))
    return numba.get_num_threads()


def _numba() -> Any:
    """Import numba, its OpenMP threads told to sleep rather than spin between loops.

    OpenMP's default (``OMP_WAIT_POLICY=active``) keeps a finished loop's threads spinning:
    on a machine whose cores other work also wants, each of a decode's few dozen parallel
    loops then waits a scheduler slice for a thread to come back (a 2-core machine with one
    busy core decoded three times slower on two threads than on one). Passive threads cost
    some microseconds a loop on an idle machine. A policy set by the user is kept; it acts
    only if the OpenMP runtime is not loaded yet.
    """
    os.environ.setdefault("OMP_WAIT_POLICY", "passive")
    import numba

    return numba


TWO_PI32 = np.float32(2.0 * math.pi)
PI32 = np.float32(math.pi)


def _numba_inline(fn: Callable) -> Callable:
    """Mark a helper that the kernels call: compiled into them with ``numba.njit``."""
    fn._inline = "always"  # type: ignore[attr-defined]
    return fn


def _numba_called(fn: Callable) -> Callable:
    """Mark a helper that the kernels call: compiled with ``numba.njit`` on its own (not
    inlined: numba's parallel loops miscompile some inlined bodies that write arrays)."""
    fn._inline = "never"  # type: ignore[attr-defined]
    return fn


@_numba_inline
def _wrapped(raw: np.float32) -> np.float32:
    """``((raw + pi) % 2pi) - pi`` in float32, as NumPy computes it, for ``|raw| < 2pi``."""
    d = raw + PI32
    if d >= TWO_PI32:
        d = d - TWO_PI32
    elif d < 0:
        d = d + TWO_PI32
    return d - PI32


def chunk_count(n: int) -> int:
    """How many chunks a flat pass over ``n`` pixels runs in: enough for the threads, each
    a few thousand pixels.

    Parameters
    ----------
    n : int
        Pixels.

    Returns
    -------
    int
        Between 1 and 64.

    Examples
    --------
    >>> chunk_count(100), chunk_count(1280 * 1024)
    (1, 64)
    """
    return max(1, min(64, n // 4096))


@_numba_inline
def _fmax(a: float, b: float) -> float:
    """``np.maximum`` of two floats (NaN from either)."""
    if a != a or b != b:
        return a if a != a else b
    return a if a >= b else b



@_numba_inline
def _fmin(a: float, b: float) -> float:
    """``np.minimum`` of two floats (NaN from either)."""
    if a != a or b != b:
        return a if a != a else b
    return a if a <= b else b
