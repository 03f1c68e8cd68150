"""N-step phase shifting: the patterns and the wrapped phase, average and modulation.

Convention: frame ``n`` of an ``N``-step set shows
``a + b*cos(2*pi*x/T + phase_offset + shift_sign*2*pi*n/N)`` (``phase_offset = 0`` and
``shift_sign = +1`` unless a rig says otherwise); the camera sees
``A + B*cos(phi + phase_offset + shift_sign*2*pi*n/N)`` and the wrapped phase
``phi = 2*pi*x/T mod 2*pi`` lies in ``[0, 2*pi)``.

Examples
--------
>>> import numpy as np
>>> x = np.arange(60.0)
>>> frames = phase_shift_patterns(x, period=30, steps=4)[:, None, :]
>>> phi, avg, mod = wrapped_phase(frames)
>>> bool(np.allclose(phi[0], 2 * np.pi * (x % 30) / 30, atol=1e-5))
True
>>> float(avg.mean()), round(float(mod.mean()), 4)
(0.5, 0.5)
"""

from __future__ import annotations

import numpy as np

from .phase_jit import offset_parts, phase_of_sums32, shift_weights, wrap_angles

TWO_PI = 2.0 * np.pi


def shifts_of(steps: int, shift_sign: int = 1, phase_offset: float = 0.0) -> np.ndarray:
    """The phase added to frame ``n``: ``phase_offset + shift_sign*2*pi*n/steps`` (float64).

    Parameters
    ----------
    steps : int
        Number of frames ``N`` of the set.
    shift_sign : int
        +1 or -1: the direction the shifts run (see the module docstring).
    phase_offset : float
        Phase added to every frame, in radians.

    Returns
    -------
    ndarray
        Float64 array of shape (steps,), in radians.

    Examples
    --------
    >>> shifts_of(4, -1).round(4).tolist()
    [0.0, -1.5708, -3.1416, -4.7124]
    """
    return phase_offset + shift_sign * TWO_PI * np.arange(steps) / steps


def phase_shift_patterns(
    x: np.ndarray, period: float, steps: int, offset: float = 0.5, amplitude: float = 0.5,
    phase_offset: float = 0.0, shift_sign: int = 1,
) -> np.ndarray:
    """Intensities ``offset + amplitude*cos(2*pi*x/period + phase_offset +
    shift_sign*2*pi*n/steps)``, n = 0..steps-1.

    Parameters
    ----------
    x : ndarray
        Projector coordinate along the coded axis (projector pixels), any shape.
    period : float
        Fringe period in projector pixels.
    steps : int
        Number of frames ``N``.
    offset, amplitude : float
        Pattern offset ``a`` and amplitude ``b`` (fractions of full scale).
    phase_offset : float
        Phase added to every frame, in radians.
    shift_sign : int
        +1 or -1: the direction the shifts run.

    Returns
    -------
    ndarray
        Float64 array of shape ``(steps, *x.shape)``.

    Examples
    --------
    >>> phase_shift_patterns(np.array([0.0, 1.0]), period=4, steps=4).round(3).tolist()
    [[1.0, 0.5], [0.5, 0.0], [0.0, 0.5], [0.5, 1.0]]
    """
    shifts = shifts_of(steps, shift_sign, phase_offset)
    shifts = shifts.reshape((steps,) + (1,) * np.ndim(x))
    return offset + amplitude * np.cos(TWO_PI * np.asarray(x, dtype=np.float64) / period + shifts)


def wrapped_phase(frames: np.ndarray, shift_sign: int = 1, phase_offset: float = 0.0
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Wrapped phase in ``[0, 2*pi)``, average ``A`` and modulation ``B`` of an N-step stack.

    Least-squares N-step estimate (Eq. 9-11 of the paper for N = 4, general N here):
    ``phi = atan2(-sum I_n sin d_n, sum I_n cos d_n) - phase_offset`` with
    ``d_n = shift_sign*2*pi*n/N``.

    Parameters
    ----------
    frames : (N, H, W) array
        The N-step stack, any dtype (values as they are: fractions of full scale for a
        prepared capture); N >= 3.
    shift_sign, phase_offset : int, float
        The rig's phase convention (see the module docstring).

    Returns
    -------
    phi : ndarray
        Float32 wrapped phase in ``[0, 2*pi)``, shape (H, W).
    A : ndarray
        Float32 average intensity, shape (H, W).
    B : ndarray
        Float32 modulation (amplitude of the fitted sinusoid), shape (H, W).

    Raises
    ------
    ValueError
        If the stack has fewer than 3 frames.

    Examples
    --------
    >>> frames = phase_shift_patterns(np.array([[1.0, 2.0, 3.0]]), period=4, steps=4)
    >>> phi, avg, mod = wrapped_phase(frames)
    >>> phi.astype(float).round(4).tolist()
    [[1.5708, 3.1416, 4.7124]]
    >>> round(float(avg.mean()), 4), round(float(mod.mean()), 4)
    (0.5, 0.5)
    """
    stack = np.asarray(frames, dtype=np.float32)
    steps = stack.shape[0]
    if steps < 3:
        raise ValueError("N-step phase shifting needs at least 3 frames")
    shifts = shifts_of(steps, shift_sign)
    num = -np.tensordot(np.sin(shifts).astype(np.float32), stack, axes=1)
    den = np.tensordot(np.cos(shifts).astype(np.float32), stack, axes=1)
    phi, mod = phase_of_sums(num, den, steps, phase_offset)
    avg = stack.mean(axis=0)
    return phi, avg.astype(np.float32), mod


def phase_of_sums(num: np.ndarray, den: np.ndarray, steps: int, phase_offset: float = 0.0
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The wrapped phase in ``[0, 2*pi)`` and the modulation of an N-step set from its sums
    ``num = -sum I_n sin d_n`` and ``den = sum I_n cos d_n`` (float32, as the decode's own
    pass computes them: :func:`~bistair.core.phase_jit.phase_of_sums32`, the arctangent
    of :func:`~bistair.core.phase_jit.arctan2_32`).

    Parameters
    ----------
    num, den : ndarray
        The sums over the frames, float32 arrays of the same shape (H, W).
    steps : int
        Number of frames ``N`` the sums are over.
    phase_offset : float
        The rig's phase offset in radians, subtracted from the phase.

    Returns
    -------
    phi : ndarray
        Float32 wrapped phase in ``[0, 2*pi)``.
    mod : ndarray
        Float32 modulation ``B = 2/N * hypot(num, den)``.

    Examples
    --------
    >>> phi, mod = phase_of_sums(np.float32([0.0, 2.0, -2.0]), np.float32([2.0, 0.0, 0.0]), 4)
    >>> phi.astype(float).round(4).tolist(), mod.tolist()
    ([0.0, 1.5708, 4.7124], [1.0, 1.0, 1.0])
    """
    return phase_of_sums32(num, den, steps, phase_offset)


def residuals(frames: np.ndarray, phi: np.ndarray, avg: np.ndarray, mod: np.ndarray,
              shift_sign: int = 1, phase_offset: float = 0.0) -> np.ndarray:
    """The N-step stack minus its fitted sinusoid, shape (N, ...).

    Parameters
    ----------
    frames : (N, ...) array
        The N-step stack, any dtype.
    phi, avg, mod : ndarray
        The fitted wrapped phase (radians), average and modulation (:func:`wrapped_phase`),
        of the frames' pixel shape.
    shift_sign, phase_offset : int, float
        The rig's phase convention (see the module docstring).

    Returns
    -------
    ndarray
        Float32 ``frames - (avg + mod*cos(phi + shifts))``, shape (N, ...).

    Examples
    --------
    >>> frames = phase_shift_patterns(np.arange(3.0), period=12, steps=4)
    >>> res = residuals(frames, *wrapped_phase(frames))
    >>> res.shape, bool(np.abs(res).max() < 1e-6)
    ((4, 3), True)
    """
    stack = np.asarray(frames, dtype=np.float32)
    steps = stack.shape[0]
    shifts = shifts_of(steps, shift_sign, phase_offset).astype(np.float32)
    shifts = shifts.reshape((steps,) + (1,) * (stack.ndim - 1))
    return stack - (avg[None] + mod[None] * np.cos(phi[None] + shifts))


def wrap(angle: np.ndarray) -> np.ndarray:
    """Wrap angles into ``[-pi, pi)``.

    Parameters
    ----------
    angle : float or ndarray
        Angles in radians.

    Returns
    -------
    ndarray
        ``(angle + pi) mod 2*pi - pi``, same shape (a NumPy scalar for a scalar input).

    Examples
    --------
    >>> wrap(np.array([0.5, 4.0, -4.0, np.pi])).round(4).tolist()
    [0.5, -2.2832, 2.2832, -3.1416]
    """
    angle = np.asarray(angle)
    if angle.dtype in (np.float32, np.float64) and angle.size >= 4096:
        return wrap_angles(angle)  # the same values, without NumPy's slow remainder
    return (angle + np.pi) % TWO_PI - np.pi


def order_from_reference(phi: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Fringe order that brings ``phi`` nearest an absolute ``reference`` phase (same period).

    Parameters
    ----------
    phi : ndarray
        Wrapped phase in radians, in ``[0, 2*pi)``.
    reference : ndarray
        Absolute phase in radians (same period), broadcastable to ``phi``.

    Returns
    -------
    ndarray
        ``rint((reference - phi) / (2*pi))``: whole numbers as floats (float64 for float64
        inputs).

    Examples
    --------
    >>> order_from_reference(np.array([0.1, 6.2]), np.array([12.7, 12.5])).tolist()
    [2.0, 1.0]
    """
    return np.rint((np.asarray(reference) - phi) * (1.0 / TWO_PI))


def nstep_weights(steps: int, shift_sign: int = 1, phase_offset: float = 0.0
                  ) -> tuple[np.ndarray, np.ndarray, np.float32, np.float32]:
    """The constants of an N-step set's phase as the compiled passes take them (pass 0,
    :func:`bistair.core.sample_jit.sample_pixels`, and pass 1,
    :func:`bistair.core.measure_jit.front_end`): each frame's sine and cosine weight
    (:func:`bistair.core.phase_jit.shift_weights`) and the phase offset in two exact parts
    (:func:`bistair.core.phase_jit.offset_parts`).

    Parameters
    ----------
    steps : int
        Number of frames ``N``.
    shift_sign : int
        +1 or -1: the rig's direction of the phase shift.
    phase_offset : float
        The rig's phase offset in radians.

    Returns
    -------
    sin_w, cos_w : (N,) float32 array
        The weights of the N-step sums.
    off_hi, off_lo : numpy.float32
        The phase offset's parts.

    Examples
    --------
    >>> sin_w, cos_w, hi, lo = nstep_weights(4, -1, np.pi / 2)
    >>> sin_w.tolist(), cos_w.tolist(), float(hi + lo)
    ([0.0, -1.0, 0.0, 1.0], [1.0, 0.0, -1.0, 0.0], 1.5707963705062866)
    """
    return (*shift_weights(steps, shift_sign), *offset_parts(phase_offset))

