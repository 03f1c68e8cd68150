"""``bistair calibrate``, ``bistair calibrate-stereo`` and ``bistair import-calibration``:
a rig's calibration, from board captures or imported (:mod:`bistair.app.calibrate`).

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
    board_choice,
    quiet_option,
    reports_errors,
)


@click.command()
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


@click.command("import-calibration")
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
@click.option("--pixel-origin", "pixel_origin", type=click.IntRange(0, 1), default=None,
              help="with --projection-matrices: the cameras' pixel origin in the matrices, "
              "0 (OpenCV) or 1 (MATLAB) [default: 1 for .mat files, 0 otherwise]")
@quiet_option
@reports_errors
def import_calibration(files: tuple[Path, ...], out: Path, projector_size: str | None,
                       camera_size: str | None, keys: str | None, stereo: bool,
                       matrices: str | None, pixel_origin: int | None, quiet: bool) -> None:
    """Convert an OpenCV FileStorage calibration (YAML or XML, e.g. stereo_calib's
    intrinsics.yml and extrinsics.yml, camera as device 1) into a bistair calibration file.
    R, T map the camera frame to the projector frame; T in millimetres. With --stereo, two
    cameras: R, T map the left camera's frame to the right one's. With
    --projection-matrices (and no FILES), two cameras and the projector from their 3x4
    matrices P = K [R | t] (X_device = R X_world + t, mm); --pixel-origin 1 for matrices
    of 1-based camera pixels (MATLAB's)."""
    if matrices is not None:
        from ..calibrate import import_projection_matrices

        if files or stereo or keys:
            raise CliError("--projection-matrices takes no FILES, --stereo or --keys")
        rig, origin = import_projection_matrices(matrices, out, camera_size, projector_size,
                                                 pixel_origin)
        if quiet:
            return
        click.echo(f"cameras {rig.left.width}x{rig.left.height} (pixel origin {origin}), "
                   f"baseline {rig.baseline:.2f} mm, projector {rig.projector.device.width}x"
                   f"{rig.projector.device.height} at "
                   f"{float(np.linalg.norm(rig.projector.R.T @ rig.projector.T)):.2f} mm from "
                   f"the left camera; wrote {out}")
        return
    if pixel_origin is not None:
        raise CliError("--pixel-origin goes with --projection-matrices")
    if not files:
        raise CliError("give the calibration FILES (or --projection-matrices)")
    if stereo:
        from ...geometry.calibration import short_baseline
        from ..calibrate import import_stereo_calibration

        if projector_size is not None:
            raise CliError("--projector-size does not apply to a stereo calibration (two "
                           "cameras)")
        pair = import_stereo_calibration(files, out, camera_size, keys)
        if not quiet:
            click.echo(f"cameras {pair.left.width}x{pair.left.height}, baseline "
                       f"{pair.baseline:.2f} mm; wrote {out}")
        if short_baseline(pair):
            click.echo(f"Warning: {short_baseline(pair)}", err=True)
        return
    from ..calibrate import import_calibration as run

    cal = run(files, out, projector_size, camera_size, keys)
    if quiet:
        return
    click.echo(f"camera {cal.camera.width}x{cal.camera.height}, projector "
               f"{cal.projector.width}x{cal.projector.height}, baseline {cal.baseline:.2f} mm; "
               f"wrote {out}")


@click.command("calibrate-stereo")
@click.argument("poses", type=Input())
@board_choice("POSES")
@click.option("--out", "-o", required=True, type=Output(file=True),
              help="stereo calibration file to write (JSON)")
@click.option("--min-poses", type=int, default=3, show_default=True,
              help="fewest poses with the board found in both images (3 or more)")
@quiet_option
@reports_errors
def calibrate_stereo(poses: Path, board: str | None, out: Path, min_poses: int,
                     quiet: bool) -> None:
    """Calibrate two cameras from image pairs of a board.

    POSES: one folder per pose holding a left and a right image (named left/right, else in
    name order), or left/ and right/ folders whose images pair up in name order. Poses
    where the board is not found in both images are skipped."""
    from ..calibrate import calibrate_stereo_folder
    from ..progress import Progress

    with Progress(quiet) as say:
        cal, skipped = calibrate_stereo_folder(poses, out, board, min_poses, progress=say)
    for name in skipped:
        click.echo(f"Warning: pose {name} skipped: the board is not found in both images",
                   err=True)
    if quiet:
        return
    click.echo(f"stereo RMS {cal.rms:.3f} px (left {cal.left.rms:.3f} px, right "
               f"{cal.right.rms:.3f} px), baseline {cal.baseline:.2f} +/- "
               f"{cal.uncertainty.baseline:.2f} mm, {len(cal.poses)} of {cal.poses_total} "
               f"poses; wrote {out}")
    for name, dev, sd in (("left", cal.left, cal.uncertainty.camera),
                          ("right", cal.right, cal.uncertainty.projector)):
        values = (dev.K[0, 0], dev.K[1, 1], dev.K[0, 2], dev.K[1, 2])
        click.echo(f"  {name + ':':7s} " + ", ".join(
            f"{key} {v:.2f} +/- {s:.2f}"
            for key, v, s in zip(("fx", "fy", "cx", "cy"), values, sd[:4], strict=True)) + " px")
    for pose in cal.poses:
        click.echo(f"  {pose['name']}: {pose['features']} corners, left "
                   f"{pose['left_rms']:.3f} px, right {pose['right_rms']:.3f} px")
