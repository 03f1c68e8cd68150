"""``bistair simulate``: preset scenes, data sets and two cameras on the virtual rig.

Registered on the command group by :mod:`bistair.app.cli`; imports deferred into the
commands, as there."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import click

from .options import (
    CliError,
    Input,
    LazyHelp,
    Output,
    Size,
    method_names,
    quiet_option,
    reports_errors,
)


@click.command()
@click.option("--scene", default=None, metavar="SCENE", help="preset scene (paper-sim, "
              "two-masks, mask-prism, two-sculptures, plane, sphere-on-plane, "
              "objects-on-plane, mugs-on-wall) or calibration (board captures of a 9 x 6 "
              "checkerboard in eight poses)")
@click.option("--method", "methods", multiple=True, metavar="METHOD",
              cls=LazyHelp, help_from=method_names,
              help="method to render (repeatable): {} or all; with --spec, its method or "
              "none")
@click.option("--spec", "spec_path", type=Input(), default=None,
              help="render the set this spec.json describes (its size, code and gamma) "
              "instead of the method's comparable set")
@click.option("--out", "-o", required=True, type=Output(),
              help="output folder: OUT/<method>/ (captures and spec.json), OUT/truth/, "
              "calibration.json, scene.json; --scene calibration: board.json and pose-NN/ "
              "(OUT/<method>/ each for several methods)")
@click.option("--camera", type=Size("WxH"), default=None, help="camera size WIDTHxHEIGHT "
              "[default: 1280x1024]")
@click.option("--noise", type=float, default=0.01, show_default=True,
              help="read noise, fraction of full scale")
@click.option("--blur", type=float, default=1.0, show_default=True,
              help="camera defocus, Gaussian sigma in pixels")
@click.option("--gamma", type=float, default=2.2, show_default=True, help="projector gamma")
@click.option("--compensated/--uncompensated", default=True, show_default=True,
              help="patterns pre-compensate the projector gamma")
@click.option("--ambient", type=float, default=0.05, show_default=True,
              help="ambient light on the scene, fraction of the projector's full white")
@click.option("--bits", type=click.Choice(["8", "10", "12", "16"]), default="8",
              show_default=True, help="camera bit depth")
@click.option("--seed", type=int, default=0, show_default=True,
              help="seed of the noise (with --count, of the whole data set)")
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
@click.option("--cameras", type=click.IntRange(1, 2), default=1, show_default=True,
              help="2: a second camera (OUT/<method>/L and R, stereo.json, truth/L and R)")
@click.option("--baseline", type=float, default=200.0, show_default=True,
              help="with --cameras 2: mm between the cameras (the projector between them)")
# -- things that move (issue 34): one block --------------------------------------------------
@click.option("--motion", default=None, metavar="MOTION",
              help="a rigid motion per frame, each frame rendered at its own pose (truth of "
              "each frame in OUT/truth/frame-NNNN/, frame 0 the reference pose): 1px (camera "
              "pixels along the coded axis, in mm at the moving surfaces' depth), 1,0.5px "
              "(x,y pixels), 0.4,0,0mm (x,y,z mm), 0.4,0,0mm,0,0.2,0deg (and a rotation "
              "vector in degrees about the body's centre) or 0,0.2,0deg")
@click.option("--motion-of", "motion_of", type=click.Choice(["objects", "scene"]),
              default="objects", show_default=True,
              help="what --motion moves: the objects (every surface but the planes, each "
              "about its centre) or the whole scene (about its centre)")
@click.option("--frames", type=int, default=None,
              help="with --continuous: the stream's length in frames")
@click.option("--continuous", is_flag=True,
              help="a stream of --frames N whose shift advances one step per frame (frame i "
              "shows shift i mod N of one N-step set of one period: --steps, --period; "
              "--method multifreq; OUT/multifreq/0000.png ..., spec.json of that single "
              "period)")
@click.option("--steps", type=int, default=None,
              help="with --continuous: the stream's phase-shift steps N [default: 4]")
@click.option("--period", type=float, default=None,
              help="with --continuous: the stream's fringe period in projector pixels "
              "[default: 30]")
@quiet_option
@reports_errors
def simulate(scene: str | None, methods: tuple[str, ...], out: Path,
             camera: tuple[int, int] | None, noise: float, blur: float, gamma: float,
             compensated: bool, ambient: float, bits: str, seed: int, count: int | None,
             vary: str | None, workers: int | None, scheduler: str | None, no_white: bool,
             both_axes: bool, cameras: int, baseline: float, motion: str | None,
             motion_of: str, frames: int | None, continuous: bool, steps: int | None,
             period: float | None, spec_path: Path | None, quiet: bool) -> None:
    """Render a preset scene on the virtual rig: one capture folder per method + the truth.

    With --count N, a data set of N scenes (deterministic for a --seed whatever the number
    of workers), each varied as --vary says. With --cameras 2, two cameras and the
    projector between them, for 'bistair stereo'. With --spec, the set the spec describes
    (--method may then be left out). With --motion, things move between frames; with
    --frames N --continuous, a stream whose shift advances every frame."""
    from ...codecs import REGISTRY

    if not methods and spec_path is None:
        raise CliError("name a --method to render (or give --spec)")
    chosen = list(REGISTRY) if "all" in methods else list(dict.fromkeys(methods))
    spec = None
    if spec_path is not None:
        from ...io.read import load_spec

        if cameras == 2 or count is not None:
            raise CliError("--spec renders one scene with one camera: leave out --count and "
                           "--cameras 2")
        spec = load_spec(spec_path)
    imaging = dict(read_noise=noise, camera_blur=blur, gamma=gamma, ambient=ambient,
                   bits=int(bits))
    if not continuous and (steps is not None or period is not None):
        raise CliError(f"--{'steps' if steps is not None else 'period'} applies to a stream: "
                       "give --frames N --continuous too")
    if motion is not None or continuous or frames is not None:
        if spec is not None:
            raise CliError("--spec renders a still scene: --motion and --continuous render "
                           "the comparable sets (leave out --spec)")
        stream = {k: v for k, v in (("steps", steps), ("period", period)) if v is not None}
        _simulate_motion(scene, chosen, out, camera, compensated, seed, count, vary,
                         no_white or both_axes, cameras, baseline, motion, motion_of, frames,
                         continuous, quiet, imaging, stream)
        return
    if cameras == 2:
        if no_white or both_axes:
            raise CliError("--no-white and --both-axes are for one camera's --scene "
                           "calibration")
        _simulate_stereo(scene, chosen, out, camera, compensated, seed, count, baseline,
                         quiet, imaging)
        return
    if count is None:
        for name, value in (("--vary", vary), ("--workers", workers),
                            ("--scheduler", scheduler)):
            if value is not None:
                raise CliError(f"{name} applies to a data set: give --count too")
        if scene is None:
            raise CliError("name a --scene (or give --count with --vary objects)")
        from ..progress import Progress
        from ..simulate import simulate as run

        with Progress(quiet) as say:
            run(scene, chosen, out, camera_size=camera, compensated=compensated, seed=seed,
                progress=say, white=not no_white, both_axes=both_axes, spec=spec,
                **imaging)
        if spec is not None:
            chosen = [spec.method]
        if quiet:
            return
        if scene == "calibration":
            where = str(out) if len(chosen) == 1 else f"{out}/<method>/"
            click.echo(f"wrote {', '.join(chosen)} board captures (8 poses, "
                       f"{'both axes at once' if both_axes else 'both orientations'}) to "
                       f"{where}")
        else:
            click.echo(f"wrote {', '.join(chosen)} captures of {scene} and its ground truth "
                       f"to {out}")
        return
    if no_white or both_axes:
        raise CliError("--no-white and --both-axes are for --scene calibration")
    from ..simulate import simulate_many

    try:
        report = simulate_many(count, chosen, out, seed=seed, scene=scene, vary=vary or (),
                               camera_size=camera, compensated=compensated, workers=workers,
                               scheduler=scheduler,
                               show_progress=sys.stderr.isatty() and not quiet, **imaging)
    except (KeyboardInterrupt, SystemExit) as exc:  # Ctrl-C: exit 1; SIGTERM: 143
        click.echo(f"Interrupted: the scenes finished are in {out}; index.csv is not "
                   "written", err=True)
        if isinstance(exc, SystemExit):
            raise
        raise click.exceptions.Abort() from None
    for name, error in report.failed:
        click.echo(f"failed {name}: {error}", err=quiet)
    if not quiet:
        click.echo(f"wrote {count - len(report.failed)} of {count} scenes ({len(report.rows)} "
                   f"capture sets) and index.csv to {out} in {report.seconds:.1f} s on "
                   f"{report.workers} worker{'s' if report.workers != 1 else ''}")
    if report.failed:
        raise CliError(f"{len(report.failed)} of {count} scenes failed (listed above)")


def _simulate_motion(scene: str | None, methods: list[str], out: Path,
                     camera: tuple[int, int] | None, compensated: bool, seed: int,
                     count: int | None, vary: str | None, boards: bool, cameras: int,
                     baseline: float, motion: str | None, motion_of: str, frames: int | None,
                     continuous: bool, quiet: bool, imaging: dict[str, Any],
                     stream: dict[str, Any] | None = None) -> None:
    """``bistair simulate --motion`` / ``--frames N --continuous``."""
    from ..progress import Progress
    from ..simulate_motion import simulate_motion

    if count is not None or vary is not None:
        raise CliError("--motion and --continuous render one scene: leave out --count and "
                       "--vary")
    if scene is None or scene == "calibration":
        raise CliError("--motion and --continuous render a preset scene: name one with "
                       "--scene (not calibration)")
    if boards:
        raise CliError("--no-white and --both-axes are for --scene calibration")
    with Progress(quiet) as say:
        simulate_motion(scene, methods, out, motion, moves=motion_of, frames=frames,
                        continuous=continuous, cameras=cameras, baseline=baseline,
                        camera_size=camera, compensated=compensated, progress=say,
                        seed=seed, **(stream or {}), **imaging)
    if quiet:
        return
    what = (f"a stream of {frames} frames" if continuous
            else f"{', '.join(methods)} captures")
    moved = f"{motion_of} moving {motion} per frame" if motion else "nothing moving"
    cams = " from two cameras" if cameras == 2 else ""
    click.echo(f"wrote {what} of {scene} ({moved}){cams} and the truth of every frame to "
               f"{out}")


def _simulate_stereo(scene: str | None, methods: list[str], out: Path,
                     camera: tuple[int, int] | None, compensated: bool, seed: int,
                     count: int | None, baseline: float, quiet: bool,
                     imaging: dict[str, Any]) -> None:
    """``bistair simulate --cameras 2``."""
    from ..progress import Progress
    from ..simulate import simulate_stereo

    if count is not None:
        raise CliError("--cameras 2 renders one scene: leave out --count")
    if scene is None:
        raise CliError("name a --scene")
    with Progress(quiet) as say:
        simulate_stereo(scene, methods, out, camera_size=camera, baseline=baseline,
                        compensated=compensated, progress=say, seed=seed, **imaging)
    if quiet:
        return
    if scene == "calibration":
        click.echo(f"wrote board pairs (8 poses, left and right) to {out}")
    else:
        click.echo(f"wrote {', '.join(methods)} captures of {scene} from two cameras "
                   f"{baseline:g} mm apart (L/, R/), stereo.json and the truth to {out}")
