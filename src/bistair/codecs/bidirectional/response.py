"""Where the stair levels read in a capture, and the stair phase read there.

A projector response the patterns do not pre-compensate (its gamma) moves each stair level's
reading by its own amount, the same everywhere in the image: with a gamma of 2.2 by up to
0.38 rad, which is past half the gap between two of 11 or more levels, so that a level reads
nearer its neighbour than itself and whole partitions took their neighbour's order (the paper
scene at 11 x 11, 20% of its pixels). :func:`linear_stair` fits the response exponent to a
sample of the capture's own stair phases (:func:`~bistair.core.stair.fit_level_response`)
and, where it moves the readings, maps the stair phase so that each level reads where the
patterns put it (:func:`~bistair.core.stair.relinearize`); the band rows are then read
against the levels as before, and :func:`~bistair.codecs.bidirectional.level_offset` says
whether they can be (the decode refuses where they read as far from the levels as a coin
toss).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ...core.measure import FringeSet
from ...core.phase import TWO_PI, wrap
from ...core.stair import fit_level_response, half_gaps, level_readings, relinearize
from ...core.stair_jit import quantize32
from .bands import union_levels
from .stairs_jit import decoded_sample

if TYPE_CHECKING:
    from . import BidirectionalSpec

SAMPLES = 5000  # stair phases the response is fitted to
MIN_SHIFT = 0.25  # readings moved less than this share of a half gap: read as they are
MAX_RATIO = 0.9  # the fit must bring the phases this much nearer the readings than the levels


def linear_stair(fs: FringeSet, theta: np.ndarray, stair_mod: np.ndarray, ks: np.ndarray,
                 spec: BidirectionalSpec) -> tuple[np.ndarray, np.ndarray, float]:
    """The stair phase and its local levels, mapped so that the levels read where the
    patterns put them, and the response exponent that moved them (1.0: not mapped).

    The exponent is fitted to about 5000 valid pixels away from the fringe edges whose stair
    phase noise is under 0.3 rad (at least 500). The phase is mapped only where that
    exponent moves some level's reading by at least a quarter of the way to halfway
    (``MIN_SHIFT`` of its half gap) and fits the phases better than the levels do (mean
    clipped squared distance at most ``MAX_RATIO`` of theirs): a compensated projector
    decodes exactly as before.

    Parameters
    ----------
    fs : FringeSet
        Stage 1, column layout (validity, wrapped phase, camera noise).
    theta : numpy.ndarray
        (H, W) float32 stair phase in radians.
    stair_mod : numpy.ndarray
        (H, W) modulation of the stair pair.
    ks : numpy.ndarray
        (H, W) int32 local stair level per pixel (-1 where not valid).
    spec : BidirectionalSpec
        The spec (partitions, stairs, offset, amplitude).

    Returns
    -------
    theta : numpy.ndarray
        The (mapped) stair phase, float32.
    ks : numpy.ndarray
        Its local stair level per pixel.
    exponent : float
        The fitted response exponent, 1.0 where the phase was not mapped.

    Examples
    --------
    Patterns of 12 x 12 levels through a projector gamma of 2.2 the spec does not
    compensate: levels 0 and 2 read nearer level 1 than themselves, until mapped.

    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.codecs.bidirectional import code_columns
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("bidirectional", width=480, height=96, period=4, partitions=12,
    ...                  stairs=12, group_rows=16, local_rows=10)
    >>> cols = prepare(encode(spec) ** 2.2, spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> theta, smod = code.maps["stair_phase"], code.maps["stair_modulation"]
    >>> code.code[0, 2:12:4].tolist()  # fringes 0, 1, 2: local levels 0, 1, 2
    [1, 1, 1]
    >>> lin, ks, exponent = linear_stair(fs, theta, smod, code.code, spec)
    >>> ks[0, 2:12:4].tolist(), round(exponent, 1)
    ([0, 1, 2], 2.2)
    """
    levels = union_levels(spec.partitions, spec.stairs)
    idx = decoded_sample(fs.valid, ks, SAMPLES)
    sigma = fs.noise * math.sqrt(2.0) / np.maximum(stair_mod.ravel()[idx], 1e-6)
    phi = fs.phi.ravel()[idx]
    keep = (sigma < 0.3) & (phi > 0.5) & (phi < TWO_PI - 0.5)
    if keep.sum() < 500 or levels.size < 3:
        return theta, ks, 1.0
    exponent, ratio = fit_level_response(theta.ravel()[idx][keep], levels, spec.offset,
                                         spec.amplitude)
    read = level_readings(levels, exponent, spec.offset, spec.amplitude)
    shift = float(np.max(np.abs(wrap(read - levels)) / half_gaps(levels)))
    if ratio > MAX_RATIO or shift < MIN_SHIFT:
        return theta, ks, 1.0
    try:
        mapped = relinearize(theta, read, levels)
    except ValueError:  # readings out of the levels' order: no power law explains them
        return theta, ks, 1.0
    return mapped, quantize32(mapped, spec.stairs, fs.valid), exponent
