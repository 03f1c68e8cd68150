"""The projector's response (its gamma) measured from a ramp of uniform grey frames.

A projector shows pattern value ``v`` (0..1) as light ``R(v)``; a linear camera sees
``I = a + b*R(v)`` per pixel, ``a`` the ambient light and black level, ``b`` the albedo and
gain. Normalising each pixel between the ramp's darkest and brightest frame removes ``a``
and ``b``: ``r(v) = (I(v) - I(v_0)) / (I(v_max) - I(v_0))`` is the response relative to its
ends, the same at every well-lit pixel. Its median over those pixels, fitted with
``r = ((v - v_0) / (v_max - v_0)) ** gamma`` on the levels between, gives the gamma that
patterns pre-compensate with (``spec.gamma``: each pattern value ``p`` is sent as
``p ** (1 / gamma)``).

Examples
--------
>>> levels = np.linspace(0.0, 1.0, 9)
>>> albedo = np.linspace(0.3, 0.9, 256).reshape(16, 16)
>>> frames = 0.05 + 0.8 * albedo[None] * (levels[:, None, None] ** 2.2)
>>> fit = estimate_response(frames, levels)
>>> round(fit.gamma, 3), fit.pixels
(2.2, 256)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import BistairError


@dataclass(frozen=True)
class Response:
    """A measured projector response.

    Attributes
    ----------
    gamma : the fitted exponent.
    levels : the ramp's pattern values, ascending.
    response : the median relative response at each level (0 at the first, 1 at the last).
    rms : RMS misfit of the power law to ``response``.
    pixels : the well-lit pixels the medians are taken over.
    """

    gamma: float
    levels: tuple[float, ...]
    response: tuple[float, ...]
    rms: float
    pixels: int

    def to_dict(self) -> dict:
        return {"format": "bistair-gamma", "version": 1, "gamma": self.gamma,
                "levels": list(self.levels), "response": list(self.response),
                "rms": self.rms, "pixels": self.pixels}


def ramp_levels(count: int) -> np.ndarray:
    """``count`` pattern values evenly from 0 to 1 (at least 5).

    Parameters
    ----------
    count : int
        Number of grey levels of the ramp, at least 5.

    Returns
    -------
    ndarray
        Float64 array of shape (count,), from 0.0 to 1.0.

    Raises
    ------
    BistairError
        If ``count`` is below 5.

    Examples
    --------
    >>> ramp_levels(5).tolist()
    [0.0, 0.25, 0.5, 0.75, 1.0]
    """
    if count < 5:
        raise BistairError(f"a gamma ramp needs at least 5 levels, got {count}")
    return np.linspace(0.0, 1.0, count)


def estimate_response(frames: np.ndarray, levels: np.ndarray, full_scale: float = 1.0,
                      min_contrast: float = 0.1) -> Response:
    """Fit the projector's gamma to captures of uniform frames at pattern values ``levels``.

    Parameters
    ----------
    frames : (N, H, W) array
        Captures, one per level, in the levels' order.
    levels : (N,) array
        Pattern values in [0, 1], strictly increasing (at least 5).
    full_scale : float
        The capture value of full scale (pixels reaching it are left out).
    min_contrast : float
        Well-lit pixels differ between the brightest and darkest frame by at least this
        share of full scale.

    Returns
    -------
    Response
        The fitted gamma, the median relative response per level, the fit's RMS misfit and
        the number of well-lit pixels (at least 100) it was measured on.

    Raises
    ------
    BistairError
        Frames and levels that do not match, levels that do not increase, or too few
        well-lit pixels.

    Examples
    --------
    >>> levels = ramp_levels(6)
    >>> frames = 0.1 + 0.7 * np.ones((1, 12, 12)) * levels[:, None, None] ** 1.8
    >>> fit = estimate_response(frames, levels)
    >>> round(fit.gamma, 3), fit.pixels, [round(r, 3) for r in fit.response]
    (1.8, 144, [0.0, 0.055, 0.192, 0.399, 0.669, 1.0])
    """
    stack = np.asarray(frames, dtype=np.float64) / full_scale
    levels = np.asarray(levels, dtype=np.float64)
    if stack.ndim != 3 or stack.shape[0] != levels.size:
        raise BistairError(f"the gamma ramp has {levels.size} levels, the captures "
                           f"{stack.shape[0] if stack.ndim == 3 else 'no'} frames")
    if levels.size < 5 or np.any(np.diff(levels) <= 0):
        raise BistairError("gamma ramp levels must be at least 5 increasing values")
    low, high = stack[0], stack[-1]
    lit = ((high - low) >= min_contrast) & (stack.max(axis=0) < 0.999)
    pixels = int(lit.sum())
    if pixels < 100:
        raise BistairError(f"only {pixels} pixels are lit well enough by the ramp (the "
                           f"brightest frame at least {100 * min_contrast:.0f}% of full "
                           "scale above the darkest, none saturated)")
    rel = (stack[:, lit] - low[lit]) / (high[lit] - low[lit])
    response = np.median(rel, axis=1)
    x = (levels - levels[0]) / (levels[-1] - levels[0])
    inner = (x > 0.05) & (x < 1) & (response > 1e-4)
    if inner.sum() < 2:
        raise BistairError("the ramp shows no response between its ends")
    # least squares of log r = gamma * log x through the origin
    lx, lr = np.log(x[inner]), np.log(response[inner])
    gamma = float((lx @ lr) / (lx @ lx))
    rms = float(np.sqrt(np.mean((x ** gamma - response) ** 2)))
    return Response(gamma, tuple(levels.tolist()), tuple(response.tolist()), rms, pixels)
