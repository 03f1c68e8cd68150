"""The engine behind ``bistair batch`` and ``bistair simulate --count``: many independent
tasks on Dask, each reading its own files and writing its own outputs.

A local cluster of worker processes (one thread each: a decode is NumPy, one set at a time
per worker keeps the memory of a worker at one set's) or an existing cluster reached through
its scheduler's address. Tasks are plain functions of paths and small parameters that return
a small summary (a dictionary); no image array passes through the scheduler, so the workers
of a remote cluster must see the same files under the same (absolute) paths.

Temporaries: every output a task writes goes through a temporary named with the run's
prefix (:func:`run_prefix`, ``.bistair-batch-<run id>-``) beside it, so the temporaries of
workers killed mid-write (Ctrl-C, a lost worker) are recognised and deleted
(:func:`remove_run_temporaries`) when the next run starts and when this one ends.

Examples
--------
>>> import operator
>>> with dask_client(workers=1) as client:
...     run_tasks(client, operator.add, [(1, 2), (3, 4)], lambda i, exc: None)
[3, 7]
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import os
import signal
import sys
import threading
import uuid
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

import dask
from distributed import Client, LocalCluster, as_completed

from ..core.jit import set_threads
from ..core.memory import keep_freed_memory
from ..errors import BistairError
from ..io.atomic import TEMP_PREFIX, remove_temporaries

BATCH_PREFIX = TEMP_PREFIX + "batch-"  # the temporaries of every batch run
CONNECT_TIMEOUT = 20  # seconds to reach a scheduler
# Dask starts its worker processes with MALLOC_TRIM_THRESHOLD_=65536, which turns off
# glibc's growing mmap threshold: every large NumPy temporary is then a fresh mmap with its
# pages faulted in, some 15% more time for a decode. Unset for the local cluster's workers;
# each task then keeps freed memory for the next (bistair.core.memory).
WORKER_CONFIG = {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}
WORKER_TIMEOUT = 60  # seconds to wait for a scheduler's first worker


def in_threads(threads: int | None, func: Callable[..., Any], *args: Any) -> Any:
    """``func(*args)`` with the compiled kernels on ``threads`` threads (numba's setting is
    per thread, so it is made in the task's own thread); ``None`` leaves them as they are.

    >>> in_threads(1, max, 3, 4)
    4
    """
    if threads is not None:
        set_threads(threads)
    keep_freed_memory()  # a worker decodes scan after scan: its freed arrays serve the next
    return func(*args)


def task_threads(client: Client) -> int | None:
    """Threads per task on a local cluster: the cores shared out among its workers, so that
    workers whose kernels would each run on every core do not fight over them (Dask sets
    the BLAS and OpenMP pools to one thread already). ``None`` on a remote cluster, whose
    machines are unknown here."""
    if not isinstance(getattr(client, "cluster", None), LocalCluster):
        return None
    return max(1, (os.cpu_count() or 1) // max(1, len(client.nthreads())))


def default_workers() -> int:
    """The cores this process may use (the default number of local workers)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def check_workers(workers: int | None, scheduler: str | None) -> None:
    """Refuse a worker count that is not a positive whole number, or one given with a
    scheduler (whose cluster has its own workers).

    Raises
    ------
    BistairError
        One line naming the problem.

    Examples
    --------
    >>> check_workers(2, None)
    >>> check_workers(0, None)
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: --workers must be 1 or more, got 0
    """
    if workers is not None and scheduler is not None:
        raise BistairError("--workers starts a local cluster; with --scheduler the cluster's "
                           "own workers run the tasks")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise BistairError(f"--workers must be 1 or more, got {workers!r}")
    if scheduler is not None and not str(scheduler).strip():
        raise BistairError("--scheduler is empty: give the address, e.g. tcp://HOST:8786")


@contextlib.contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None,
                tasks: int | None = None) -> Iterator[Client]:
    """A Dask client: on a new local cluster of ``workers`` processes with one thread each
    (default :func:`default_workers`, at most ``tasks``), or on the cluster whose scheduler
    listens at ``scheduler`` (``tcp://HOST:PORT``). The local cluster is closed, and its
    worker processes ended, when the block is left (also on Ctrl-C or an error).

    Raises
    ------
    BistairError
        A bad worker count, a scheduler that cannot be reached or has no workers.
    """
    check_workers(workers, scheduler)
    # A Ctrl-C that lands inside distributed's sync() can make its cancel callback fail
    # (NameError on 'future', distributed 2024-2025) and tornado logs that traceback;
    # the interrupt itself is reported in one line, so the event loop's log stays quiet.
    quiet = logging.getLogger("tornado.application")
    level = quiet.level
    quiet.setLevel(logging.CRITICAL)
    try:
        yield from _client(workers, scheduler, tasks)
    finally:
        quiet.setLevel(level)


def _client(workers: int | None, scheduler: str | None, tasks: int | None
            ) -> Iterator[Client]:
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT, set_as_default=False)
        except (OSError, TimeoutError, ValueError) as exc:
            reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise BistairError(f"cannot reach the Dask scheduler at {scheduler}: "
                               f"{reason}") from None
        try:
            try:
                client.wait_for_workers(1, timeout=WORKER_TIMEOUT)
            except TimeoutError:
                raise BistairError(f"the Dask scheduler at {scheduler} has no workers "
                                   f"(none joined in {WORKER_TIMEOUT} s)") from None
            yield client
        finally:
            client.close()
        return
    count = workers or default_workers()
    if tasks is not None:
        count = max(1, min(count, tasks))
    # The worker processes start with Ctrl-C ignored (an ignored signal stays ignored in a
    # new process): a Ctrl-C on the terminal reaches the whole process group, and only this
    # process should answer it, by closing the cluster, rather than every worker dying with
    # a traceback of its own.
    handler = signal.signal(signal.SIGINT, signal.SIG_IGN) if _main_thread() else None
    try:
        # the dashboard on a free port: None still serves it on 8787, with a three-line
        # warning on the user's terminal whenever another cluster holds that port. The
        # cluster's own logs are kept off the terminal up to CRITICAL: a worker whose
        # heartbeat meets the scheduler closing at the end of a run logs an ERROR with a
        # 30-line traceback (seen once in a dozen runs) although nothing failed; a task's
        # error reaches this process as the task's result, and a lost worker as an error.
        with dask.config.set({**WORKER_CONFIG,
                              "distributed.worker.multiprocessing-method": start_method()}):
            cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True,
                                   dashboard_address=":0", silence_logs=logging.CRITICAL)
    finally:
        if handler is not None:
            signal.signal(signal.SIGINT, handler)
    try:
        client = Client(cluster, set_as_default=False)
        try:
            yield client
        finally:
            client.close()
    except (KeyboardInterrupt, SystemExit):  # Ctrl-C or SIGTERM: stop now
        # A worker asked to close finishes its task first (up to 4 s, the nanny's timeout,
        # before it is killed): the tasks are cancelled and what a worker was writing is a
        # temporary its caller deletes, so the worker processes (the multiprocessing
        # children of this process) are killed; the cluster then closes in 0.2-0.5 s, not
        # 0.9-1.6 s (measured: bistair batch of 8 sets, 2 workers, on 2 busy cores).
        for child in multiprocessing.active_children():
            child.kill()
        raise
    finally:
        cluster.close()


def start_method() -> str:
    """How the local cluster starts its worker processes: ``fork`` where it is safe (Linux,
    and numba's OpenMP threads not started in this process: forked after that, a worker
    would abort), else ``spawn``.

    A forked worker starts with this process's modules imported and its compiled kernels
    loaded, in some 0.1 s; a spawned one imports bistair, numba, OpenCV and SciPy and loads
    the kernels again (seconds, on every worker), which a batch of fast decodes would pay
    as a large share of its time.

    >>> start_method() in ("fork", "spawn")
    True
    """
    if not sys.platform.startswith("linux"):
        return "spawn"
    parallel = sys.modules.get("numba.np.ufunc.parallel")
    if parallel is not None and getattr(parallel, "_is_initialized", True):
        return "spawn"
    return "fork"


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def run_tasks(client: Client, func: Callable[..., Any], tasks: Sequence[tuple],
              failed: Callable[[int, str], Any],
              done: Callable[[int, Any], None] | None = None) -> list[Any]:
    """Run ``func(*args)`` for every ``args`` in ``tasks`` on the client's workers; returns
    the results in the order of ``tasks``.

    ``func`` must be importable by the workers (a module-level function of bistair) and
    should catch its own errors; a task that raises anyway or whose worker dies gives
    ``failed(index, one-line message)`` as its result. ``done(index, result)`` is called in
    the order the tasks finish (for progress). On any exception here (Ctrl-C) the tasks
    not yet finished are cancelled before it propagates.
    """
    threads = task_threads(client)
    futures = [client.submit(in_threads, threads, func, *args, pure=False) for args in tasks]
    where = {future.key: i for i, future in enumerate(futures)}
    results: list[Any] = [None] * len(futures)
    try:
        for future in as_completed(futures, loop=client.loop):
            i = where[future.key]
            try:
                value = future.result()
            except Exception as exc:  # a bug in the task, a worker lost: record, go on
                value = failed(i, one_line(exc))
            results[i] = value
            if done is not None:
                done(i, value)
    except BaseException:
        with contextlib.suppress(Exception):
            client.cancel(futures, force=True)
        raise
    return results


def one_line(exc: BaseException) -> str:
    """An exception as one line: its message's first line, else its type's name.

    Examples
    --------
    >>> one_line(ValueError("bad value\\nmore"))
    'bad value'
    >>> one_line(MemoryError())
    'not enough memory (MemoryError)'
    """
    if isinstance(exc, MemoryError):
        return "not enough memory (MemoryError)"
    text = str(exc).strip()
    name = type(exc).__name__
    if name == "KilledWorker":
        return "its worker died while running it (out of memory or killed?)"
    return text.splitlines()[0] if text else name


def run_prefix() -> str:
    """The temporaries' prefix of a new run: ``.bistair-batch-<12 hex digits>-``."""
    return f"{BATCH_PREFIX}{uuid.uuid4().hex[:12]}-"


def remove_run_temporaries(folders: Iterable[str | Path], prefix: str = BATCH_PREFIX
                           ) -> list[Path]:
    """Delete the temporaries named ``prefix*`` directly in each of ``folders`` (default:
    those of every batch run); returns what was deleted."""
    removed: list[Path] = []
    for folder in dict.fromkeys(Path(f) for f in folders):
        removed += remove_temporaries(folder, prefix)
    return removed
