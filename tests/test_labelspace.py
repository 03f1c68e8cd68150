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
from support.labelspace_before import (
    drop_transitions,
    level_offsets,
    profile_centroids,
    relabel_then_stair_sums,
    split_profiles,
)

import bistair
from bistair.codecs import bidirectional
from bistair.codecs.bidirectional import bands, evidence, profiles, response
from bistair.codecs.bidirectional.bands import Runs, union_levels
from bistair.codecs.bidirectional.profiles import RowProfiles
from bistair.codecs.bidirectional.profiles_jit import relabel_stair_sums
from bistair.core.jit import set_threads
from bistair.core.phase import wrap

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


def copied(runs: Runs) -> Runs:
    return Runs(**{k: np.array(v, copy=True) for k, v in runs.__dict__.items()})


def assert_same_runs(got: Runs, want: Runs) -> None:
    for key, value in want.__dict__.items():
        have = getattr(got, key)
        assert have.dtype == value.dtype and np.array_equal(have, value), key


@PROPERTY
@given(n=st.integers(0, 40), seed=st.integers(0, 2**16), levels=st.integers(1, 4))
def test_transitions_are_dropped_as_numpy_dropped_them(n, seed, levels):
    """Runs of few levels (neighbours alike or not), short and fractional lengths, phases
    across the wrap, ragged ends and bounded runs, the first and last runs among them."""
    rng = np.random.default_rng(seed)
    theta = rng.choice([-np.pi, -3.0, -1.0, 0.0, 0.5, 3.0, np.pi - 1e-12], n)
    theta = np.where(rng.random(n) < 0.5, rng.uniform(-np.pi, np.pi, n), theta)
    runs = Runs(region=np.sort(rng.integers(1, 4, n)), y0=np.arange(n), y1=np.arange(n) + 1,
                length=rng.choice([0.5, 1.0, 2.0, 2.5, 3.0, 7.0, 10.0, 25.0], n)
                * rng.choice([1.0, 1.0 + 1e-9], n),
                theta=theta, weight=rng.random(n),
                uid=rng.integers(0, levels, n).astype(np.int32),
                top_ok=rng.random(n) < 0.8, bottom_ok=rng.random(n) < 0.8,
                misfit=rng.random(n))
    runs.top_ok[:1] = False  # (as row_runs makes them: no run above the first)
    runs.bottom_ok[-1:] = False
    assert_same_runs(bands._drop_transitions(copied(runs)), drop_transitions(copied(runs)))


@pytest.mark.parametrize(("scene", "noise"), RENDERS[:3], ids=[f"{s}-{n}" for s, n in
                                                                RENDERS[:3]])
def test_transitions_of_decoded_renders(scene, noise, monkeypatch):
    """The runs each band analysis of a decode cuts, dropped as before, and the decode
    itself the same with the NumPy passes."""
    from test_regions_jit import render

    images, spec = render(scene, "bidirectional", noise)
    seen = []
    compiled = bands._drop_transitions

    def watch(runs):
        seen.append(copied(runs))
        return compiled(runs)

    monkeypatch.setattr(bands, "_drop_transitions", watch)
    new = bistair.decode(images, spec, force=True)
    assert seen and sum(r.uid.size for r in seen) > 200
    for runs in seen:
        assert_same_runs(compiled(copied(runs)), drop_transitions(copied(runs)))
    monkeypatch.setattr(bands, "_drop_transitions", drop_transitions)
    old = bistair.decode(images, spec, force=True)
    assert np.array_equal(new.order, old.order) and new.info == old.info


@PROPERTY
@given(n=st.integers(0, 300), seed=st.integers(0, 2**16),
       stairs=st.sampled_from([(6, 6), (3, 4), (8, 8), (12, 12)]), nudge=st.booleans())
def test_level_offsets_are_numpys(n, seed, stairs, nudge):
    """Band rows on their levels, between two, across the wrap, at equal shares (ties in
    the sort), with zero weights, none of band-core modulation or all, against the union
    levels or levels read off them (as a response moves them): the same medians."""
    rng = np.random.default_rng(seed)
    levels = np.array(union_levels(*stairs))
    if nudge:
        levels = np.sort(wrap(levels + rng.normal(0, 0.05, levels.size)))
    theta = levels[rng.integers(0, levels.size, n)] + rng.choice(
        [0.0, 0.05, -0.05, 0.2, np.pi / levels.size], n) * (rng.random(n) < 0.7)
    theta = np.where(rng.random(n) < 0.3, rng.uniform(-np.pi, np.pi, n), theta)
    radius = rng.choice([1.0, 0.5, 3.0], n)
    weight = rng.choice([0.0, 1.0, 2.5, 7.0], n) * rng.choice([1.0, rng.random()], n)
    level = rng.choice([0.0, 0.69, 0.7, 1.0, rng.uniform(0, 2)], n)
    one = np.ones(n)
    prof = RowProfiles(np.arange(n), np.arange(n), radius * np.cos(theta),
                       radius * np.sin(theta), weight, level, one, one)
    offset, per_level = response.level_offsets(prof, levels)
    want_offset, want_per_level = level_offsets(prof, levels)
    assert type(offset) is float and offset == want_offset
    assert per_level.dtype == want_per_level.dtype
    assert np.array_equal(per_level, want_per_level)


def random_profiles(rng: np.random.Generator, n: int, regions: int) -> RowProfiles:
    """Row profiles sorted by region, then row (as a decode makes them), each (region,
    row) once: pixel counts from 1, column sums, region 0 among them."""
    region = np.sort(rng.integers(0, regions + 1, n))
    row = np.zeros(n, np.int64)
    for r in np.unique(region):
        at = np.flatnonzero(region == r)
        row[at] = np.sort(rng.choice(4 * n + 8, at.size, replace=False))
    count = rng.integers(1, 300, n)
    one = np.ones(n)
    return RowProfiles(region, row, one, one, one, one, count,
                       count * rng.uniform(0, 1279, n))


@PROPERTY
@given(n=st.integers(0, 200), seed=st.integers(0, 2**16), regions=st.integers(0, 12))
def test_profile_centroids_are_numpys(n, seed, regions):
    """Regions without entries, region 0, one entry, many: the same centroids."""
    prof = random_profiles(np.random.default_rng(seed), n, regions)
    got = profiles.profile_centroids(prof, regions)
    want = profile_centroids(prof, regions)
    assert got.dtype == want.dtype and np.array_equal(got, want)


@PROPERTY
@given(n=st.integers(0, 200), seed=st.integers(0, 2**16), regions=st.integers(1, 12),
       count=st.integers(0, 5), shuffled=st.booleans())
def test_split_profiles_are_numpys(n, seed, regions, count, shuffled):
    """Splits of a region once or twice (its middle then its tail), at its first row, past
    its last, of regions without entries; the profiles out of order too (the lexsort
    decides there): the same profiles, in the same order."""
    rng = np.random.default_rng(seed)
    prof = random_profiles(rng, n, regions)
    if shuffled and n:
        prof = RowProfiles(*(v[rng.permutation(n)] for v in prof.__dict__.values()))
    splits = [(int(rng.integers(1, regions + 1)), int(rng.integers(0, 4 * n + 9)))
              for _ in range(count)]
    got = evidence.split_profiles(prof, regions, splits)
    want = split_profiles(prof, regions, splits)
    for key, value in want.__dict__.items():
        have = getattr(got, key)
        assert have.dtype == value.dtype and np.array_equal(have, value), key


@pytest.mark.parametrize(("scene", "noise"), RENDERS, ids=[f"{s}-{n}" for s, n in RENDERS])
def test_label_space_of_decoded_renders(scene, noise, monkeypatch):
    """The decodes' own row profiles (a response left uncompensated among them: levels
    squeezed together; regions split) read as NumPy read them: level offsets, centroids,
    split profiles; and the decode the same with the NumPy."""
    from test_regions_jit import render

    images, spec = render(scene, "bidirectional", noise)
    if scene == "warp0":  # a gamma of 2.2 nothing compensates
        images = images ** 2.2
    oracles = {"level_offsets": level_offsets, "profile_centroids": profile_centroids,
               "split_profiles": split_profiles}
    seen = {name: [] for name in oracles}
    for name in oracles:
        compiled = getattr(bidirectional, name)

        def watch(*args, name=name, compiled=compiled):
            seen[name].append(args)
            return compiled(*args)

        monkeypatch.setattr(bidirectional, name, watch)
    new = bistair.decode(images, spec, force=True)
    assert len(seen["level_offsets"]) == 1 and seen["level_offsets"][0][0].region.size > 500
    assert seen["profile_centroids"] and (seen["split_profiles"] or scene.startswith("warp"))
    offset, per_level = response.level_offsets(*seen["level_offsets"][0])
    want_offset, want_per_level = level_offsets(*seen["level_offsets"][0])
    assert offset == want_offset and np.array_equal(per_level, want_per_level)
    for args in seen["profile_centroids"]:
        assert np.array_equal(profiles.profile_centroids(*args), profile_centroids(*args))
    for args in seen["split_profiles"]:
        got, want = evidence.split_profiles(*args), split_profiles(*args)
        assert all(np.array_equal(getattr(got, k), v) for k, v in want.__dict__.items())
    for name, oracle in oracles.items():
        monkeypatch.setattr(bidirectional, name, oracle)
    old = bistair.decode(images, spec, force=True)
    assert np.array_equal(new.order, old.order) and new.info == old.info
