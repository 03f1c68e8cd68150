"""``bistair demo``: the paper's simulation, every method, one table
(:mod:`bistair.app.demo`).

Registered on the command group by :mod:`bistair.app.cli`; imports deferred into the
command, as there."""

from __future__ import annotations

from pathlib import Path

import click

from .options import Output, Size, reports_errors


@click.command()
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
