"""Measuring an N-step fringe set in a capture: phase, average, modulation, validity.

Every codec starts here, so validity (modulation above the noise, no saturation) and the
refusal of dark or blown captures are the same for all methods.

Examples
--------
>>> import numpy as np
>>> from bistair.core.captures import prepare
>>> from bistair.core.phase import phase_shift_patterns
>>> x = np.tile(np.arange(120.0), (16, 1))
>>> frames = 0.1 + 0.8 * phase_shift_patterns(x, 30, 4, offset=0.5, amplitude=0.4)
>>> fs = measure(prepare(frames, 4, "demo"), 0, 4)
>>> bool(fs.valid.all()), round(float(fs.mod.mean()), 3)
(True, 0.32)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .captures import Prepared, ScaledStack, check_decodable, modulation_threshold
from .checks import judge_sample
from .measure_jit import fit_residual_energy, front_end, keep_coherent, phase_noise
from .phase import nstep_weights, shifts_of
from .regions import MIN_REGION, Links, label_fringes
from .sample import Sample, chi2_median, clip_level, kernel_view, set_noise, take_sample


@dataclass(frozen=True)
class FringeSet:
    """One N-step set measured in a capture."""

    phi: np.ndarray  # wrapped phase in [0, 2*pi)
    avg: np.ndarray | None  # average intensity A (fraction of full scale; None: let go)
    mod: np.ndarray | None  # modulation B (None: let go, ``measure(..., maps=False)``)
    valid: np.ndarray  # enough modulation, not saturated
    noise: float  # camera noise sigma estimated from the fit residual
    steps: int | None = None  # N
    threshold: float | None = None  # the modulation a valid pixel needs
    sigma: np.ndarray | None = None  # the phase noise per pixel of the full pass, if kept
    stair: tuple[np.ndarray, np.ndarray] | None = None  # the stair pair's phase, modulation
    sample: Sample | None = None  # pass 0's sample of the capture (column layout)
    # the links of the coherent dim pixels' labelling, for the decode's own labelling of
    # ``phi`` to take over (``links`` of :func:`~bistair.core.regions.fringe_regions`)
    links: Links | None = None

    @property
    def phase_noise(self) -> np.ndarray:
        """Standard deviation of the wrapped phase per pixel, ``noise / (B * sqrt(N/2))``
        (float32 radians): the full pass's (``sigma``) where it kept it, else computed
        when asked for (:func:`~bistair.core.measure_jit.phase_noise`)."""
        if self.sigma is not None:
            return self.sigma
        return phase_noise(self.mod, self.noise, 4 if self.steps is None else self.steps)

    def transposed(self) -> FringeSet:
        """The same set with image axes swapped (for the rows orientation; the sample and
        the links, of the column layout, are left out)."""
        def t(a: np.ndarray | None) -> np.ndarray | None:
            return None if a is None else np.ascontiguousarray(a.T)

        return FringeSet(t(self.phi), t(self.avg), t(self.mod), t(self.valid), self.noise,
                         self.steps, self.threshold, t(self.sigma),
                         None if self.stair is None else (t(self.stair[0]), t(self.stair[1])))


def noise_level(frames: np.ndarray, phi: np.ndarray, avg: np.ndarray, mod: np.ndarray,
                shift_sign: int = 1, phase_offset: float = 0.0) -> float:
    """Camera noise sigma (fraction of full scale) of an N-step set.

    N >= 4: from the fit residual. The residual also holds the projector's harmonics (an
    uncompensated gamma), but those change slowly along a fringe while noise does not: the
    residuals of vertically adjacent pixels are differenced, and the median of their
    squared norm is scaled by the chi-square median of N - 3 degrees of freedom.

    N = 3 leaves no residual (three unknowns, three frames): the frames' second differences
    along the fringes (down the columns of the column layout, where the pattern does not
    change) are used instead, ``sigma = median|d2| / (0.6745 * sqrt(6))``.

    Pixels that a frame clips (or that read exactly 0) are left out.

    Parameters
    ----------
    frames : (N, H, W) array or ScaledStack
        The N-step frames as fractions of full scale, in the column layout.
    phi, avg, mod : (H, W) array
        The set's fitted wrapped phase (radians), average and modulation.
    shift_sign, phase_offset : int, float
        The rig's phase convention (:func:`~bistair.core.phase.wrapped_phase`).

    Returns
    -------
    float
        The noise sigma, fraction of full scale.

    Examples
    --------
    >>> from bistair.core.phase import phase_shift_patterns, wrapped_phase
    >>> rng = np.random.default_rng(0)
    >>> x = np.tile(np.arange(128.0), (64, 1))
    >>> frames = phase_shift_patterns(x, 32, 4, amplitude=0.4) + rng.normal(0, 0.01, (4, 64, 128))
    >>> round(noise_level(frames, *wrapped_phase(frames)), 3)
    0.01
    >>> frames = phase_shift_patterns(x, 32, 3, amplitude=0.4) + rng.normal(0, 0.01, (3, 64, 128))
    >>> round(noise_level(frames, *wrapped_phase(frames)), 3)  # N = 3: along the fringes
    0.01
    """
    steps = frames.shape[0]
    if steps <= 3:
        return along_fringe_noise(frames)
    # every fourth row and column: plenty for a median
    raw, scale = ((frames.raw, frames.scale) if isinstance(frames, ScaledStack)
                  else (np.asarray(frames, np.float32), 1.0))
    energy, ok = fit_residual_energy(raw, 0, steps, scale, phi, avg, mod,
                                     shifts_of(steps, shift_sign, phase_offset))
    sample = energy[ok] if ok.sum() >= 100 else energy.ravel()
    dof = steps - 3
    return float(np.sqrt(np.median(sample) / (2.0 * chi2_median(dof))))


def along_fringe_noise(frames: np.ndarray) -> float:
    """Camera noise sigma from the frames' second differences down the columns (along the
    fringes or stripes of the column layout, where a pattern does not change):
    ``median|d2| / (0.6745 * sqrt(6))``, pixels that a frame clips or that read 0 left out.

    Parameters
    ----------
    frames : (F, H, W) array
        Frames as fractions of full scale, column layout.

    Returns
    -------
    float
        The noise sigma (0.0 for frames too small to tell).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> frames = 0.5 + rng.normal(0, 0.01, (2, 200, 64))
    >>> round(along_fringe_noise(frames), 3)
    0.01
    """
    f = frames[:, :, ::4]  # every fourth column: plenty for a median
    d2 = f[:, :-2] - 2.0 * f[:, 1:-1] + f[:, 2:]
    lo, hi = f.min(axis=0), f.max(axis=0)
    ok = ((lo[:-2] > 0) & (lo[1:-1] > 0) & (lo[2:] > 0)
          & (hi[:-2] < 1) & (hi[1:-1] < 1) & (hi[2:] < 1))
    sample = np.abs(d2[:, ok]) if ok.sum() >= 100 else np.abs(d2).reshape(len(f), -1)
    if sample.size == 0:
        return 0.0
    return float(np.median(sample) / (0.6745 * np.sqrt(6.0)))


def measure(prepared: Prepared, start: int, steps: int, min_modulation: float | None = None,
            check: bool = True, shift_sign: int = 1, phase_offset: float = 0.0,
            coherent: bool = True, maps: bool = True, pair: int | None = None) -> FringeSet:
    """Measure frames ``start .. start+steps-1`` of a prepared stack as an N-step set (and,
    with ``pair``, the stair pair of frames ``pair``, ``pair + 1`` in the same pass).

    Two passes: pass 0 (:mod:`bistair.core.sample`) takes the camera noise from a sparse
    grid (:func:`~bistair.core.sample.set_noise`), hence the thresholds, and with ``check``
    the set's :class:`~bistair.core.sample.Sample` for the checks of the whole capture
    (those waiting in :func:`~bistair.core.checks.sample_checks` judge it at once);
    pass 1 (:func:`~bistair.core.measure_jit.front_end`) measures every pixel in tiles of
    rows, each frame read once: phase, average, modulation, validity, the phase noise and
    the pair's stair phase.

    ``shift_sign`` and ``phase_offset`` are the rig's phase convention
    (:func:`~bistair.core.phase.wrapped_phase`). Valid pixels are not saturated (a frame of
    the set or of the pair at full scale, and the fitted sinusoid above it), have, when the
    capture has white and black frames, twice the modulation threshold of contrast between
    them, and have enough modulation:

    - at least the threshold (:func:`~bistair.core.captures.modulation_threshold`: four
      times the noise, at least 1% of full scale, or ``min_modulation`` if given), or
    - with ``coherent`` and no ``min_modulation``, at least half of it (twice the noise,
      at least 0.5%) where the pixel belongs to a fringe region
      (:func:`~bistair.core.regions.fringe_regions`) that holds ten pixels above the full
      threshold or a hundred pixels in all: the dim parts of a lit surface, not noise,
      whose phases do not join into regions (:func:`coherent_pixels`).

    With ``check``, captures with (almost) no valid pixel are refused as dark or saturated.

    Parameters
    ----------
    prepared : Prepared
        The capture stack (:func:`~bistair.core.captures.prepare`).
    start : int
        Index of the set's first frame in ``prepared``.
    steps : int
        Number of frames ``N`` of the set (at least 3).
    min_modulation : float, optional
        The modulation a valid pixel needs (fraction of full scale, strictly between 0 and
        1); from the noise when not given.
    check : bool
        Refuse captures with (almost) nothing to decode, and keep the sample.
    shift_sign, phase_offset : int, float
        The rig's phase convention.
    coherent : bool
        Also accept dim pixels in coherent fringe regions (see above).
    maps : bool
        Keep the average, the modulation and the phase noise; without, they are let go once
        the validity is known (before the fringe regions of ``coherent``, the stage's
        largest) and the set holds ``None`` for them: for sets of which only phase and
        validity are read.
    pair : int, optional
        The stair pair's cosine frame (its sine frame follows): its phase in ``[-pi, pi]``
        (``atan2(sin - A, cos - A)``) and modulation are kept in ``stair``.

    Returns
    -------
    FringeSet
        Float32 (H, W) wrapped phase in ``[0, 2*pi)``, average and modulation (fractions of
        full scale), the bool validity mask, the noise sigma, ``steps``, the modulation
        threshold, the phase noise (``sigma``), the stair pair's maps and the sample.

    Raises
    ------
    BistairError
        With ``check``, if the captures are dark or saturated or no pixel has
        ``min_modulation`` (:func:`~bistair.core.captures.check_decodable`); if
        ``min_modulation`` is not strictly between 0 and 1.

    Examples
    --------
    >>> from bistair.core.captures import prepare
    >>> x = np.tile(np.arange(64.0), (16, 1))
    >>> shifts = 2 * np.pi * np.arange(4)[:, None, None] / 4
    >>> stack = np.round(255 * (0.5 + 0.3 * np.cos(2 * np.pi * x / 16 + shifts))).astype(np.uint8)
    >>> fs = measure(prepare(stack, 4, "demo"), 0, 4)
    >>> fs.phi.shape, fs.phi.dtype.name, bool(fs.valid.all()), round(float(fs.mod.mean()), 3)
    ((16, 64), 'float32', True, 0.3)
    >>> measure(prepare(np.full((4, 16, 64), 9, np.uint8), 4, "demo"), 0, 4)
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: captures are dark: no pixel has enough fringe modulation to decode
    """
    noise = set_noise(prepared, start, steps)  # pass 0: the noise, hence the thresholds
    threshold = modulation_threshold(noise, min_modulation)
    lowest = threshold if (min_modulation is not None or not coherent) else \
        max(0.005, 2.0 * noise)
    sample = None if not check else take_sample(prepared, start, steps, pair, lowest,
                                                threshold, shift_sign, phase_offset)
    if sample is not None:  # the checks that need only the sample refuse before pass 1
        judge_sample(sample)
    contrast = prepared.white is not None and prepared.black is not None
    none = np.zeros((1, 1), np.float32)
    raw, first, cos_frame = kernel_view(prepared, start, steps, pair)
    phi, mod, avg, valid, strong, sigma, theta, stair_mod, weak = front_end(  # pass 1
        raw, first, int(steps), cos_frame, float(prepared.scale),
        *nstep_weights(steps, shift_sign, phase_offset), clip_level(prepared),
        float(lowest), float(threshold), np.float32(noise / np.sqrt(steps / 2.0)),
        prepared.white if contrast else none, prepared.black if contrast else none, contrast)
    if not maps:
        avg = None
        if not check:
            mod = None
    links = None
    if lowest < threshold and weak:  # dim pixels to judge by their regions
        valid, links = coherent_pixels(phi, valid, strong, sigma)
    del strong
    if check:
        check_decodable(valid, lambda: prepared.clipped, min_modulation, mod)
    return FringeSet(phi, avg, mod if maps else None, valid, noise, steps, threshold,
                     sigma if maps else None,
                     None if pair is None else (theta, stair_mod), sample,
                     links if maps else None)


def coherent_pixels(phi: np.ndarray, weak: np.ndarray, strong: np.ndarray,
                    phase_noise: np.ndarray, min_strong: int = 10,
                    min_size: int = 100) -> tuple[np.ndarray, Links | None]:
    """The ``strong`` pixels and the ``weak`` ones in fringe regions of the weak mask that
    hold at least ``min_strong`` strong pixels or ``min_size`` pixels in all, and the
    links of that labelling, for the decode's own labelling of ``phi`` to take over.

    Noise has random phases: its pixels do not join into fringe regions, so a dim pixel
    whose phase runs on smoothly with a region's is part of a lit surface.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    weak : (H, W) bool array
        Pixels with at least the lower modulation threshold (a superset of ``strong``).
    strong : (H, W) bool array
        Pixels with at least the full modulation threshold.
    phase_noise : (H, W) float32 array
        Per-pixel phase noise in radians (:func:`~bistair.core.regions.fringe_regions`).
    min_strong : int
        Strong pixels that keep a region.
    min_size : int
        Pixels in all that keep a region.

    Returns
    -------
    keep : (H, W) bool array
        The pixels to count as valid.
    links : Links or None
        The labelling's links (:class:`~bistair.core.regions.Links`), for the decode's
        own labelling of ``phi`` and ``phase_noise`` to take over (``FringeSet.links``).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> phi = np.tile((2 * np.pi * (np.arange(60.0) + 0.5) / 30) % (2 * np.pi), (20, 1))
    >>> phi[:, 35:] = rng.uniform(0, 2 * np.pi, (20, 25))  # noise on the right
    >>> weak = np.ones(phi.shape, bool)
    >>> weak[:, 30:35] = False
    >>> keep, links = coherent_pixels(phi.astype(np.float32), weak,
    ...                               np.zeros(phi.shape, bool),
    ...                               np.full(phi.shape, 0.02, np.float32))
    >>> bool(keep[:, :30].all()), bool(keep[:, 35:].any()), links.bits.shape
    (True, False, (20, 60))
    """
    # the regions fringe_regions drops as too small are left out here; the labelling
    # counted each region's pixels and strong pixels: no relabelling, no counting pass.
    # Its links are handed on: the decode's own labelling of phi takes them over
    lab = label_fringes(phi, weak, phase_noise=phase_noise, strong=strong, share=True)
    return keep_coherent(lab.labels, lab.roots, lab.size, lab.strong, strong, min_strong,
                         min_size, MIN_REGION), lab.links
