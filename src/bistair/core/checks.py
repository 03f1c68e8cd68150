"""Checks that a decode's spec fits its captures: where the code's edges fall on the phase.

A code (Gray code, stair level, ...) steps at its own edges, which sit at a known wrapped
phase (0 for most methods: at the phase jumps). Along the coded axis, pairs of neighbouring
pixels whose code differs show where those edges fall in the capture: around the expected
phase when the spec is right, half a period off when the phase convention is off by pi
(``phase_offset``), with the phase rising instead of falling across them when the shifts run
the other way (``shift_sign``) or the shift frames are in reverse order.

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

from dataclasses import dataclass

import numpy as np

from .phase import TWO_PI, wrap

MIN_EDGES = 50  # code steps needed before the check says anything


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
    phi : wrapped phase in ``[0, 2*pi)``.
    edges : the code as read from its own patterns, -1 where not read.
    valid : pixels whose phase counts.
    edge_phase : the wrapped phase at which the code's edges should sit.
    levels : the code's cycle, if it has one.

    Returns
    -------
    EdgeCheck
    """
    e = np.where(valid, edges, -1)
    a0, a, b, b1 = e[:, :-3], e[:, 1:-2], e[:, 2:-1], e[:, 3:]
    ok = (a >= 0) & (b >= 0) & (a != b) & (a0 == a) & (b1 == b)
    pa, pb = phi[:, 1:-2][ok].astype(np.float64), phi[:, 2:-1][ok].astype(np.float64)
    if pa.size == 0:
        return EdgeCheck(0, 0.0, 0.0, 0, 0.0)
    mid = np.angle(np.exp(1j * pa) + np.exp(1j * pb))  # the phase between the two pixels
    z = np.exp(1j * (mid - edge_phase)).mean()
    step = (b - a)[ok].astype(np.int64)
    if levels:
        step = np.where(step % levels < levels / 2, 1, -1)
    rise = wrap(pb - pa)
    against = np.sign(step) != np.sign(rise)  # the phase falls where the code grows
    return EdgeCheck(int(pa.size), float(wrap(np.angle(z))), float(np.abs(z)), int(pa.size),
                     float(against.mean()))


def convention_problem(check: EdgeCheck, phase_offset: float, shift_sign: int,
                       edge_phase: float = 0.0) -> tuple[str, str] | None:
    """What a check says of the spec's phase convention: ``None`` when it fits (or the
    evidence is too thin), else ``("refuse" | "warn", one-line message)``.

    A phase that rises across most code steps means the shifts run the other way; code
    steps more than pi/3 off their expected phase (with the steps concentrated, spread
    >= 0.5) mean the phase offset is wrong; more than 0.25 rad is worth a warning.

    >>> kind, message = convention_problem(EdgeCheck(500, 3.1, 0.9, 20, 0.1), 0.0, 1)
    >>> kind, message.split(": ")[1]
    ('refuse', 'is phase_offset pi?')
    >>> convention_problem(EdgeCheck(500, 0.02, 0.9, 400, 0.97), 0.0, 1)[0]
    'refuse'
    """
    if check.edges < MIN_EDGES:
        return None
    if check.wraps >= MIN_EDGES and check.reversed > 0.8:
        return ("refuse", f"the phase falls where the code grows "
                f"({100 * check.reversed:.0f}% of its steps): is shift_sign {-shift_sign:+d} "
                "(or are the shift frames in reverse order)?")
    if check.spread < 0.5 or abs(check.crossing) <= 0.25:
        return None
    guess = (phase_offset + check.crossing + np.pi) % TWO_PI - np.pi
    named = {0.0: "0", np.pi: "pi", -np.pi: "-pi", np.pi / 2: "pi/2", -np.pi / 2: "-pi/2",
             2 * np.pi / 3: "2*pi/3", -2 * np.pi / 3: "-2*pi/3"}
    near = [(value, name) for value, name in named.items() if abs(guess - value) < 0.2]
    suggestion = near[0][1] if near else f"{guess:.3f}"
    message = (f"the code steps where the wrapped phase is "
               f"{wrap(check.crossing + edge_phase) % TWO_PI:.2f} rad, not at "
               f"{edge_phase:.2f} rad: is phase_offset {suggestion}?")
    return ("refuse" if abs(check.crossing) > np.pi / 3 else "warn", message)


def axis_problem(phi: np.ndarray, valid: np.ndarray, orientation: str) -> str | None:
    """A one-line reason to refuse when the wrapped phase (column layout: the coded axis
    along the rows) changes more down the columns than along the rows, i.e. the fringes run
    along the image's coded axis instead of across it.

    >>> x = np.arange(128.0)
    >>> phi = np.tile((2 * np.pi * x / 16) % (2 * np.pi), (64, 1)).astype(np.float32)
    >>> ok = np.ones(phi.shape, bool)
    >>> axis_problem(phi, ok, "columns") is None, axis_problem(phi.T, ok.T, "columns")[:34]
    (True, 'the phase changes down the image (')
    """
    sub = (slice(None, None, 4), slice(None, None, 2))
    p, v = phi[sub], valid[sub]
    along = np.abs(wrap(np.diff(p, axis=1)))[v[:, 1:] & v[:, :-1]]
    across = np.abs(wrap(np.diff(p, axis=0)))[v[1:] & v[:-1]]
    if min(along.size, across.size) < 500:
        return None
    a, c = float(np.median(along)), float(np.median(across))
    if c <= a:
        return None
    axis, other = ("x", "rows") if orientation == "columns" else ("y", "columns")
    down = "down" if orientation == "columns" else "across"
    return (f"the phase changes {down} the image ({c:.3f} rad/px) more than along its {axis} "
            f"axis ({a:.3f}), the spec's coded axis: is orientation {other}? (a turned "
            "camera's images must be turned back)")


def outside_problem(decoded: int, outside: int, length: int) -> str | None:
    """A one-line reason to refuse when many decoded pixels land outside the projector.

    >>> outside_problem(900, 5000, 1080)[:40]
    'the coordinates of 85% of the decoded pi'
    >>> outside_problem(90000, 40, 1080) is None
    True
    """
    total = decoded + outside
    if outside < 100 or outside <= 0.1 * total:
        return None
    return (f"the coordinates of {100 * outside / total:.0f}% of the decoded pixels fall "
            f"outside the {length}-px projector: is the period (or the projector size) right?")


def jump_problem(violations: int, links: int) -> str | None:
    """A one-line reason to refuse when the fringe orders do not step by one across many
    phase jumps (the code does not fit the spec's levels).

    >>> jump_problem(600, 2000)[:36]
    'the fringe orders do not step by one'
    """
    if links < 200 or violations <= 0.1 * links:
        return None
    return (f"the fringe orders do not step by one across {100 * violations / links:.0f}% of "
            "the phase jumps, so the code is not read reliably: does the spec fit the "
            "captures (method, levels, stairs, partitions, period, frame order)?")


def stair_misfit(theta: np.ndarray, valid: np.ndarray, levels: np.ndarray) -> float:
    """Median distance of the stair phases from the nearest level, in halves of that
    level's distance to its neighbour (0: on the levels, 1: halfway between two).

    >>> lv = np.array([-2.0, 0.0, 2.0])
    >>> round(stair_misfit(np.array([[0.1, 1.0, -2.0]]), np.ones((1, 3), bool), lv), 2)
    0.1
    """
    t = theta[::4, ::4][valid[::4, ::4]][:20000].astype(np.float64)  # plenty for a median
    if t.size == 0:
        return 0.0
    gap = (np.abs(wrap(levels[:, None] - levels[None, :])) + np.eye(levels.size) * 9).min(axis=1)
    d = np.abs(wrap(t[:, None] - levels[None, :]))
    nearest = d.argmin(axis=1)
    return float(np.median(d[np.arange(t.size), nearest] / (0.5 * gap[nearest])))
