"""What the commands of the ``bistair`` command line share: one-line errors and exit
code 2, the common options (``--quiet``, ``--force``, ``--threads``, ``--strategy``),
parameter types that say what they take (inputs and outputs among them: no output of a
command may be, hold or mix with one of its inputs), and the printing of a decode's
warnings."""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from ...errors import BistairError


class CliError(click.ClickException):
    """A refusal of the command line: ``Error: <message>`` on one line and exit code 2.

    >>> CliError("--min-poses 1 is too few").exit_code
    2
    """

    exit_code = 2


def reports_errors(func: Callable) -> Callable:
    """Turn :class:`BistairError` into a one-line message and exit code 2; run the command
    with its :class:`Input` values as its inputs (:func:`bistair.io.inputs.reading`), and
    refuse first an :class:`Output` that is, holds or mixes with one of them."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        from ...io.atomic import check_output
        from ...io.inputs import reading

        ctx = click.get_current_context(silent=True)
        params = [] if ctx is None else [p for p in ctx.command.params if p.name in kwargs]
        inputs = [path for p in params if isinstance(p.type, Input)
                  for path in p.type.paths(kwargs[p.name])]
        try:
            with reading(*inputs):
                for p in params:
                    if isinstance(p.type, Output) and kwargs[p.name] is not None:
                        check_output(kwargs[p.name], file=p.type.file)
                return func(*args, **kwargs)
        except BistairError as exc:
            raise CliError(str(exc)) from None
        except MemoryError:
            raise CliError("not enough memory for these captures") from None

    return wrapper


class Input(click.Path):
    """A path the command reads (a file, a folder or, as text, a glob pattern): no output
    of the command may be it, hold it or mix with it (:func:`reports_errors`).

    Parameters
    ----------
    text : bool
        Keep the value as text (glob patterns), not a :class:`~pathlib.Path`.
    path_of : callable, optional
        The path in a value that holds more (``FOLDER:HEIGHT``), ``None`` for a value that
        names no file (``chessboard:9x7:25``); by default the value itself.
    """

    def __init__(self, text: bool = False,
                 path_of: Callable[[str], str | None] | None = None) -> None:
        super().__init__(path_type=None if text else Path)
        self.path_of = path_of

    def paths(self, value: Any) -> list[str]:
        """The paths of a parameter's value (one, several or none)."""
        values = [] if value is None else list(value) if isinstance(value, tuple | list) \
            else [value]
        found = [str(v) if self.path_of is None else self.path_of(str(v)) for v in values]
        return [v for v in found if v]


def board_choice(default: str) -> Callable[[Callable], Callable]:
    """The ``--board`` option of ``calibrate`` and ``calibrate-stereo`` (a ``board.json`` or
    a description such as ``chessboard:9x7:25``, read by
    :func:`bistair.app.calibrate.board_option`); ``default``: the folder whose
    ``board.json`` is read without it.

    >>> board_choice("POSES")(lambda board: board).__click_params__[0].metavar
    'FILE|TYPE:COLSxROWS:SPACING'
    """
    return click.option("--board", default=None, metavar="FILE|TYPE:COLSxROWS:SPACING",
                        type=Input(text=True, path_of=board_file),
                        help="board.json, or e.g. chessboard:9x7:25 (inner corners, square "
                        f"in mm) [default: {default}/board.json]")


def board_file(value: str) -> str | None:
    """The file a ``--board`` value names, ``None`` for a description such as
    ``chessboard:9x7:25`` (:func:`bistair.geometry.board.is_board_text`).

    >>> board_file("chessboard:9x7:25"), board_file("calib/board.json")
    (None, 'calib/board.json')
    """
    from ...geometry.board import is_board_text

    return None if is_board_text(value) else value


class Output(click.Path):
    """A path the command writes, a folder or a ``file`` (kept as ``text`` as typed, e.g.
    with its final ``/``, or as a :class:`~pathlib.Path`): an empty one is refused here (a
    path given as ``''`` would otherwise be the current folder), one that is, holds or
    mixes with an :class:`Input` before the command runs (:func:`reports_errors`)."""

    def __init__(self, file: bool = False, text: bool = False) -> None:
        super().__init__(path_type=None if text else Path)
        self.file = file

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        if isinstance(value, str) and not value.strip():
            self.fail("the output path is empty", param, ctx)
        return super().convert(value, param, ctx)


def quiet_option(func: Callable) -> Callable:
    """``--quiet``: no progress and no summary; errors and warnings are still printed.

    Parameters
    ----------
    func : callable
        The command (under its ``@click.command``), given a ``quiet`` argument.

    Returns
    -------
    callable
        ``func`` with the option.

    Examples
    --------
    >>> quiet_option(lambda quiet: quiet).__click_params__[0].opts
    ['--quiet', '-q']
    """
    return click.option("--quiet", "-q", is_flag=True,
                        help="print only errors and warnings (no progress, no summary)")(func)


def force_option(func: Callable) -> Callable:
    """``--force``: decode where a thresholded check would refuse.

    Parameters
    ----------
    func : callable
        The command, given a ``force`` argument.

    Returns
    -------
    callable
        ``func`` with the option.

    Examples
    --------
    >>> force_option(lambda force: force).__click_params__[0].is_flag
    True
    """
    return click.option("--force", is_flag=True,
                        help="decode where a thresholded check would refuse the captures: its "
                        "reasons are printed as warnings and kept in info.json ('forced'); "
                        "hard errors (frame count, unreadable files, no valid pixel) stay "
                        "errors")(func)


def threads_option(func: Callable) -> Callable:
    """``--threads N``: at most N threads in the decode's kernels and OpenCV, set when the
    option is parsed (the command is given no argument for it).

    Parameters
    ----------
    func : callable
        The command.

    Returns
    -------
    callable
        ``func`` with the option.

    Examples
    --------
    >>> threads_option(lambda: None).__click_params__[0].expose_value
    False
    """

    def limit(ctx: click.Context, param: click.Parameter, value: int | None) -> int | None:
        if value is not None:
            import cv2

            from ...core.jit import set_threads

            set_threads(value)
            cv2.setNumThreads(value)
        return value

    return click.option("--threads", type=click.IntRange(min=1), default=None,
                        expose_value=False, callback=limit,
                        help="use at most N threads [default: every core]")(func)


class Text(click.ParamType):
    """A value kept as text for the command to parse, shown in the help by its form
    (``WxH``, ``NUMBER``: a number, a fraction such as 1920/58 or ``-2*pi/3``, ...).

    >>> Text("NUMBER").convert("1920/58", None, None)
    '1920/58'
    """

    def __init__(self, metavar: str) -> None:
        self.name = metavar.lower()
        self.metavar = metavar

    def get_metavar(self, param: click.Parameter, ctx: click.Context | None = None) -> str:
        return self.metavar

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        return value


class Size(Text):
    """``WIDTHxHEIGHT`` as ``(width, height)``.

    >>> Size("WxH").convert("1280x1024", None, None)
    (1280, 1024)
    """

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        if isinstance(value, tuple):
            return value
        try:
            width, height = (int(v) for v in str(value).lower().split("x"))
        except ValueError:
            self.fail("expected WIDTHxHEIGHT, e.g. 1280x1024", param, ctx)
        return width, height


class _Strategy(Text):
    """A fringe-order strategy of some method's decoder (each decoder checks its own)."""

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        if value not in {v for values in _strategies().values() for v in values}:
            self.fail(f"{value!r} is no decoder's strategy ({_strategy_help()})", param, ctx)
        return value


def _strategies() -> dict[str, tuple[str, ...]]:
    """Each method's strategies, its default first (from the codecs' order stages)."""
    from ...codecs import REGISTRY

    return {name: codec.choices["strategy"] for name, codec in REGISTRY.items()
            if "strategy" in codec.choices}


def _strategy_help() -> str:
    from ...codecs import REGISTRY

    listed = "; ".join(f"{name}: {' [default] | '.join(values)}"
                       for name, values in _strategies().items())
    alone = [name for name in REGISTRY if name not in _strategies()]
    return listed + (f" ({' and '.join(alone)}: none)" if alone else "")


def method_names() -> str:
    """The registry's methods joined by commas, for a help made when it is shown
    (:class:`LazyHelp`).

    Returns
    -------
    str
        The method names.

    Examples
    --------
    >>> "graycode" in method_names().split(", ")
    True
    """
    from ...codecs import REGISTRY

    return ", ".join(REGISTRY)


class LazyHelp(click.Option):
    """An option whose help names what the registry holds, made when the help is shown (so
    that ``bistair --help`` and every command itself do not import the codecs for it):
    ``help_from()`` fills the ``{}`` of its help.

    >>> LazyHelp(["--method"], help_from=method_names, help="one of {}").help_text
    'one of {}'
    """

    def __init__(self, *args: Any, help_from: Callable[[], str], **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.help_from, self.help_text = help_from, kwargs.get("help") or ""

    def get_help_record(self, ctx: click.Context) -> tuple[str, str] | None:
        self.help = self.help_text.format(self.help_from())
        return super().get_help_record(ctx)


def strategy_option(func: Callable) -> Callable:
    """``--strategy``: a fringe-order strategy, listed per method in the help; a name that
    is no decoder's strategy is refused (each decoder checks its own).

    Parameters
    ----------
    func : callable
        The command, given a ``strategy`` argument (``None`` when not given).

    Returns
    -------
    callable
        ``func`` with the option.

    Examples
    --------
    >>> strategy_option(lambda strategy: strategy).__click_params__[0].name
    'strategy'
    """
    return click.option("--strategy", type=_Strategy("STRATEGY"), default=None, cls=LazyHelp,
                        help_from=_strategy_help,
                        help="fringe-order strategy of the method's decoder: {}")(func)


def print_warnings(result: Any) -> None:
    """Print a decode's warnings on stderr, one line each (``Warning: <message>``).

    Parameters
    ----------
    result : DecodeResult or AxesResult
        The decode; of both axes, the warnings of x, then of y.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> print_warnings(SimpleNamespace(info={"warnings": []}))  # none: prints nothing
    """
    infos = [result.info] if not hasattr(result, "x") else [result.x.info, result.y.info]
    for info in infos:
        for message in info.get("warnings", []):
            click.echo(f"Warning: {message}", err=True)
