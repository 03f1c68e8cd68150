"""``bistair bench``: every codec's decode speed on this machine against the OpenCV floor.

Registered on the command group by :mod:`bistair.app.cli`; imports deferred into the
command, as there."""

from __future__ import annotations

from pathlib import Path

import click

from .options import LazyHelp, Size, method_names, quiet_option, reports_errors, threads_option


@click.command()
@click.option("--camera", type=Size("WxH"), default="1280x1024", show_default=True,
              help="camera size WIDTHxHEIGHT of the rendered captures (at least 192 a side)")
@click.option("--method", "picked", multiple=True, metavar="METHOD", cls=LazyHelp,
              help_from=method_names,
              help="time this method only (repeatable, or joined by commas: {}) [default: "
              "all; the default decoder is always timed, the ratios are to it]")
@click.option("--runs", type=int, default=5, show_default=True,
              help="timed decodes per codec (after a first one, not timed)")
@click.option("--json", "json_path", type=click.Path(path_type=Path), default=None,
              metavar="FILE", help="also write the figures to FILE (JSON)")
@threads_option
@quiet_option
@reports_errors
def bench(camera: tuple[int, int], picked: tuple[str, ...], runs: int, json_path: Path | None,
          quiet: bool) -> None:
    """Time every codec's decode on this machine: ms per decode, scans/s, MP/s and the
    ratio to the OpenCV floor timed in the same run (its 4-step pass: two frame
    differences, their phase and magnitude, on the same frames after each decode).

    Renders the speed scene (benchmarks/decode_speed.py's) at --camera for each codec,
    decodes it once (that first decode, which loads the kernels, is not timed), then times
    --runs decodes. The machine is described on the last line (cores, threads, CPU, numba's
    threading layer, load): compare the ratios, which a busy machine changes less than the
    times."""
    from ..bench import bench_lines, check_json_path, run_bench, write_bench_json
    from ..progress import Progress

    names = [name.strip() for item in picked for name in item.split(",") if name.strip()]
    if json_path is not None:  # refused before the work, not after it
        check_json_path(json_path)
    with Progress(quiet) as say:
        report = run_bench(camera, names or None, runs, progress=say)
    if json_path is not None:
        write_bench_json(report, json_path)
    if quiet:
        return
    click.echo("\n".join(bench_lines(report)))
    if json_path is not None:
        click.echo(f"wrote {json_path}")
