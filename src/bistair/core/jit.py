"""The numba decorator, the compiled kernels' cache, thread control and the compiled helpers
several passes share.

The compiled passes of a concept module ``X.py`` live beside it in ``X_jit.py``
(:mod:`.phase_jit`, :mod:`.measure_jit`, :mod:`.stair_jit`, :mod:`.regions_jit` and its
parts, :mod:`.resolve_jit`, :mod:`.parts_jit`, :mod:`.checks_jit`, :mod:`.result_jit`); a
pass that one codec alone uses lives beside that codec. Callers import the concept module,
not its twin (``tests/test_architecture.py``). Every pass is plain Python over arrays, marked with
:func:`kernel` and compiled with numba on its first call; numba itself is imported only
then, so importing bistair or starting the command line does not pay for it. Passes that
loop over image rows or chunks run them on every core (``prange``); :func:`set_threads`
limits that. Each pass gives, bit for bit, what the NumPy it replaced gives (the exceptions
say so in their docstrings).

Compiled kernels are looked up, in order, in the folder of kernels compiled when bistair was
installed (``bistair/_kernels``, made by :mod:`.prebuild`; the environment variable
``BISTAIR_KERNELS`` names another folder, or ``none``) and in numba's own cache
(``__pycache__`` beside the source, ``NUMBA_CACHE_DIR`` or the user's cache folder), where a
kernel compiled here is kept. A kernel found in neither is compiled, which takes seconds;
:func:`on_compile` lets a caller say so (core itself prints nothing).

Examples
--------
>>> chunk_count(1280 * 1024)  # a flat pass over 1.3 MP runs in 64 chunks
64
"""

from __future__ import annotations

import atexit
import hashlib
import math
import os
import sys
import threading
from collections.abc import Callable
from functools import cache, wraps
from pathlib import Path
from typing import Any

import numpy as np

prange = range  # numba's prange once the first kernel compiles
_COMPILED: dict[str, Any] = {}
PREBUILT = Path(__file__).resolve().parents[1] / "_kernels"  # made at install time
KERNELS_ENV = "BISTAIR_KERNELS"
RECORD_ENV = "BISTAIR_RECORD_KERNELS"  # a file: the signatures compiled, added at exit
_LISTENERS: list[Callable[[], None]] = []
_STATE: dict[str, Any] = {"told": False, "building": None, "cache_class": None}
# kernels running in the main thread (where signal handlers run) and a signal's exception
# that waits for them to return (:func:`interrupt`)
_SIGNALS: dict[str, Any] = {"depth": 0, "pending": None}
_MAIN = threading.main_thread().ident


def kernel(parallel: bool = False) -> Callable[[Callable], Callable]:
    """Compile the decorated function with ``numba.njit`` on its first call.

    The compiled function is kept per function (module and name) and cached on disk (see
    the module's docstring); the plain Python function stays available as the wrapper's
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
                compiled = _COMPILED[key] = _dispatcher(fn, parallel)
            main = threading.get_ident() == _MAIN
            if main:
                _SIGNALS["depth"] += 1
            try:
                return compiled(*args)
            except SystemError as exc:
                raise signalled(exc) from None
            finally:
                if main:
                    _SIGNALS["depth"] -= 1
                    pending = _SIGNALS["pending"]
                    if pending is not None and _SIGNALS["depth"] == 0:
                        _SIGNALS["pending"] = None
                        raise pending

        call.py_func = fn  # type: ignore[attr-defined]
        call.parallel = parallel  # type: ignore[attr-defined]
        return call

    return wrap


def interrupt(exc: BaseException, frame: Any = None) -> None:
    """Raise a signal handler's exception now, or, when the signal is handled inside
    numba's call back into Python from a kernel, as the kernel returns.

    A signal that arrives while a kernel runs is handled at the next Python step, which can
    be inside numba's own call back into Python as the kernel hands its arrays over
    (``_numba_unpickle``). An exception raised there does not stop the kernel's call
    cleanly: it comes out as ``SystemError: CPUDispatcher(...) returned a result with an
    exception set`` (:func:`signalled`), or, on a kernel's first call in a process, is lost
    and leaves a hole in the results. A handler that calls this instead of raising lets the
    kernel return whole, and the exception is raised as the call returns. The command line's
    handlers of SIGINT (Ctrl-C) and SIGTERM do. Anywhere else, numba compiling a kernel
    included, ``exc`` is raised at once.

    Parameters
    ----------
    exc : BaseException
        What the signal should raise (``KeyboardInterrupt()``, ``SystemExit(143)``); if
        several signals arrive during one kernel, the first one's.
    frame : frame, optional
        The frame the handler was given (where the signal is handled).

    Returns
    -------
    None
        Only inside numba's call back from a kernel in the main thread; else ``exc`` is
        raised.

    Raises
    ------
    BaseException
        ``exc``, outside numba's call back from a kernel.

    Examples
    --------
    >>> interrupt(SystemExit(143))  # no kernel runs: at once
    Traceback (most recent call last):
    ...
    SystemExit: 143
    """
    if _SIGNALS["depth"] > 0 and threading.get_ident() == _MAIN and _in_callback(frame):
        if _SIGNALS["pending"] is None:
            _SIGNALS["pending"] = exc
        return
    raise exc


def _in_callback(frame: Any) -> bool:
    """Whether ``frame`` runs inside numba's ``_numba_unpickle`` (what compiled code calls
    back into Python for)."""
    while frame is not None:
        code = frame.f_code
        if code.co_name == "_numba_unpickle" and "numba" in code.co_filename:
            return True
        frame = frame.f_back
    return False


def signalled(exc: SystemError) -> BaseException:
    """The ``KeyboardInterrupt`` or ``SystemExit`` behind a kernel's ``SystemError``, else
    the error itself.

    A signal handler that raises (Python's own for Ctrl-C, where :func:`interrupt` is not
    used) inside numba's call back into Python as a kernel hands its arrays over makes the
    kernel's call raise ``SystemError: CPUDispatcher(...) returned a result with an
    exception set``, caused (through numba's own ``SystemError``) by the handler's
    exception. Raised instead of the ``SystemError``, it stops the program as the signal
    should.

    Parameters
    ----------
    exc : SystemError
        What the kernel's call raised.

    Returns
    -------
    BaseException
        The signal's exception that caused ``exc``, or ``exc``.

    Examples
    --------
    >>> try:
    ...     try:
    ...         raise SystemError("_numba_unpickle ...") from KeyboardInterrupt()
    ...     except SystemError as inner:
    ...         raise SystemError("CPUDispatcher(...) ...") from inner
    ... except SystemError as exc:
    ...     signalled(exc)
    KeyboardInterrupt()
    >>> signalled(SystemError("another"))
    SystemError('another')
    """
    seen: BaseException | None = exc
    while isinstance(seen, SystemError):
        seen = seen.__cause__ if seen.__cause__ is not None else seen.__context__
    return seen if isinstance(seen, KeyboardInterrupt | SystemExit) else exc


def dispatcher(func: Callable) -> Any:
    """The numba dispatcher of a :func:`kernel` (made, not compiled, if it has not run yet).

    Parameters
    ----------
    func : callable
        A function decorated with :func:`kernel`.

    Returns
    -------
    numba.core.registry.CPUDispatcher
        Its dispatcher: ``signatures`` lists what it has compiled or loaded in this process,
        ``compile(signature)`` compiles (or loads) one.

    Examples
    --------
    >>> from bistair.core.phase_jit import arctan2_flat
    >>> type(dispatcher(arctan2_flat)).__name__
    'CPUDispatcher'
    """
    fn = func.py_func
    key = f"{fn.__module__}.{fn.__qualname__}"
    if key not in _COMPILED:
        _COMPILED[key] = _dispatcher(fn, func.parallel)
    return _COMPILED[key]


def compiled_kernels() -> dict[str, list[tuple]]:
    """The kernels compiled or loaded in this process and their signatures (numba types).

    Returns
    -------
    dict
        ``module.function`` -> list of argument type tuples.

    Examples
    --------
    >>> isinstance(compiled_kernels(), dict)
    True
    """
    return {key: list(d.signatures) for key, d in sorted(_COMPILED.items())}


def load_cached(func: Callable, signatures: list[tuple]) -> int:
    """Load the compiled code of a :func:`kernel` for ``signatures`` (tuples of numba types)
    from the caches, without compiling what is not there and without running anything;
    returns how many were loaded.

    A process that starts others by ``fork`` (the local cluster of ``bistair batch``) loads
    the kernels once, before, and its children start with them.

    Parameters
    ----------
    func : callable
        A function decorated with :func:`kernel`.
    signatures : list of tuple
        Argument types, as ``dispatcher(func).signatures`` lists them.

    Returns
    -------
    int
        The signatures now loaded (found in a cache or loaded before).

    Examples
    --------
    >>> from bistair.core.phase_jit import arctan2_flat
    >>> load_cached(arctan2_flat, []) == 0
    True
    """
    compiled = dispatcher(func)
    loaded = 0
    for sig in signatures:
        sig = tuple(sig)
        if sig in compiled.overloads:
            loaded += 1
            continue
        _STATE["quiet"] = True
        try:
            cres = compiled._cache.load_overload(sig, compiled.targetctx)
        finally:
            _STATE["quiet"] = False
        if cres is None:
            continue
        compiled.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
        compiled.add_overload(cres)
        loaded += 1
    return loaded


def on_compile(callback: Callable[[], None]) -> None:
    """Call ``callback()`` once, when the first kernel of this process is compiled rather
    than loaded from a cache (seconds per kernel: the caller may want to say why it waits).

    Parameters
    ----------
    callback : callable
        Called without arguments, at most once per process (not if a kernel has already
        been compiled; a callback given twice is called once).

    Returns
    -------
    None

    Examples
    --------
    >>> on_compile(lambda: None)
    """
    if not _STATE["told"] and callback not in _LISTENERS:
        _LISTENERS.append(callback)


def prebuilt_folder() -> Path | None:
    """The folder of kernels compiled at install time that this process reads: the
    environment variable ``BISTAIR_KERNELS`` (``none`` for no folder), else the package's
    ``_kernels``.

    Returns
    -------
    pathlib.Path or None
        The folder (it may not exist: then nothing is found there).

    Examples
    --------
    >>> prebuilt_folder() is None or prebuilt_folder().name != ""
    True
    """
    value = os.environ.get(KERNELS_ENV)
    if value is None or value == "":
        return PREBUILT
    return None if value.lower() == "none" else Path(value)


def _compiling() -> None:
    """A kernel is about to be compiled: tell the listeners, once per process."""
    if _STATE["told"] or _STATE["building"] is not None or _STATE.get("quiet"):
        return
    _STATE["told"] = True
    listeners = list(_LISTENERS)
    _LISTENERS.clear()
    for callback in listeners:
        callback()


def _dispatcher(fn: Callable, parallel: bool) -> Any:
    """The numba dispatcher of kernel ``fn`` with its cache (see the module docstring)."""
    numba = _numba()
    if os.environ.get(RECORD_ENV) and not _STATE.get("recording"):
        _STATE["recording"] = True
        atexit.register(_record, os.environ[RECORD_ENV])
    _compile_helpers(fn.__globals__, numba)  # the kernel's own module (a *_jit.py)
    # nogil: two threads may run kernels at once (:func:`side_by_side`)
    compiled = numba.njit(cache=False, parallel=parallel, fastmath=False,
                          error_model="numpy", nogil=True)(fn)
    try:
        compiled._cache = _cache_class()(fn)
    except (RuntimeError, OSError):  # numba finds no folder to keep compiled code in
        pass  # compiled in every process, as numba's cache=True would refuse to
    return compiled


#: Held while a module's helpers are made numba's: two threads (a stereo pair's decodes side
#: by side) may meet a module's first kernels at once, and the second must not compile its
#: kernel while the helpers are still plain Python ("Untyped global name").
_HELPERS_LOCK = threading.RLock()


def _compile_helpers(module: dict[str, Any], numba: Any) -> None:
    """On a module's first kernel: its helpers (marked with :func:`inline` or
    :func:`called`) compiled, once, then its ``prange`` made numba's (the mark that the
    module is done); a helper imported from another module is compiled after that module's
    own helpers, which it may call. A second thread waits until the first is done."""
    with _HELPERS_LOCK:
        if module.get("prange") is not range:
            return
        for name, value in list(module.items()):
            how = getattr(value, "_inline", None)
            if how is not None and not hasattr(value, "py_func"):  # (not compiled already)
                if value.__globals__ is not module:
                    _compile_helpers(value.__globals__, numba)
                module[name] = numba.njit(cache=True, inline=how)(value)
        module["prange"] = numba.prange


def _record(path: str) -> None:
    """Add this process's kernel signatures to ``path``, one line each (for
    :mod:`bistair.app.kernels`, which lists what is compiled at install time)."""
    lines = "".join(f"{key} ({', '.join(str(t) for t in sig)})\n"
                    for key, sigs in compiled_kernels().items() for sig in sigs)
    with open(path, "a") as fh:
        fh.write(lines)


def _source_stamp(fn: Callable) -> str:
    """A hash of the kernel's source file and of the files of the compiled helpers its
    module takes from other modules (compiled into it): a kernel compiled from other
    sources is never loaded."""
    return _module_stamp(fn.__module__)


@cache
def _module_stamp(name: str) -> str:
    """:func:`_source_stamp` of every kernel of module ``name`` (the same files for all of
    them: hashed once a process)."""
    module = sys.modules[name]
    files = {Path(module.__file__), Path(__file__)}  # this file: the compile options
    for value in vars(module).values():
        origin = getattr(getattr(value, "py_func", value), "__module__", None)
        if getattr(value, "_inline", None) is not None or (
                origin and origin.startswith("bistair.") and hasattr(value, "py_func")):
            files.add(Path(sys.modules[origin].__file__))
    digest = hashlib.sha256()
    for path in sorted(files):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _cache_class() -> type:
    """numba's ``FunctionCache`` that looks in the prebuilt folder first (made once: numba
    is imported on first use)."""
    if _STATE["cache_class"] is not None:
        return _STATE["cache_class"]
    from numba.core.caching import FunctionCache, IndexDataCacheFile

    class KernelCache(FunctionCache):
        """Loads from the prebuilt folder, then numba's own cache; saves to numba's own
        (or, while :mod:`.prebuild` runs, to the folder it builds)."""

        def __init__(self, py_func: Callable) -> None:
            super().__init__(py_func)
            folder = _STATE["building"] or prebuilt_folder()
            name = f"{py_func.__module__}.{py_func.__qualname__}.py{sys.version_info[0]}" \
                   f"{sys.version_info[1]}"
            self._prebuilt = (None if folder is None else
                              IndexDataCacheFile(str(folder), name, _source_stamp(py_func)))

        def _index_key(self, sig: Any, codegen: Any) -> Any:
            # numba's key names the source and types, not the compile options (this
            # file's): with the stamp, code compiled with other options is never loaded
            return (super()._index_key(sig, codegen), _source_stamp(self._py_func))

        def _load_overload(self, sig: Any, target_context: Any) -> Any:
            if not self._enabled:
                return None
            key = self._index_key(sig, target_context.codegen())
            # while the prebuilt folder is made, only what is in it counts
            stores = (self._prebuilt,) if _STATE["building"] is not None else (
                self._prebuilt, self._cache_file)
            for store in stores:
                data = None if store is None else store.load(key)
                if data is not None:
                    return self._impl.rebuild(target_context, data)
            _compiling()
            return None

        def _save_overload(self, sig: Any, data: Any) -> None:
            if not self._enabled or not self._impl.check_cachable(data):
                return
            key = self._index_key(sig, data.codegen)
            if _STATE["building"] is not None:
                self._prebuilt.save(key, self._impl.reduce(data))
                return
            try:
                self._impl.locator.ensure_cache_path()
                self._cache_file.save(key, self._impl.reduce(data))
            except OSError:  # a cache folder that went away or is read-only: not kept
                return

    _STATE["cache_class"] = KernelCache
    return KernelCache


def kernel_frames(raw: np.ndarray, start: int = 0, count: int | None = None
                  ) -> tuple[np.ndarray, int]:
    """A capture stack as the compiled passes take it: ``(stack, start)``, the stack itself
    if it is uint8, uint16 or float32 and C-contiguous, else frames ``start .. start+count-1``
    as float32 (and start 0).

    The passes turn every value into float32 before anything else, so the values are the
    same; they are compiled for these three types only (each type of stack is a kernel
    compiled and kept of its own).

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, any numeric dtype.
    start : int
        The first frame the pass reads.
    count : int, optional
        How many frames from ``start`` it reads (all the rest if not given).

    Returns
    -------
    stack : (F', H, W) array
        The stack to pass.
    start : int
        The first frame's index in it.

    Examples
    --------
    >>> raw = np.zeros((4, 2, 3), np.int32)
    >>> stack, start = kernel_frames(raw, 2, 2)
    >>> stack.shape, stack.dtype.name, start
    ((2, 2, 3), 'float32', 0)
    >>> kernel_frames(raw.astype(np.uint8), 2)[1]
    2
    """
    if raw.dtype in _RAW_TYPES and raw.flags.c_contiguous:
        return raw, int(start)
    stop = raw.shape[0] if count is None else int(start) + int(count)
    return np.ascontiguousarray(raw[int(start):stop], dtype=np.float32), 0


_RAW_TYPES = (np.dtype(np.uint8), np.dtype(np.uint16), np.dtype(np.float32))


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


def thread_count() -> int:
    """The threads the kernels called from this thread use (numba keeps the count per
    thread: a new thread starts with every core, whatever :func:`set_threads` said in the
    thread that started it; give it the count with :func:`set_threads`).

    Returns
    -------
    int

    Examples
    --------
    >>> set_threads(1), thread_count()
    (1, 1)
    >>> set_threads(None) == thread_count()
    True
    """
    return int(_numba().get_num_threads())


def threading_layer() -> str:
    """numba's threading layer (``omp``, ``tbb`` or ``workqueue``), or ``not started`` before
    the first parallel kernel of the process has run.

    Returns
    -------
    str

    Examples
    --------
    >>> threading_layer() in ("omp", "tbb", "workqueue", "not started")
    True
    """
    try:
        return str(_numba().threading_layer())
    except ValueError:  # no parallel kernel has run yet
        return "not started"


def side_by_side(first: Callable[[], Any], second: Callable[[], Any]) -> tuple[Any, Any]:
    """``(first(), second())``, run at once on two threads that share this thread's kernel
    threads (half each) where numba's threading layer allows kernels from two threads at
    a time (OpenMP or TBB) and there are two threads to share, else one after the other.

    The kernels release the GIL, so two decodes run side by side: on two cores, about 0.7
    the time of one after the other (each decode's serial NumPy stretches overlap the
    other's kernels).

    Parameters
    ----------
    first, second : callable
        Functions of no argument; ``first`` runs in this thread.

    Returns
    -------
    tuple
        What each returned.

    Raises
    ------
    BaseException
        What either raised (``first``'s if both did), once both have ended.

    Examples
    --------
    >>> side_by_side(lambda: 1, lambda: 2)
    (1, 2)
    """
    numba = _numba()
    total = numba.get_num_threads()  # (starts the threading layer)
    if total < 2 or numba.threading_layer() not in ("omp", "tbb"):
        return first(), second()
    results: list[Any] = [None, None]
    errors: list[BaseException | None] = [None, None]

    def run(i: int, func: Callable[[], Any], threads: int) -> None:
        numba.set_num_threads(threads)  # (per thread)
        try:
            results[i] = func()
        except BaseException as exc:  # raised in the calling thread below
            errors[i] = exc

    other = threading.Thread(target=run, args=(1, second, total // 2), daemon=True)
    other.start()
    try:
        run(0, first, total - total // 2)
    finally:
        numba.set_num_threads(total)
        other.join()
    for exc in errors:
        if exc is not None:
            raise exc
    return results[0], results[1]


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


def inline(fn: Callable) -> Callable:
    """Mark a helper that the kernels call: compiled into them with ``numba.njit``.

    Parameters
    ----------
    fn : callable
        A plain function of numbers or arrays, in a ``*_jit.py`` module.

    Returns
    -------
    callable
        ``fn`` itself, marked: the first kernel of a module that holds it (or imports it)
        compiles it, inlined (``inline="always"``).

    Examples
    --------
    >>> @inline
    ... def twice(x):
    ...     return 2 * x
    >>> twice(3), twice._inline
    (6, 'always')
    """
    fn._inline = "always"  # type: ignore[attr-defined]
    return fn


def called(fn: Callable) -> Callable:
    """Mark a helper that the kernels call: compiled with ``numba.njit`` on its own (not
    inlined: numba's parallel loops miscompile some inlined bodies that write arrays).

    Parameters
    ----------
    fn : callable
        A plain function of numbers or arrays, in a ``*_jit.py`` module.

    Returns
    -------
    callable
        ``fn`` itself, marked (``inline="never"``).

    Examples
    --------
    >>> @called
    ... def fill(out, value):
    ...     out[:] = value
    >>> fill._inline
    'never'
    """
    fn._inline = "never"  # type: ignore[attr-defined]
    return fn


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


@inline
def fmax(a: float, b: float) -> float:
    """``np.maximum`` of two floats (NaN from either), for the kernels.

    Parameters
    ----------
    a, b : float
        Two numbers.

    Returns
    -------
    float
        The larger; NaN where either is NaN.

    Examples
    --------
    >>> fmax(1.0, 2.0), fmax(float("nan"), 2.0)
    (2.0, nan)
    """
    if a != a or b != b:
        return a if a != a else b
    return a if a >= b else b


@inline
def fmin(a: float, b: float) -> float:
    """``np.minimum`` of two floats (NaN from either), for the kernels.

    Parameters
    ----------
    a, b : float
        Two numbers.

    Returns
    -------
    float
        The smaller; NaN where either is NaN.

    Examples
    --------
    >>> fmin(1.0, 2.0), fmin(1.0, float("nan"))
    (1.0, nan)
    """
    if a != a or b != b:
        return a if a != a else b
    return a if a <= b else b
