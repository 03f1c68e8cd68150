"""Stair phases: levels, the cos/sin coded pair, the decoded stair phase and its quantisation.

The decode's path: :func:`read_stairs` (the pair's phase, modulation and levels),
:func:`stair_levels` (the levels of a phase read otherwise) and :func:`relinearize_levels`
(the phase through a level table, and its levels); their compiled passes are in
:mod:`.stair_jit`. :func:`quantize` is the same quantisation in NumPy.

A stair of ``levels`` steps uses the phases ``-pi + pi/levels + 2*pi*j/levels`` (Eq. 13-14),
so level ``j`` is the centre of the bin ``[-pi + 2*pi*j/levels, -pi + 2*pi*(j+1)/levels)``.
The top level sits next to the wrap at ``+-pi``; quantisation is taken modulo ``levels`` so
a top-level pixel whose noise pushes it across the wrap still reads as the top level.

Examples
--------
>>> import numpy as np
>>> theta = stair_level_phase(np.arange(6), 6)
>>> quantize(theta, 6).tolist()
[0, 1, 2, 3, 4, 5]
>>> quantize(np.array([np.pi + 0.1, -np.pi - 0.1]), 6).tolist()   # across the wrap
[0, 5]
"""

from __future__ import annotations

import math

import numpy as np

from . import stair_jit
from .captures import Prepared
from .phase import TWO_PI, wrap


def stair_level_phase(level: np.ndarray | int, levels: int) -> np.ndarray | float:
    """Phase of stair level ``level`` (0-based) of a ``levels``-step stair (a float for an
    int level).

    Level ``j`` sits at ``-pi + pi/levels + 2*pi*j/levels`` (Eq. 13-14), the centre of its
    quantisation bin.

    Parameters
    ----------
    level : int or array of int
        Stair level index, 0 .. levels-1.
    levels : int
        Number of steps of the stair.

    Returns
    -------
    float or ndarray
        The level's phase in radians, in ``(-pi, pi)``: a Python float for an int
        ``level``, else a float64 array of ``level``'s shape.

    Examples
    --------
    >>> round(stair_level_phase(0, 4), 4)
    -2.3562
    >>> stair_level_phase(np.arange(4), 4).round(4).tolist()
    [-2.3562, -0.7854, 0.7854, 2.3562]
    """
    if isinstance(level, int | np.integer):
        return -math.pi + math.pi / levels + TWO_PI * int(level) / levels
    return -np.pi + np.pi / levels + TWO_PI * np.asarray(level, dtype=np.float64) / levels


def stair_pair(theta: np.ndarray, offset: float = 0.5, amplitude: float = 0.5) -> np.ndarray:
    """The coded pair ``a + b*cos(theta)``, ``a + b*sin(theta)`` (Eq. 15-16), shape (2, ...).

    Parameters
    ----------
    theta : ndarray
        Stair phase in radians, any shape.
    offset : float
        Pattern offset ``a`` (fraction of full scale).
    amplitude : float
        Pattern amplitude ``b`` (fraction of full scale).

    Returns
    -------
    ndarray
        Float64 array of shape ``(2, *theta.shape)``: the cosine pattern, then the sine
        pattern.

    Examples
    --------
    >>> stair_pair(np.array([0.0, np.pi / 2])).round(3).tolist()
    [[1.0, 0.5], [0.5, 1.0]]
    """
    return np.stack([offset + amplitude * np.cos(theta), offset + amplitude * np.sin(theta)])


def quantize(theta: np.ndarray | float, levels: int) -> np.ndarray | int:
    """Stair level index of the phase ``theta`` (Eq. 20), modulo ``levels``; int32 (an int
    for a float phase).

    Parameters
    ----------
    theta : float or ndarray
        Stair phase in radians (float32 arrays are quantised in float32).
    levels : int
        Number of steps of the stair.

    Returns
    -------
    int or ndarray
        Level ``floor((theta + pi) * levels / (2*pi)) mod levels``: a Python int for a float
        ``theta``, else an int32 array of its shape.

    Examples
    --------
    >>> quantize(0.1, 6)
    3
    >>> quantize(np.array([-3.0, 0.0, 3.0]), 4).tolist()
    [0, 2, 3]
    """
    if isinstance(theta, float):
        return int(math.floor(((theta + math.pi) % TWO_PI) * levels / TWO_PI)) % levels
    theta = np.asarray(theta)
    scale = (levels / TWO_PI) if theta.dtype != np.float32 else np.float32(levels / TWO_PI)
    scaled = (theta + (np.pi if theta.dtype != np.float32 else np.float32(np.pi))) * scale
    return np.floor(scaled).astype(np.int32) % np.int32(levels)


def half_gaps(levels: np.ndarray) -> np.ndarray:
    """Half the wrapped distance from each stair level to its nearest other level: how far
    a reading may stray from its level before it is nearer another (the unit of the band
    evidence's and the checks' misfits).

    Parameters
    ----------
    levels : (L,) float array
        The levels' phases in radians, any order (L >= 1; a lone level's nearest other is
        itself a full turn away).

    Returns
    -------
    (L,) float64 array
        ``0.5 * min over j != i of |wrap(levels[i] - levels[j])|``, the differences taken
        in the levels' own float type.

    Examples
    --------
    >>> half_gaps(np.array([-2.0, 0.0, 2.0])).round(3).tolist()
    [1.0, 1.0, 1.0]
    >>> half_gaps(np.array([0.0, 0.5, np.pi])).round(3).tolist()
    [0.25, 0.25, 1.321]
    """
    levels = np.asarray(levels)
    if not np.issubdtype(levels.dtype, np.floating):
        levels = levels.astype(np.float64)
    gaps = np.abs(wrap(levels[:, None] - levels[None, :])) + np.eye(levels.size) * TWO_PI
    return 0.5 * gaps.min(axis=1)


def level_readings(levels: np.ndarray, exponent: float, offset: float = 0.5,
                   amplitude: float = 0.5) -> np.ndarray:
    """Where stair levels read through a response that raises each pattern value to
    ``exponent`` (a projector's uncompensated gamma, or what is left of it).

    The pair ``(offset + amplitude*cos(theta)) ** exponent``, ``(offset + amplitude *
    sin(theta)) ** exponent``, read against the fringes' average (the mean of ``(offset +
    amplitude*cos(psi)) ** exponent`` over a period), as :func:`read_stairs` reads it. Ambient
    light, albedo and gain cancel; a linear response (``exponent`` 1) reads every level
    where the patterns put it.

    Parameters
    ----------
    levels : (L,) float array
        Level phases in radians.
    exponent : float
        The response exponent, at least 0.4 (where the readings keep the levels' order for
        any offset and amplitude that fit in [0, 1]).
    offset, amplitude : float
        The patterns' offset and amplitude (fractions of full scale).

    Returns
    -------
    (L,) float64 array
        The phase each level reads, radians in [-pi, pi].

    Examples
    --------
    >>> levels = stair_level_phase(np.arange(8), 8)
    >>> bool(np.allclose(level_readings(levels, 1.0), levels))
    True
    >>> (level_readings(levels, 2.2) - levels).round(3).tolist()  # gamma 2.2 left in
    [0.277, -0.277, -0.162, -0.078, -0.243, 0.243, 0.078, 0.162]
    """
    levels = np.asarray(levels, dtype=np.float64)
    psi = np.linspace(0.0, TWO_PI, 256, endpoint=False)
    avg = np.mean(np.maximum(offset + amplitude * np.cos(psi), 0.0) ** exponent)
    c = np.maximum(offset + amplitude * np.cos(levels), 0.0) ** exponent - avg
    s = np.maximum(offset + amplitude * np.sin(levels), 0.0) ** exponent - avg
    return np.arctan2(s, c)


def fit_level_response(theta: np.ndarray, levels: np.ndarray, offset: float = 0.5,
                       amplitude: float = 0.5) -> tuple[float, float]:
    """The response exponent (:func:`level_readings`) whose level readings lie nearest a
    sample of stair phases, and how much better they fit than the levels themselves.

    Each phase (binned in 1024 steps of the circle) counts its squared distance to the
    nearest reading, clipped at a quarter of the smallest gap between two levels (phases
    between bands, blurred or noisy, weigh no more than that); exponents 0.4 to 4 in steps
    of 10%, then of 2% around the best.

    Parameters
    ----------
    theta : (n,) float array
        Stair phases in radians (a sample of the valid pixels).
    levels : (L,) float array
        The code's level phases in radians.
    offset, amplitude : float
        The patterns' offset and amplitude.

    Returns
    -------
    exponent : float
        The best exponent (1.0 when ``theta`` is empty).
    ratio : float
        Its mean clipped squared distance over the levels' own (1.0: no better; 0.0 when
        the levels' own is already 0).

    Examples
    --------
    >>> levels = stair_level_phase(np.arange(8), 8)
    >>> rng = np.random.default_rng(0)
    >>> read = level_readings(levels, 2.2)[rng.integers(0, 8, 4000)]
    >>> exponent, ratio = fit_level_response(read + rng.normal(0, 0.05, 4000), levels)
    >>> round(exponent, 1), round(ratio, 2)
    (2.2, 0.09)
    >>> fit_level_response(levels[rng.integers(0, 8, 4000)], levels)  # read where they are
    (1.0, 1.0)
    """
    theta = np.asarray(theta, dtype=np.float64).ravel()
    levels = np.asarray(levels, dtype=np.float64)
    if theta.size == 0 or levels.size < 2:
        return 1.0, 1.0
    clip = 0.5 * float(half_gaps(levels).min())
    # the phases as a histogram of 1024 steps: each exponent is judged on the steps' centres
    bins = 1024
    step = np.floor((wrap(theta) + np.pi) * (bins / TWO_PI)).astype(np.int64)
    counts = np.bincount(np.clip(step, 0, bins - 1), minlength=bins)
    seen = np.flatnonzero(counts)
    centre, count = -np.pi + (seen + 0.5) * (TWO_PI / bins), counts[seen] / theta.size

    def cost(exponent: float) -> float:
        read = np.sort(level_readings(levels, exponent, offset, amplitude))
        i = np.searchsorted(read, centre)
        d = np.minimum(np.abs(wrap(centre - read[i % read.size])),
                       np.abs(wrap(centre - read[i - 1])))
        return float(count @ np.minimum(d, clip) ** 2)

    base = cost(1.0)
    coarse = np.exp(np.linspace(math.log(0.4), math.log(4.0), 25))  # steps of 10%
    best = float(coarse[int(np.argmin([cost(e) for e in coarse]))])
    fine = [1.0, *np.clip(best * np.exp(np.linspace(-0.1, 0.1, 11)), 0.4, 4.0)]
    costs = [cost(e) for e in fine]
    i = int(np.argmin(costs))  # ties keep 1.0 (listed first)
    return float(fine[i]), costs[i] / base if base > 0 else 0.0


def level_table(readings: np.ndarray, levels: np.ndarray, bins: int = 8192) -> np.ndarray:
    """The map that puts each level's reading on the level, piecewise linear on the circle
    between the readings, as a table: entry ``i`` is where the phases from ``-pi + 2*pi*i /
    bins`` on go (its step's centre mapped; the error at most half a step times the map's
    slope).

    Parameters
    ----------
    readings : (L,) float array
        Where the levels read (:func:`level_readings`), in the levels' circular order.
    levels : (L,) float array
        The levels' phases, radians.
    bins : int
        Table steps over the circle.

    Returns
    -------
    (bins,) float32 array
        The mapped phases, in [-pi, pi).

    Raises
    ------
    ValueError
        The readings do not keep the levels' circular order.

    Examples
    --------
    >>> levels = stair_level_phase(np.arange(6), 6)
    >>> table = level_table(level_readings(levels, 2.2), levels)
    >>> table.shape, table.dtype
    ((8192,), dtype('float32'))
    >>> level_table(levels[::-1] + 0.0, levels)
    Traceback (most recent call last):
    ...
    ValueError: the readings do not keep the levels' circular order
    """
    readings = np.asarray(readings, dtype=np.float64)
    levels = np.asarray(levels, dtype=np.float64)
    order = np.argsort(readings)
    x, y = readings[order], levels[order]
    y = y[0] + np.r_[0.0, np.cumsum((np.diff(y)) % TWO_PI)]
    if not math.isclose(y[-1] - y[0] + (levels[order[0]] - levels[order[-1]]) % TWO_PI,
                        TWO_PI, abs_tol=1e-6):
        raise ValueError("the readings do not keep the levels' circular order")
    x = np.r_[x - TWO_PI, x, x + TWO_PI]
    y = np.r_[y - TWO_PI, y, y + TWO_PI]
    grid = -np.pi + (np.arange(bins) + 0.5) * (TWO_PI / bins)
    return wrap(np.interp(grid, x, y)).astype(np.float32)


def read_stairs(prepared: Prepared, first: int, levels: int, avg: np.ndarray,
                valid: np.ndarray, pair: tuple[np.ndarray, np.ndarray] | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The stair pair's phase, modulation and level per pixel: the pair that pass 1 read
    (``pair``: :attr:`bistair.core.measure.FringeSet.stair`) or, where it read none, frames
    ``first`` (cosine) and ``first + 1`` (sine) read now, centred on ``avg``
    (:func:`bistair.core.stair_jit.pair_phase`), and its level (:func:`stair_levels`).

    Parameters
    ----------
    prepared : Prepared
        The capture stack.
    first : int
        Index of the cosine frame in ``prepared.raw``; the sine frame follows it.
    levels : int
        Number of steps of the stair.
    avg : (H, W) float32 array
        The fringes' average intensity ``A``.
    valid : (H, W) bool array
        Pixels whose level is read.
    pair : tuple of two (H, W) float32 arrays, optional
        The phase and modulation already read (then the frames are not read again).

    Returns
    -------
    theta : (H, W) float32 array
        The stair phase in radians, in ``[-pi, pi]``.
    modulation : (H, W) float32 array
        The length of the pair's vector.
    level : (H, W) int32 array
        The level of ``theta`` (as :func:`quantize`), -1 where not valid.

    Examples
    --------
    >>> from bistair.core.captures import Prepared
    >>> c, s = stair_pair(stair_level_phase(np.arange(4), 4))
    >>> raw = np.round(np.stack([c, s])[:, None] * 255).astype(np.uint8)
    >>> prepared = Prepared(raw, 255.0)
    >>> theta, mod, level = read_stairs(prepared, 0, 4, np.full((1, 4), 0.5, np.float32),
    ...                                 np.array([[True, True, True, False]]))
    >>> level.tolist(), theta.astype(float).round(2).tolist()
    ([[0, 1, 2, -1]], [[-2.36, -0.79, 0.79, 2.36]])
    """
    theta, mod = pair if pair is not None else stair_jit.pair_phase(
        prepared.raw, first, prepared.scale, avg)
    return theta, mod, stair_levels(theta, levels, valid)


def stair_levels(theta: np.ndarray, levels: int, valid: np.ndarray) -> np.ndarray:
    """The level of each pixel's stair phase, -1 where not valid: :func:`quantize` in one
    pass (:func:`bistair.core.stair_jit.quantize32`, the same levels bit for bit).

    Parameters
    ----------
    theta : (H, W) float32 array
        Stair phase in radians.
    levels : int
        Number of steps of the stair.
    valid : (H, W) bool array
        Pixels to quantise.

    Returns
    -------
    (H, W) int32 array
        Level indices, -1 where not valid.

    Examples
    --------
    >>> theta = stair_level_phase(np.arange(6), 6).astype(np.float32)[None]
    >>> stair_levels(theta, 6, theta > -2).tolist()
    [[-1, 1, 2, 3, 4, 5]]
    """
    return stair_jit.quantize32(theta, levels, valid)


def relinearize_levels(theta: np.ndarray, table: np.ndarray, levels: int, valid: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """The stair phase through a :func:`level_table` and its levels in one pass
    (:func:`bistair.core.stair_jit.relinearize32`).

    Parameters
    ----------
    theta : (H, W) float32 array
        Stair phase in radians.
    table : (bins,) float32 array
        From :func:`level_table`.
    levels : int
        Number of steps of the stair.
    valid : (H, W) bool array
        Pixels to quantise.

    Returns
    -------
    mapped : (H, W) float32 array
        The phase through the table.
    level : (H, W) int32 array
        Its level (as :func:`stair_levels`), -1 where not valid.

    Examples
    --------
    >>> levels = stair_level_phase(np.arange(6), 6)
    >>> readings = level_readings(levels, 2.2)
    >>> theta = readings.astype(np.float32)[None]
    >>> mapped, level = relinearize_levels(theta, level_table(readings, levels), 6,
    ...                                    np.ones(theta.shape, bool))
    >>> level.tolist(), bool(np.allclose(mapped, levels, atol=1e-3))
    ([[0, 1, 2, 3, 4, 5]], True)
    """
    return stair_jit.relinearize32(theta, table, levels, valid)
