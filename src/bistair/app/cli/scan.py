"""``bistair scan``: project a pattern set and grab it with a camera.

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
    print_warnings,
    quiet_option,
    reports_errors,
)


@click.command()
@click.option("--spec", "spec_path", type=Input(), default=None,
              help="spec.json of the pattern set to project (from 'bistair patterns')")
@click.option("--display", required=True, metavar="DISPLAY",
              help="window[:SCREEN] (a full-screen window on the projector's screen, from 0) "
              "or none (the projector holds the patterns and triggers the camera)")
@click.option("--camera", required=True, metavar="CAMERA",
              help="opencv:INDEX|URL, genicam:PRODUCER.cti[:SERIAL], screen[:MONITOR] or "
              "sim[:SCENE[:WxH]][@FPS]")
@click.option("--out", "-o", type=Output(), default=None,
              help="output folder: NN.png, spec.json, scan.json (replaced as a whole)")
@click.option("--settle-ms", type=float, default=None,
              help="wait after showing each pattern [default: as measured by "
              "--measure-latency]")
@click.option("--average", type=int, default=1, show_default=True,
              help="frames grabbed and averaged per pattern")
@click.option("--drop", type=int, default=None,
              help="frames dropped after the wait [default: the camera's buffer]")
@click.option("--exposure", type=float, default=None,
              help="camera exposure in its own units (genicam: microseconds)")
@click.option("--gain", type=float, default=None, help="camera gain in its own units")
@click.option("--pixel-format", type=click.Choice(["Mono8", "Mono12", "Mono16"]),
              default=None, help="genicam pixel format")
@click.option("--decode", "decode_it", is_flag=True,
              help="also decode the scan into OUT/decode/")
@click.option("--calibration", type=Input(), default=None,
              help="also reconstruct: OUT/decode/cloud.ply, depth.npy")
@click.option("--depth-range", default=None, metavar="MIN:MAX",
              help="with --calibration: keep points with depth z in [MIN, MAX] mm")
@click.option("--measure-latency", is_flag=True,
              help="flash black and white, time when the camera sees it and save the settle "
              "time for this display and camera (no scan)")
@click.option("--latency-file", type=click.Path(path_type=Path), default=None,
              help="where measured settle times are kept [default: "
              "~/.config/bistair/latency.json or $BISTAIR_LATENCY_FILE]")
@click.option("--scans", type=int, default=1, show_default=True,
              help="scan the pattern set this many times in a row into OUT/scan-NNNN/ (with "
              "--decode each decoded while the next is grabbed) and OUT/series.json")
@click.option("--backlog", type=int, default=2, show_default=True,
              help="with --scans and --decode: scans that may wait for the decoder; a scan "
              "grabbed when this many wait is not decoded (counted and said)")
@click.option("--no-previews", is_flag=True,
              help="skip the decode's PNG previews (they take about as long as the decode)")
@click.option("--compress-captures", is_flag=True,
              help="with --scans: deflate the captures' PNG as one scan does (files 2.2 "
              "times smaller, five times the CPU time) instead of storing them")
@quiet_option
@reports_errors
def scan(spec_path: Path | None, display: str, camera: str, out: Path | None,
         settle_ms: float | None, average: int, drop: int | None, exposure: float | None,
         gain: float | None, pixel_format: str | None, decode_it: bool,
         calibration: Path | None, depth_range: str | None, measure_latency: bool,
         latency_file: Path | None, scans: int, backlog: int, no_previews: bool,
         compress_captures: bool, quiet: bool) -> None:
    """Project a pattern set with DISPLAY, grab it with CAMERA, write a capture folder.

    Per pattern: show it, wait --settle-ms, drop the frames the camera buffered before,
    grab --average frames and average them. Esc in the window or Ctrl-C stops cleanly
    (with --scans, keeping the scans grabbed)."""
    from ..progress import Progress

    settings = dict(exposure=exposure, gain=gain, pixel_format=pixel_format)
    if measure_latency:
        from ..scan import measure_settle

        with Progress(quiet) as say:
            latency, path = measure_settle(display, camera, latency_file, progress=say,
                                           **settings)
        if not quiet:
            times = latency.latencies_ms
            click.echo(f"latency {latency.display} -> {latency.camera}: {min(times):.0f} to "
                       f"{max(times):.0f} ms over {len(times)} changes (camera levels: black "
                       f"{100 * latency.black:.1f}%, white {100 * latency.white:.1f}%); settle "
                       f"{latency.settle_ms:g} ms saved to {path}")
        return
    for name, value in (("--spec", spec_path), ("--out", out)):
        if value is None:
            raise CliError(f"{name} is needed for a scan (or give --measure-latency)")
    if depth_range is not None and calibration is None:
        raise CliError("--depth-range applies to the reconstruction: give --calibration too")
    given = click.get_current_context().get_parameter_source("backlog")
    if given is not click.core.ParameterSource.DEFAULT and (scans == 1 or not decode_it):
        raise CliError("--backlog applies to --scans N with --decode")
    if compress_captures and scans == 1:
        raise CliError("--compress-captures applies to --scans N (one scan's captures are "
                       "always compressed)")
    if scans != 1:
        _series(spec_path, display, camera, out, scans, decode_it, backlog, no_previews,
                calibration, quiet, settle_ms=settle_ms, average=average, drop=drop,
                latency_file=latency_file, compress_captures=compress_captures, **settings)
        return
    from ..decode import parse_depth_range
    from ..scan import scan_folder

    low, high = (0.0, np.inf) if depth_range is None else parse_depth_range(depth_range)
    with Progress(quiet) as say:
        report = scan_folder(spec_path, display, camera, out, decode=decode_it,
                             calibration=calibration, depth_range=(low, high), progress=say,
                             settle_ms=settle_ms, average=average, drop=drop,
                             latency_file=latency_file, previews=not no_previews, **settings)
    info = report.scan.info
    for message in info["warnings"]:
        click.echo(f"Warning: {message}", err=True)
    if report.decoded is not None:
        print_warnings(report.decoded)
    if quiet:
        return
    frames = report.scan.frames
    click.echo(f"scanned {len(frames)} {report.scan.spec.method} patterns with "
               f"{info['display']['name']} and {info['camera']['name']} in "
               f"{info['seconds']:.1f} s (settle {info['settle_ms']:g} ms, "
               f"{info['settle_source']}; {frames.shape[2]}x{frames.shape[1]} "
               f"{frames.dtype.itemsize * 8}-bit frames); wrote {out}")
    result = report.decoded
    if result is not None:
        click.echo(f"decoded {result.method}: {int(result.mask.sum())} of {result.mask.size} "
                   f"pixels valid ({100 * result.mask.mean():.1f}%); wrote {out}/decode")
    if report.reconstruction is not None:
        click.echo(f"{int(report.reconstruction.mask.sum())} points; wrote "
                   f"{out}/decode/cloud.ply and depth.npy")


def _series(spec_path: Path, display: str, camera: str, out: Path, scans: int, decode: bool,
            backlog: int, no_previews: bool, calibration: Path | None, quiet: bool,
            **options: object) -> None:
    """``bistair scan --scans N``: :func:`bistair.app.scan_series.scan_series` and its summary."""
    from ..progress import Progress
    from ..scan_series import scan_series, summary_lines

    if calibration is not None:
        raise CliError("--calibration applies to one scan: reconstruct a series afterwards "
                       "with 'bistair batch OUT --calibration FILE --out RESULT'")
    with Progress(quiet) as say:
        report = scan_series(spec_path, display, camera, out, scans, decode=decode,
                             backlog=backlog, previews=not no_previews, progress=say,
                             **options)
    lines, warnings = summary_lines(report)
    for message in warnings:
        click.echo(f"Warning: {message}", err=True)
    if not quiet:
        click.echo("\n".join(lines))
