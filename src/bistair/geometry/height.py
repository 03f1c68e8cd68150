"""Height above a reference plane without a calibration (phase-to-height).

Height above a flat reference plane follows from the shift ``d = x_p - x_ref`` of the
projector coordinate against the reference (the same spec on the empty plane). Along one
camera ray the projector coordinate is a linear-fractional function of the height for a
pinhole projector, so per pixel ``h = d / (a - c * d)`` exactly: the classical ``h = L *
dPhi / (dPhi - 2*pi*f0*b)`` (Takeda and Mutoh, Appl. Opt. 22(24), 1983; camera-plane
distance ``L``, baseline ``b``, fringe frequency ``f0`` on the plane) is the special case
``a = -T*f0*b/L``, ``c = -1/L`` with constant coefficients. :meth:`HeightModel.fit` measures
``a`` and ``c`` per pixel from two or more planes parallel to the reference at known
heights, which absorbs the geometry and the camera's distortion (not the projector's).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import BistairError


@dataclass(frozen=True, eq=False)
class HeightModel:
    """Height above a reference plane from the projector-coordinate shift
    ``d = coord - reference``: ``h = d / (a - c * d)`` per pixel (see the module docstring).

    Examples
    --------
    >>> ref = np.full((2, 2), 100.0)
    >>> model = HeightModel.fit(ref, [ref + 8.0, ref + 15.0], [10.0, 20.0])
    >>> model.height(ref + 8.0).round(6).tolist()
    [[10.0, 10.0], [10.0, 10.0]]
    """

    reference: np.ndarray
    a: np.ndarray | float
    c: np.ndarray | float

    @classmethod
    def classical(cls, reference: np.ndarray, distance: float, baseline: float,
                  frequency: float, period: float) -> HeightModel:
        """Takeda and Mutoh's ``h = L dPhi / (dPhi - 2 pi f0 b)``: camera-plane ``distance``
        ``L`` (mm), ``baseline`` ``b`` (mm), fringe ``frequency`` ``f0`` on the reference
        plane (fringes per mm), ``period`` of the phase in projector pixels.

        Examples
        --------
        >>> model = HeightModel.classical(np.zeros(1), 600.0, 200.0, 0.1, 30.0)
        >>> dphi = 2 * np.pi * np.array([-2.0]) / 30.0  # a shift of -2 projector pixels
        >>> h = model.height(np.array([-2.0]))[0]
        >>> round(float(h), 6), round(float(600 * dphi[0] / (dphi[0] - 2 * np.pi * 0.1 * 200)), 6)
        (1.993355, 1.993355)
        """
        return cls(np.asarray(reference, float), -period * frequency * baseline / distance,
                   -1.0 / distance)

    @classmethod
    def fit(cls, reference: np.ndarray, planes: Sequence[np.ndarray],
            heights: Sequence[float]) -> HeightModel:
        """Per-pixel ``a, c`` (least squares) from projector coordinates measured on planes
        parallel to the reference at known, non-zero ``heights`` (two or more)."""
        ref = np.asarray(reference, float)
        if len(planes) != len(heights) or len(planes) < 2:
            raise BistairError("the height model needs two or more planes with their heights")
        if any(h == 0 for h in heights):
            raise BistairError("plane heights must be non-zero (0 is the reference)")
        shift = np.stack([np.asarray(p, float) - ref for p in planes])
        hts = np.asarray(heights, float).reshape(-1, *([1] * ref.ndim))
        # a * h - c * h * d = d, per pixel: 2x2 normal equations
        c1, c2 = hts * np.ones_like(shift), -hts * shift
        s11, s12, s22 = (c1 * c1).sum(0), (c1 * c2).sum(0), (c2 * c2).sum(0)
        r1, r2 = (c1 * shift).sum(0), (c2 * shift).sum(0)
        det = s11 * s22 - s12 * s12
        with np.errstate(divide="ignore", invalid="ignore"):
            a = np.where(det != 0, (s22 * r1 - s12 * r2) / det, np.nan)
            c = np.where(det != 0, (s11 * r2 - s12 * r1) / det, np.nan)
        return cls(ref, a, c)

    def height(self, coord: np.ndarray) -> np.ndarray:
        """Height (mm, toward the camera for the fitted model) per pixel, NaN where invalid."""
        d = np.asarray(coord, float) - self.reference
        with np.errstate(divide="ignore", invalid="ignore"):
            return d / (self.a - self.c * d)
