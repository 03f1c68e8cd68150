"""``bistair decode``, ``bistair reconstruct`` and ``bistair height``: captures into phase,
points and heights (:mod:`bistair.app.decode`; ``decode --window``:
:mod:`bistair.app.decode_stream`).

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
    force_option,
    print_warnings,
    quiet_option,
    reports_errors,
    strategy_option,
    threads_option,
)


@click.command()
@click.argument("captures", nargs=-1, required=True, type=Input(text=True))
@click.option("--spec", "spec_path", type=Input(), default=None,
              help="spec.json of the pattern set [default: spec.json in the captures' folder]")
@click.option("--out", "-o", required=True, type=Output(text=True),
              help="output folder: phase.npy, coord.npy, order.npy, ..., the PNG previews "
              "and info.json")
@strategy_option
@click.option("--min-modulation", type=float, default=None,
              help="modulation threshold as a fraction of full scale, between 0 and 1 "
              "[default: from noise]")
@click.option("--no-previews", is_flag=True, help="skip the PNG previews")
@click.option("--window", default=None, metavar="N|N+K",
              help="a stream of one single-period N-step set whose shift advances one step "
              "per frame: decode every window of N frames (N+K: motion compensated to order "
              "K) into OUT/<start>/ (wrapped.npy, modulation.npy, info.json)")
@click.option("--starts", default=None, metavar="S,S,...",
              help="with --window: the window starts to write [default: every one]")
@force_option
@threads_option
@quiet_option
@reports_errors
def decode(captures: tuple[str, ...], spec_path: Path | None, out: str, strategy: str | None,
           min_modulation: float | None, no_previews: bool, window: str | None,
           starts: str | None, force: bool, quiet: bool) -> None:
    """Decode captured images into absolute phase, projector coordinate and fringe order.

    CAPTURES: a folder, image files, or quoted glob patterns ('scan/pat*.png'), in that
    order; a folder's or pattern's images in natural name order; or one .npy stack.
    """
    from ..decode import decode_folder
    from ..progress import Progress

    if window is not None or starts is not None:
        _decode_stream(list(captures), spec_path, out, window, starts, min_modulation,
                       strategy, force, quiet)
        return
    from ..decode_stream import refuse_single_period

    refuse_single_period(list(captures), spec_path)
    options = {k: v for k, v in (("strategy", strategy), ("min_modulation", min_modulation),
                                 ("force", force or None)) if v is not None}
    with Progress(quiet) as say:
        result = decode_folder(list(captures), out, spec_path, previews=not no_previews,
                               progress=say, **options)
    print_warnings(result)
    if quiet:
        return
    if hasattr(result, "x"):
        click.echo(f"decoded {result.method} on both axes: {int(result.mask.sum())} of "
                   f"{result.mask.size} pixels valid on both ({100 * result.mask.mean():.1f}%; "
                   f"x {100 * result.x.mask.mean():.1f}%, y {100 * result.y.mask.mean():.1f}%); "
                   f"wrote {out}")
    else:
        click.echo(f"decoded {result.method}: {int(result.mask.sum())} of {result.mask.size} "
                   f"pixels valid ({100 * result.mask.mean():.1f}%); wrote {out}")


def _decode_stream(captures: list[str], spec_path: Path | None, out: str, window: str | None,
                   starts: str | None, min_modulation: float | None, strategy: str | None,
                   force: bool, quiet: bool) -> None:
    """``decode --window``: a stream decoded window by window
    (:mod:`bistair.app.decode_stream`)."""
    from ..decode_stream import decode_stream
    from ..progress import Progress

    if window is None:
        raise CliError("--starts needs --window N or N+K")
    if strategy is not None or force:
        raise CliError(f"--{'strategy' if strategy is not None else 'force'} does not apply "
                       "to a stream (--window): it gives the wrapped phase, no fringe order")
    with Progress(quiet) as say:
        written = decode_stream(captures, spec_path, out, window, starts, min_modulation,
                                progress=say)
    if not quiet:
        count = sum(1 for p in Path(written).iterdir() if p.is_dir() and p.name.isdigit())
        click.echo(f"decoded {count} windows of --window {window.strip()}; wrote {out}")


@click.command()
@click.argument("captures", type=Input())
@click.option("--spec", "spec_path", type=Input(), default=None,
              help="spec.json of the pattern set [default: CAPTURES/spec.json]")
@click.option("--calibration", required=True, type=Input(),
              help="calibration file (JSON) from 'bistair calibrate' or 'bistair "
              "import-calibration'")
@click.option("--out", "-o", required=True, type=Output(file=True),
              help="point cloud to write (.ply)")
@click.option("--depth", type=Output(), default=None,
              help="folder for depth.npy and depth.png [default: OUT without .ply + -depth]")
@strategy_option
@click.option("--depth-range", default=None, metavar="MIN:MAX",
              help="keep points with depth z in [MIN, MAX] mm (camera frame)")
@click.option("--epipolar-tolerance", type=float, default=1.5, show_default=True,
              metavar="PX", help="specs of both axes: drop pixels whose projector column and "
              "row lie farther than this (projector pixels) from the camera ray's projection")
@force_option
@threads_option
@quiet_option
@reports_errors
def reconstruct(captures: Path, spec_path: Path | None, calibration: Path, out: Path,
                depth: Path | None, strategy: str | None, depth_range: str | None,
                epipolar_tolerance: float, force: bool, quiet: bool) -> None:
    """Decode, triangulate with a calibration, write a coloured PLY and a depth map.

    With a spec of both axes (orientation both), each point fits both projector
    coordinates, and pixels whose coordinates no point on their camera ray shows are
    dropped as wrong decodes."""
    from ..decode import parse_depth_range, reconstruct_folder
    from ..progress import Progress

    if out.suffix.lower() != ".ply":
        raise CliError(f"--out {out} must name a .ply file: the point cloud is written as PLY")
    depth = depth or out.with_name(out.stem + "-depth")
    low, high = (0.0, np.inf) if depth_range is None else parse_depth_range(depth_range)
    options = {k: v for k, v in (("strategy", strategy), ("force", force or None))
               if v is not None}
    with Progress(quiet) as say:
        rec = reconstruct_folder(captures, spec_path, calibration, out, depth_dir=depth,
                                 min_depth=low, max_depth=high,
                                 epipolar_tolerance=epipolar_tolerance, progress=say, **options)
    for message in rec.info.get("warnings", []):
        click.echo(f"Warning: {message}", err=True)
    if quiet:
        return
    notes = []
    if "both_axes" in rec.info:
        notes.append(f"{rec.info['both_axes']} pixels with both axes, {rec.info['one_axis']} "
                     f"with the {rec.info['baseline_axis']} alone, {rec.info['off_epipolar']} "
                     f"off the epipolar line dropped")
    if depth_range is not None:
        notes.append(f"{rec.info['outside_range']} outside the depth range")
    note = f" ({'; '.join(notes)})" if notes else ""
    click.echo(f"{int(rec.mask.sum())} points{note}; wrote {out} and {depth}/depth.npy")


@click.command()
@click.argument("captures", type=Input())
@click.option("--reference", required=True, type=Input(),
              help="captures of the flat reference plane (same spec)")
@click.option("--spec", "spec_path", type=Input(), default=None,
              help="spec.json of the pattern set [default: CAPTURES/spec.json]")
@click.option("--out", "-o", required=True, type=Output(),
              help="output folder: height.npy (mm, NaN where invalid) and height.png")
@click.option("--plane", "planes", multiple=True, metavar="FOLDER:HEIGHT_MM",
              type=Input(text=True, path_of=lambda v: v.rpartition(":")[0]),
              help="captures of a plane parallel to the reference and its height in mm "
              "(repeatable; two or more calibrate the height per pixel)")
@click.option("--geometry", default=None, metavar="DISTANCE,BASELINE,FREQUENCY",
              help="mm, mm and fringes per mm on the reference, for the classical formula "
              "instead of planes")
@quiet_option
@reports_errors
def height(captures: Path, reference: Path, spec_path: Path | None, out: Path,
           planes: tuple[str, ...], geometry: str | None, quiet: bool) -> None:
    """Height above a reference plane without a calibration (phase-to-height)."""
    from ..decode import height_folder
    from ..progress import Progress

    with Progress(quiet) as say:
        h = height_folder(captures, reference, out, spec_path, planes, geometry, progress=say)
    if not quiet:
        click.echo(f"height of {int(np.isfinite(h).sum())} pixels; wrote {out}/height.npy")
