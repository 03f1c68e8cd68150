"""The command line explains itself (issue 25): every option of every command has help, a
type (numbers as numbers) or a metavar naming its form, ``--strategy`` lists every method's
strategies from the codecs, and ``simulate --help`` names every scene and method."""

from __future__ import annotations

import click
import pytest

from bistair.app.cli import cli
from bistair.codecs import REGISTRY
from bistair.sim import scene_names


def _commands(group: click.Group, ctx: click.Context, path: str = "bistair"):
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        sub = click.Context(command, info_name=name, parent=ctx)
        if isinstance(command, click.Group):
            yield from _commands(command, sub, f"{path} {name}")
        else:
            yield f"{path} {name}", command, sub


COMMANDS = list(_commands(cli, click.Context(cli, info_name="bistair")))


def test_every_command_is_walked():
    names = {name for name, _, _ in COMMANDS}
    assert {"bistair decode", "bistair simulate", "bistair scan", "bistair patterns gamma",
            *(f"bistair patterns {m}" for m in REGISTRY)} <= names


@pytest.mark.parametrize(("name", "command", "ctx"), COMMANDS, ids=[c[0] for c in COMMANDS])
def test_every_option_is_explained_and_typed(name, command, ctx):
    for param in command.params:
        if not isinstance(param, click.Option) or param.name in ("help", "version"):
            continue
        record = param.get_help_record(ctx)
        assert record is not None and record[1].strip(), f"{name} {param.opts[0]}: no help"
        metavar = param.make_metavar(ctx)
        assert param.is_flag or metavar != "TEXT", f"{name} {param.opts[0]} is typed TEXT"
        default = param.default
        if isinstance(default, int | float) and not isinstance(default, bool):
            assert isinstance(param.type, click.types.IntParamType | click.types.FloatParamType
                              | click.Choice), f"{name} {param.opts[0]}: a number as text"


@pytest.mark.parametrize("command", ["decode", "reconstruct", "batch"])
def test_strategy_lists_every_methods_strategies(command):
    ctx = click.Context(cli.commands[command], info_name=command)
    option = next(p for p in cli.commands[command].params if p.name == "strategy")
    text = " ".join(option.get_help_record(ctx)[1].split())
    for method, codec in REGISTRY.items():
        choices = codec.choices.get("strategy")
        if choices:
            assert f"{method}: {choices[0]} [default] | {' | '.join(choices[1:])}" in text
        else:
            assert method in text.split("(")[-1]  # "(lv and multifreq: none)"


def test_the_codecs_declare_their_strategies():
    assert REGISTRY["bidirectional"].choices == {"strategy": ("region", "paper")}
    assert REGISTRY["graycode"].choices == {"strategy": ("pixel", "region")}
    assert REGISTRY["multifreq"].choices == {}


def test_simulate_help_names_every_scene_and_method():
    ctx = click.Context(cli.commands["simulate"], info_name="simulate")
    text = " ".join(cli.commands["simulate"].get_help(ctx).split()).replace("- ", "-")
    for name in [*scene_names(), "calibration", *REGISTRY]:
        assert name in text, name


def test_a_strategy_no_decoder_has_is_refused_in_one_line(tmp_path, monkeypatch, capsys):
    from conftest import cli_run

    code, _, err = cli_run(monkeypatch, capsys, "decode", tmp_path, "--out", tmp_path / "o",
                           "--strategy", "mode")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "'mode' is no decoder's strategy (bidirectional: region [default] | paper" in err


def test_every_command_of_app_cli_is_on_the_group():
    """Each command module of app/cli/ (one per job module, issue 35) puts every click
    command it defines on the group: a command made and left off would be missing from
    ``bistair --help``."""
    import importlib
    from pathlib import Path

    folder = Path(importlib.import_module("bistair.app.cli").__file__).parent
    made = []
    for path in sorted(folder.glob("*.py")):
        module = importlib.import_module("bistair.app.cli" + (
            "" if path.stem == "__init__" else f".{path.stem}"))
        made += [value for value in vars(module).values() if isinstance(value, click.Command)
                 and value is not cli and value.callback.__module__ == module.__name__]
    on_group = [cmd for _, cmd, _ in COMMANDS] + [cmd for cmd in cli.commands.values()]
    assert len(made) >= 15
    assert [c.name for c in made if not any(c is cmd for cmd in on_group)] == []
