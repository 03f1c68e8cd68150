"""``bistair stereo``: two cameras and a projector (:mod:`bistair.app.stereo`; ``stereo
--window``: :mod:`bistair.app.stereo_stream`).

Registered on the command group by :mod:`bistair.app.cli`; imports deferred into the
commands, as there."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from .options import (
    CliError,
    Input,
    Output,
    quiet_option,
    reports_errors,
    strategy_option,
    threads_option,
)


@click.command("stereo")
@click.argument("left", type=Input(text=True))
@click.argument("right", type=Input(text=True))
@click.option("--spec", "spec_path", type=Input(), default=None,
              help="spec.json of the pattern set, for both cameras [default: spec.json beside "
              "LEFT]")
@click.option("--calibration", required=True, type=Input(),
              help="the two cameras' calibration (bistair calibrate-stereo, or "
              "import-calibration --stereo)")
@click.option("--out", "-o", required=True, type=Output(), help="output folder")
@click.option("--depth-range", default=None, metavar="MIN:MAX",
              help="keep points with depth z in [MIN, MAX] mm (left camera frame); also "
              "narrows the search; needed, holding the whole scene, for a single-period "
              "spec (stereo phase unwrapping)")
@click.option("--force", is_flag=True, help="keep what the checks would refuse (too few "
              "matches; the decoder's checks where it offers this), as warnings in info.json")
@strategy_option
@click.option("--min-modulation", type=float, default=None,
              help="modulation threshold as a fraction of full scale [default: from noise]")
@click.option("--smooth", type=float, default=None, metavar="PX",
              help="Gaussian sigma of a smoothing of the projector coordinates before "
              "matching (never across surfaces): less depth noise, less lateral detail; 0: "
              "none [default: 1; not for a single-period spec or --window, which match no "
              "projector coordinates]")
@click.option("--no-previews", is_flag=True, help="skip the decodes' PNG previews (with "
              "--window: each window's depth.png)")
@click.option("--continue-unseen", is_flag=True,
              help="single-period spec: also decide the left pixels the right camera cannot "
                   "see, by continuing their decided neighbours' phase (off: the published "
                   "pipeline leaves them)")
@click.option("--window", default=None, metavar="N|N+K",
              help="two streams of one single-period N-step set whose shift advances one "
              "step per frame: a depth map for every window of N frames (N+K: motion "
              "compensated to order K) into OUT/<start>/ (depth.npy, cloud.ply, info.json); "
              "needs --depth-range")
@click.option("--starts", default=None, metavar="S,S,...",
              help="with --window: the window starts to write [default: every one]")
@threads_option
@quiet_option
@reports_errors
def stereo(left: str, right: str, spec_path: Path | None, calibration: Path, out: Path,
           depth_range: str | None, force: bool, strategy: str | None,
           min_modulation: float | None, smooth: float | None, no_previews: bool,
           continue_unseen: bool, window: str | None, starts: str | None,
           quiet: bool) -> None:
    """Two cameras and a projector: decode both cameras' captures of one pattern set, match
    equal absolute phase along rectified rows, triangulate.

    LEFT, RIGHT: each camera's captures, a folder, a quoted glob pattern or a .npy stack.
    Writes OUT/left/ and OUT/right/ (each decode), disparity.npy, depth.npy, depth.png,
    cloud.ply (left camera frame, mm) and info.json. The projector needs no calibration,
    except for a single-period spec (patterns multifreq --periods T): its fringe order comes
    from the projector's pose in the calibration and --depth-range (stereo phase
    unwrapping); pixels that stay ambiguous are left out."""
    from ..decode import parse_depth_range
    from ..progress import Progress
    from ..stereo import stereo_folder, warnings

    low, high = (0.0, np.inf) if depth_range is None else parse_depth_range(depth_range)
    if window is not None or starts is not None:
        if continue_unseen:
            raise CliError("--continue-unseen decides one set's unseen pixels; a stream's "
                           "tracked windows do not continue: drop one")
        _stereo_stream(left, right, spec_path, calibration, out, (low, high), window, starts,
                       force, strategy, min_modulation, smooth, not no_previews, quiet)
        return
    options = {k: v for k, v in (("strategy", strategy), ("min_modulation", min_modulation))
               if v is not None}
    if continue_unseen:
        options["continue_unseen"] = True
    with Progress(quiet) as say:
        res = stereo_folder(left, right, out, calibration, spec_path, min_depth=low,
                            max_depth=high, force=force, smooth=smooth,
                            previews=not no_previews, progress=say, **options)
    for message in warnings(res):
        click.echo(f"Warning: {message}", err=True)
    if quiet:
        return
    info = res.info
    if info.get("unwrapping") == "stereo":
        continued = info.get("continued", 0)
        unseen = (f" and {continued} continued where the right camera cannot see them"
                  if continued else "")
        click.echo(f"{info['decided']} points from {info['left_decoded']} decoded left pixels "
                   f"({100 * info['decided_fraction']:.1f}%; by the projector at "
                   f"{low:g}-{high:g} mm, {info.get('grown', 0)} of them by their "
                   f"neighbours{unseen}: {info['undecided']} undecided, two or more candidates "
                   f"agree; {info['no_candidate']} without one; "
                   f"{info['not_confirmed'] + info['unsupported']} not confirmed by the "
                   f"right camera or the rows beside); wrote {out}")
        return
    rejected = info["inconsistent"] + info["ambiguous"] + info["not_monotonic"] + \
        info["other_axis"] + info["alone"]
    within = f" at {low:g}-{high:g} mm" if depth_range else ""
    click.echo(f"{info['matched']} points from {info['left_decoded']} decoded left pixels "
               f"({100 * info['matched_fraction']:.1f}%; {info['unmatched']} without a match "
               f"in the right camera{within}, {rejected} rejected by the checks); wrote {out}")


def _stereo_stream(left: str, right: str, spec_path: Path | None, calibration: Path,
                   out: Path, depth: tuple[float, float], window: str | None,
                   starts: str | None, force: bool, strategy: str | None,
                   min_modulation: float | None, smooth: float | None, previews: bool,
                   quiet: bool) -> None:
    """``stereo --window``: a depth map per window of two streams
    (:mod:`bistair.app.stereo_stream`)."""
    from ..progress import Progress
    from ..stereo_stream import stereo_stream

    if window is None:
        raise CliError("--starts needs --window N or N+K")
    if strategy is not None:
        raise CliError("--strategy does not apply to a stream (--window): stereo phase "
                       "unwrapping decodes it")
    if smooth is not None:
        raise CliError("--smooth does not apply to a stream (--window): stereo phase "
                       "unwrapping takes each pixel's depth from the projector column of its "
                       "phase, with no smoothing")
    with Progress(quiet) as say:
        kept = stereo_stream(left, right, out, calibration, spec_path, window, starts,
                             *depth, force=force, min_modulation=min_modulation,
                             previews=previews, progress=say)
    for message in dict.fromkeys(w for r in kept for w in r.info.get("warnings", [])):
        click.echo(f"Warning: {message}", err=True)  # (as one set's; also when quiet)
    if quiet:
        return
    shares = [r.info["decided_fraction"] for r in kept]
    ms = 1000 * float(np.median([r.info["cpu_seconds"] for r in kept[1:] or kept]))
    click.echo(f"{len(kept)} depth maps of --window {window.strip()} at {depth[0]:g}-"
               f"{depth[1]:g} mm: {100 * min(shares):.1f}-{100 * max(shares):.1f}% of the "
               f"decoded left pixels decided, {ms:.1f} ms CPU a window; wrote {out}")
