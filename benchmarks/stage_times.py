"""Where a decode's time goes: every function of ``bistair.core`` and ``bistair.codecs`` timed
while a decode runs, its own time (less the timed functions it calls) added to one of five
stages (:data:`STAGES`) by the module and name it is defined under (:data:`PATTERNS`).

The timers replace the functions' names in the modules that call them (and the stage
functions a codec holds) for the ``with`` block and put every one back afterwards; the
compiled kernels are timed as single calls (from Python), the modules of compiled code are
left as they are. A function no pattern names is counted in the orders and outputs (``unassigned``
lists those that took any time, so that the patterns follow the code when it moves).

    with instrumented() as clock:
        bistair.codecs.decode(frames, spec)
    clock.seconds  # stage -> seconds, in STAGES order
"""

from __future__ import annotations

import contextlib
import fnmatch
import sys
import time
import types
from collections.abc import Iterator
from dataclasses import fields

# (stage, patterns of "module:function"): the first pattern that matches a function decides
PATTERNS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("checks: do the captures fit the spec", (
        "bistair.core.checks*:*", "bistair.codecs.base:shift_order_problem",
        "bistair.codecs.base:check_convention", "bistair.codecs.graycode:_second_period_check",
        "bistair.codecs.bidirectional.stairs:stair_fit", "bistair.codecs.bidirectional:_misfit",
        "bistair.codecs.bidirectional.stairs:grid_sample",
        "bistair.codecs.bidirectional.stairs_jit:stair_agreement",
        "bistair.core.captures:check_*")),
    ("labelling and links: fringe regions, stair edges", (
        "bistair.core.regions*:*", "bistair.core.measure:coherent_pixels",
        "bistair.core.measure_jit:keep_coherent", "bistair.codecs.bidirectional.stairs*:*")),
    ("label space: band evidence, region orders", (
        "bistair.codecs.bidirectional.profiles*:*", "bistair.codecs.bidirectional.bands*:*",
        "bistair.codecs.bidirectional.evidence*:*", "bistair.codecs.bidirectional.paper*:*",
        "bistair.codecs.bidirectional:_region_orders",
        "bistair.codecs.bidirectional:thin_band_doubt",
        "bistair.codecs.bidirectional:level_offset", "bistair.codecs.bidirectional.response*:*",
        "bistair.core.split:*", "bistair.core.parts*:*",
        "bistair.core.resolve:resolve_regions",
        "bistair.core.resolve:jump_violations", "bistair.core.resolve:drop_contradicted",
        "bistair.core.resolve:settle", "bistair.core.resolve:unanchored",
        "bistair.core.resolve:code_evidence", "bistair.core.resolve_jit:label_*",
        "bistair.core.resolve_jit:pass_messages", "bistair.codecs.lv:window_evidence",
        "bistair.codecs.multifreq_jit:*")),
    ("front end: phase, modulation, noise, validity, codes", (
        "bistair.core.captures:*", "bistair.core.phase*:*", "bistair.core.measure*:*",
        "bistair.core.sample*:*",
        "bistair.core.stair*:*", "bistair.codecs.base:*",
        "bistair.codecs.*:measure_*", "bistair.codecs.*:code_*",
        "bistair.codecs.graycode_jit:code_bits", "bistair.codecs.graycode_alone:*")),
    ("orders and outputs (and the rest)", ("*",)),
)
FRONT, LABELS, SPACE, ORDERS, CHECKS = (PATTERNS[i][0] for i in (3, 1, 2, 4, 0))
STAGES = (FRONT, LABELS, SPACE, ORDERS, CHECKS)  # as a decode runs them (checks between)
SKIP_MODULES = ("bistair.core.jit",)  # the kernels' own machinery


def stage_of(module: str, name: str) -> str:
    """The stage a function defined as ``module.name`` counts in."""
    key = f"{module}:{name}"
    return next(stage for stage, patterns in PATTERNS
                if any(fnmatch.fnmatchcase(key, p) for p in patterns))


class Clock:
    """Own seconds per stage and per function, from a stack of the timed calls."""

    def __init__(self) -> None:
        self.seconds = {stage: 0.0 for stage in STAGES}
        self.functions: dict[str, float] = {}
        self._stack: list[tuple[str, str]] = []
        self._last = time.perf_counter()

    def _tick(self) -> None:
        now = time.perf_counter()
        if self._stack:
            stage, key = self._stack[-1]
            self.seconds[stage] += now - self._last
            self.functions[key] = self.functions.get(key, 0.0) + now - self._last
        self._last = now

    def enter(self, stage: str, key: str) -> None:
        self._tick()
        self._stack.append((stage, key))

    def leave(self) -> None:
        self._tick()
        self._stack.pop()

    @property
    def total(self) -> float:
        """The seconds of the ``with`` block: every stage's together."""
        return sum(self.seconds.values())

    def unassigned(self, share: float = 0.005) -> list[str]:
        """Functions no pattern but the last stage's names, above ``share`` of the total."""
        return sorted(key for key, s in self.functions.items()
                      if stage_of(*key.split(":")) == ORDERS
                      and not any(fnmatch.fnmatchcase(key, p) for p in _NAMED_REST)
                      and s > share * self.total)


# functions the last stage is meant for (the rest there is listed as unassigned)
_NAMED_REST = ("bistair.core.result*:*", "bistair.codecs.*:order_columns", "bistair.codecs:*",
               "bistair.core.resolve*:*", "bistair.codecs.*_jit:*", "bistair.core.memory:*",
               "bistair.codecs.base:*")


def _timed(func: types.FunctionType, clock: Clock) -> types.FunctionType:
    stage = stage_of(func.__module__, func.__name__)
    key = f"{func.__module__}:{func.__name__}"

    def timed(*args, **kwargs):
        clock.enter(stage, key)
        try:
            return func(*args, **kwargs)
        finally:
            clock.leave()

    timed.__dict__.update(func.__dict__)  # a kernel's py_func and parallel
    timed.__wrapped__ = func
    timed.stage = stage  # what makes it a timer (a kernel's wrapper has __wrapped__ too)
    timed.__name__, timed.__qualname__ = func.__name__, func.__qualname__
    return timed


def _ours(value: object) -> bool:
    module = getattr(value, "__module__", "") or ""
    return (isinstance(value, types.FunctionType) and module.startswith(("bistair.core",
                                                                         "bistair.codecs"))
            and not module.startswith(SKIP_MODULES))


@contextlib.contextmanager
def instrumented() -> Iterator[Clock]:
    """Time every function of ``bistair.core`` and ``bistair.codecs`` for the ``with``
    block (see the module's description); everything is put back on the way out."""
    from bistair.codecs import REGISTRY

    clock = Clock()
    wrappers: dict[int, types.FunctionType] = {}
    undo: list[tuple[object, str, object]] = []

    def wrap(value: types.FunctionType) -> types.FunctionType:
        if id(value) not in wrappers:
            wrappers[id(value)] = _timed(value, clock)
        return wrappers[id(value)]

    try:
        for name, module in list(sys.modules.items()):
            if not name.startswith("bistair.") or name.endswith("_jit") \
                    or name.startswith(SKIP_MODULES):
                continue  # compiled modules' names stay what their kernels were compiled with
            for attr, value in list(vars(module).items()):
                if _ours(value):
                    undo.append((module, attr, value))
                    setattr(module, attr, wrap(value))
        for codec in REGISTRY.values():
            for f in fields(codec):
                value = getattr(codec, f.name)
                if _ours(value):
                    undo.append((codec, f.name, value))
                    object.__setattr__(codec, f.name, wrap(value))
        clock.enter(ORDERS, "bistair.codecs:decode")  # what no timed function holds
        yield clock
        clock.leave()
    finally:
        for owner, attr, value in reversed(undo):
            object.__setattr__(owner, attr, value) if not isinstance(owner, types.ModuleType) \
                else setattr(owner, attr, value)


def stage_times(decode, frames, spec, options: dict, runs: int) -> tuple[dict[str, float],
                                                                            float, list[str]]:
    """The stages' seconds of the fastest of ``runs`` instrumented decodes, its total and
    the functions left unassigned (the first decode, which loads the kernels, not timed)."""
    decode(frames, spec, **options)
    best = None
    for _ in range(max(1, runs)):
        with instrumented() as clock:
            decode(frames, spec, **options)
        if best is None or clock.total < best.total:
            best = clock
    return dict(best.seconds), best.total, best.unassigned()
