"""The ``bistair`` command line: the group, :func:`main` and the handling of signals.

Each command lives in the module named after its job module in :mod:`bistair.app`
(``bistair decode`` and ``reconstruct`` in :mod:`bistair.app.cli.decode`, which calls
:mod:`bistair.app.decode`); the options they share are :mod:`bistair.app.cli.options`.
Every failure on bad input prints one line, ``Error: <what is wrong>``, and exits with 2.
Commands import their jobs when they run, so that ``bistair --help`` and ``--version`` do
not pay for the imaging and geometry libraries.
"""

from __future__ import annotations

import signal
import sys
from typing import Any

import click

from ...core.jit import interrupt
from ...core.memory import keep_freed_memory
from . import batch, bench, calibrate, decode, demo, patterns, scan, simulate, stereo


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="bistair", prog_name="bistair")
def cli() -> None:
    """Absolute phase measurement for fringe projection profilometry."""


# every command, each from the module of its job's name (bistair.app.<name>)
COMMANDS = (batch.batch, bench.bench, calibrate.calibrate, calibrate.calibrate_stereo,
            calibrate.import_calibration, decode.decode, decode.height, decode.reconstruct,
            demo.demo, patterns.gamma, patterns.patterns, scan.scan, simulate.simulate,
            stereo.stereo)
for _command in COMMANDS:
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
