"""Stair phases: levels, the cos/sin coded pair, the decoded stair phase and its quantisation.

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

from .phase import TWO_PI, wrap
from .phase_jit import arctan2_32


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


def stair_phase(cos_frame: np.ndarray, sin_frame: np.ndarray,
                avg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """NumPy reference of :func:`~bistair.core.stair_jit.pair_phase`, which a decode runs:
    the decoded stair phase in ``[-pi, pi)`` and its modulation (Eq. 19).

    ``avg`` is the average intensity of the fringe frames (Eq. 9).

    Parameters
    ----------
    cos_frame, sin_frame : ndarray
        The captured cosine and sine stair frames, shape (H, W) (any shape, any dtype), as
        fractions of full scale.
    avg : ndarray
        Average intensity ``A`` of the fringe frames, broadcastable to the frames.

    Returns
    -------
    theta : ndarray
        Float32 stair phase in radians (:func:`~bistair.core.phase_jit.arctan2_32` of the frames
        minus ``avg``).
    modulation : ndarray
        Float32 length of that (cos, sin) vector (``sqrt(c*c + s*s)`` in float32), same
        shape.

    Examples
    --------
    >>> c, s = stair_pair(stair_level_phase(np.arange(4), 4))
    >>> theta, mod = stair_phase(c, s, np.full(4, 0.5))
    >>> theta.astype(float).round(4).tolist(), mod.astype(float).round(3).tolist()
    ([-2.3562, -0.7854, 0.7854, 2.3562], [0.5, 0.5, 0.5, 0.5])
    """
    c = np.asarray(cos_frame, dtype=np.float32) - np.asarray(avg, np.float32)
    s = np.asarray(sin_frame, dtype=np.float32) - np.asarray(avg, np.float32)
    return arctan2_32(s, c), np.sqrt(c * c + s * s)


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


def level_misfit(theta: float, level: int, levels: int) -> float:
    """NumPy reference of the band evidence's compiled ``_level_misfit``, which a decode runs:
    the squared distance of a phase from a stair level, in half steps (0 on the level, 1 at
    the border of its quantisation bin).

    Parameters
    ----------
    theta : float
        Stair phase in radians.
    level : int
        Stair level index, 0 .. levels-1.
    levels : int
        Number of steps of the stair.

    Returns
    -------
    float
        ``(d / (pi/levels))**2`` with ``d`` the wrapped difference between ``theta`` and the
        level's phase (:func:`stair_level_phase`).

    Examples
    --------
    >>> level_misfit(float(stair_level_phase(2, 6)), 2, 6), round(level_misfit(0.0, 2, 6), 9)
    (0.0, 1.0)
    """
    d = (theta - stair_level_phase(level, levels) + math.pi) % TWO_PI
    return ((d - math.pi) / (math.pi / levels)) ** 2


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
