"""Bidirectional's label space, old passes against new, with the OpenCV floor of a 4-step
decode in the same rounds (issue 32 part C).

The inputs are the decode's own: one default (bidirectional) decode of the speed scene
(:mod:`bistair.evaluation.speed`, as ``decode_speed.py`` and ``bistair bench`` render it;
kept in /tmp between runs) is run with
``relabel_stair_profiles`` watched and its arguments kept (provisional labels, roots, the
final numbering, the four maps). Then, in interleaved rounds: the final numbering and the
(region, row) stair sums as the decode at the branch point ran them (``relabel``, then
``label_stair_sums``, a scan of its own) and as it runs them now (``relabel_stair_sums``,
gathered in the numbering's scan), each on a fresh copy of the provisional labels (the
copy timed alone too); the band runs' transitions dropped by the NumPy of the branch point
(``tests/support/labelspace_before.py``) and by the compiled pass, on a copy of the runs
the decode's first band analysis cut. One kernel thread and process CPU time by default,
or ``--wall`` on every core; the minimum over the rounds, in ms and ns a pixel.

    python benchmarks/labelspace_speed.py [--size 1.3|12] [--rounds 8] [--wall] [--decode]
                                          [--stages]

``--decode`` times whole default decodes instead, interleaved with the floor; ``--stages``
the label-space stages (band runs, nearest levels, level offsets, centroids, split
profiles) on the arguments the decode gave them, each called by name: run either with each
checkout on ``PYTHONPATH`` for a before / after pair.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import cv2
import numpy as np
from regions_speed import SIZES, report, rounds, scene  # the same scene and timing

import bistair
from bistair.codecs.bidirectional import bands
from bistair.codecs.bidirectional.bands import Runs
from bistair.core.jit import set_threads
from bistair.core.memory import keep_freed_memory
from bistair.evaluation.speed import opencv_floor


def decode_inputs(frames: np.ndarray, spec) -> tuple[tuple, Runs]:
    """The arguments of the decode's ``relabel_stair_profiles`` (the labels copied) and the
    runs its first band analysis hands ``bands._drop_transitions``."""
    from bistair.codecs import bidirectional

    seen: list[tuple] = []
    runs: list[Runs] = []
    gathered, drop = bidirectional.relabel_stair_profiles, bands._drop_transitions

    def watch(labels, *args):
        if not seen:
            seen.append((labels.copy(), *args))
        return gathered(labels, *args)

    def watch_runs(r: Runs) -> Runs:
        if not runs:
            runs.append(copied(r))
        return drop(r)

    bidirectional.relabel_stair_profiles, bands._drop_transitions = watch, watch_runs
    try:
        bistair.decode(frames, spec)
    finally:
        bidirectional.relabel_stair_profiles, bands._drop_transitions = gathered, drop
    return seen[0], runs[0]


def copied(runs: Runs) -> Runs:
    return Runs(**{k: np.array(v, copy=True) for k, v in runs.__dict__.items()})


def cases(frames: np.ndarray, spec) -> dict:
    from bistair.codecs.bidirectional.profiles_jit import label_stair_sums, relabel_stair_sums
    from bistair.core.regions_labels_jit import relabel

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from support.labelspace_before import drop_transitions  # the oracle, in tests/support

    (labels, roots, remap, phi, theta, stair_mod, mod, n), runs = decode_inputs(frames, spec)
    final = labels.copy()
    relabel(final, roots, remap)
    h, w = labels.shape
    print(f"{h}x{w}: {n} regions, {int(labels.max())} provisional labels, "
          f"{runs.uid.size} band runs")

    def old() -> None:
        lab = labels.copy()
        relabel(lab, roots, remap)
        label_stair_sums(lab, phi, theta, stair_mod, mod, n)

    return {
        "floor": lambda: opencv_floor(frames),
        "copy of the labels": lambda: labels.copy(),
        "old relabel (+ the copy)": lambda: relabel(labels.copy(), roots, remap),
        "old label_stair_sums": lambda: label_stair_sums(final, phi, theta, stair_mod, mod,
                                                         n),
        "old both (+ the copy)": old,
        "new relabel_stair_sums (+ copy)": lambda: relabel_stair_sums(
            labels.copy(), roots, remap, phi, theta, stair_mod, mod, n),
        "copy of the runs": lambda: copied(runs),
        "old _drop_transitions (+ copy)": lambda: drop_transitions(copied(runs)),
        "new _drop_transitions (+ copy)": lambda: bands._drop_transitions(copied(runs)),
    }


def stage_cases(frames: np.ndarray, spec) -> dict:
    """The label-space stages on the arguments a default decode gave them (its first band
    analysis; its split profiles), each called through the name the decode calls, so that
    the same jobs time any checkout (``--stages`` under each ``PYTHONPATH``)."""
    from bistair.codecs import bidirectional
    from bistair.codecs.bidirectional import bands, evidence, profiles, response

    names = ("row_runs", "level_offsets", "profile_centroids", "split_profiles")
    seen: dict[str, tuple] = {}
    kept = {name: getattr(bidirectional, name) for name in names}

    def watch(name):
        def watched(*args):
            seen.setdefault(name, args)
            return kept[name](*args)
        return watched

    for name in names:
        setattr(bidirectional, name, watch(name))
    try:
        bistair.decode(frames, spec)
    finally:
        for name in names:
            setattr(bidirectional, name, kept[name])
    prof, levels = seen["row_runs"]
    theta = np.arctan2(prof.sin, prof.cos)
    print(f"{prof.region.size} (region, row) entries, {levels.size} levels, "
          f"{len(seen.get('split_profiles', (0, 0, []))[2])} splits")
    jobs = {
        "floor": lambda: opencv_floor(frames),
        "row_runs": lambda: bands.row_runs(prof, levels),
        "nearest_level": lambda: bands.nearest_level(theta, levels),
        "level_offsets": lambda: response.level_offsets(*seen["level_offsets"]),
        "profile_centroids": lambda: profiles.profile_centroids(*seen["profile_centroids"]),
    }
    if "split_profiles" in seen:
        jobs["split_profiles"] = lambda: evidence.split_profiles(*seen["split_profiles"])
    return jobs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="1.3", choices=sorted(SIZES))
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--wall", action="store_true",
                        help="every core, wall time (else one thread, CPU time)")
    parser.add_argument("--decode", action="store_true", help="time whole default decodes")
    parser.add_argument("--stages", action="store_true",
                        help="time the label-space stages by name (any checkout)")
    args = parser.parse_args()
    keep_freed_memory()
    threads = set_threads(None if args.wall else 1)
    cv2.setNumThreads(threads)
    clock = time.perf_counter if args.wall else time.process_time
    frames, spec = scene(args.size)
    if args.decode:
        jobs = {"floor": lambda: opencv_floor(frames),
                "default decode": lambda: bistair.decode(frames, spec)}
    elif args.stages:
        jobs = stage_cases(frames, spec)
    else:
        jobs = cases(frames, spec)
    for job in jobs.values():  # compiled and warm
        job()
    report(rounds(jobs, args.rounds, clock), frames, args.size, threads, args.rounds, args.wall)


if __name__ == "__main__":
    main()
