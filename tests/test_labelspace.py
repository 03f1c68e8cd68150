"""Bidirectional's label space (issue 32 part C): the (region, row) stair sums gathered in
the labelling's final scan (profiles_jit.relabel_stair_sums) are, bit for bit, the final
labels and the sums a scan of their own gave (tests/support/labelspace_before.py, NumPy
bincount), on random labellings (hypothesis) at one and all threads; a decode that reads
them decodes exactly as the decode that scans the labels again."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.labelspace_before import relabel_then_stair_sums

import bistair
from bistair.codecs import bidirectional
from bistair.codecs.bidirectional.profiles_jit import relabel_stair_sums
from bistair.core.jit import set_threads

PROPERTY = settings(max_examples=40, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow])


def labelling(h: int, w: int, seed: int, regions: int) -> tuple[np.ndarray, ...]:
    """Provisional labels in runs (blocks of random widths, holes of 0), their regions
    (several labels a region, region 0 for label 0), a numbering that drops some regions,
    and the four float32 maps (phases in [0, 2*pi), modulations from 0 up)."""
    rng = np.random.default_rng(seed)
    n_prov = 3 * regions
    labels = np.zeros((h, w), np.int32)
    for y in range(h):
        x = 0
        while x < w:
            run = int(rng.integers(1, 9))
            labels[y, x:x + run] = rng.integers(0, n_prov + 1)
            x += run
    roots = np.concatenate([[0], rng.integers(1, regions + 1, n_prov)]).astype(np.int32)
    kept = rng.random(regions + 1) < 0.8
    kept[0] = False
    remap = np.where(kept, np.cumsum(kept), 0).astype(np.int32)
    phi = rng.uniform(0, 2 * np.pi, (h, w)).astype(np.float32)
    theta = rng.uniform(-np.pi, np.pi, (h, w)).astype(np.float32)
    stair_mod = rng.uniform(0, 0.6, (h, w)).astype(np.float32)
    mod = rng.uniform(0, 0.5, (h, w)).astype(np.float32)
    mod[rng.random((h, w)) < 0.05] = 0  # the 1e-6 floor of the ratio
    return labels, roots, remap, phi, theta, stair_mod, mod


@PROPERTY
@given(h=st.integers(1, 140), w=st.integers(1, 70), seed=st.integers(0, 2**16),
       regions=st.integers(1, 40), threads=st.sampled_from([1, None]))
def test_sums_gathered_in_the_relabel_scan_are_a_scan_of_their_own(h, w, seed, regions,
                                                                   threads):
    """Tiles of 32 rows, bands of 64 or more (h up to 140: three bands), runs of a label
    across tiles and bands, labels dropped (0) by the numbering."""
    labels, roots, remap, *maps = labelling(h, w, seed, regions)
    final, keys, counts, sums = relabel_then_stair_sums(labels, roots, remap, *maps)
    try:
        set_threads(threads)
        got = relabel_stair_sums(labels, roots, remap, *maps, int(remap.max()))
    finally:
        set_threads(None)
    assert np.array_equal(labels, final)
    assert np.array_equal(got[0], keys)
    assert np.array_equal(got[1], counts)
    assert got[2].shape == sums.shape and np.array_equal(got[2], sums)


# regions split, detached and cut (mugs-on-wall), split (paper-sim, warp0), none (warp1)
RENDERS = [("mugs-on-wall", 0.06), ("mugs-on-wall", None), ("paper-sim", 0.03),
           ("warp0", 0.01), ("warp1", 0.08)]


@pytest.mark.parametrize(("scene", "noise"), RENDERS, ids=[f"{s}-{n}" for s, n in RENDERS])
def test_a_decode_reads_the_gathered_sums_as_it_read_its_own(scene, noise, monkeypatch):
    """Against the decode that scans the final labels again (``GATHER`` False): the same
    orders, phases and figures, also where regions are split, cut and detached and the
    evidence is read again."""
    from test_regions_jit import render

    images, spec = render(scene, "bidirectional", noise)
    calls = []
    gathered = bidirectional.relabel_stair_profiles

    def counted(*args):
        calls.append(1)
        return gathered(*args)

    monkeypatch.setattr(bidirectional, "relabel_stair_profiles", counted)
    new = bistair.decode(images, spec, force=True)
    assert calls  # the decode took the gathered sums
    monkeypatch.setattr(bidirectional, "GATHER", False)
    old = bistair.decode(images, spec, force=True)
    assert len(calls) == 1
    assert np.array_equal(new.order, old.order)
    assert np.array_equal(new.phase, old.phase, equal_nan=True)
    assert new.info == old.info
