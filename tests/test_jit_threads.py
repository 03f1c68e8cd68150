"""The lazy compile of a module's helpers holds when two threads meet it at once (a stereo
pair's two decodes side by side compile the same codec's kernels on a first run): the second
thread must find every helper compiled, never a plain Python function (numba then stops with
"Untyped global name", as the whole-suite run did on stale kernels)."""

from __future__ import annotations

import threading
from types import SimpleNamespace

from bistair.core import jit


def test_a_second_thread_finds_the_helpers_compiled():
    module: dict = {"prange": range, "__name__": "fake_jit"}  # a *_jit module's globals
    inside, returned = threading.Event(), threading.Event()
    seen: dict[str, bool] = {}

    def njit(**_options):
        def wrap(fn):
            inside.set()
            returned.wait(2.0)  # the second thread's turn, while the first is compiling
            return SimpleNamespace(py_func=fn)
        return wrap

    numba = SimpleNamespace(prange="numba-prange", njit=njit)
    # an @inline helper of that module (numba's dispatchers have ``py_func``)
    module["_helper"] = SimpleNamespace(_inline="always", __globals__=module)

    first = threading.Thread(target=jit._compile_helpers, args=(module, numba))
    first.start()
    assert inside.wait(10.0)

    def second() -> None:
        jit._compile_helpers(module, numba)
        seen["compiled"] = hasattr(module["_helper"], "py_func")
        seen["prange"] = module["prange"] == "numba-prange"
        returned.set()

    other = threading.Thread(target=second)
    other.start()
    first.join(10.0)
    other.join(10.0)
    assert seen == {"compiled": True, "prange": True}
