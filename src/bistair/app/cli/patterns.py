"""``bistair patterns NAME``, ``bistair patterns gamma`` and ``bistair gamma``: pattern
sets and the projector's gamma (:mod:`bistair.app.patterns`).

Registered on the command group by :mod:`bistair.app.cli`; imports deferred into the
commands, as there."""

from __future__ import annotations

import dataclasses
import difflib
from pathlib import Path
from typing import Any

import click

from ...spec import BaseSpec, coerce_field, field_kind
from .options import (
    Input,
    Output,
    Text,
    quiet_option,
    reports_errors,
)


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


@click.group(cls=_MethodCommands)
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
    params += quiet_option(lambda quiet: None).__click_params__  # (as the other commands')

    @reports_errors
    def callback(out: Path, gamma_file: Path | None, quiet: bool, **values: Any) -> None:
        from ..patterns import read_gamma, save_patterns

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
        if not quiet:
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
@quiet_option
@reports_errors
def patterns_gamma(width: int, height: int, levels: int, bits: str, out: Path,
                   quiet: bool) -> None:
    """A ramp of uniform grey frames (NN.png and ramp.json) for 'bistair gamma'."""
    from ..patterns import save_ramp

    save_ramp(width, height, levels, int(bits), out)
    if not quiet:
        click.echo(f"wrote {levels} grey frames and ramp.json to {out}")


@click.command()
@click.argument("captures", nargs=-1, required=True, type=Input(text=True))
@click.option("--ramp", type=Input(), default=None,
              help="ramp.json of the grey frames [default: ramp.json in the captures' folder]")
@click.option("--out", "-o", required=True, type=Output(file=True),
              help="gamma file to write (JSON)")
@quiet_option
@reports_errors
def gamma(captures: tuple[str, ...], ramp: Path | None, out: Path, quiet: bool) -> None:
    """Measure the projector's gamma from captures of 'bistair patterns gamma'."""
    from ..patterns import measure_gamma

    fit = measure_gamma(list(captures), out, ramp)
    if not quiet:
        click.echo(f"projector gamma {fit.gamma:.3f} (RMS misfit {fit.rms:.4f} over "
                   f"{len(fit.levels)} levels, {fit.pixels} pixels); wrote {out}")
