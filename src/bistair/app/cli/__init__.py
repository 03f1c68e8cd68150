"""The ``bistair`` command line.

Every failure on bad input prints one line, ``Error: <what is wrong>``, and exits with 2.
Commands import their jobs when they run, so that ``bistair --help`` and ``--version`` do
not pay for the imaging and geometry libraries.
"""

from __future__ import annotations

import dataclasses
import difflib
import signal
import sys
from pathlib import Path
from typing import Any

import click
import numpy as np

from ...core.jit import interrupt
from ...core.memory import keep_freed_memory
from ...spec import BaseSpec, coerce_field, field_kind
from .batch import batch
from .bench import bench
from .options import (
    CliError,
    Input,
    Output,
    Size,
    Text,
    board_choice,
    force_option,
    print_warnings,
    quiet_option,
    reports_errors,
    strategy_option,
    threads_option,
)
from .scan import scan
from .simulate import simulate
from .stereo import calibrate_stereo, stereo


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="bistair", prog_name="bistair")
def cli() -> None:
    """Absolute phase measurement for fringe projection profilometry."""


class _MethodCommands(click.Group):
    """A group whose method commands are made from the registry when asked for, so that
    ``bistair --version`` and ``--help`` do not import the codecs."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        from ...codecs import REGISTRY

        return [*REGISTRY, *(c for c in super().list_commands(ctx) if c not in REGISTRY)]

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        from ...codecs import REGISTRY

        codec = REGISTRY.get(cmd_name)
        if codec is None:
            return super().get_command(ctx, cmd_name)
        return _spec_command(codec.name, codec.spec_class, codec.summary)

    def resolve_command(self, ctx: click.Context, args: list[str]
                        ) -> tuple[str | None, click.Command | None, list[str]]:
        """An unknown name is refused with the closest method and the list of them."""
        from ...codecs import REGISTRY

        name = args[0] if args else ""
        if name and not name.startswith("-") and self.get_command(ctx, name) is None:
            others = [c for c in super().list_commands(ctx) if c not in REGISTRY]
            close = difflib.get_close_matches(name, [*REGISTRY, *others], n=1)
            ctx.fail(f"unknown method {name!r}"
                     + (f", did you mean {close[0]!r}?" if close else "")
                     + f" (methods: {', '.join(REGISTRY)}"
                     + (f"; also: {', '.join(others)})" if others else ")"))
        return super().resolve_command(ctx, args)


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
                               "default": shown, "type": Text(_SPEC_TYPES[kind])}
        if "choices" in f.metadata:
            opt["type"] = click.Choice([_show(c) for c in f.metadata["choices"]])
            if tuple(f.metadata["choices"]) == (0, 1):  # a switch: --white alone means 1
                opt.update(is_flag=False, flag_value="1")
        params.append(click.Option([f"--{f.name.replace('_', '-')}", f.name], **opt))
    params.append(click.Option(["--gamma-file"], type=Input(), default=None,
                               help="gamma.json from 'bistair gamma': pre-compensate the "
                               "measured projector gamma (instead of --gamma)"))
    params.append(click.Option(["--out", "-o"], required=True, type=Output(),
                               help="output folder"))

    @reports_errors
    def callback(out: Path, gamma_file: Path | None, **values: Any) -> None:
        from ..jobs import read_gamma, save_patterns

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


# how a spec field's value is shown in the help (numbers may be fractions or hold pi)
_SPEC_TYPES = {int: "INTEGER", float: "NUMBER", str: "TEXT", tuple: "NUMBER,..."}


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
@click.option("--bits", type=click.Choice(["8", "16"]), default="8", show_default=True,
              help="bit depth of the frames")
@click.option("--out", "-o", required=True, type=Output(), help="output folder")
@reports_errors
def patterns_gamma(width: int, height: int, levels: int, bits: str, out: Path) -> None:
    """A ramp of uniform grey frames (NN.png and ramp.json) for 'bistair gamma'."""
    from ..jobs import save_ramp

    save_ramp(width, height, levels, int(bits), out)
    click.echo(f"wrote {levels} grey frames and ramp.json to {out}")


@cli.command()
@click.argument("captures", nargs=-1, required=True, type=Input(text=True))
@click.option("--ramp", type=Input(), default=None,
              help="ramp.json of the grey frames [default: ramp.json in the captures' folder]")
@click.option("--out", "-o", required=True, type=Output(file=True),
              help="gamma file to write (JSON)")
@reports_errors
def gamma(captures: tuple[str, ...], ramp: Path | None, out: Path) -> None:
    """Measure the projector's gamma from captures of 'bistair patterns gamma'."""
    from ..jobs import measure_gamma

    fit = measure_gamma(list(captures), out, ramp)
    click.echo(f"projector gamma {fit.gamma:.3f} (RMS misfit {fit.rms:.4f} over "
               f"{len(fit.levels)} levels, {fit.pixels} pixels); wrote {out}")


@cli.command()
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
    from ..jobs import decode_folder
    from ..progress import Progress

    if window is not None or starts is not None:
        _decode_stream(list(captures), spec_path, out, window, starts, min_modulation,
                       strategy, force, quiet)
        return
    from ..stream import refuse_single_period

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
    """``decode --window``: a stream decoded window by window (:mod:`bistair.app.stream`)."""
    from ..progress import Progress
    from ..stream import decode_stream

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


@cli.command()
@click.option("--out", "-o", type=Output(), default=Path("demo-out"),
              show_default=True, help="output folder")
@click.option("--seed", type=int, default=0, show_default=True,
              help="seed of the rendered noise")
@click.option("--camera", type=Size("WxH"), default="1280x1024", show_default=True,
              help="camera size WIDTHxHEIGHT")
@reports_errors
def demo(out: Path, seed: int, camera: tuple[int, int]) -> None:
    """The paper's simulation on the virtual rig: every method, one table, a report."""
    from ..demo import run_demo

    run_demo(out, seed=seed, camera_size=camera)


@cli.command()
@click.argument("captures", type=Input())
@click.option("--out", "-o", required=True, type=Output(file=True),
              help="calibration file to write (JSON)")
@board_choice("CAPTURES")
@click.option("--spec", "spec_path", type=Input(), default=None,
              help="spec of both axes for pose folders of captures [default: each "
              "folder's spec.json, else CAPTURES/spec.json]")
@click.option("--min-poses", type=int, default=3, show_default=True,
              help="fewest poses with the board found and mapped (3 or more)")
@click.option("--corner-fit", type=click.Choice(["homography", "quadratic"]),
              default="homography", show_default=True,
              help="how a board feature is mapped to the projector")
@quiet_option
@reports_errors
def calibrate(captures: Path, out: Path, board: str | None, spec_path: Path | None,
              min_poses: int, corner_fit: str, quiet: bool) -> None:
    """Calibrate camera and projector from board captures (both projector axes per pose:
    columns/ and rows/ folders, or captures of both axes with one spec).

    Prints the reprojection errors and one standard deviation of every parameter; a pose
    that does not decode or does not show the board is skipped with a warning."""
    from ...geometry.calibrate import MIN_POSES
    from ..calibrate import calibrate_folder, summary_lines
    from ..progress import Progress

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
@click.argument("files", nargs=-1, type=Input())
@click.option("--out", "-o", required=True, type=Output(file=True),
              help="calibration file to write (JSON)")
@click.option("--projector-size", default=None, metavar="WxH",
              help="projector size WIDTHxHEIGHT [default: from projector_size, screenResX + "
              "screenResY, ... in the files; not with --stereo]")
@click.option("--camera-size", default=None, metavar="WxH",
              help="camera size WIDTHxHEIGHT [default: from image_size, imageSize, "
              "image_width + image_height, frameWidth + frameHeight, S, ... in the files]")
@click.option("--keys", default=None, metavar="NAME=KEY,...",
              help="key names, NAME=KEY joined by commas [default: camera=M1,camera_dist=D1,"
              "projector=M2,projector_dist=D2,R=R,T=T; with --stereo left=M1,left_dist=D1,"
              "right=M2,right_dist=D2,R=R,T=T]; camera_size=KEY and projector_size=KEY name "
              "the size keys")
@click.option("--stereo", is_flag=True, help="two cameras (left first) for 'bistair stereo', "
              "not a camera and a projector")
@click.option("--projection-matrices", "matrices", default=None,
              metavar="LEFT,RIGHT,PROJECTOR",
              help="three 3x4 projection matrices of one world frame (.npy, .txt or .mat "
              "files; needs --camera-size and --projector-size): a calibration of two "
              "cameras and the projector in the left camera's frame, no distortion")
@reports_errors
def import_calibration(files: tuple[Path, ...], out: Path, projector_size: str | None,
                       camera_size: str | None, keys: str | None, stereo: bool,
                       matrices: str | None) -> None:
    """Convert an OpenCV FileStorage calibration (YAML or XML, e.g. stereo_calib's
    intrinsics.yml and extrinsics.yml, camera as device 1) into a bistair calibration file.
    R, T map the camera frame to the projector frame; T in millimetres. With --stereo, two
    cameras: R, T map the left camera's frame to the right one's. With
    --projection-matrices (and no FILES), two cameras and the projector from their 3x4
    matrices P = K [R | t] (X_device = R X_world + t, mm)."""
    if matrices is not None:
        from ..jobs import import_projection_matrices

        if files or stereo or keys:
            raise CliError("--projection-matrices takes no FILES, --stereo or --keys")
        rig = import_projection_matrices(matrices, out, camera_size, projector_size)
        click.echo(f"cameras {rig.left.width}x{rig.left.height}, baseline "
                   f"{rig.baseline:.2f} mm, projector {rig.projector.device.width}x"
                   f"{rig.projector.device.height} at "
                   f"{float(np.linalg.norm(rig.projector.R.T @ rig.projector.T)):.2f} mm from "
                   f"the left camera; wrote {out}")
        return
    if not files:
        raise CliError("give the calibration FILES (or --projection-matrices)")
    if stereo:
        from ...geometry.stereo_calibration import short_baseline
        from ..stereo import import_stereo_calibration

        if projector_size is not None:
            raise CliError("--projector-size does not apply to a stereo calibration (two "
                           "cameras)")
        pair = import_stereo_calibration(files, out, camera_size, keys)
        click.echo(f"cameras {pair.left.width}x{pair.left.height}, baseline "
                   f"{pair.baseline:.2f} mm; wrote {out}")
        if short_baseline(pair):
            click.echo(f"Warning: {short_baseline(pair)}", err=True)
        return
    from ..jobs import import_calibration as run

    cal = run(files, out, projector_size, camera_size, keys)
    click.echo(f"camera {cal.camera.width}x{cal.camera.height}, projector "
               f"{cal.projector.width}x{cal.projector.height}, baseline {cal.baseline:.2f} mm; "
               f"wrote {out}")


@cli.command()
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
    from ..jobs import parse_depth_range, reconstruct_folder
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


@cli.command()
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
    from ..jobs import height_folder
    from ..progress import Progress

    with Progress(quiet) as say:
        h = height_folder(captures, reference, out, spec_path, planes, geometry, progress=say)
    if not quiet:
        click.echo(f"height of {int(np.isfinite(h).sum())} pixels; wrote {out}/height.npy")


for _command in (simulate, batch, stereo, calibrate_stereo, scan, bench):
    cli.add_command(_command)


def _terminated(signum: int, frame: Any) -> None:
    """SIGTERM ends the command like Ctrl-C, with exit code 143: temporary outputs are
    removed on the way out (raised when a running compiled kernel returns:
    :func:`~bistair.core.jit.interrupt`)."""
    interrupt(SystemExit(128 + signum), frame)


def _interrupted(signum: int, frame: Any) -> None:
    """Ctrl-C: Python's KeyboardInterrupt, raised when a running compiled kernel returns."""
    interrupt(KeyboardInterrupt(), frame)


# a group called without a command (click 8.2 and later; 8.1 shows the help itself)
_NO_ARGS = getattr(click.exceptions, "NoArgsIsHelpError", ())


def main() -> None:
    signal.signal(signal.SIGTERM, _terminated)
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # (not if ignored)
        signal.signal(signal.SIGINT, _interrupted)
    keep_freed_memory()  # a short-lived process: freed arrays serve the next ones
    args = sys.argv[1:] or ["--help"]  # a bare `bistair` shows the help, as --help does
    try:
        cli(args, prog_name="bistair", standalone_mode=False)
    except click.exceptions.Abort:
        click.echo("Aborted.", err=True)
        sys.exit(1)
    except _NO_ARGS as exc:  # `bistair patterns` alone shows its help, as a bare `bistair`
        click.echo(exc.ctx.get_help())
        sys.exit(0)
    except click.UsageError as exc:  # one line, like every other refusal
        where = f" (see '{exc.ctx.command_path} --help')" if exc.ctx is not None else ""
        click.echo(f"Error: {exc.format_message()}{where}", err=True)
        sys.exit(2)
    except click.ClickException as exc:
        exc.show()
        sys.exit(exc.exit_code)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
