"""The ``bistair`` command line.

Every failure on bad input prints one line, ``Error: <what is wrong>``, and exits with 2.
"""

from __future__ import annotations

import dataclasses
import functools
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from . import __version__
from .codecs import CODECS
from .errors import BistairError
from .spec import BaseSpec, _field_kind


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


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="bistair")
def cli() -> None:
    """Absolute phase measurement for fringe projection profilometry."""


@cli.group()
def patterns() -> None:
    """Write a method's patterns (NN.png) and their spec.json into a folder."""


def _parse_list(ctx: click.Context, param: click.Parameter, value: Any) -> Any:
    if value is None or isinstance(value, tuple):
        return value
    try:
        return tuple(int(v) for v in str(value).split(",") if v.strip())
    except ValueError:
        raise click.BadParameter("expected comma-separated integers, e.g. 1080,180,30") from None


def _spec_command(name: str, spec_class: type[BaseSpec], summary: str) -> click.Command:
    params: list[click.Parameter] = []
    for f in dataclasses.fields(spec_class):
        if f.metadata.get("cli") is False:
            continue
        kind = _field_kind(f)
        opt: dict[str, Any] = {"help": f.metadata.get("help", ""), "show_default": True}
        if "choices" in f.metadata:
            opt["type"] = click.Choice([str(c) for c in f.metadata["choices"]])
            opt["default"] = str(f.default)
        elif kind is tuple:
            opt["type"] = str
            opt["default"] = ",".join(map(str, f.default))
            opt["callback"] = _parse_list
        else:
            opt["type"] = kind
            opt["default"] = f.default
        params.append(click.Option([f"--{f.name.replace('_', '-')}", f.name], **opt))
    params.append(click.Option(["--out", "-o"], required=True, type=click.Path(path_type=Path),
                               help="output folder"))

    @reports_errors
    def callback(out: Path, **values: Any) -> None:
        from .workflow import save_patterns

        for f in dataclasses.fields(spec_class):
            if f.name in values and isinstance(f.default, int) and isinstance(values[f.name], str):
                values[f.name] = int(values[f.name])
        spec = spec_class(**values)
        save_patterns(spec, out)
        click.echo(f"wrote {spec.frame_count} {name} patterns and spec.json to {out}")

    return click.Command(name, params=params, callback=callback, help=summary)


for _codec in CODECS.values():
    patterns.add_command(_spec_command(_codec.name, _codec.spec_class, _codec.summary))


@cli.command()
@click.argument("captures", type=click.Path(path_type=Path))
@click.option("--spec", "spec_path", type=click.Path(path_type=Path), default=None,
              help="spec.json of the pattern set [default: CAPTURES/spec.json]")
@click.option("--out", "-o", required=True, type=click.Path(path_type=Path),
              help="output folder")
@click.option("--strategy", default=None, help="fringe-order strategy (bidirectional: "
              "region [default] or paper)")
@click.option("--min-modulation", type=float, default=None,
              help="modulation threshold as a fraction of full scale [default: from noise]")
@click.option("--no-previews", is_flag=True, help="skip the PNG previews")
@reports_errors
def decode(captures: Path, spec_path: Path | None, out: Path, strategy: str | None,
           min_modulation: float | None, no_previews: bool) -> None:
    """Decode captured images into absolute phase, projector coordinate and fringe order."""
    from .workflow import decode_folder

    options = {k: v for k, v in (("strategy", strategy), ("min_modulation", min_modulation))
               if v is not None}
    result = decode_folder(captures, out, spec_path, previews=not no_previews, **options)
    click.echo(f"decoded {result.method}: {int(result.mask.sum())} of {result.mask.size} "
               f"pixels valid ({100 * result.mask.mean():.1f}%); wrote {out}")


@cli.command()
@click.option("--out", "-o", type=click.Path(path_type=Path), default=Path("demo-out"),
              show_default=True, help="output folder")
@click.option("--seed", type=int, default=0, show_default=True)
@reports_errors
def demo(out: Path, seed: int) -> None:
    """Generate patterns, synthesise isolated objects, decode and score against the truth."""
    from .demo import run_demo

    run_demo(out, seed=seed)


def main() -> None:
    try:
        cli(standalone_mode=False)
    except click.exceptions.Abort:
        click.echo("Aborted.", err=True)
        sys.exit(1)
    except click.ClickException as exc:
        exc.show()
        sys.exit(exc.exit_code)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
