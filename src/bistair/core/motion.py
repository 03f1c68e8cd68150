"""A stream whose phase shift advances one step per frame, and binomial self-compensation.

Frame ``i`` of a stream shows shift ``i mod N`` of one N-step set:
``A + B*cos(phi + phase_offset + shift_sign*2*pi*(i mod N)/N)`` (the spec's conventions
describe the stream's first frame). Every ``N`` consecutive frames form a set, the window
starting at frame ``s``; its wrapped phase is the N-step phase of its frames, corrected by
its own shift offset ``shift_sign*2*pi*s/N`` (computed here at once, each frame weighted
with its own shift), and describes the time ``s + (N-1)/2``.

Motion between the frames of a window leaves an error ``~ sin(2*phi + ...)``: a ripple at
twice the fringe frequency, whose sign alternates from one window to the next (for N = 4:
the window one frame later sees the ripple turned by ``4*pi/N = pi``). Binomial
self-compensation (Zhang et al., *Binomial Self-compensation for Motion Error in Dynamic 3D
Scanning*, ECCV 2024) averages the phases of ``K + 1`` consecutive windows with the binomial
weights ``C(K, k) / 2**K``, which cancel that alternating error up to order ``K``, without
estimating the motion: pairwise means of neighbours (each across the wrap), ``K`` times
over. The result for windows ``s .. s+K`` uses frames ``s .. s+N+K-1`` and describes the
time ``s + (N+K-1)/2``: a lag of ``(N+K-1)/2`` frames behind the newest frame.

:func:`window_phases` and :func:`compensate` are the batch form; :class:`PhaseStream`
takes one frame at a time and reuses the sums of the frames already seen (each frame adds
its difference to the frame ``N`` before it, of the same shift), equal to the batch form to
float tolerance.

Examples
--------
>>> import numpy as np
>>> x = np.linspace(0, 90, 7)[None, :]
>>> frames = [0.5 + 0.4 * np.cos(2 * np.pi * (x + 0.3 * i) / 30 + np.pi * i / 2)
...           for i in range(8)]  # 4 steps, moving 0.3 projector px per frame
>>> phi, mod = window_phases(np.stack(frames), 4)
>>> phi.shape, round(float(mod.mean()), 3)
((5, 1, 7), 0.4)
>>> comp = compensate(phi, 4)
>>> truth = 2 * np.pi * (x + 0.3 * 3.5) / 30 % (2 * np.pi)  # the time of frame 3.5
>>> plain = float(abs(wrap(phi[2] - truth)).max())  # the window of the same time
>>> compensated = float(abs(wrap(comp[0] - truth)).max())
>>> round(plain, 3), compensated < plain / 10
(0.028, True)
"""

from __future__ import annotations

from math import comb

import numpy as np

from ..errors import BistairError
from .motion_jit import StreamState, stream_state, stream_update
from .phase import TWO_PI, phase_of_sums, wrap


def binomial_weights(order: int) -> np.ndarray:
    """The weights ``C(K, k) / 2**K``, ``k = 0..K``, of ``K + 1`` consecutive windows.

    Parameters
    ----------
    order : int
        ``K``, 0 or more.

    Returns
    -------
    ndarray
        Float64, shape (K + 1,), summing to 1.

    Examples
    --------
    >>> binomial_weights(4).tolist()
    [0.0625, 0.25, 0.375, 0.25, 0.0625]
    """
    _check_order(order)
    return np.array([comb(order, k) for k in range(order + 1)], float) / 2.0**order


def stream_shifts(count: int, steps: int, shift_sign: int = 1, first: int = 0) -> np.ndarray:
    """The shift (radians, without the phase offset) of frames ``first .. first+count-1``
    of a stream: ``shift_sign*2*pi*(i mod N)/N``.

    Parameters
    ----------
    count, steps : int
        How many frames, and ``N``.
    shift_sign : int
        +1 or -1: the direction the shifts run.
    first : int
        The index of the first frame.

    Returns
    -------
    ndarray
        Float64, shape (count,), radians.

    Examples
    --------
    >>> (stream_shifts(6, 4) / (np.pi / 2)).round(6).tolist()
    [0.0, 1.0, 2.0, 3.0, 0.0, 1.0]
    """
    return shift_sign * TWO_PI * (np.arange(first, first + count) % steps) / steps


def window_phases(frames: np.ndarray, steps: int, shift_sign: int = 1,
                  phase_offset: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The wrapped phase and modulation of every window of a stream (batch form).

    Parameters
    ----------
    frames : (F, H, W) array
        The stream from its first frame (frame ``i`` shows shift ``i mod steps``).
    steps : int
        ``N`` (3 or more); ``F >= N``.
    shift_sign, phase_offset : int, float
        The stream's conventions (of its first frame, see :mod:`bistair.core.phase`).

    Returns
    -------
    phi : (F - N + 1, H, W) float32
        Window ``s``'s wrapped phase in ``[0, 2*pi)``, its shift offset removed.
    mod : (F - N + 1, H, W) float32
        Its modulation ``B``.

    Examples
    --------
    >>> x = np.arange(8.0)[None, :]
    >>> still = np.stack([0.5 + 0.5 * np.cos(2 * np.pi * x / 8 + np.pi * i / 2)
    ...                   for i in range(6)])
    >>> phi, mod = window_phases(still, 4)
    >>> bool(np.allclose(phi, 2 * np.pi * x / 8, atol=1e-5)), phi.shape
    (True, (3, 1, 8))
    """
    stack = np.asarray(frames)
    _check_stream(stack, steps)
    count = stack.shape[0] - steps + 1
    shifts = stream_shifts(stack.shape[0], steps, shift_sign)
    sin, cos = np.sin(shifts), np.cos(shifts)
    phi = np.empty((count, *stack.shape[1:]), np.float32)
    mod = np.empty_like(phi)
    for s in range(count):
        window = stack[s:s + steps].astype(np.float64)
        num = -np.tensordot(sin[s:s + steps], window, axes=1)
        den = np.tensordot(cos[s:s + steps], window, axes=1)
        phi[s], mod[s] = phase_of_sums(num.astype(np.float32), den.astype(np.float32), steps,
                                       phase_offset)
    return phi, mod


def pair_mean(a: np.ndarray, b: np.ndarray, reduce: bool = True) -> np.ndarray:
    """The mean of two wrapped phases across the wrap: ``a + wrap(b - a) / 2`` in
    ``[0, 2*pi)`` (float32; NaN where either is).

    Parameters
    ----------
    a, b : ndarray
        Wrapped phases in radians, of one shape (any multiple of ``2*pi`` off).
    reduce : bool
        Bring the mean into ``[0, 2*pi)`` (else it lies within ``pi/2`` of ``a``).

    Returns
    -------
    ndarray
        Float32 phase halfway from ``a`` to ``b`` the short way round.

    Examples
    --------
    >>> pair_mean(np.float32([6.2, 1.0]), np.float32([0.1, 2.0])).astype(float).round(4).tolist()
    [0.0084, 1.5]
    """
    a = np.asarray(a, np.float32)
    mean = a + np.asarray(wrap(np.asarray(b, np.float32) - a), np.float32) / np.float32(2)
    return np.mod(mean, np.float32(TWO_PI)).astype(np.float32) if reduce else mean


def compensate(phases: np.ndarray, order: int) -> np.ndarray:
    """Binomial self-compensation of order ``K``: window ``s``'s result is the phases of
    windows ``s .. s+K`` averaged with the weights :func:`binomial_weights`, pairwise
    across the wrap (``K`` rounds of :func:`pair_mean` of neighbours).

    Parameters
    ----------
    phases : (windows, H, W) array
        Consecutive windows' wrapped phases (:func:`window_phases`), ``W > K``.
    order : int
        ``K`` (0: the phases themselves).

    Returns
    -------
    (windows - K, H, W) float32
        The compensated phases in ``[0, 2*pi)``; the result for windows ``s .. s+K``
        describes the time ``s + (N+K-1)/2``.

    Raises
    ------
    BistairError
        Fewer than ``K + 1`` windows, or an order that is not a whole number of 0 or more.

    Examples
    --------
    >>> p = np.float32([[0.1], [6.2], [0.3]])
    >>> compensate(p, 2).astype(float).round(4).tolist()  # (0.1 + 2 * (6.2 - 2 pi) + 0.3) / 4
    [[0.0584]]
    """
    _check_order(order)
    level = np.asarray(phases, np.float32)
    if level.shape[0] <= order:
        raise BistairError(f"order {order} needs {order + 1} windows, got {level.shape[0]}")
    for k in range(order):
        level = pair_mean(level[:-1], level[1:], reduce=k == order - 1)
    return level


def compensate_modulation(mods: np.ndarray, order: int) -> np.ndarray:
    """The modulations of windows ``s .. s+K`` averaged with the binomial weights.

    Parameters
    ----------
    mods : (windows, H, W) array
        Consecutive windows' modulations (:func:`window_phases`), ``W > K``.
    order : int
        ``K``.

    Returns
    -------
    (windows - K, H, W) float32
        The weighted means.

    Examples
    --------
    >>> compensate_modulation(np.float32([[1.0], [2.0], [3.0]]), 2).tolist()
    [[2.0]]
    """
    level = np.asarray(mods, np.float32)
    weights = binomial_weights(order).astype(np.float32)
    count = level.shape[0] - order
    return np.stack([np.tensordot(weights, level[s:s + order + 1], axes=1)
                     for s in range(count)]).astype(np.float32)


class PhaseStream:
    """The stream form: :meth:`push` one frame at a time, get the newest window's phase.

    Keeps the last ``N`` frames, the running sums of the newest window (float64; a new
    frame adds its difference to the frame ``N`` before it, which has the same shift:
    two multiply-adds a pixel instead of a whole set's ``N``) and, for order ``K``, the
    newest value of each round of pairwise means of the phases and of the modulations
    (``K`` of each a frame); all in one compiled pass a frame
    (:func:`~bistair.core.motion_jit.stream_update`), in buffers reused.

    Examples
    --------
    >>> x = np.arange(8.0)[None, :]
    >>> frames = [np.float32(0.5 + 0.4 * np.cos(2 * np.pi * (x + 0.2 * i) / 8 + np.pi * i / 2))
    ...           for i in range(9)]
    >>> stream = PhaseStream(4, order=2)
    >>> out = [stream.push(f) for f in frames]
    >>> [o is None for o in out]
    [True, True, True, True, True, False, False, False, False]
    >>> phi, mod = window_phases(np.stack(frames), 4)
    >>> bool(np.allclose(out[-1][0], compensate(phi, 2)[-1], atol=1e-5))
    True
    """

    def __init__(self, steps: int, order: int = 0, shift_sign: int = 1,
                 phase_offset: float = 0.0) -> None:
        _check_order(order)
        if steps < 3:
            raise BistairError("a stream of N-step windows needs N >= 3")
        if shift_sign not in (1, -1):
            raise BistairError(f"shift_sign must be +1 or -1, got {shift_sign}")
        self.steps, self.order = steps, order
        self.shift_sign, self.phase_offset = shift_sign, phase_offset
        self.count = 0  # frames pushed
        self.state: StreamState | None = None  # the buffers, from the first frame
        self._shape: tuple[int, ...] = ()

    @property
    def lag(self) -> float:
        """Frames between the newest frame and the time its result describes."""
        return (self.steps + self.order - 1) / 2

    def push(self, frame: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """Add the next frame (copied: the caller may reuse its buffer); the wrapped phase
        and modulation (float32; the modulation in the frames' own units, e.g. 0-255 for
        uint8 frames) of the newest window, compensated to order ``K``, once ``N + K``
        frames are in, else None."""
        if not self.update(frame):
            return None
        assert self.state is not None
        return (self.state.phase.reshape(self._shape).copy(),
                self.state.mod.reshape(self._shape).copy())

    def update(self, frame: np.ndarray) -> bool:
        """:meth:`push` without the copies: whether ``state.phase`` and ``state.mod`` now
        hold the newest window's results (buffers the next frame overwrites).

        Parameters
        ----------
        frame : numpy.ndarray
            ``(H, W)`` the next frame.

        Returns
        -------
        bool
            ``N + K`` frames are in.

        Examples
        --------
        >>> stream = PhaseStream(3)
        >>> [stream.update(np.full((2, 2), v, np.uint8)) for v in (1, 2, 3)]
        [False, False, True]
        """
        frame = np.asarray(frame)
        state = self.state
        if state is not None and frame.shape != self._shape:
            raise BistairError(f"frame {self.count} is {frame.shape}, the stream's frames "
                               f"are {self._shape}")
        self._shape = frame.shape
        if frame.ndim != 2:  # (the pass runs over rows)
            frame = frame.reshape(-1, frame.shape[-1]) if frame.ndim else frame.reshape(1, 1)
        kind = frame.dtype if frame.dtype in _KEPT else np.dtype(np.float64)
        if state is None:
            state = self.state = stream_state(frame.shape, self.steps, self.order, kind)
        elif kind != state.kept.dtype:  # frames of another type: keep them all as float64
            state.kept = state.kept.astype(np.float64)
        ready = stream_update(state, frame, self.count, self.steps, self.order,
                              self.shift_sign, self.phase_offset)
        self.count += 1
        return ready


_KEPT = tuple(np.dtype(t) for t in (np.uint8, np.uint16, np.float32, np.float64))


def _check_order(order: int) -> None:
    if isinstance(order, bool) or not isinstance(order, int | np.integer) or order < 0:
        raise BistairError(f"the compensation order must be a whole number of 0 or more, got "
                         f"{order!r}")


def _check_stream(stack: np.ndarray, steps: int) -> None:
    if steps < 3:
        raise BistairError("a stream of N-step windows needs N >= 3")
    if stack.ndim < 1 or stack.shape[0] < steps:
        raise BistairError(f"a stream of {steps}-step windows needs {steps} frames or more, "
                         f"got {stack.shape[0] if stack.ndim else 0}")
