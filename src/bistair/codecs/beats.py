"""Heterodyne beats of fringe periods, and whether they cover the coded axis as written.

People write periods such as ``1920/58`` to some digits (``33.10344828``): the beats of the
written periods then fall a hair short of the axis that the exact ones span (1919.99996 px
for 1920/64, 1920/58, 1920/53 written to 10 significant digits). :func:`check_beat` accepts
such a beat when the precision the periods state (half a unit in their last written digit,
:func:`stated_precision`) explains the shortfall (:func:`beat_reach`, worst case) and the
written beat is within half a projector pixel of the axis; a real shortfall is refused.

Whatever the beat, the decode cannot tell a pixel from one a top beat further when its
noise carries the top beat's phase across its wrap and the finer periods nearly repeat
there (1920/k periods repeat exactly every 1920 px; 30, 33.1, 36.23 nearly): the decode
leaves the coordinates with such a second reading inside the axis invalid
(:func:`wrap_shift`, :func:`ambiguous`).

Examples
--------
>>> written = (30.0, 33.10344828, 36.22641509)
>>> round(beat_tree(written)[-1][0], 5), check_beat(written, 1920)
(1919.99996, None)
"""

from __future__ import annotations

import decimal
import math

from ..errors import BistairError
from ..spec import format_period

# how far short of the axis (projector pixels) the written beat may fall: patterns with the
# periods as written repeat past the middle of the last column, no earlier
HALF_PIXEL = 0.5
# float rounding of the beats themselves, relative
ROUNDING = 1e-9


def beat(shorter: float, longer: float) -> float:
    """The beat period of two fringe periods: the period of the difference of their
    phases.

    Parameters
    ----------
    shorter, longer : float
        The two periods in projector pixels, ``shorter < longer``.

    Returns
    -------
    float
        ``shorter * longer / (longer - shorter)``.

    Examples
    --------
    >>> beat(42.0, 45.0)
    630.0
    """
    return shorter * longer / (longer - shorter)


def beat_tree(periods: tuple[float, ...]) -> list[list[float]]:
    """Levels of beat periods: level 0 the periods ascending, each next the beats of
    neighbours of the one below (:func:`beat`), ascending, up to a single period.

    Parameters
    ----------
    periods : tuple of float
        Fringe periods in projector pixels, any order, all different.

    Returns
    -------
    list of list of float
        The levels, each ascending; the last holds one period (the widest beat).

    Raises
    ------
    BistairError
        Two beats come out equal, or a beat equals a period: their phases cannot be told
        apart.

    Examples
    --------
    >>> beat_tree((48, 42, 45))
    [[42.0, 45.0, 48.0], [630.0, 720.0], [5040.0]]
    >>> beat_tree((42, 45, 50))  # the beats of 42 & 45 and 45 & 50 are 630 and 450
    [[42.0, 45.0, 50.0], [450.0, 630.0], [1575.0]]
    >>> beat_tree((40, 60, 120))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the periods (40, 60, 120) give two equal beats or a beat ...
    """
    levels = [sorted(float(p) for p in periods)]
    seen = set(levels[0])
    while len(levels[-1]) > 1:
        low = levels[-1]
        beats = sorted(beat(a, b) for a, b in zip(low[:-1], low[1:], strict=True))
        same = [t for i, t in enumerate(beats) if t in seen or t in beats[:i]]
        if same:
            shown = ", ".join(format_period(p) for p in periods)
            raise BistairError(f"the periods ({shown}) give two equal beats or a beat equal to "
                               f"a period ({same[0]:.0f} px): their phases cannot be told apart")
        seen.update(beats)
        levels.append(beats)
    return levels


def covers(period: float, length: int) -> bool:
    """Whether a period (or beat) spans ``length`` projector pixels, to within float
    rounding: the beat of ``1920/58`` and ``1920/53`` computes as 1919.99999999998.

    Parameters
    ----------
    period : float
        A period or beat in projector pixels.
    length : int
        The coded axis in projector pixels.

    Returns
    -------
    bool
        ``period >= length`` up to a relative 1e-9.

    Examples
    --------
    >>> top = beat_tree((1920 / 64, 1920 / 58, 1920 / 53))[-1][0]
    >>> top < 1920, covers(top, 1920), covers(1919.0, 1920)
    (True, True, False)
    """
    return period >= length * (1.0 - ROUNDING)


def stated_precision(period: float) -> float:
    """The precision a period's written digits state: half a unit in the last digit of its
    shortest form; 0 for a whole number (pattern generators use whole periods exactly).

    Parameters
    ----------
    period : float
        A period in projector pixels.

    Returns
    -------
    float
        The half-width, projector pixels.

    Examples
    --------
    >>> stated_precision(33.10344828), stated_precision(33.1), stated_precision(30.0)
    (5e-09, 0.05, 0.0)
    >>> stated_precision(1920 / 58)  # a fraction: all of a float's digits
    5e-15
    """
    digits = decimal.Decimal(repr(float(period)))
    if digits == digits.to_integral_value():
        return 0.0
    return 0.5 * 10.0 ** digits.normalize().as_tuple().exponent


def _top_weights(periods: tuple[float, ...]) -> tuple[list[float], list[int]]:
    """The periods ascending and the top beat's frequency as a sum of theirs: weights
    ``c`` with ``1 / top = sum(c / period)`` (a beat's frequency is its shorter period's
    less its longer one's)."""
    levels = beat_tree(periods)
    base = levels[0]
    weight = {t: [int(i == j) for j in range(len(base))] for i, t in enumerate(base)}
    for low in levels[:-1]:
        for a, b in zip(low[:-1], low[1:], strict=True):
            weight[beat(a, b)] = [x - y for x, y in zip(weight[a], weight[b], strict=True)]
    return base, weight[levels[-1][0]]


def beat_reach(periods: tuple[float, ...],
               precision: float | None = None) -> tuple[float, float]:
    """The top beat of the written periods and the widest it can be, worst case, for
    periods anywhere within their stated precision.

    Parameters
    ----------
    periods : tuple of float
        Fringe periods in projector pixels, as written.
    precision : float, optional
        One half-width for every period (projector pixels); by default each period's own
        (:func:`stated_precision`).

    Returns
    -------
    (float, float)
        The top beat of the periods as written and its upper bound (``inf`` when the
        periods' precision leaves their beat unbounded).

    Examples
    --------
    >>> top, reach = beat_reach((30.0, 33.10344828, 36.22641509))  # 33.1 +- 5e-9 ...
    >>> round(top, 5), round(reach, 5)  # the exact periods (1920/k) beat at 1920 px
    (1919.99996, 1920.00001)
    >>> [round(x) for x in beat_reach((30.0, 33.1, 36.2))]  # 33.1 +- 0.05, 36.2 +- 0.05
    [1870, 2468]
    """
    base, weights = _top_weights(periods)
    half = [stated_precision(t) if precision is None else precision for t in base]
    top = beat_tree(periods)[-1][0]
    # the smallest top frequency: each period moved the way that lowers it
    low = sum(c / (t + h) if c > 0 else c / (t - h) if h < t else -math.inf
              for c, t, h in zip(weights, base, half, strict=True) if c)
    return top, (1.0 / low if low > 0 else math.inf)


def precision_needed(periods: tuple[float, ...], length: int) -> float:
    """The one precision (projector pixels, every period) at which the periods' top beat
    can reach ``length``: 0 when their beat already covers it (to first order).

    Parameters
    ----------
    periods : tuple of float
        Fringe periods in projector pixels, as written.
    length : int
        The coded axis in projector pixels.

    Returns
    -------
    float
        The half-width, projector pixels.

    Examples
    --------
    >>> f"{precision_needed((30.0, 33.10344828, 36.22641509), 1920):.1g}"
    '3e-09'
    """
    base, weights = _top_weights(periods)
    top = beat_tree(periods)[-1][0]
    if top >= length:
        return 0.0
    slope = sum(abs(c) / t ** 2 for c, t in zip(weights, base, strict=True))
    return (1.0 / top - 1.0 / length) / slope


def _as_written(period: float) -> str:
    """A period with all its digits (``30``, ``33.10344828``)."""
    text = repr(float(period))
    return text[:-2] if text.endswith(".0") else text


def check_beat(periods: tuple[float, ...], length: int) -> None:
    """Refuse periods whose top beat falls short of the coded axis, unless their stated
    precision explains the shortfall and it is under half a projector pixel.

    Parameters
    ----------
    periods : tuple of float
        Fringe periods in projector pixels, as written.
    length : int
        The coded axis in projector pixels.

    Raises
    ------
    BistairError
        Naming the beat, the axis, the precision the periods state and the one that would
        explain the shortfall.

    Examples
    --------
    >>> check_beat((30, 33.1034, 36.2264), 1920)  # beats at 1920.28 px
    >>> check_beat((1919 / 64, 1919 / 58, 1919 / 53), 1920)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the beat of periods (29.984375, 33.08620689655172, ...
    """
    top, reach = beat_reach(periods)
    if covers(top, length) or (top >= length - HALF_PIXEL and covers(reach, length)):
        return
    shown = ", ".join(_as_written(t) for t in periods)
    stated = max(stated_precision(t) for t in periods)
    need = precision_needed(periods, length)
    repeat = " by more than half a pixel, so patterns with these periods repeat within it" \
        if top < length - HALF_PIXEL else ""
    fix = ("as these are written: write them to more digits, or as fractions such as 1920/58"
           if stated >= need else f"these are written to +-{stated:.2g} px")
    raise BistairError(
        f"the beat of periods ({shown}) is {top:.10g} px, narrower than the {length}-px coded "
        f"axis{repeat}; periods known to only +-{need:.2g} px could beat at {length} px, {fix}")


def wrap_shift(periods: tuple[float, ...]) -> tuple[float, float]:
    """How far a pixel's decoded coordinate moves when its top beat is read one period
    further (its noise carried it across the wrap): each period follows the beat it is
    unwrapped from to its own nearest whole number of fringes, as the decode does.

    Where the shift is under the axis and every step's fringe count comes out within a
    quarter fringe of whole (the decode's own tolerance), a coordinate ``c`` and
    ``c - shift`` (or ``c + shift``) both inside the axis (``[-0.5, length - 0.5)``) are
    two readings of the same captures: the decode leaves them invalid.

    Parameters
    ----------
    periods : tuple of float
        Fringe periods in projector pixels.

    Returns
    -------
    (float, float)
        The shift of the shortest period's coordinate (projector pixels) and the largest
        step's distance from a whole fringe count (fringes, at most 0.5).

    Examples
    --------
    >>> wrap_shift((42, 45, 48))  # one more 5040-px beat is 5040 px further at every level
    (5040.0, 0.0)
    >>> [round(x, 3) for x in wrap_shift((30, 33.1, 36.23))]  # beat 1953.9, shift 1920
    [1920.0, 0.125]
    >>> wrap_shift((42, 45, 50))[1]  # 1575 / 450 = 3.5 fringes: no second reading
    0.5
    """
    levels = beat_tree(periods)
    shift = {levels[-1][0]: levels[-1][0]}
    misfit = 0.0
    for low in levels[-2::-1]:
        for i, t in enumerate(low):
            j = min(i, len(low) - 2)
            fringes = shift[beat(low[j], low[j + 1])] / t
            misfit = max(misfit, abs(fringes - round(fringes)))
            shift[t] = round(fringes) * t
    return shift[levels[0][0]], misfit


def ambiguous(coord, periods: tuple[float, ...], length: int):
    """The decoded coordinates with a second reading inside the axis (:func:`wrap_shift`).

    Parameters
    ----------
    coord : numpy.ndarray
        Decoded projector coordinates (pixels).
    periods : tuple of float
        Fringe periods in projector pixels.
    length : int
        The coded axis in projector pixels.

    Returns
    -------
    numpy.ndarray or None
        Bool, where ``coord`` has a second reading; None where no coordinate can.

    Examples
    --------
    >>> import numpy as np
    >>> c = np.array([0.0, 1919.2, 1919.7])
    >>> ambiguous(c, (30, 33.1, 36.23), 1920).tolist(), ambiguous(c, (42, 45, 48), 1920)
    ([False, False, True], None)
    """
    shift, misfit = wrap_shift(periods)
    if misfit >= 0.25 or shift - 0.5 >= length:
        return None
    return (coord >= shift - 0.5) | (coord < length - 0.5 - shift)
