"""Measuring an N-step fringe set in a capture: phase, average, modulation, validity.

Every codec starts here, so validity (modulation above the noise, no saturation) and the
refusal of dark or blown captures are the same for all methods.

Examples
--------
>>> import numpy as np
>>> from bistair.captures import prepare
>>> from bistair.phase import phase_shift_patterns
>>> x = np.tile(np.arange(120.0), (16, 1))
>>> frames = 0.1 + 0.8 * phase_shift_patterns(x, 30, 4, offset=0.5, amplitude=0.4)
>>> fs = measure(prepare(frames, 4, "demo"), 0, 4)
>>> bool(fs.valid.all()), round(float(fs.mod.mean()), 3)
(True, 0.32)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .captures import Prepared, check_decodable, noise_level, saturation, validity
from .phase import wrapped_phase


@dataclass(frozen=True)
class FringeSet:
    """One N-step set measured in a capture."""

    phi: np.ndarray  # wrapped phase in [0, 2*pi)
    avg: np.ndarray  # average intensity A (fraction of full scale)
    mod: np.ndarray  # modulation B
    valid: np.ndarray  # enough modulation, not saturated
    noise: float  # camera noise sigma estimated from the fit residual
    steps: int | None = None  # N

    @property
    def phase_noise(self) -> np.ndarray:
        """Standard deviation of the wrapped phase per pixel, ``noise / (B * sqrt(N/2))``."""
        steps = 4 if self.steps is None else self.steps
        return self.noise / (np.maximum(self.mod, 1e-6) * np.sqrt(steps / 2.0))


def measure(prepared: Prepared, start: int, steps: int, min_modulation: float | None = None,
            check: bool = True) -> FringeSet:
    """Measure frames ``start .. start+steps-1`` of a prepared stack as an N-step set.

    With ``check``, captures with (almost) no valid pixel are refused as dark or saturated.
    """
    frames = prepared.frames[start:start + steps]
    phi, avg, mod = wrapped_phase(frames)
    noise = noise_level(frames, phi, avg, mod)
    valid = validity(mod, saturation(prepared.clipped, avg, mod), noise, min_modulation)
    if check:
        check_decodable(valid, prepared.clipped)
    return FringeSet(phi, avg, mod, valid, noise, steps)
