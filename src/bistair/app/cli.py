"""The ``bistair`` command line.

Every failure on bad input prints one line, ``Error: <what is wrong>``, and exits with 2.
Commands import their jobs when they run, so that ``bistair --help`` and ``--version`` do
not pay for the imaging and geometry libraries.
"""

from __future__ import annotations

import dataclasses
import functools
import signal
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click
import numpy as np

from ..core.memory import keep_freed_memory
from ..errors import BistairError
from ..spec import BaseSpec, coerce_field, field_kind

BATCH_SETS_FAILED = 3  # bistair batch's exit code when some sets failed (each in batch.csv)


class CliError(click.ClickException):
    exit_code = 2


def reports_errors(func: Callable) -> Callable:
    """Turn :class:`BistairError` into a one-line message and exit code 2."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except BistairError as exc:
            raise CliError(str(exc)) from None
        except MemoryError:
            raise CliError("not enough memory for these captures") from None

    return wrapper


def _quiet(func: Callable) -> Callable:
    """``--quiet``: no progress and no summary; errors and warnings are still printed."""
    return click.option("--quiet", "-q", is_flag=True,
                        help="print only errors and warnings (no progress, no summary)")(func)


def _force(func: Callable) -> Callable:
    """``--force``: decode where a thresholded check would refuse."""
    return click.option("--force", is_flag=True,
                        help="decode where a thresholded check would refuse the captures: its "
                        "reasons are printed as warnings and kept in info.json ('forced'); "
                        "hard errors (frame count, unreadable files, no valid pixel) stay "
                        "errors")(func)


def _threads(func: Callable) -> Callable:
    """``--threads N``: at most N threads in the decode's kernels and OpenCV."""

    def limit(ctx: click.Context, param: click.Parameter, value: int | None) -> int | None:
        if value is not None:
            import cv2

            from ..core.jit import set_threads

            set_threads(value)
            cv2.setNumThreads(value)
        return value

    return click.option("--threads", type=click.IntRange(min=1), default=None,
                        expose_value=False, callback=limit,
                        help="use at most N threads [default: every core]")(func)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="bistair", prog_name="bistair")
def cli() -> None:
    """Absolute phase measurement for fringe projection profilometry."""


class _MethodCommands(click.Group):
    """A group whose method commands are made from the registry when asked for, so that
    ``bistair --version`` and ``--help`` do not import the codecs."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        from ..codecs import REGISTRY

        return [*REGISTRY, *super().list_commands(ctx)]

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        from ..codecs import REGISTRY

        codec = REGISTRY.get(cmd_name)
        if codec is None:
            return super().get_command(ctx, cmd_name)
        return _spec_command(codec.name, codec.spec_class, codec.summary)


@cli.group(cls=_MethodCommands)
def patterns() -> None:
    """Write a method's patterns (NN.png) and their spec.json into a folder."""


def _spec_command(name: str, spec_class: type[BaseSpec], summary: str) -> click.Command:
    """``bistair patterns NAME``: an option per spec field (numbers may be written as
    fractions such as ``1920/58`` or with ``pi`` such as ``-2*pi/3``; lists with commas)."""
    params: list[click.Parameter] = []
    fields = {f.name: f for f in dataclasses.fields(spec_class)
              if f.metadata.get("cli") is not False}
    for f in fields.values():
        kind = field_kind(f)
        default = f.default
        shown = ",".join(_show(v) for v in default) if kind is tuple else _show(default)
        opt: dict[str, Any] = {"help": f.metadata.get("help", ""), "show_default": True,
                               "default": shown, "type": str}
        if "choices" in f.metadata:
            opt["type"] = click.Choice([_show(c) for c in f.metadata["choices"]])
            if tuple(f.metadata["choices"]) == (0, 1):  # a switch: --white alone means 1
                opt.update(is_flag=False, flag_value="1")
        params.append(click.Option([f"--{f.name.replace('_', '-')}", f.name], **opt))
    params.append(click.Option(["--gamma-file"], type=click.Path(path_type=Path), default=None,
                               help="gamma.json from 'bistair gamma': pre-compensate the "
                               "measured projector gamma (instead of --gamma)"))
    params.append(click.Option(["--out", "-o"], required=True, type=click.Path(path_type=Path),
                               help="output folder"))

    @reports_errors
    def callback(out: Path, gamma_file: Path | None, **values: Any) -> None:
        from .jobs import read_gamma, save_patterns

        values = {key: coerce_field(fields[key], value) for key, value in values.items()}
        ctx = click.get_current_context()
        given = {key: value for key, value in values.items()
                 if ctx.get_parameter_source(key) is not click.core.ParameterSource.DEFAULT}
        values.update({key: value for key, value in spec_class.defaults(given).items()
                       if key not in given})
        if gamma_file is not None:
            values["gamma"] = read_gamma(gamma_file)
        spec = spec_class(**values)
        save_patterns(spec, out)
        click.echo(f"wrote {spec.frame_count} {name} patterns and spec.json to {out}")

    return click.Command(name, params=params, callback=callback, help=summary)


def _show(value: Any) -> str:
    """A default as the command line shows it: 30 rather than 30.0."""
    return str(int(value)) if isinstance(value, float) and value.is_integer() else str(value)


@patterns.command("gamma")
@click.option("--width", type=int, default=1080, show_default=True,
              help="projector width in pixels")
@click.option("--height", type=int, default=1080, show_default=True,
              help="projector height in pixels")
@click.option("--levels", type=int, default=17, show_default=True,
              help="grey levels from black to white")
@click.option("--bits", type=click.Choice(["8", "16"]), default="8", show_default=True)
@click.option("--out", "-o", required=True, type=click.Path(path_type=Path),
              help="output folder")
@reports_errors
def patterns_gamma(width: int, height: int, levels: int, bits: str, out: Path) -> None:
    """A ramp of uniform grey frames (NN.png and ramp.json) for 'bistair gamma'."""
    from .jobs import save_ramp

    save_ramp(width, height, levels, int(bits), out)
    click.echo(f"wrote {levels} grey frames and ramp.json to {out}")


@cli.command()
@click.argument("captures", nargs=-1, required=True)
@click.option("--ramp", type=click.Path(path_type=Path), default=None,
              help="ramp.json of the grey frames [default: ramp.json in the captures' folder]")
@click.option("--out", "-o", required=True, type=click.Path(path_type=Path),
              help="gamma file to write (JSON)")
@reports_errors
def gamma(captures: tuple[str, ...], ramp: Path | None, out: Path) -> None:
    """Measure the projector's gamma from captures of 'bistair patterns gamma'."""
    from .jobs import measure_gamma

    fit = measure_gamma(list(captures), out, ramp)
    click.echo(f"projector gamma {fit.gamma:.3f} (RMS misfit {fit.rms:.4f} over "
               f"{len(fit.levels)} levels, {fit.pixels} pixels); wrote {out}")


@cli.command()
@click.argument("captures", nargs=-1, required=True)
@click.option("--spec", "spec_path", type=click.Path(path_type=Path), default=None,
              help="spec.json of the pattern set [default: spec.json in the captures' folder]")
@click.option("--out", "-o", required=True, help="output folder")
@click.option("--strategy", default=None, help="fringe-order strategy (bidirectional: "
              "region [default] or paper)")
@click.option("--min-modulation", type=float, default=None,
              help="modulation threshold as a fraction of full scale, between 0 and 1 "
              "[default: from noise]")
@click.option("--no-previews", is_flag=True, help="skip the PNG previews")
@_force
@_threads
@_quiet
@reports_errors
def decode(captures: tuple[str, ...], spec_path: Path | None, out: str, strategy: str | None,
           min_modulation: float | None, no_previews: bool, force: bool, quiet: bool) -> None:
    """Decode captured images into absolute phase, projector coordinate and fringe order.

    CAPTURES: a folder, image files, or quoted glob patterns ('scan/pat*.png'), in that
    order; a folder's or pattern's images in natural name order; or one .npy stack.
    """
    from .jobs import decode_folder
    from .progress import Progress

    options = {k: v for k, v in (("strategy", strategy), ("min_modulation", min_modulation),
                                 ("force", force or None)) if v is not None}
    with Progress(quiet) as say:
        result = decode_folder(list(captures), out, spec_path, previews=not no_previews,
                               progress=say, **options)
    _warn(result)
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


def _warn(result: Any) -> None:
    """Print a decode's warnings on stderr, one line each."""
    infos = [result.info] if not hasattr(result, "x") else [result.x.info, result.y.info]
    for info in infos:
        for message in info.get("warnings", []):
            click.echo(f"Warning: {message}", err=True)


def _size(ctx: click.Context, param: click.Parameter, value: str | None) -> Any:
    if value is None:
        return None
    try:
        width, height = (int(v) for v in value.lower().split("x"))
    except ValueError:
        raise click.BadParameter("expected WIDTHxHEIGHT, e.g. 1280x1024") from None
    return width, height


@cli.command()
@click.option("--out", "-o", type=click.Path(path_type=Path), default=Path("demo-out"),
              show_default=True, help="output folder")
@click.option("--seed", type=int, default=0, show_default=True)
@click.option("--camera", callback=_size, default="1280x1024", show_default=True,
              help="camera size WIDTHxHEIGHT")
@reports_errors
def demo(out: Path, seed: int, camera: tuple[int, int]) -> None:
    """The paper's simulation on the virtual rig: every method, one table, a report."""
    from .demo import run_demo

    run_demo(out, seed=seed, camera_size=camera)


@cli.command()
@click.option("--scene", default=None, help="preset scene (paper-sim, two-masks, mask-prism, "
              "two-sculptures, plane, sphere-on-plane, objects-on-plane, mugs-on-wall) or "
              "calibration (board captures)")
@click.option("--method", "methods", required=True, multiple=True,
              help="method to render (repeatable), or all")
@click.option("--out", "-o", required=True, type=click.Path(path_type=Path))
@click.option("--camera", callback=_size, default=None, help="camera size WIDTHxHEIGHT "
              "[default: 1280x1024]")
@click.option("--noise", type=float, default=0.01, show_default=True,
              help="read noise, fraction of full scale")
@click.option("--blur", type=float, default=1.0, show_default=True,
              help="camera defocus, Gaussian sigma in pixels")
@click.option("--gamma", type=float, default=2.2, show_default=True, help="projector gamma")
@click.option("--compensated/--uncompensated", default=True, show_default=True,
              help="patterns pre-compensate the projector gamma")
@click.option("--ambient", type=float, default=0.05, show_default=True)
@click.option("--bits", type=click.Choice(["8", "10", "12", "16"]), default="8",
              show_default=True, help="camera bit depth")
@click.option("--seed", type=int, default=0, show_default=True)
@click.option("--count", type=int, default=None,
              help="a data set: COUNT scenes in OUT/scene-NNNN/ and OUT/index.csv, rendered "
              "in parallel")
@click.option("--vary", default=None, metavar="optics,objects,pose",
              help="with --count: what each scene draws at random (see README)")
@click.option("--workers", type=int, default=None,
              help="with --count: processes of the local cluster [default: the cores]")
@click.option("--scheduler", default=None, metavar="tcp://HOST:PORT",
              help="with --count: run on an existing Dask cluster instead")
@click.option("--no-white", is_flag=True,
              help="--scene calibration: no white frame (the board is found in the mean image)")
@click.option("--both-axes", is_flag=True,
              help="--scene calibration: one capture set of both axes per pose")
@_quiet
@reports_errors
def simulate(scene: str | None, methods: tuple[str, ...], out: Path,
             camera: tuple[int, int] | None, noise: float, blur: float, gamma: float,
             compensated: bool, ambient: float, bits: str, seed: int, count: int | None,
             vary: str | None, workers: int | None, scheduler: str | None, no_white: bool,
             both_axes: bool, quiet: bool) -> None:
    """Render a preset scene on the virtual rig: one capture folder per method + the truth.

    With --count N, a data set of N scenes (deterministic for a --seed whatever the number
    of workers), each varied as --vary says."""
    from ..codecs import REGISTRY

    chosen = list(REGISTRY) if "all" in methods else list(dict.fromkeys(methods))
    imaging = dict(read_noise=noise, camera_blur=blur, gamma=gamma, ambient=ambient,
                   bits=int(bits))
    if count is None:
        for name, value in (("--vary", vary), ("--workers", workers),
                            ("--scheduler", scheduler)):
            if value is not None:
                raise CliError(f"{name} applies to a data set: give --count too")
        if scene is None:
            raise CliError("name a --scene (or give --count with --vary objects)")
        from .progress import Progress
        from .simulate import simulate as run

        with Progress(quiet) as say:
            run(scene, chosen, out, camera_size=camera, compensated=compensated, seed=seed,
                progress=say, white=not no_white, both_axes=both_axes, **imaging)
        if quiet:
            return
        if scene == "calibration":
            click.echo(f"wrote {chosen[0]} board captures (8 poses, both orientations) to "
                       f"{out}")
        else:
            click.echo(f"wrote {', '.join(chosen)} captures of {scene} and its ground truth "
                       f"to {out}")
        return
    if no_white or both_axes:
        raise CliError("--no-white and --both-axes are for --scene calibration")
    from .simulate import simulate_many

    try:
        report = simulate_many(count, chosen, out, seed=seed, scene=scene, vary=vary or (),
                               camera_size=camera, compensated=compensated, workers=workers,
                               scheduler=scheduler,
                               show_progress=sys.stderr.isatty() and not quiet, **imaging)
    except KeyboardInterrupt:
        click.echo(f"Interrupted: the scenes finished are in {out}; index.csv is not "
                   "written", err=True)
        raise click.exceptions.Abort() from None
    for name, error in report.failed:
        click.echo(f"failed {name}: {error}", err=quiet)
    if not quiet:
        click.echo(f"wrote {count - len(report.failed)} of {count} scenes ({len(report.rows)} "
                   f"capture sets) and index.csv to {out} in {report.seconds:.1f} s on "
                   f"{report.workers} worker{'s' if report.workers != 1 else ''}")
    if report.failed:
        raise CliError(f"{len(report.failed)} of {count} scenes failed (listed above)")


@cli.command()
@click.argument("captures", type=click.Path(path_type=Path))
@click.option("--out", "-o", required=True, type=click.Path(path_type=Path),
              help="calibration file to write (JSON)")
@click.option("--board", default=None, metavar="FILE|TYPE:COLSxROWS:SPACING",
              help="board.json, or e.g. chessboard:9x7:25 (inner corners, square in mm) "
              "[default: CAPTURES/board.json]")
@click.option("--spec", "spec_path", type=click.Path(path_type=Path), default=None,
              help="spec of both axes for pose folders of captures [default: each "
              "folder's spec.json, else CAPTURES/spec.json]")
@click.option("--min-poses", type=int, default=3, show_default=True,
              help="fewest poses with the board found and mapped (3 or more)")
@click.option("--corner-fit", type=click.Choice(["homography", "quadratic"]),
              default="homography", show_default=True,
              help="how a board feature is mapped to the projector")
@_quiet
@reports_errors
def calibrate(captures: Path, out: Path, board: str | None, spec_path: Path | None,
              min_poses: int, corner_fit: str, quiet: bool) -> None:
    """Calibrate camera and projector from board captures (both projector axes per pose:
    columns/ and rows/ folders, or captures of both axes with one spec).

    Prints the reprojection errors and one standard deviation of every parameter; a pose
    that does not decode or does not show the board is skipped with a warning."""
    from ..geometry.calibrate import MIN_POSES
    from .calibrate import calibrate_folder, summary_lines
    from .progress import Progress

    if min_poses < MIN_POSES:
        raise CliError(f"--min-poses {min_poses} is too few: a camera-projector calibration "
                       f"needs at least {MIN_POSES} board poses")
    with Progress(quiet) as say:
        cal = calibrate_folder(captures, out, board=board, spec=spec_path, min_poses=min_poses,
                               corner_fit=corner_fit, progress=say,
                               skipped=lambda name, why: say.warn(f"skipped {name}: {why}"))
    if not quiet:
        click.echo("\n".join(summary_lines(cal, out)))


@cli.command("import-calibration")
@click.argument("files", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--out", "-o", required=True, type=click.Path(path_type=Path),
              help="calibration file to write (JSON)")
@click.option("--projector-size", default=None, metavar="WxH",
              help="projector size WIDTHxHEIGHT [default: from projector_size, screenResX + "
              "screenResY, ... in the files]")
@click.option("--camera-size", default=None, metavar="WxH",
              help="camera size WIDTHxHEIGHT [default: from image_size, imageSize, "
              "image_width + image_height, frameWidth + frameHeight, S, ... in the files]")
@click.option("--keys", default=None, metavar="NAME=KEY,...",
              help="key names, NAME=KEY joined by commas [default: camera=M1,camera_dist=D1,"
              "projector=M2,projector_dist=D2,R=R,T=T]; "
              "camera_size=KEY and projector_size=KEY name the size keys")
@reports_errors
def import_calibration(files: tuple[Path, ...], out: Path, projector_size: str | None,
                       camera_size: str | None, keys: str | None) -> None:
    """Convert an OpenCV FileStorage calibration (YAML or XML, e.g. stereo_calib's
    intrinsics.yml and extrinsics.yml, camera as device 1) into a bistair calibration file.
    R, T map the camera frame to the projector frame; T in millimetres."""
    from .jobs import import_calibration as run

    cal = run(files, out, projector_size, camera_size, keys)
    click.echo(f"camera {cal.camera.width}x{cal.camera.height}, projector "
               f"{cal.projector.width}x{cal.projector.height}, baseline {cal.baseline:.2f} mm; "
               f"wrote {out}")


@cli.command()
@click.argument("captures", type=click.Path(path_type=Path))
@click.option("--spec", "spec_path", type=click.Path(path_type=Path), default=None,
              help="spec.json of the pattern set [default: CAPTURES/spec.json]")
@click.option("--calibration", required=True, type=click.Path(path_type=Path))
@click.option("--out", "-o", required=True, type=click.Path(path_type=Path),
              help="point cloud to write (.ply)")
@click.option("--depth", type=click.Path(path_type=Path), default=None,
              help="folder for depth.npy and depth.png [default: OUT without .ply + -depth]")
@click.option("--strategy", default=None, help="fringe-order strategy of the decoder")
@click.option("--depth-range", default=None, metavar="MIN:MAX",
              help="keep points with depth z in [MIN, MAX] mm (camera frame)")
@click.option("--epipolar-tolerance", type=float, default=1.5, show_default=True,
              metavar="PX", help="specs of both axes: drop pixels whose projector column and "
              "row lie farther than this (projector pixels) from the camera ray's projection")
@_force
@_threads
@_quiet
@reports_errors
def reconstruct(captures: Path, spec_path: Path | None, calibration: Path, out: Path,
                depth: Path | None, strategy: str | None, depth_range: str | None,
                epipolar_tolerance: float, force: bool, quiet: bool) -> None:
    """Decode, triangulate with a calibration, write a coloured PLY and a depth map.

    With a spec of both axes (orientation both), each point fits both projector
    coordinates, and pixels whose coordinates no point on their camera ray shows are
    dropped as wrong decodes."""
    from .jobs import parse_depth_range, reconstruct_folder
    from .progress import Progress

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


@cli.command()
@click.argument("captures", type=click.Path(path_type=Path))
@click.option("--reference", required=True, type=click.Path(path_type=Path),
              help="captures of the flat reference plane (same spec)")
@click.option("--spec", "spec_path", type=click.Path(path_type=Path), default=None)
@click.option("--out", "-o", required=True, type=click.Path(path_type=Path))
@click.option("--plane", "planes", multiple=True, help="FOLDER:HEIGHT_MM of a plane parallel "
              "to the reference (two or more calibrate the height per pixel)")
@click.option("--geometry", default=None, help="DISTANCE,BASELINE,FREQUENCY (mm, mm, fringes "
              "per mm on the reference) for the classical formula instead of planes")
@reports_errors
def height(captures: Path, reference: Path, spec_path: Path | None, out: Path,
           planes: tuple[str, ...], geometry: str | None) -> None:
    """Height above a reference plane without a calibration (phase-to-height)."""
    from .jobs import height_folder

    h = height_folder(captures, reference, out, spec_path, planes, geometry)
    click.echo(f"height of {int(np.isfinite(h).sum())} pixels; wrote {out}/height.npy")


@cli.command()
@click.argument("root", type=click.Path(path_type=Path))
@click.option("--out", "-o", required=True, type=click.Path(path_type=Path),
              help="output folder: OUT/<set name>/ per set and OUT/batch.csv")
@click.option("--spec", "spec_path", type=click.Path(path_type=Path), default=None,
              help="spec.json of every set [default: spec.json in each set's folder]")
@click.option("--calibration", type=click.Path(path_type=Path), default=None,
              help="calibration file: also reconstruct every set (cloud.ply, depth.npy)")
@click.option("--workers", type=int, default=None,
              help="processes of the local cluster [default: the cores]")
@click.option("--scheduler", default=None, metavar="tcp://HOST:PORT",
              help="run on an existing Dask cluster instead (its workers must see the same "
              "paths)")
@click.option("--resume", is_flag=True, help="skip sets whose outputs are complete")
@click.option("--strategy", default=None, help="fringe-order strategy of the decoder")
@click.option("--min-modulation", type=float, default=None,
              help="modulation threshold as a fraction of full scale, between 0 and 1 "
              "[default: from noise]")
@click.option("--no-previews", is_flag=True, help="skip the PNG previews")
@click.option("--depth-range", default=None, metavar="MIN:MAX",
              help="with --calibration: keep points with depth z in [MIN, MAX] mm")
@click.option("--epipolar-tolerance", type=float, default=1.5, show_default=True,
              metavar="PX", help="with --calibration and specs of both axes: see "
              "'bistair reconstruct --help'")
@_force
@_quiet
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
    Exit code 0 when every set decoded, 3 when some failed, 2 on bad input.
    """
    from .batch import run_batch
    from .jobs import parse_depth_range

    low, high = (0.0, np.inf) if depth_range is None else parse_depth_range(depth_range)
    options = {k: v for k, v in (("strategy", strategy), ("min_modulation", min_modulation),
                                 ("force", force or None)) if v is not None}
    try:
        report = run_batch(root, out, spec_path, calibration, workers=workers,
                           scheduler=scheduler, resume=resume, previews=not no_previews,
                           min_depth=low, max_depth=high,
                           epipolar_tolerance=epipolar_tolerance,
                           show_progress=sys.stderr.isatty() and not quiet, **options)
    except KeyboardInterrupt:
        click.echo(f"Interrupted: the finished sets are in {out} (listed in batch.csv); "
                   "run again with --resume to go on", err=True)
        raise click.exceptions.Abort() from None
    for row in report.failed:
        click.echo(f"failed {row['name']}: {row['error']}", err=quiet)
    if not quiet:
        click.echo(f"{report.summary()}; wrote {out / 'batch.csv'}")
    if report.failed:  # scripts can tell: 0 every set decoded, 3 some failed, 2 bad input
        sys.exit(BATCH_SETS_FAILED)


@cli.command()
@click.option("--spec", "spec_path", type=click.Path(path_type=Path), default=None,
              help="spec.json of the pattern set to project (from 'bistair patterns')")
@click.option("--display", required=True, metavar="DISPLAY",
              help="window[:SCREEN] (a full-screen window on the projector's screen, from 0) "
              "or none (the projector holds the patterns and triggers the camera)")
@click.option("--camera", required=True, metavar="CAMERA",
              help="opencv:INDEX|URL, genicam:PRODUCER.cti[:SERIAL], screen[:MONITOR] or "
              "sim[:SCENE[:WxH]]")
@click.option("--out", "-o", type=click.Path(path_type=Path), default=None,
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
@click.option("--calibration", type=click.Path(path_type=Path), default=None,
              help="also reconstruct: OUT/decode/cloud.ply, depth.npy")
@click.option("--depth-range", default=None, metavar="MIN:MAX",
              help="with --calibration: keep points with depth z in [MIN, MAX] mm")
@click.option("--measure-latency", is_flag=True,
              help="flash black and white, time when the camera sees it and save the settle "
              "time for this display and camera (no scan)")
@click.option("--latency-file", type=click.Path(path_type=Path), default=None,
              help="where measured settle times are kept [default: "
              "~/.config/bistair/latency.json or $BISTAIR_LATENCY_FILE]")
@_quiet
@reports_errors
def scan(spec_path: Path | None, display: str, camera: str, out: Path | None,
         settle_ms: float | None, average: int, drop: int | None, exposure: float | None,
         gain: float | None, pixel_format: str | None, decode_it: bool,
         calibration: Path | None, depth_range: str | None, measure_latency: bool,
         latency_file: Path | None, quiet: bool) -> None:
    """Project a pattern set with DISPLAY, grab it with CAMERA, write a capture folder.

    Per pattern: show it, wait --settle-ms, drop the frames the camera buffered before,
    grab --average frames and average them. Esc in the window or Ctrl-C stops cleanly."""
    from .progress import Progress

    settings = dict(exposure=exposure, gain=gain, pixel_format=pixel_format)
    if measure_latency:
        from .scan import measure_settle

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
    from .jobs import parse_depth_range
    from .scan import scan_folder

    low, high = (0.0, np.inf) if depth_range is None else parse_depth_range(depth_range)
    with Progress(quiet) as say:
        report = scan_folder(spec_path, display, camera, out, decode=decode_it,
                             calibration=calibration, depth_range=(low, high), progress=say,
                             settle_ms=settle_ms, average=average, drop=drop,
                             latency_file=latency_file, **settings)
    info = report.scan.info
    for message in info["warnings"]:
        click.echo(f"Warning: {message}", err=True)
    if report.decoded is not None:
        _warn(report.decoded)
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


def _terminated(signum: int, frame: Any) -> None:
    """SIGTERM ends the command like Ctrl-C: temporary outputs are removed on the way out."""
    raise SystemExit(128 + signum)


def main() -> None:
    signal.signal(signal.SIGTERM, _terminated)
    keep_freed_memory()  # a short-lived process: freed arrays serve the next ones
    try:
        cli(standalone_mode=False)
    except click.exceptions.Abort:
        click.echo("Aborted.", err=True)
        sys.exit(1)
    except click.UsageError as exc:  # one line, like every other refusal
        where = f" (see '{exc.ctx.command_path} --help')" if exc.ctx is not None else ""
        click.echo(f"Error: {exc.format_message()}{where}", err=True)
        sys.exit(2)
    except click.ClickException as exc:
        exc.show()
        sys.exit(exc.exit_code)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
