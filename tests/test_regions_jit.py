"""The fringe regions' compiled passes (bistair.core.regions_jit) give exactly what the passes
they replaced gave (tests/support/regions_before.py, bistair 02b6580: period_jump_links +
fringe_links for the links, cv2.connectedComponents + reattach + drop_small for the regions,
keep_coherent for the coherent dim pixels), and their period jumps what the NumPy reference
support.reference.period_jumps gives: on random fields and masks (hypothesis), on renders
decoded by several codecs at several noise levels, and on every real capture in
../shared/data that a decode labels."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from conftest import warped_scene
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support import regions_before as before
from support.real_parts import parts
from support.reference import period_jumps

import bistair
from bistair.core.jit import set_threads
from bistair.core.measure import coherent_pixels
from bistair.core.regions import cut_reference, default_cut, fringe_regions
from bistair.core.regions_cuts_jit import cut_links, cut_medians
from bistair.core.regions_jit import NO_CUTS, TILE, link_bits, relink, valid_changes
from bistair.core.regions_labels_jit import label_kept
from bistair.io.read import read_with_spec
from bistair.sim import Imaging, expose, preset, trace
from bistair.sim.presets import preset_spec
from bistair.sim.warp import render_warp

PROPERTY = settings(max_examples=60, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow])


def test_median_sign():
    from bistair.core.regions import _median_sign

    rng = np.random.default_rng(8)
    for _ in range(2000):
        n = int(rng.integers(1, 12))
        values = rng.choice([-2.0, -1e-45, -0.0, 0.0, 1e-45, 0.5, 2.0], n).astype(np.float32)
        if rng.random() < 0.3:
            values = rng.normal(size=n).astype(np.float32)
        want, got = np.median(values), _median_sign(values)
        assert (want >= 0) == (got >= 0)


def field(h: int, w: int, seed: int, noise: float = 0.05, holes: float = 0.15,
          nan: bool = False, ties: bool = False) -> tuple[np.ndarray, ...]:
    """Fringes whose period and slant change from block to block, phase noise, invalid
    pixels (NaN phases there with ``nan``), per-pixel phase noise; with ``ties`` phases
    on a grid of pi/8, where differences land on pi and on the cut."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    period = np.where((x // 37 + y // 23) % 2 == 0, 20.0, 33.0)
    slant = np.where((x // 29) % 3 == 0, 0.3, -0.2)
    phi = 2 * np.pi * (x + slant * y) / period + rng.normal(0, noise, (h, w))
    if ties:
        phi = np.round(phi / (np.pi / 8)) * (np.pi / 8)
    phi = (phi % (2 * np.pi)).astype(np.float32)
    valid = rng.random((h, w)) > holes
    if nan:
        phi[~valid & (rng.random((h, w)) < 0.5)] = np.nan
    sigma = rng.uniform(0.001, 0.05, (h, w)).astype(np.float32)
    return phi, valid, sigma


@pytest.mark.parametrize("shape", [(1, 1), (1, 9), (9, 1), (2, 5), (37, 41), (70, 1200)])
@pytest.mark.parametrize("threads", [1, None])
def test_period_jumps_are_numpys(shape, threads):
    """The links of link_bits are those of the old link pass cut where the NumPy
    reference finds period jumps (windows of 3 gradients, as a decode runs it)."""
    phi, valid, sigma = field(*shape, seed=shape[0] * shape[1])
    jumps = period_jumps(phi, valid, sigma, 0.3, 3)
    want = before.fringe_links(phi, valid, 1.5, 1, sigma, *jumps)
    try:
        set_threads(threads)
        bits = link_bits(phi, valid, sigma, 1.5, 1, 0.3, NO_CUTS, NO_CUTS, False)
    finally:
        set_threads(None)
    assert before.same_links(bits, *want, valid)
    # the reference cut links here that nothing else cuts
    unjumped = before.fringe_links(phi, valid, 1.5, 1, sigma, *(np.zeros_like(j) for j in jumps))
    assert not np.array_equal(unjumped[1], want[1]) or shape[0] * shape[1] < 1000


@PROPERTY
@given(h=st.integers(1, 100), w=st.integers(1, 90), seed=st.integers(0, 2**32 - 1),
       noise=st.sampled_from([0.0, 0.05, 0.3, 3.0]), holes=st.sampled_from([0.0, 0.1, 0.6]),
       sign=st.sampled_from([1, -1]), cut=st.sampled_from([0.6, np.pi / 4, 2.2]),
       nan=st.booleans(), ties=st.booleans(), cuts=st.booleans())
def test_links_are_the_old_passes(h, w, seed, noise, holes, sign, cut, nan, ties, cuts):
    """Every link and kept pixel, for any field: wraps, steps, backward runs, period jumps
    and a codec's cuts, across tile edges (up to four tiles of rows)."""
    phi, valid, sigma = field(h, w, seed, noise, holes, nan, ties)
    rng = np.random.default_rng(seed + 1)
    edges = (rng.random((h - 1, w)) < 0.05, rng.random((h, w - 1)) < 0.05) if cuts else None
    want = before.links_before(phi, valid, cut, sign, sigma, edges)
    got = link_bits(phi, valid, sigma, float(np.float32(cut)), sign, 0.3,
                    *(edges if cuts else (NO_CUTS, NO_CUTS)), cuts)
    assert before.same_links(got, *want, valid)


@PROPERTY
@given(h=st.integers(1, 70), w=st.integers(1, 70), seed=st.integers(0, 2**32 - 1),
       noise=st.sampled_from([0.0, 0.05, 3.0]), holes=st.sampled_from([0.0, 0.3, 0.97, 1.0]),
       nan=st.booleans(), ties=st.booleans(), flip=st.booleans())
def test_cut_is_numpys(h, w, seed, noise, holes, nan, ties, flip):
    """default_cut of a float32 phase (compiled medians) gives what its NumPy reference
    gives, bit for bit: odd and even counts, ties on a grid of pi/8 (differences on pi,
    equal middle values), NaN phases at valid pixels, no pair at all."""
    phi, valid, _ = field(h, w, seed, noise, holes if holes < 1 else 0.0, nan, ties)
    if holes == 1.0:
        valid[:] = False
    if nan:  # NaN where it counts, now and then
        valid |= np.random.default_rng(seed).random((h, w)) < 0.02
    if flip:
        phi = np.ascontiguousarray(phi[:, ::-1])
    cut, want = default_cut(phi, valid), cut_reference(phi, valid)
    assert cut == want or (np.isnan(cut) and np.isnan(want))


def test_cut_medians_of_many_equal_and_spread_values():
    """The medians' count by bins, then selection: a middle pair split across bins, all
    values equal, values from 0 to pi (many exponents), large images (many per bin)."""
    rng = np.random.default_rng(4)
    for h, w in [(400, 600), (8, 8), (3, 2), (1000, 5)]:
        for kind in range(4):
            if kind == 0:
                phi = rng.uniform(0, 2 * np.pi, (h, w))
            elif kind == 1:
                phi = np.full((h, w), 1.25)
            elif kind == 2:  # differences of every size (tiny to pi)
                phi = np.cumsum(10.0 ** rng.uniform(-7, 0.5, (h, w)), axis=1) % (2 * np.pi)
            else:
                phi = (np.arange(w) * 0.7 + np.arange(h)[:, None] * 0.2) % (2 * np.pi)
            phi = phi.astype(np.float32)
            valid = rng.random((h, w)) < 0.8
            meds, counts, ok = cut_medians(phi, valid)
            assert ok
            gx = np.abs(phi[::4, 1::4] - phi[::4, :-1:4][:, :phi[::4, 1::4].shape[1]])
            assert counts[0] == (valid[::4, :-1:4][:, :gx.shape[1]]
                                 & valid[::4, 1::4]).sum()
            assert default_cut(phi, valid) == cut_reference(phi, valid)


@PROPERTY
@given(h=st.integers(1, 100), w=st.integers(1, 60), seed=st.integers(0, 2**32 - 1),
       noise=st.sampled_from([0.05, 0.3]), holes=st.sampled_from([0.0, 0.1]),
       sign=st.sampled_from([1, -1]), change=st.sampled_from([0.0, 0.002, 0.05, 0.5]),
       nan=st.booleans(), cuts=st.booleans())
def test_links_taken_over_are_their_own(h, w, seed, noise, holes, sign, change, nan, cuts):
    """The links of one mask made for another (relink: the tiles whose rows changed,
    across tile edges) and a codec's cuts added (cut_links): link_bits' own of that mask
    with those cuts, bit for bit."""
    phi, weak, sigma = field(h, w, seed, noise, holes, nan)
    rng = np.random.default_rng(seed + 3)
    valid = weak & ~(rng.random((h, w)) < change)  # weak pixels dropped here and there
    edges = (rng.random((h - 1, w)) < 0.05, rng.random((h, w - 1)) < 0.05) if cuts else None
    bits = link_bits(phi, weak, sigma, 1.0, sign, 0.3, NO_CUTS, NO_CUTS, False)
    relink(phi, valid, sigma, 1.0, sign, 0.3, bits, valid_changes(bits, valid))
    if cuts:
        bits = cut_links(bits, *edges)
    want = link_bits(phi, valid, sigma, 1.0, sign, 0.3,
                     *(edges if cuts else (NO_CUTS, NO_CUTS)), cuts)
    assert np.array_equal(bits, want)


def test_relink_makes_every_row_that_reads_a_changed_row():
    """The bytes of row y read the rows y-1 .. y+2 (its vertical link's windows take the
    gradients of row y+1, down to row y+2): one changed row makes every row that reads it
    again (rarely does a single row change a link there, which the property test cannot
    count on)."""
    phi, valid, sigma = field(3 * TILE + 5, 40, 9)
    bits = link_bits(phi, valid, sigma, 1.0, 1, 0.3, NO_CUTS, NO_CUTS, False)
    h = phi.shape[0]
    for r in range(h):
        changed = np.zeros(h, np.uint8)
        changed[r] = 1
        want = min(r + 1, h - 1) - max(r - 2, 0) + 1
        assert relink(phi, valid, sigma, 1.0, 1, 0.3, bits.copy(), changed) == want


@PROPERTY
@given(h=st.integers(2, 80), w=st.integers(2, 60), seed=st.integers(0, 2**32 - 1),
       change=st.sampled_from([0.0, 0.001, 0.01, 0.3]), cuts=st.booleans(),
       strong=st.sampled_from([0.0, 0.9]))
def test_a_labelling_that_takes_links_over_is_its_own(h, w, seed, change, cuts, strong):
    """A labelling of the coherent pixels hands its links on; the decode's labelling of
    the same phase and noise given them (another mask, its cuts, its own cut threshold and
    direction) takes them over where it may: the same regions as its own pass; the links
    are taken once."""
    from bistair.core import regions

    phi, weak, sigma = field(h, w, seed, 0.05, 0.1)
    rng = np.random.default_rng(seed + 4)
    valid = weak & ~((rng.random((h, w)) < change) & (rng.random((h, w)) > strong))
    edges = (rng.random((h - 1, w)) < 0.05, rng.random((h, w - 1)) < 0.05) if cuts else None
    want = regions.label_fringes(phi, valid, phase_noise=sigma, boundaries=edges)
    assert want.links is None  # (handed on only when asked)
    links = regions.label_fringes(phi, weak, phase_noise=sigma, share=True).links
    assert links is not None and links.bits is not None
    got = regions.label_fringes(phi, valid, phase_noise=sigma, boundaries=edges,
                                links=links)
    assert links.bits is None  # taken over once
    assert got.n == want.n and np.array_equal(got.size, want.size)
    assert np.array_equal(got.roots[got.labels], want.roots[want.labels])


def test_links_are_shared_only_for_the_same_phase_and_noise():
    """A labelling given the links of another phase, or of the same phase with another
    noise array (even of equal values), makes its own links; so does one given links
    already taken, and one whose changed cut threshold cuts a link otherwise."""
    from bistair.core import regions

    phi, weak, sigma = field(64, 80, 5, 0.05, 0.1)
    taken = []
    original = regions._shared_links

    def spy(*args):
        out = original(*args)
        taken.append(out[0] is not None)
        return out

    try:
        regions._shared_links = spy
        for other, noise in [(phi.copy(), sigma), (phi, sigma.copy()), (phi, sigma)]:
            links = regions.label_fringes(phi, weak, phase_noise=sigma, share=True).links
            regions.label_fringes(other, weak, phase_noise=noise, links=links)
        regions.label_fringes(phi, weak, phase_noise=sigma, links=links)  # taken already
        cut = regions.default_cut(phi, weak)
        steps = np.abs(np.diff(phi, axis=1))[weak[:, 1:] & weak[:, :-1]]
        other_cut = float(np.sort(steps[steps > cut])[0])  # cuts one link more or less
        links = regions.label_fringes(phi, weak, phase_noise=sigma, share=True).links
        regions.label_fringes(phi, weak, cut=other_cut, phase_noise=sigma, links=links)
    finally:
        regions._shared_links = original
    assert taken == [False, False, False, False, False, True, False, False, False]


def masks(draw_rng: np.random.Generator, h: int, w: int, kind: str) -> np.ndarray:
    """Masks of random pixels, of stripes with gaps (fringe regions), or of thin spirals
    and combs whose parts meet far from where they start (joins across tiles)."""
    if kind == "random":
        return draw_rng.random((h, w)) < draw_rng.uniform(0.2, 0.8)
    y, x = np.mgrid[0:h, 0:w]
    if kind == "stripes":
        mask = (x + (y // 7)) % int(draw_rng.integers(3, 12)) > 0
        return mask & (draw_rng.random((h, w)) > 0.03)
    comb = (x % 4 == 0) | (y == h - 1) | ((y % 13 == 0) & (x % 8 < 6))
    return comb & (draw_rng.random((h, w)) > 0.01)


@PROPERTY
@given(h=st.integers(1, 120), w=st.integers(1, 90), seed=st.integers(0, 2**32 - 1),
       kind=st.sampled_from(["random", "stripes", "comb"]),
       tile=st.sampled_from([1, 2, 3, 7, TILE, 200]), count=st.booleans())
def test_labels_are_opencvs(h, w, seed, kind, tile, count):
    """The labels of label_kept are cv2.connectedComponents' (4-connected, their numbering
    too) for any mask and tile height; its counts are each region's pixels and strong
    pixels."""
    rng = np.random.default_rng(seed)
    keep = masks(rng, h, w, kind)
    strong = rng.random((h, w)) < 0.3
    bits = (keep * np.uint8(4) | rng.integers(0, 2, (h, w), np.uint8) * np.uint8(8)
            ).astype(np.uint8)
    labels, roots, n, size, bright = label_kept(bits, strong if count else NO_CUTS, count,
                                                tile, 0)
    n_cv, want = cv2.connectedComponents(keep.view(np.uint8), connectivity=4,
                                         ltype=cv2.CV_32S)
    assert n == n_cv - 1
    assert np.array_equal(roots[labels], want)
    assert np.array_equal(size, np.bincount(want[keep], minlength=n + 1))
    expected = np.bincount(want[keep & strong], minlength=n + 1) if count else np.zeros(n + 1)
    assert np.array_equal(bright, expected)


@PROPERTY
@given(h=st.integers(1, 90), w=st.integers(1, 90), seed=st.integers(0, 2**32 - 1),
       noise=st.sampled_from([0.05, 0.5, 3.0]), holes=st.sampled_from([0.0, 0.1, 0.5]),
       min_size=st.sampled_from([1, 2, 20, 60]), cuts=st.booleans())
def test_regions_are_the_old_passes(h, w, seed, noise, holes, min_size, cuts):
    """fringe_regions' labels and count, and coherent_pixels' pixels, for any field."""
    phi, valid, sigma = field(h, w, seed, noise, holes)
    rng = np.random.default_rng(seed + 2)
    edges = (rng.random((h - 1, w)) < 0.05, rng.random((h, w - 1)) < 0.05) if cuts else None
    labels, n = fringe_regions(phi, valid, None, min_size, sigma, edges)
    want, n_want = before.regions_before(phi, valid, None, min_size, sigma, edges)
    assert n == n_want and labels.dtype == np.int32 and np.array_equal(labels, want)
    strong = valid & (rng.random((h, w)) < rng.uniform(0, 0.3))
    for thresholds in [(10, 100), (1, 5), (3, 10**9)]:
        assert np.array_equal(coherent_pixels(phi, valid, strong, sigma, *thresholds)[0],
                              before.coherent_before(phi, valid, strong, sigma, *thresholds))


HARD = dict(gamma=2.2, read_noise=0.03, camera_blur=1.2, projector_blur=1.0, ambient=0.15)


def render(scene: str, method: str, noise: float | None, **params):
    """Captures of a small scene: a warp (``warp<seed>``) or a preset of the simulator
    (320 x 256 with hard optics, or with ``noise`` None 640 x 512 as
    tests/support/pre_speed.py renders it: mugs-on-wall's stair edges, the codec's cuts,
    show at that size)."""
    if scene.startswith("warp"):
        spec = bistair.make_spec(method, width=1080, height=1080, period=30, **params)
        scene = warped_scene(int(scene[4:]), noise, 1.2, size=(240, 320))
        return render_warp(spec, scene)[0], spec
    spec = (preset_spec(scene, method, **params) if method == "bidirectional" else
            bistair.make_spec(method, width=1920, height=1080, period=30, **params))
    if noise is None:
        rig, sc = preset(scene, camera_size=(640, 512))
        imaging = Imaging(seed=3)
        return expose(trace(rig, sc, imaging), bistair.encode(spec), imaging), spec
    rig, sc = preset(scene, camera_size=(320, 256))
    imaging = Imaging(**{**HARD, "read_noise": noise}, seed=5)
    return expose(trace(rig, sc, imaging), bistair.encode(spec), imaging), spec


RENDERS = [  # scene, method, noise, options
    ("warp0", "bidirectional", 0.01, {}), ("warp1", "bidirectional", 0.08, {}),
    ("warp2", "bidirectional", 0.03, {"strategy": "paper"}), ("warp3", "lv", 0.05, {}),
    ("warp4", "phase-coding", 0.02, {}), ("warp5", "graycode", 0.04, {"strategy": "region"}),
    ("paper-sim", "bidirectional", 0.03, {}), ("mugs-on-wall", "bidirectional", 0.06, {}),
    ("two-masks", "lv", 0.1, {}), ("mugs-on-wall", "bidirectional", None, {}),
]


# the renders whose decode's labelling takes over the links of its coherent dim pixels'
# labelling (FringeSet.links; measured, the same as the thread's slot handed over before)
HANDED_ON = {("warp0", 0.01), ("warp2", 0.03), ("warp3", 0.05), ("warp4", 0.02),
             ("mugs-on-wall", None)}


@pytest.mark.parametrize(("scene", "method", "noise", "options"), RENDERS,
                         ids=[f"{s}-{m}-{n}" for s, m, n, _ in RENDERS])
def test_renders_label_as_before(scene, method, noise, options, monkeypatch):
    """Every labelling a decode of a render runs (its coherent dim pixels, its codec's
    regions with the codec's cuts): the same links, labels and pixels as before. The
    bidirectional region decoder labels through ``fringe_regions`` here (``GATHER`` off):
    the labelling that gathers its stair sums gives the same decode
    (tests/test_labelspace.py)."""
    from bistair.codecs import bidirectional

    monkeypatch.setattr(bidirectional, "GATHER", False)
    images, spec = render(scene, method, noise)
    with before.Watch() as watch:
        try:
            bistair.decode(images, spec, force=True, **options)
        except bistair.BistairError:
            pass  # refused after its labellings ran
    assert watch.differ == []
    assert watch.seen["link_bits"] >= 1 and watch.seen["fringe_regions"] >= 1
    assert watch.seen["shared links"] == int((scene, noise) in HANDED_ON)
    if noise is None:  # (the one render here whose decoder cuts links itself)
        assert watch.seen["codec cuts"] >= 1


REAL = list(parts())


@pytest.mark.parametrize(("name", "folder", "spec", "options"), REAL,
                         ids=[p[0] for p in REAL])
def test_real_captures_label_as_before(name, folder, spec, options):
    stack, spec = read_with_spec(folder, spec)
    with before.Watch() as watch:
        bistair.decode(stack, spec, force=True, **options)
    if watch.seen["link_bits"] == 0:
        pytest.skip("its decode labels no fringe regions")
    assert watch.differ == []


@pytest.mark.parametrize("shape", [(64, 1001), (33, 2), (1, 7)])
def test_labels_of_a_checkerboard(shape):
    """The most runs a row can hold (every other pixel) and a region a pixel: the ids a
    tile may make are all used, none overflows into the next tile's."""
    y, x = np.mgrid[0:shape[0], 0:shape[1]]
    keep = (x + y) % 2 == 0
    labels, roots, n, size, _ = label_kept(keep.astype(np.uint8) * np.uint8(4), NO_CUTS,
                                           False, TILE, 0)
    n_cv, want = cv2.connectedComponents(keep.view(np.uint8), connectivity=4,
                                         ltype=cv2.CV_32S)
    assert n == n_cv - 1 == keep.sum() and np.array_equal(roots[labels], want)
    assert (size[1:] == 1).all()


def test_the_cheap_noise_test_passes_where_the_exact_one_does():
    """link_bits runs the period-jump test only where cheap forms of its first two tests
    pass: the second's (no square root, no division, a looser margin) must pass wherever
    the test's own does, at any scale (noise from 0 to overflow, near the threshold)."""
    import math

    import numba

    from bistair.core import regions_jit

    link_bits(np.zeros((2, 2), np.float32), np.ones((2, 2), bool),
              np.zeros((2, 2), np.float32), 1.0, 1, 0.3, NO_CUTS, NO_CUTS, False)
    loud = regions_jit._loud  # compiled with the module's first kernel

    @numba.njit
    def check(px, py, qx, qy, pn, qn, noise_p, noise_q) -> int:
        misses = 0
        for i in range(px.size):
            one = np.float32(1.0)
            dx, dy = px[i] - qx[i], py[i] - qy[i]
            d2 = dx * dx + dy * dy
            # _jump's second test, as it is written there
            spread = np.float32(2.0) * max(noise_p[i] / np.float32(math.sqrt(max(pn[i], one))),
                                           noise_q[i] / np.float32(math.sqrt(max(qn[i], one))))
            limit = np.float32(4.0) * spread
            passes = not (d2 < limit * limit * np.float32(0.9999))
            inv_p = np.float32(1.0) / np.float32(math.sqrt(pn[i]))
            inv_q = np.float32(1.0) / np.float32(math.sqrt(qn[i]))
            if passes and not loud(px[i], py[i], qx[i], qy[i], noise_p[i], noise_q[i], inv_p,
                                   inv_q):
                misses += 1
        return misses

    rng = np.random.default_rng(4)
    n = 200_000
    px, py, qx, qy = (rng.normal(0, 0.3, n).astype(np.float32) for _ in range(4))
    pn, qn = (rng.integers(3, 7, n).astype(np.float32) for _ in range(2))
    dx, dy = px - qx, py - qy
    d = np.sqrt(dx.astype(np.float64) ** 2 + dy.astype(np.float64) ** 2)
    # noise putting the threshold at the step itself, a few units in the last place apart
    near = d / (8.0 * np.maximum(1 / np.sqrt(pn), 1 / np.sqrt(qn)))
    noise_p = (near * rng.choice([1.0, 1 - 1e-7, 1 + 1e-7, 1 - 3e-5, 1 + 3e-5], n)
               ).astype(np.float32)
    noise_q = (noise_p * rng.uniform(0, 1, n)).astype(np.float32)
    scales = rng.choice([1.0, 1e-18, 1e-22, 1e-40, 1e18, 1e20], n)
    px, py, qx, qy = (a * scales.astype(np.float32) for a in (px, py, qx, qy))
    noise_p, noise_q = (a * scales.astype(np.float32) for a in (noise_p, noise_q))
    noise_p[::97] = np.nan
    noise_q[::89] = 0.0
    assert check(px, py, qx, qy, pn, qn, noise_p, noise_q) == 0
