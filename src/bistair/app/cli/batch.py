"""``bistair batch``: many capture sets on Dask.

Registered on the command group by :mod:`bistair.app.cli`; imports deferred into the
commands, as there."""

from __future__ import annotations

import sys
from pathlib import Path

import click
import numpy as np

from .options import (
    CliError,
    Input,
    Output,
    force_option,
    quiet_option,
    reports_errors,
    strategy_option,
)

BATCH_SETS_FAILED = 3  # the exit code when some sets failed (each a row of batch.csv)


@click.command()
@click.argument("root", type=Input())
@click.option("--out", "-o", required=True, type=Output(),
              help="output folder: OUT/<set name>/ per set and OUT/batch.csv")
@click.option("--spec", "spec_path", type=Input(), default=None,
              help="spec.json of every set [default: spec.json in each set's folder]")
@click.option("--calibration", type=Input(), default=None,
              help="calibration file: also reconstruct every set (cloud.ply, depth.npy)")
@click.option("--workers", type=int, default=None,
              help="processes of the local cluster [default: the cores]")
@click.option("--scheduler", default=None, metavar="tcp://HOST:PORT",
              help="run on an existing Dask cluster instead (its workers must see the same "
              "paths)")
@click.option("--resume", is_flag=True, help="skip sets whose outputs are complete")
@strategy_option
@click.option("--min-modulation", type=float, default=None,
              help="modulation threshold as a fraction of full scale, between 0 and 1 "
              "[default: from noise]")
@click.option("--no-previews", is_flag=True, help="skip the PNG previews")
@click.option("--depth-range", default=None, metavar="MIN:MAX",
              help="with --calibration: keep points with depth z in [MIN, MAX] mm")
@click.option("--epipolar-tolerance", type=float, default=1.5, show_default=True,
              metavar="PX", help="with --calibration and specs of both axes: see "
              "'bistair reconstruct --help'")
@force_option
@quiet_option
@reports_errors
def batch(root: Path, out: Path, spec_path: Path | None, calibration: Path | None,
          workers: int | None, scheduler: str | None, resume: bool, strategy: str | None,
          min_modulation: float | None, no_previews: bool, depth_range: str | None,
          epipolar_tolerance: float, force: bool, quiet: bool) -> None:
    """Decode (with --calibration also reconstruct) many capture sets on Dask.

    ROOT: a folder whose sub-folders are the capture sets, or a CSV manifest with the
    columns captures, spec, calibration, out (paths relative to the manifest; empty cells
    take the defaults). Each set writes what 'bistair decode' (and 'reconstruct') write
    into OUT/<set name>/; a failing set is recorded in OUT/batch.csv and the batch goes on.
    Exit code 0 when every set decoded, 3 when some failed, 2 on bad input; after Ctrl-C
    1, after SIGTERM 143 (batch.csv lists the finished sets).
    """
    from ..batch import run_batch
    from ..decode import parse_depth_range

    if depth_range is not None and calibration is None:
        raise CliError("--depth-range applies to the reconstruction: give --calibration too")
    low, high = (0.0, np.inf) if depth_range is None else parse_depth_range(depth_range)
    if calibration is not None:  # a stereo one's baseline under 10 mm: said once
        from ...geometry.calibration import StereoCalibration, load_calibration, short_baseline

        cal = load_calibration(calibration)
        if isinstance(cal, StereoCalibration) and short_baseline(cal):
            click.echo(f"Warning: {calibration}: {short_baseline(cal)}", err=True)
    options = {k: v for k, v in (("strategy", strategy), ("min_modulation", min_modulation),
                                 ("force", force or None)) if v is not None}
    try:
        report = run_batch(root, out, spec_path, calibration, workers=workers,
                           scheduler=scheduler, resume=resume, previews=not no_previews,
                           min_depth=low, max_depth=high,
                           epipolar_tolerance=epipolar_tolerance,
                           show_progress=sys.stderr.isatty() and not quiet, **options)
    except (KeyboardInterrupt, SystemExit) as exc:  # Ctrl-C: exit 1; SIGTERM: 143
        click.echo(f"Interrupted: the finished sets are in {out} (listed in batch.csv); "
                   "run again with --resume to go on", err=True)
        if isinstance(exc, SystemExit):
            raise
        raise click.exceptions.Abort() from None
    for row in report.failed:
        click.echo(f"failed {row['name']}: {row['error']}", err=quiet)
    if not quiet:
        click.echo(f"{report.summary()}; wrote {out / 'batch.csv'}")
    if report.failed:  # scripts can tell: 0 every set decoded, 3 some failed, 2 bad input
        sys.exit(BATCH_SETS_FAILED)
