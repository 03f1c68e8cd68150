"""Checks that a decode's spec fits its captures.

:class:`Judge` runs the checks every decode runs, one method per row of the checks guide's
table (``docs/guide/checks.md``), in the order a decode meets them. Its parts, each usable
alone:

- refusing: :func:`refuse`, :func:`forcing`, :func:`sample_checks`, :func:`judge_sample`;
- the frame order: :func:`shift_order_problem`, :func:`exchange_fits`,
  :func:`rotated_frames`, :func:`swapped_frames`, :func:`fit_residual`;
- the axis: :func:`axis_rates`, :func:`axis_problem`;
- the phase convention: :func:`edge_alignment` (an :class:`EdgeCheck`),
  :func:`convention_problem`;
- the orders: :func:`wrap_steps`, :func:`jump_problem`, :func:`wilson_low`,
  :func:`edge_steps`, :func:`edge_jump_problem`, :func:`sparse_problem`;
- the result: :func:`outside_problem`;
- for the codecs' own checks: :func:`cell_steps`, :func:`direction_problem`,
  :func:`stair_misfit`, :func:`stair_sample`.

Where the code's edges fall on the phase: a code (Gray code, stair level, ...) steps at its
own edges, which sit at a known wrapped phase (0 for most methods: at the phase jumps).
Along the coded axis, pairs of neighbouring pixels whose code differs show where those edges
fall in the capture: around the expected phase when the spec is right, half a period off
when the phase convention is off by pi (``phase_offset``), with the phase rising instead of
falling across them when the shifts run the other way (``shift_sign``) or the shift frames
are in reverse order.

Examples
--------
>>> x = np.arange(300.0) + 0.5
>>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (8, 1)).astype(np.float32)
>>> code = np.tile((x // 30).astype(np.int32), (8, 1))
>>> ok = np.ones(phi.shape, bool)
>>> check = edge_alignment(phi, code, ok)
>>> check.edges, abs(round(check.crossing, 3)), check.reversed
(72, 0.0, 0.0)
>>> shifted = (phi + np.float32(np.pi)) % np.float32(2 * np.pi)   # a spec off by pi
>>> round(abs(edge_alignment(shifted, code, ok).crossing), 3)
3.142
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from ..errors import BistairError
from ..spec import BaseSpec
from .checks_jit import level_misfits, step_sums, wrap_step_counts
from .phase import TWO_PI, residuals, wrap, wrapped_phase
from .sample import Sample, sample_grid
from .stair import half_gaps

if TYPE_CHECKING:  # (measure calls judge_sample: no import at run time)
    from .measure import FringeSet

MIN_EDGES = 50  # code steps needed before the check says anything
_FORCED: ContextVar[list[str] | None] = ContextVar("bistair_forced", default=None)
_ON_SAMPLE: ContextVar[Callable[[Sample], None] | None] = ContextVar("bistair_on_sample",
                                                                     default=None)


def refuse(problem: str | None) -> None:
    """Refuse captures that a thresholded check finds not to fit the spec: raise
    ``BistairError("the captures do not fit the spec: <problem>")``, or inside
    :func:`forcing` record the problem and go on.

    Only the thresholded checks (a share of pixels, steps or windows past a limit) go
    through here; hard errors (frame count, unreadable captures, no valid pixel) always
    raise.

    Parameters
    ----------
    problem : str or None
        The check's one-line reason, or ``None`` when the check passed.

    Raises
    ------
    BistairError
        ``problem`` is not ``None`` and no :func:`forcing` is active.

    Examples
    --------
    >>> refuse(None)
    >>> refuse("half the windows are unknown")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the captures do not fit the spec: half the windows are unknown
    >>> with forcing(True) as forced:
    ...     refuse("half the windows are unknown")
    >>> forced
    ['half the windows are unknown']
    """
    if problem is None:
        return
    forced = _FORCED.get()
    if forced is None:
        raise BistairError(f"the captures do not fit the spec: {problem}")
    forced.append(problem)


@contextlib.contextmanager
def forcing(force: bool = True) -> Iterator[list[str]]:
    """Within the block, :func:`refuse` records problems instead of raising (``force``
    True); yields the list it records them in (empty when ``force`` is False).

    Parameters
    ----------
    force : bool
        Decode where a thresholded check would refuse.

    Yields
    ------
    list of str
        The problems found, in the order the checks ran.

    Examples
    --------
    >>> with forcing(False) as forced:
    ...     pass
    >>> forced
    []
    """
    forced: list[str] = []
    token = _FORCED.set(forced if force else None)
    try:
        yield forced
    finally:
        _FORCED.reset(token)


@contextlib.contextmanager
def sample_checks(judge: Callable[[Sample], None]) -> Iterator[None]:
    """Within the block, the first capture measured with a sample (pass 0 of
    :func:`bistair.core.measure.measure`, ``check=True``) is given to ``judge`` before its
    pass over every pixel: the refusals that need only the sample come before any full
    pass.

    Parameters
    ----------
    judge : callable
        Called once with the :class:`~bistair.core.sample.Sample`; it refuses through
        :func:`refuse`.

    Yields
    ------
    None

    Examples
    --------
    >>> seen = []
    >>> with sample_checks(seen.append):
    ...     judge_sample("a sample")
    ...     judge_sample("another")  # only the first
    >>> judge_sample("outside"); seen
    ['a sample']
    """
    token = _ON_SAMPLE.set(judge)
    try:
        yield
    finally:
        _ON_SAMPLE.reset(token)


def judge_sample(sample: Sample) -> None:
    """Give pass 0's sample to the checks of :func:`sample_checks`, if any are waiting
    (the first sample of the block only); called by :func:`bistair.core.measure.measure`
    between pass 0 and pass 1.

    Parameters
    ----------
    sample : Sample
        Pass 0's sample of the capture.

    Examples
    --------
    >>> judge_sample("a sample")  # no check waiting: nothing happens
    """
    judge = _ON_SAMPLE.get()
    if judge is not None:
        _ON_SAMPLE.set(None)  # (the block's own token restores what was outside it)
        judge(sample)


@dataclass(frozen=True)
class EdgeCheck:
    """Where a code's steps fall on the wrapped phase.

    Attributes
    ----------
    edges : neighbour pairs along the coded axis where the code steps.
    crossing : circular mean of the wrapped phase at those steps, relative to where the
        code's edges should sit, in ``[-pi, pi)`` (0 when the spec fits).
    spread : resultant length of those phases, in [0, 1] (1: every step at one phase).
    wraps : steps whose direction was judged.
    reversed : share of the steps where the phase falls as the code grows (0 when the
        spec fits; near 1 when the shifts run the other way).
    """

    edges: int
    crossing: float
    spread: float
    wraps: int
    reversed: float


def edge_alignment(phi: np.ndarray, edges: np.ndarray, valid: np.ndarray,
                   edge_phase: float = 0.0, levels: int | None = None) -> EdgeCheck:
    """Where the steps of the code ``edges`` (int, -1 undecided) fall on the wrapped phase
    ``phi`` along the rows (the coded axis of the column layout).

    Only steps between runs of at least two equal codes count (a code that flickers in
    noise says nothing of its edges). A code that cycles through ``levels`` values (a
    stair) steps up when it grows by less than half a cycle, modulo ``levels``.

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in ``[0, 2*pi)``.
    edges : (H, W) int array
        The code as read from its own patterns, -1 where not read.
    valid : (H, W) bool array
        Pixels whose phase counts.
    edge_phase : float
        The wrapped phase (radians) at which the code's edges should sit.
    levels : int, optional
        The code's cycle, if it has one.

    Returns
    -------
    EdgeCheck
        The number of steps judged, the circular mean of their phase relative to
        ``edge_phase`` and its spread, and the share of steps where the phase falls as the
        code grows (all zero when no step counts).

    Examples
    --------
    >>> x = np.arange(120.0) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 20) % (2 * np.pi), (4, 1)).astype(np.float32)
    >>> code = np.tile((x // 20).astype(np.int32), (4, 1))
    >>> ok = np.ones(phi.shape, bool)
    >>> check = edge_alignment(phi, code, ok)
    >>> check.edges, abs(round(check.crossing, 3)), round(check.spread, 3), check.reversed
    (20, 0.0, 1.0, 0.0)
    >>> edge_alignment(np.float32(2 * np.pi) - phi, code, ok).reversed  # shifts run backwards
    1.0
    """
    count, zc, zs, against = step_sums(phi, edges, valid, edge_phase, levels)  # one pass
    if count == 0:
        return EdgeCheck(0, 0.0, 0.0, 0, 0.0)
    z = complex(zc, zs) / count
    return EdgeCheck(count, float(wrap(np.angle(z))), float(abs(z)), count, against / count)


def convention_problem(check: EdgeCheck, phase_offset: float, shift_sign: int,
                       edge_phase: float = 0.0, code_pair: tuple[str, ...] = (),
                       half_period: str = "") -> tuple[str, str] | None:
    """What a check says of the spec's phase convention: ``None`` when it fits (or the
    evidence is too thin), else ``("refuse" | "warn", one-line message)``.

    A phase that rises across most code steps means the shifts run the other way; code
    steps more than pi/3 off their expected phase (with the steps concentrated, spread
    >= 0.5) mean the phase offset is wrong; more than 0.25 rad is worth a warning.

    Parameters
    ----------
    check : EdgeCheck
        The result of :func:`edge_alignment` (at least ``MIN_EDGES`` steps to say anything).
    phase_offset : float
        The spec's phase offset in radians (to suggest the one that fits).
    shift_sign : int
        The spec's shift direction, +1 or -1 (to suggest the other).
    edge_phase : float
        The wrapped phase (radians) at which the code's edges should sit.
    code_pair : tuple of str
        The names of a cos/sin pair of code frames, if the code has one: exchanged, they
        reverse the code as reversed shifts do, so the message names them too.
    half_period : str
        The spec fields of another reading of the same frames whose code's edges sit half a
        period from this one's (a plain Gray code's shifted twin, or the other way round),
        if there is one: with the phase offset pi from the one suggested it explains the
        captures exactly as well, so the message names both readings.

    Returns
    -------
    tuple of (str, str) or None
        ``("refuse", message)`` for reversed shifts or an offset more than pi/3 off,
        ``("warn", message)`` for an offset between 0.25 rad and pi/3 off, else ``None``.

    Examples
    --------
    >>> kind, message = convention_problem(EdgeCheck(500, 3.1, 0.9, 20, 0.1), 0.0, 1)
    >>> kind, message.split(": ")[1]
    ('refuse', 'is phase_offset pi?')
    >>> convention_problem(EdgeCheck(500, 0.02, 0.9, 400, 0.97), 0.0, 1)[0]
    'refuse'
    >>> convention_problem(EdgeCheck(500, 0.02, 0.9, 400, 0.97), 0.0, 1, 0.0,
    ...                    ("stair-cos", "stair-sin"))[1]  # doctest: +ELLIPSIS
    '... (or are the shift frames in reverse order, or stair-cos and stair-sin exchanged)?'
    >>> convention_problem(EdgeCheck(500, 0.4, 0.9, 400, 0.0), 0.0, 1)[0]
    'warn'
    >>> convention_problem(EdgeCheck(20, 3.1, 0.9, 20, 0.0), 0.0, 1) is None  # too few steps
    True
    >>> convention_problem(EdgeCheck(500, 3.14, 0.9, 20, 0.1), -np.pi, 1, 0.0, (),
    ...                    "gray_offset 0.5")[1].split(": ")[1]  # doctest: +ELLIPSIS
    'is phase_offset 0, or gray_offset 0.5 with phase_offset -pi (the captures fit both ...)?'
    """
    if check.edges < MIN_EDGES:
        return None
    if check.wraps >= MIN_EDGES and check.reversed > 0.8:
        return ("refuse", f"the phase falls where the code grows "
                f"({100 * check.reversed:.0f}% of its steps): is shift_sign {-shift_sign:+d} "
                "(or are the shift frames in reverse order"
                + (f", or {code_pair[0]} and {code_pair[1]} exchanged" if len(code_pair) == 2
                   else "") + ")?")
    if check.spread < 0.5 or abs(check.crossing) <= 0.25:
        return None
    guess = (phase_offset + check.crossing + np.pi) % TWO_PI - np.pi
    suggestion = f"is phase_offset {_offset_name(guess)}"
    if half_period:  # the same captures, read with the code half a period over
        other = guess % TWO_PI - np.pi  # guess - pi, in [-pi, pi)
        near_spec = float(wrap(np.array(other - phase_offset)))
        if abs(near_spec) < 0.25:  # next to the spec's own offset, as it writes it (-pi)
            other = phase_offset + near_spec
        suggestion += (f", or {half_period} with phase_offset {_offset_name(other)} (the "
                       "captures fit both readings alike)")
    message = (f"the code steps where the wrapped phase is "
               f"{wrap(check.crossing + edge_phase) % TWO_PI:.2f} rad, not at "
               f"{edge_phase:.2f} rad: {suggestion}?")
    return ("refuse" if abs(check.crossing) > np.pi / 3 else "warn", message)


def _offset_name(value: float) -> str:
    """A phase offset as a hint names it: a named one (pi, -pi/2, ...) where ``value`` is
    within 0.05 rad of it, beside the measured value where it is within 0.25 rad (the
    steps' crossing reads short of a large offset: kamino's -2*pi/3 read as -1.851 from 0),
    else the value."""
    named = {0.0: "0", np.pi: "pi", -np.pi: "-pi", np.pi / 2: "pi/2", -np.pi / 2: "-pi/2",
             2 * np.pi / 3: "2*pi/3", -2 * np.pi / 3: "-2*pi/3"}
    near = [(v, name) for v, name in named.items() if abs(value - v) < 0.25]
    if not near:
        return f"{value:.3f}"
    return near[0][1] if abs(value - near[0][0]) < 0.05 else f"{near[0][1]} (measured {value:.3f})"


def axis_rates(sample: Sample) -> tuple[float, float] | None:
    """How fast the wrapped phase changes along the rows and down the columns (column
    layout: the coded axis along the rows), in rad per pixel, on pass 0's sample: the median
    absolute wrapped difference between the two pixels of each column pair (along) and half
    that between the first and last row of each run of three (down), where both pixels are
    ``strong``.

    Over two rows, the phase noise weighs half as much per pixel down the columns. The
    ratio of the two (down over along, refused above 1 by :func:`axis_problem`) is at or
    below what the check judged before pass 0 (every fourth row against every second column
    of the full maps) where the spec fits, and far above 1 for a turned camera: kamino's
    axes 0.234 and 0.238 (were 0.245 and 0.293), CFPE 0.073 (0.148), the rendered scene of
    tests/test_spec_mismatch.py 0.047 (0.048); there, two shift frames swapped 0.52
    (0.75), the wrong orientation 11 (42) (``benchmarks/sample_checks.py``).

    Parameters
    ----------
    sample : Sample
        Pass 0's sample of the capture (:func:`bistair.core.sample.take_sample`).

    Returns
    -------
    (along, down) : tuple of float, or None
        ``None`` with fewer than 500 differences either way.

    Examples
    --------
    >>> from bistair.core.sample import sample_grid
    >>> rows, cols = sample_grid(256, 512)
    >>> phi = ((2 * np.pi * cols / 16) % (2 * np.pi))[None].repeat(rows.size, 0)
    >>> ok = np.ones(phi.shape, bool)
    >>> s = Sample(rows, cols, phi[None], 1.0, phi.astype(np.float32), phi, phi, ok, ok, ~ok)
    >>> [round(r, 3) for r in axis_rates(s)]
    [0.393, 0.0]
    """
    phi, ok = sample.blocks(sample.phi), sample.blocks(sample.strong)
    along = np.abs(wrap(phi[..., 1] - phi[..., 0]))[ok[..., 1] & ok[..., 0]]
    down = np.abs(wrap(phi[:, 2] - phi[:, 0]))[ok[:, 2] & ok[:, 0]]
    if min(along.size, down.size) < 500:
        return None
    return float(np.median(along)), float(np.median(down)) / 2.0


def axis_problem(sample: Sample, orientation: str, factor: float = 1.0) -> str | None:
    """A one-line reason to refuse when the wrapped phase (column layout: the coded axis
    along the rows) changes more than ``factor`` times as fast down the columns as along
    the rows (:func:`axis_rates`, per pixel, on pass 0's sample), i.e. the fringes run along
    the image's coded axis instead of across it.

    Parameters
    ----------
    sample : Sample
        Pass 0's sample of the capture, column layout.
    orientation : str
        The spec's orientation, ``"columns"`` or ``"rows"`` (for the message).
    factor : float
        How many times faster the phase must change across than along to refuse.

    Returns
    -------
    str or None
        The reason, or ``None`` when the fringes run the expected way (or too few pixels).

    Examples
    --------
    >>> from bistair.core.sample import sample_grid
    >>> rows, cols = sample_grid(256, 512)
    >>> phi = ((2 * np.pi * rows / 16) % (2 * np.pi))[:, None].repeat(cols.size, 1)
    >>> ok = np.ones(phi.shape, bool)
    >>> s = Sample(rows, cols, phi[None], 1.0, phi.astype(np.float32), phi, phi, ok, ok, ~ok)
    >>> axis_problem(s, "columns")[:34]
    'the phase changes down the image ('
    """
    rates = axis_rates(sample)
    if rates is None:
        return None
    a, c = rates
    if c <= factor * a:
        return None
    axis, other = ("x", "rows") if orientation == "columns" else ("y", "columns")
    down = "down" if orientation == "columns" else "across"
    return (f"the phase changes {down} the image ({c:.3f} rad/px) more than along its {axis} "
            f"axis ({a:.3f}), the spec's coded axis: is orientation {other}? (a turned "
            "camera's images must be turned back)")


def outside_problem(decoded: int, outside: int, length: int, other: str = "") -> str | None:
    """A one-line reason to refuse when many decoded pixels land outside the projector.

    Many means at least 100 pixels and more than 10% of all decoded ones (inside and out).

    Parameters
    ----------
    decoded : int
        Pixels decoded inside the projector.
    outside : int
        Pixels whose coordinates fall outside ``[0, length)``.
    length : int
        Projector pixels along the coded axis.
    other : str
        The other orientation, where the decoded orders fit within its projector size
        (``"columns"`` or ``"rows"``): named first.

    Returns
    -------
    str or None
        The reason, or ``None`` when few pixels land outside.

    Examples
    --------
    >>> outside_problem(900, 5000, 1080)[:40]
    'the coordinates of 85% of the decoded pi'
    >>> outside_problem(90000, 40, 1080) is None
    True
    >>> outside_problem(900, 5000, 1080, "columns").split(": ")[1][:26]
    'is orientation columns (th'
    """
    total = decoded + outside
    if outside < 100 or outside <= 0.1 * total:
        return None
    turned = (f"is orientation {other} (they fit along the projector's other axis), or "
              if other else "is ")
    return (f"the coordinates of {100 * outside / total:.0f}% of the decoded pixels fall "
            f"outside the {length}-px projector: {turned}the period (or the projector size) "
            "right? (or shift_sign: shifts that run the other way mirror the coordinates)")


def wrap_steps(phi: np.ndarray, order: np.ndarray, valid: np.ndarray,
               every: int = 2, reach: int = 3) -> tuple[int, int, int]:
    """How the fringe orders step across the clean wraps of the wrapped phase along the
    rows (every ``every``-th row).

    A clean wrap is a place where the wrapped phase wraps around and runs on smoothly
    (within 0.6 rad per pixel once unwrapped) for ``reach`` pixels on either side, without
    another wrap and with every pixel valid. Across it the order must step by exactly one
    (up when the phase falls from near 2*pi to near 0), measured between the ends of that
    window, so that a per-pixel code that switches a pixel or two early or late beside its
    edges (blur) does not count. Object edges are rarely smooth across, so almost every
    violation is a misread code; a violation by two or more orders (``big``) is a code read
    wrong in a whole block of fringes.

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in [0, 2*pi).
    order : (H, W) int array
        Fringe orders, -1 where invalid.
    valid : (H, W) bool array
        Pixels to judge.
    every : int
        Judge every ``every``-th row.
    reach : int
        Pixels on either side of a wrap that must run on smoothly.

    Returns
    -------
    (violations, big violations, places) : tuple of int
        ``places`` counts the clean wraps.

    Examples
    --------
    >>> x = np.arange(300.0) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (8, 1)).astype(np.float32)
    >>> order = np.tile((x // 30).astype(np.int32), (8, 1))
    >>> ok = np.ones(phi.shape, bool)
    >>> wrap_steps(phi, order, ok)
    (0, 0, 36)
    >>> wrap_steps(phi, order % 4, ok)  # a code that repeats every 4 fringes
    (8, 8, 36)
    >>> late = order.copy()
    >>> late[:, 30] -= 1  # the code switches one pixel late at one edge
    >>> wrap_steps(phi, late, ok)
    (0, 0, 36)
    """
    return wrap_step_counts(phi, order, valid, every, reach)


def edge_steps(phi: np.ndarray, order: np.ndarray, valid: np.ndarray,
               edge_phase: float) -> tuple[int, int, int]:
    """How the fringe orders of a code whose edges sit mid-fringe (at wrapped phase
    ``edge_phase``, not 0: a shifted Gray code's at pi) hold across those edges, where the
    phase runs on smoothly and the order must not change: :func:`wrap_steps` on the phase
    turned by ``edge_phase`` and the order plus one past it.

    The wrap check alone cannot see such a code read wrong: its misreads sit at the code's
    edges, mid-fringe, and the orders on either side of each phase jump come from the same
    code word. Judge the orders as read (before pixels beside the edges are mended).

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in [0, 2*pi).
    order : (H, W) int array
        Fringe orders as read, -1 where invalid.
    valid : (H, W) bool array
        Pixels to judge.
    edge_phase : float
        The wrapped phase (radians) at the code's edges.

    Returns
    -------
    (violations, big violations, places) : tuple of int
        As :func:`wrap_steps` counts them, at the code's edges: ``big``, orders that change
        by two or more across an edge (a code read wrong in whole blocks).

    Examples
    --------
    >>> x = np.arange(300.0) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (8, 1)).astype(np.float32)
    >>> order = np.tile((x // 30).astype(np.int32), (8, 1))
    >>> ok = np.ones(phi.shape, bool)
    >>> edge_steps(phi, order, ok, np.pi)
    (0, 0, 40)
    >>> blocks = np.where(x % 60 < 45, order, order + 2).astype(np.int32)  # misread blocks
    >>> edge_steps(phi, blocks, ok, np.pi)
    (20, 20, 40)
    """
    return wrap_step_counts(phi, order, valid, 2, 3, float(edge_phase) % TWO_PI)


def edge_jump_problem(big: int, links: int, limit: float = 0.02) -> str | None:
    """A one-line reason to refuse when a shifted code's orders change by two or more across
    more than ``limit`` of its own edges where the phase runs on smoothly
    (:func:`edge_steps`): code frames swapped or a code that does not fit the spec.

    Parameters
    ----------
    big : int
        Code edges across which the orders change by two or more.
    links : int
        Code edges judged; with fewer than 200, nothing is said.
    limit : float
        Share above which to refuse (right decodes of the rendered scenes: 0.0-0.3%).

    Returns
    -------
    str or None

    Examples
    --------
    >>> edge_jump_problem(857, 942)[:52]
    'the fringe orders jump by whole blocks across 91.0% '
    >>> edge_jump_problem(1, 942) is None, edge_jump_problem(100, 150) is None
    (True, True)
    """
    if links < 200 or big <= limit * links:
        return None
    return (f"the fringe orders jump by whole blocks across {100 * big / links:.1f}% of the "
            "code's own edges, where the phase runs on smoothly, so the code is misread in "
            "whole blocks: are code frames swapped (check the frame order), does the spec fit "
            "the captures (gray_offset, gray_wrap, period), or is there too much noise or "
            "blur for this code?")


FEW_LINKS = 50  # phase jumps below which jump_problem says nothing


def wilson_low(successes: int, trials: int, z: float = 2.576) -> float:
    """The lower end of the Wilson score interval of a share (99% by default).

    Parameters
    ----------
    successes, trials : int
        The count and the trials it is out of (``trials > 0``).
    z : float
        The normal quantile of the interval.

    Returns
    -------
    float
        The lower bound of the share.

    Examples
    --------
    >>> round(wilson_low(22, 89), 3), round(wilson_low(5, 60), 3)
    (0.15, 0.028)
    """
    p = successes / trials
    d = 1 + z * z / trials
    r = z * np.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials))
    return float((p + z * z / (2 * trials) - r) / d)


def jump_problem(violations: int, links: int, limit: float = 0.1,
                 big: int = 0, big_limit: float = 1.0) -> str | None:
    """A one-line reason to refuse when the fringe orders do not step by one across more
    than ``limit`` of the phase jumps (the code does not fit the spec's levels), or are off
    by two or more orders at more than ``big_limit`` of them.

    Parameters
    ----------
    violations : int
        Phase jumps across which the orders do not step by one (e.g. :func:`wrap_steps`).
    links : int
        Phase jumps judged. From 200 on, the share of violations is judged against
        ``limit``; from ``FEW_LINKS`` (50) to 200, only where it exceeds ``limit`` beyond
        doubt (the lower end of its 99% Wilson interval: 22 of 89, the paper decoder's orders
        on 5-px fringes, 59% of its pixels wrong, reads 0.15); fewer say nothing.
    limit : float
        Share of violations above which to refuse.
    big : int
        Violations by two or more orders.
    big_limit : float
        Share of big violations above which to refuse.

    Returns
    -------
    str or None
        The reason, or ``None`` when the orders step as they should.

    Examples
    --------
    >>> jump_problem(600, 2000)[:36]
    'the fringe orders do not step by one'
    >>> jump_problem(150, 2000) is None, jump_problem(150, 2000, limit=0.05) is None
    (True, False)
    >>> jump_problem(50, 2000, 0.05, big=50, big_limit=0.02)[:40]
    'the fringe orders jump by whole blocks a'
    """
    if links < FEW_LINKS:
        return None
    if links < 200:
        if wilson_low(violations, links) <= limit:
            return None
        return (f"the fringe orders do not step by one across {violations} of the "
                f"{links} phase jumps judged ({100 * violations / links:.0f}%), so the code is "
                "not read reliably: does the spec fit the captures, or are the fringes too "
                "narrow in the camera for this code?")
    if big > big_limit * links:
        return (f"the fringe orders jump by whole blocks at {100 * big / links:.1f}% of the "
                "phase jumps where the phase runs on smoothly, so the code is misread in "
                "whole blocks: are code frames swapped, does the spec fit the captures "
                "(frame order, period, projector size), or is there too much noise or blur "
                "for this code?")
    if violations <= limit * links:
        return None
    return (f"the fringe orders do not step by one across {100 * violations / links:.0f}% of "
            "the phase jumps, so the code is not read reliably: does the spec fit the "
            "captures (method, levels, stairs, partitions, period, frame order), or is there "
            "too much noise or blur for this code?")


def sparse_problem(decoded: int, modulated: int, coverage: float = 0.01,
                   least: int = 5000) -> str | None:
    """A one-line reason to refuse a decode that read its code on almost no pixel: some but
    fewer than ``coverage`` of the well-modulated pixels (at least ``least`` of them) given
    an order.

    A frame of another pattern in place of a code frame (``shift-0`` and ``stair-sin``
    exchanged) leaves a region decoder about 1% of its regions passing by chance, with
    orders that may even step by one between them, all wrong (0.25-0.3% of the modulated
    pixels on the README's scene). A right decode reads far more: on every real capture in
    ``../shared/data`` at least 68%, on the rendered scenes at least 4.7% (phase coding
    under 8% read noise).

    Parameters
    ----------
    decoded : int
        Pixels given an order.
    modulated : int
        Well-modulated pixels (the phase stage's valid pixels).
    coverage : float
        Share of the modulated pixels under which to refuse.
    least : int
        Fewest modulated pixels to judge.

    Returns
    -------
    str or None
        The reason, or ``None``.

    Examples
    --------
    >>> sparse_problem(852, 285128)[:33]
    'the code was read on only 0.30% o'
    >>> [sparse_problem(*n) is None for n in ((20103, 429833), (10, 4000), (0, 9000))]
    [True, True, True]
    """
    if modulated < least or decoded >= coverage * modulated or decoded == 0:
        return None  # (none decoded: an empty answer, which the command line refuses)
    return (f"the code was read on only {100 * decoded / modulated:.2f}% of the "
            "well-modulated pixels, as few as pass by chance: does the spec fit the captures "
            "(method, frame order, levels, period), or is there too much noise or blur for "
            "this code?")


def cell_steps(order: np.ndarray) -> tuple[int, int]:
    """How a per-pixel code's cells (or orders) step between neighbouring decoded pixels
    along the rows (the coded axis of the column layout): ``(against, steps)``, the steps
    against the majority direction and all steps.

    On a surface the cells grow one way along the coded axis (the other way on a mirrored
    rig); steps against it happen only at occlusions and depth edges. A code read with a bit
    inverted (a code frame exchanged with its inverse) runs backwards inside every block of
    that bit, a low bit making half the steps go against the rest.

    Parameters
    ----------
    order : (H, W) int array
        Cells or orders, -1 where not decoded.

    Returns
    -------
    (against, steps) : tuple of int

    Examples
    --------
    >>> cells = np.tile(np.arange(40) // 2, (4, 1))
    >>> cell_steps(cells)
    (0, 76)
    >>> cell_steps(cells ^ 1)  # the lowest bit read inverted
    (36, 76)
    """
    a, b = order[:, :-1], order[:, 1:]
    step = (b - a)[(a >= 0) & (b >= 0) & (a != b)]
    up = int(np.count_nonzero(step > 0))
    return min(up, step.size - up), int(step.size)


def direction_problem(against: int, steps: int, limit: float = 0.25) -> str | None:
    """A one-line reason to refuse when more than ``limit`` of a per-pixel code's steps run
    against the rest (:func:`cell_steps`): a code frame exchanged with its inverse, or bits
    in another order than the spec's.

    Parameters
    ----------
    against : int
        Steps against the majority direction.
    steps : int
        All steps; with fewer than 200, nothing is said.
    limit : float
        Share of steps against the rest above which to refuse (right decodes of the real
        captures in ../shared/data: at most 7.5%, at occlusions).

    Returns
    -------
    str or None
        The reason, or ``None``.

    Examples
    --------
    >>> direction_problem(36, 76) is None, direction_problem(360, 760)[:31]
    (True, 'the decoded cells run backwards')
    """
    if steps < 200 or against <= limit * steps:
        return None
    return (f"the decoded cells run backwards at {100 * against / steps:.0f}% of their steps "
            "along the coded axis: are code frames exchanged with their inverses, or the bits "
            "in another order than the spec's (frames, orientation)?")


def stair_misfit(theta: np.ndarray, valid: np.ndarray, levels: np.ndarray) -> float:
    """Median distance of the stair phases from the nearest level, in halves of that
    level's distance to its neighbour (0: on the levels, 1: halfway between two).

    The median is taken over at most 20000 of the valid pixels (evenly spaced): a check of
    the whole capture passes pass 0's sample (``sample.theta``, ``sample.strong``).

    Parameters
    ----------
    theta : (H, W) float array
        Decoded stair phase in radians.
    valid : (H, W) bool array
        Pixels whose stair phase counts.
    levels : (L,) float array
        The stair levels' phases in radians.

    Returns
    -------
    float
        The median misfit; 0.0 when no pixel counts.

    Examples
    --------
    >>> lv = np.array([-2.0, 0.0, 2.0])
    >>> round(stair_misfit(np.array([[0.1, 1.0, -2.0]]), np.ones((1, 3), bool), lv), 2)
    0.1
    """
    t = theta[valid]
    t = t[:: max(1, -(-t.size // 20000))].astype(np.float64)  # plenty for a median
    if t.size == 0:
        return 0.0
    levels = np.array(levels, np.float64)  # (a copy: the kernel takes writable arrays)
    return float(np.median(level_misfits(t, levels, half_gaps(levels))))  # one pass


def stair_sample(sample: Sample | None, theta: np.ndarray, valid: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The stair phases :func:`stair_misfit` judges and the pixels that count: pass 0's
    sample's (``theta``, ``strong``) where it read the pair, else the maps' on the same grid
    (:func:`~bistair.core.sample.sample_grid`), never a scan of the image for a sample.

    Parameters
    ----------
    sample : Sample or None
        Pass 0's sample of the capture (``FringeSet.sample``).
    theta : (H, W) float array
        The stair phase of every pixel.
    valid : (H, W) bool array
        The pixels whose stair phase counts.

    Returns
    -------
    theta, valid : (R, C) arrays

    Examples
    --------
    >>> theta, ok = stair_sample(None, np.zeros((40, 20)), np.ones((40, 20), bool))
    >>> theta.shape, bool(ok.all())
    ((6, 6), True)
    """
    if sample is not None and sample.theta is not None:
        return sample.theta, sample.strong
    rows, cols = sample_grid(*theta.shape)
    return theta[np.ix_(rows, cols)], valid[np.ix_(rows, cols)]


def fit_residual(samples: np.ndarray, shift_sign: int = 1) -> float:
    """Median RMS residual of the N-step sinusoid fit over its modulation, for
    ``samples`` of shape (N, pixels) (0 for N = 3, which has no redundancy).

    Parameters
    ----------
    samples : (N, pixels) array
        The N-step intensities of some pixels.
    shift_sign : int
        The direction the shifts run, +1 or -1.

    Returns
    -------
    float
        Median over the pixels of the RMS residual (``N - 3`` degrees of freedom) divided by
        the fitted modulation; 0.0 for N <= 3 or no pixels.

    Examples
    --------
    >>> d = 2 * np.pi * np.arange(4)[:, None] / 4
    >>> phi = np.linspace(0, 6, 50)[None]
    >>> round(fit_residual(0.5 + 0.3 * np.cos(phi + d)), 6)
    0.0
    """
    steps = samples.shape[0]
    if steps <= 3 or samples.shape[1] == 0:
        return 0.0
    phi, avg, mod = wrapped_phase(samples, shift_sign)
    rest = residuals(samples, phi, avg, mod, shift_sign).astype(np.float64)
    rms = np.sqrt((rest ** 2).sum(axis=0) / (steps - 3))
    return float(np.median(rms / np.maximum(mod, 1e-6)))


def exchange_fits(samples: np.ndarray, shift_sign: int = 1
                  ) -> tuple[float, float, list[tuple[int, int]]]:
    """How much better an N-step set (``samples``: (N, pixels), N >= 4) fits a sinusoid
    with two of its frames exchanged: the set's residual (:func:`fit_residual`), the best
    exchange's over it, and the exchanges that fit about as well as the best (within 10%),
    nearest pairs first.

    Parameters
    ----------
    samples : (N, pixels) array
        The N-step intensities of some pixels, in the captured frame order.
    shift_sign : int
        The direction the shifts run, +1 or -1.

    Returns
    -------
    base : float
        The set's residual over its modulation.
    ratio : float
        The best exchange's residual over ``base`` (``inf`` for N <= 3).
    pairs : list of (int, int)
        The 0-based frame pairs ``(i, j)``, ``i < j``, whose exchange fits about as well as
        the best, nearest first (with four steps an exchange and the exchange of the other
        two frames fit alike: one of them reverses the shifts).

    Examples
    --------
    >>> d = 2 * np.pi * np.arange(4)[:, None] / 4
    >>> frames = 0.5 + 0.3 * np.cos(np.linspace(0, 6, 50)[None] + d)
    >>> base, ratio, pairs = exchange_fits(frames[[0, 1, 3, 2]])
    >>> round(base, 2), ratio < 1e-6, pairs
    (1.48, True, [(0, 1), (2, 3)])
    """
    steps = samples.shape[0]
    base = fit_residual(samples, shift_sign)
    if steps <= 3:
        return base, float("inf"), []
    tried = {}
    for i in range(steps):
        for j in range(i + 1, steps):
            order = np.arange(steps)
            order[[i, j]] = order[[j, i]]
            tried[(i, j)] = fit_residual(samples[order], shift_sign)
    best = min(tried.values())
    close = sorted((pair for pair, r in tried.items() if r <= 1.1 * best + 1e-6),
                   key=lambda pair: (pair[1] - pair[0], pair))
    return base, best / max(base, 1e-9), close


def swapped_frames(samples: np.ndarray, shift_sign: int = 1, limit: float = 1 / 3,
                   least: float = 0.3) -> tuple[int, int] | None:
    """The two frames of an N-step set (``samples``: (N, pixels), N >= 4) that look swapped:
    the set fits a sinusoid badly (residual over ``least`` of the modulation) and, with
    those two exchanged, better by the factor ``limit`` (three times by default; of equally
    good exchanges, the nearest pair). ``None`` when the set fits or no exchange helps (an
    uncompensated gamma leaves a residual that no exchange removes).

    Parameters
    ----------
    samples : (N, pixels) array
        The N-step intensities of some pixels, in the captured frame order.
    shift_sign : int
        The direction the shifts run, +1 or -1.
    limit : float
        The best exchange's residual over the set's under which the frames look swapped.
    least : float
        The set's residual over which it is judged.

    Returns
    -------
    tuple of (int, int) or None
        The 0-based indices ``(i, j)``, ``i < j``, of the frames that look swapped.

    Examples
    --------
    >>> d = 2 * np.pi * np.arange(5)[:, None] / 5
    >>> frames = 0.5 + 0.3 * np.cos(np.linspace(0, 6, 50)[None] + d)
    >>> swapped_frames(frames) is None, swapped_frames(frames[[0, 2, 1, 3, 4]])
    (True, (1, 2))
    """
    if samples.shape[0] <= 3:
        return None
    base, ratio, pairs = exchange_fits(samples, shift_sign)
    if base <= least or ratio >= limit:
        return None
    # an exchange can also turn the set into the reversed sequence, which fits as well:
    # of the exchanges that fit about as well, the closest pair is the likely mistake
    return pairs[0]


ROTATED = 0.9  # a rotated reading's residual over the set's, under which to refuse
# two shift frames look swapped: the set's residual over SWAP_LEAST of its modulation and an
# exchange's under SWAPPED of it (right captures: 1.0 and over, rendered and real;
# benchmarks/check_margins.py, tests/test_frame_order.py)
SWAP_LEAST = 0.2
SWAPPED = 0.7


def rotated_frames(samples: np.ndarray, steps: int, shift_sign: int = 1,
                   limit: float = ROTATED) -> tuple[int, float]:
    """Whether a capture's frames look rotated by one against the spec: ``samples`` (F,
    pixels) are every method frame of some pixels, the first ``steps`` of them the N-step
    set. The set fits a sinusoid worse (residual over 0.2 of the modulation) than it does,
    by the factor ``limit``, read from one frame later (frames ``F-1, 0, ..., N-2``: the
    capture started a frame late, shift-0 grabbed last) or one frame earlier (frames
    ``1, ..., N``: a frame extra at the start).

    Parameters
    ----------
    samples : (F, pixels) array
        Every method frame's intensities at some pixels, in the captured order (F > N).
    steps : int
        N, the frames of the shift set at the start (4 or more).
    shift_sign : int
        The direction the shifts run, +1 or -1.
    limit : float
        The better rotated reading's residual over the set's under which they look rotated
        (right captures: CFPE 1.85 and over; renders of every codec on the robustness
        cases, 320 x 256 and 640 x 512, default and hard optics, 1.28 and over, multifreq
        under hard optics; the sequences one frame over 0.08-0.84, those over 0.69 only
        under hard optics at 640 x 512, where the 0.7 first tried missed phase coding's
        at 0.80: ``benchmarks/check_margins.py``, ``tests/test_frame_order.py``).

    Returns
    -------
    way : int
        +1: the frames look one late (the last frame is shift-0), -1: one early (the first
        frame is not shift-0), 0: neither.
    ratio : float
        The better rotated reading's residual over the set's (``inf`` when not judged).

    Examples
    --------
    >>> d = 2 * np.pi * np.arange(4)[:, None] / 4
    >>> shifts = 0.5 + 0.3 * np.cos(np.linspace(0, 6, 50)[None] + d)
    >>> code = (np.arange(50)[None] // 7 % 2).repeat(3, 0) * 0.8 + 0.1
    >>> frames = np.concatenate([shifts, code])
    >>> rotated_frames(frames, 4)[0], rotated_frames(np.roll(frames, -1, axis=0), 4)[0]
    (0, 1)
    >>> rotated_frames(np.roll(frames, 1, axis=0), 4)[0]
    -1
    """
    frames = samples.shape[0]
    if steps < 4 or frames <= steps:
        return 0, float("inf")
    base = fit_residual(samples[:steps], shift_sign)
    late = fit_residual(samples[[frames - 1, *range(steps - 1)]], shift_sign)
    early = fit_residual(samples[1:steps + 1], shift_sign)
    ratio = min(late, early) / max(base, 1e-9)
    if base <= 0.2 or ratio >= limit:
        return 0, ratio
    return (1 if late <= early else -1), ratio


def shift_order_problem(sample: Sample, spec: BaseSpec, samples: int = 20000,
                        seen: dict[str, Any] | None = None) -> str | None:
    """A one-line reason to refuse when two frames of an N-step set look swapped
    (:func:`swapped_frames`), judged on pass 0's sample: its strong
    pixels (at most ``samples`` of them, evenly spaced), every frame's raw values there.

    Every N-step set of the spec's method frames (the frames named ``...shift-n``) with four
    or more steps is checked (:func:`exchange_fits`: an exchange that
    fits under ``SWAPPED`` of the set's residual); the first, where it starts the method
    frames, also against the whole sequence one frame over
    (:func:`rotated_frames`: a capture started a frame late or early),
    named when that fits better than any exchange. With four steps an exchange and the
    exchange of the other two frames fit alike (one of them also reverses the shifts): both
    are named.
    With fewer than 500 strong pixels in the sample nothing is said.

    Parameters
    ----------
    sample : Sample
        Pass 0's sample of the captures (``FringeSet.sample``), column layout, its
        ``values`` the method's frames in method order.
    spec : BaseSpec
        The spec whose ``method_frames`` name the frames and whose ``shift_sign`` gives the
        direction of the shifts.
    samples : int, default 20000
        At most how many strong pixels to use.
    seen : dict, optional
        Given the first set's figures, where it starts the method frames: ``rotated_fit``
        (the better reading one frame over, its residual over the set's) and
        ``exchange_fit`` (the best exchange's, likewise).

    Returns
    -------
    str or None
        The reason naming the frames, or ``None`` when the frames look in order.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=240, height=256, period=30)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> shift_order_problem(measure_shifts(cols, spec).sample, spec) is None
    True
    >>> images = encode(spec)[[1, 0, 2, 3, 4, 5, 6]]  # shift-0 and shift-1 exchanged
    >>> swapped = prepare(images, spec.frame_count, spec.method)
    >>> shift_order_problem(measure_shifts(swapped, spec).sample, spec).split(":")[0]
    'frames shift-0 and shift-1 look swapped (or shift-2 and shift-3'
    >>> late = prepare(encode(spec)[[1, 2, 3, 4, 5, 6, 0]], spec.frame_count, spec.method)
    >>> shift_order_problem(measure_shifts(late, spec).sample, spec)[:40]
    'the frames look one frame late: the last'
    """
    names = spec.method_frames()
    sets: dict[str, list[int]] = {}
    for i, name in enumerate(names):
        if "shift-" in name:
            sets.setdefault(name.rsplit("shift-", 1)[0], []).append(i)
    r, c = np.nonzero(sample.strong)
    if r.size < 500:
        return None
    step = max(1, -(-r.size // samples))
    r, c = r[::step], c[::step]
    values = sample.values[:, r, c].astype(np.float64)
    for index, members in enumerate(m for m in sets.values() if len(m) >= 4):
        base, ratio, pairs = exchange_fits(values[members], spec.shift_sign)
        way, turned = 0, float("inf")
        if index == 0 and members == list(range(len(members))) and len(names) > len(members):
            # the first set at the start: also the whole sequence one frame over
            way, turned = rotated_frames(values, len(members), spec.shift_sign)
            if seen is not None:
                seen.update(rotated_fit=round(turned, 3), exchange_fit=round(ratio, 3))
        if way and turned < ratio:  # no exchange of two frames explains it as well
            return ("the frames look one frame " + ("late: the last one fits as shift-0 "
                    "(did the capture start a frame late, or a frame go missing at the "
                    "start?)" if way > 0 else "early: the phase shifts fit from the second "
                    "frame on (is there an extra frame at the start?)")
                    + "; check the frame order")
        if base > SWAP_LEAST and ratio < SWAPPED:
            a, b = (names[members[i]] for i in pairs[0])
            other = [p for p in pairs[1:] if not set(p) & set(pairs[0])]
            also = ("" if len(members) != 4 or not other else " (or {} and {}: with four "
                    "steps the two fit alike)".format(*(names[members[i]] for i in other[0])))
            return (f"frames {a} and {b} look swapped{also}: the phase shifts fit a sinusoid "
                    f"{1 / max(ratio, 1e-3):.1f} times better exchanged (check the frame "
                    "order)")
    return None


class Judged(Protocol):
    """What :class:`Judge` reads of a decode's stage 3 (the codecs' ``Orders``): the fringe
    order per pixel, its figures, and the orders as its code read them (or ``None``)."""

    order: np.ndarray
    info: dict[str, Any]
    read: np.ndarray | None


class Judge:
    """The checks every decode runs, one method per row of the checks guide's table
    (``docs/guide/checks.md``, keys ``Judge.<method>``), in the order a decode meets them:

    ======================  ========================================================
    pass 0's sample         :meth:`frames`, :meth:`axis` (the judge is called with it)
    the code (stage 2)      :meth:`convention`
    the orders (stage 3)    :meth:`blocks`, :meth:`edges`, :meth:`steps`, :meth:`sparse`
    the result              :meth:`outside`
    ======================  ========================================================

    Each refuses through :func:`refuse` (so ``--force`` records it instead); once the axis
    check has found the phase running the other way, every later refusal names that too
    (the likelier cause). The codecs' own checks (stair levels, multi-level cells, periods,
    lv windows, a Gray code alone's direction) stay in their codecs and run inside their
    stages.

    Parameters
    ----------
    spec : BaseSpec
        The spec of the axis decoded (column layout).
    aligned : bool
        The codec needs the coded axis along the image's rows: a turned axis is refused;
        for the others it is a warning.

    Attributes
    ----------
    turned : str or None
        The axis check's reason, once it has judged.
    seen : dict
        Figures the sample's checks judged (``rotated_fit``, ``exchange_fit``), for
        ``info.json``.
    warnings : list of str
        The warnings of the convention and the axis, in that order.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=240, height=256, period=30)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> judge = Judge(spec)
    >>> with sample_checks(judge):  # the frame order and the axis, on pass 0's sample
    ...     fs = measure_shifts(cols, spec)
    >>> sorted(judge.seen), judge.turned
    (['exchange_fit', 'rotated_fit'], None)
    >>> judge.sparse(fs, np.full(fs.phi.shape, -1))  # nothing read: an empty answer, let by
    61440
    >>> late = prepare(encode(spec)[[1, 2, 3, 4, 5, 6, 0]], spec.frame_count, spec.method)
    >>> with sample_checks(Judge(spec)):
    ...     fs = measure_shifts(late, spec)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the captures do not fit the spec: the frames look one frame late...
    """

    def __init__(self, spec: BaseSpec, aligned: bool = False) -> None:
        self.spec = spec
        self.aligned = aligned
        self.turned: str | None = None
        self.seen: dict[str, Any] = {}
        self._convention: list[str] = []
        self._counted = False  # the orders' steps across the wraps counted here (per pixel)

    @property
    def warnings(self) -> list[str]:
        """The convention's warnings, then the axis's (a turned camera, where not refused)."""
        return [*self._convention, *([self.turned] if self.turned else [])]

    def _refuse(self, problem: str | None) -> None:
        """Refuse for ``problem``, naming a turned axis too (the likelier cause)."""
        refuse(problem if problem is None or self.turned is None
               else f"{problem}; {self.turned}")

    def __call__(self, sample: Sample) -> None:
        """Judge pass 0's sample (:func:`sample_checks` hands it over before any full pass):
        :meth:`frames`, then :meth:`axis`."""
        self.frames(sample)
        self.axis(sample)

    # -- pass 0's sample ---------------------------------------------------------------------
    def frames(self, sample: Sample) -> None:
        """The shift frames in their order: none of a set exchanged, the sequence not one
        frame over (:func:`shift_order_problem`)."""
        refuse(shift_order_problem(sample, self.spec, seen=self.seen))

    def axis(self, sample: Sample) -> None:
        """The phase runs along the coded axis (:func:`axis_problem`): refused for an
        aligned codec, else a warning."""
        self.turned = axis_problem(sample, self.spec.orientation)
        if self.aligned:  # a per-pixel code decodes a turned camera's images: a warning
            refuse(self.turned)

    # -- the code (stage 2) ------------------------------------------------------------------
    def convention(self, fs: FringeSet, check: EdgeCheck | None, edges: np.ndarray,
                   edge_phase: float = 0.0, cycle: int | None = None) -> list[str]:
        """The code steps where the spec's phase convention puts them
        (:func:`convention_problem`: ``shift_sign``, ``phase_offset``): refused when the
        phase falls where the code grows or the steps sit over pi/3 off, a warning from
        0.25 rad. ``check``, a codec's own (multi-frequency's), else the code's ``edges``
        aligned on the wrapped phase (at ``edge_phase``, every ``cycle`` values). Returns
        the warning, if any (also kept in :attr:`warnings`)."""
        check = check or edge_alignment(fs.phi, edges, fs.valid, edge_phase, cycle)
        spec = self.spec
        pair = tuple(f for f in spec.method_frames() if f.endswith(("-cos", "-sin")))
        # a reading of the same frames with the code half a period over (a Gray code's)
        half = getattr(spec, "half_period_reading", lambda: "")()
        problem = convention_problem(check, spec.phase_offset, spec.shift_sign, edge_phase,
                                     pair, half)
        if problem is None:
            return []
        kind, message = problem
        if kind == "refuse":
            refuse(message)
            return []
        self._convention.append(message)
        return [message]

    # -- the orders (stage 3) ----------------------------------------------------------------
    def blocks(self, fs: FringeSet, orders: Judged) -> None:
        """A per-pixel decode's orders (as read) across the clean wraps
        (:func:`wrap_steps`, counted here into ``jump_violations``, ``jump_links``,
        ``block_jumps``; a region decoder counts its own): refused for whole-block jumps
        at over 2% of them, or steps not by one at over 10% (:func:`jump_problem`)."""
        if "jump_links" in orders.info:
            return
        self._counted = True
        judged = orders.order if orders.read is None else orders.read
        bad, big, links = wrap_steps(fs.phi, judged, fs.valid)
        orders.info.update(jump_violations=bad, jump_links=links, block_jumps=big)
        self._refuse(jump_problem(bad, links, big=big, big_limit=0.02))

    def edges(self, fs: FringeSet, orders: Judged, edge_phase: float) -> None:
        """A per-pixel decode of a code whose edges sit mid-fringe (``edge_phase``, a
        shifted Gray code's): its orders as read hold across those edges
        (:func:`edge_steps` into ``edge_links``, ``edge_jumps``; :func:`edge_jump_problem`,
        2%)."""
        if not (self._counted and edge_phase and getattr(self.spec, "steps", 0)):
            return
        judged = orders.order if orders.read is None else orders.read
        _, jumps, across = edge_steps(fs.phi, judged, fs.valid, edge_phase)
        orders.info.update(edge_links=across, edge_jumps=jumps)
        self._refuse(edge_jump_problem(jumps, across))

    def steps(self, orders: Judged) -> None:
        """The orders step by one across every wrap of the phase (:func:`jump_problem`:
        over 10% refused); a per-pixel decode whose orders as read miss at over 2% of 200
        or more is warned (a plain code misread beside its edges)."""
        info = orders.info
        bad, links = info.get("jump_violations", 0), info.get("jump_links", 0)
        if self._counted and links >= 200 and bad > 0.02 * links:
            where = ("the code reads pixels beside its edges one order off" if
                     orders.read is None else "the code reads pixels beside its edges "
                     "one order off (left out where their own evidence shows it)")
            info["warnings"] = [*info.get("warnings", []), (
                f"the orders as read do not step by one across {100 * bad / links:.1f}% "
                f"of the phase jumps: {where} (a code whose edges sit on the phase "
                "jumps; a complementary or shifted code, a second period or --strategy "
                "region avoid it)")]
        self._refuse(jump_problem(bad, links))

    def sparse(self, fs: FringeSet, order: np.ndarray) -> int:
        """The code read on more than a few of the modulated pixels
        (:func:`sparse_problem`: some but under 1%); returns the modulated pixels'
        count."""
        modulated = int(np.count_nonzero(fs.valid))
        self._refuse(sparse_problem(int(np.count_nonzero(order >= 0)), modulated))
        return modulated

    # -- the result --------------------------------------------------------------------------
    def outside(self, info: dict[str, Any], decoded: int, top: int) -> None:
        """The coordinates inside the projector (:func:`outside_problem`: over 10% of the
        decoded pixels, and 100, beyond the coded length); the other orientation named
        where ``top``, the highest coordinate the codes read, fits along the projector's
        other axis."""
        spec = self.spec
        other = {"columns": "rows", "rows": "columns"}.get(spec.orientation, "")
        fits = other and spec.coded_length < top <= spec.other_length
        self._refuse(outside_problem(decoded, info.get("outside_projector", 0),
                                     spec.coded_length, other if fits else ""))
