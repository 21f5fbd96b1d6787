"""Shared rendering for commands: rich tables for people, ``--json`` for machines."""

from __future__ import annotations

import json
import re
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

import typer

from hiper_cli.commands._common import JSON_OPTION

_F = TypeVar("_F", bound=Callable[..., Any])

__all__ = ["JSON_OPTION", "HiperTyper", "console", "frame_progress", "group", "print_error", "print_json",
           "safe_text"]


# Terminal escape sequences (CSI ``ESC [ ... final``, OSC/DCS/APC/PM/SOS ``ESC ] ... BEL or ESC \``,
# two-byte ``ESC x``) and the C0/C1 controls other than newline and tab.
_ESCAPES = re.compile(
    r"\x1b\[[0-?]*[ -/]*[@-~]?"
    r"|[\x1b\x9b-\x9f][\]PX^_][^\x07\x1b\x9c]*(?:\x07|\x1b\\|\x9c)?"
    r"|\x1b[ -~]?"
    r"|[\x00-\x08\x0b-\x1f\x7f-\x9f]"
)


def safe_text(value: object, *, markup: bool = True) -> str:
    """``value`` as text that prints as itself: terminal escape sequences and control
    characters (except newline and tab) removed, lone surrogates replaced, and, for rich output
    (``markup``), ``[`` escaped so ``[bold]`` or ``[/]`` is shown rather than applied. Every
    user-supplied or stored string goes through it before rich prints it; the consoles here
    have emoji codes (``:x:``) off."""
    from rich.markup import escape

    text = _ESCAPES.sub("", str(value))
    text = text.encode("utf-8", "replace").decode("utf-8")  # a lone surrogate becomes '?'
    return escape(text) if markup else text


def print_error(message: str) -> None:
    """One red line on stderr."""
    from rich.console import Console

    # Escaped: a message such as "pip install 'hiper[view]'" keeps its brackets.
    Console(stderr=True, highlight=False, soft_wrap=True, emoji=False).print(
        f"[bold red]error:[/] {safe_text(message)}")


def print_json(data: Any) -> None:
    from hiper_cli.model import json_default

    sys.stdout.write(json.dumps(data, indent=2, default=json_default) + "\n")


def console() -> Any:
    """The stdout console of the commands: no highlighting, no emoji codes (print user or
    stored strings through ``safe_text``)."""
    from rich.console import Console

    return Console(highlight=False, emoji=False)


def _flag_names(func: Any) -> dict[str, str]:
    """Parameter name -> the long flag the user types (``fx_px`` -> ``--fx``)."""
    import inspect

    try:
        parameters = inspect.signature(func, eval_str=True).parameters
    except (NameError, TypeError):
        parameters = inspect.signature(func).parameters
    out: dict[str, str] = {}
    for name, p in parameters.items():
        for info in (p.default, *getattr(p.annotation, "__metadata__", ())):
            decls = [d for d in getattr(info, "param_decls", None) or () if isinstance(d, str)]
            first = getattr(info, "default", None)  # Annotated[..., typer.Option("--flag")]
            if isinstance(first, str) and first.startswith("-") and hasattr(info, "param_decls"):
                decls.insert(0, first)
            if decls:
                out[name] = next((d for d in decls if d.startswith("--")), decls[0])
    return out


class HiperTyper(typer.Typer):
    """A Typer whose commands check their numeric options (``hiper_cli.validate``) and turn
    ``HiperError`` into one red line and its exit code.

    Use it for the root app and every command group (``hiper kb ...``) so that both the
    installed script and typer's ``CliRunner`` in tests behave the same.
    """

    def command(self, *args: Any, **kwargs: Any) -> Callable[[_F], _F]:
        def wrap(func: _F) -> _F:
            import functools
            import inspect

            from hiper_cli.errors import HiperError
            from hiper_cli.validate import check_options

            if "short_help" not in kwargs:
                # rich help keeps a docstring's line breaks in the list of commands; one line reads
                first = (kwargs.get("help") or inspect.getdoc(func) or "").split("\n\n")[0]
                kwargs["short_help"] = " ".join(first.split())
            decorator = super(HiperTyper, self).command(*args, **kwargs)
            flags = _flag_names(func)

            @functools.wraps(func)
            def guarded(*f_args: Any, **f_kwargs: Any) -> Any:
                try:
                    check_options(f_kwargs, flags)  # every number, where the command line is parsed
                    return func(*f_args, **f_kwargs)
                except HiperError as err:
                    print_error(str(err))
                    raise typer.Exit(err.exit_code) from err

            decorator(guarded)
            return func

        return wrap


def group(name: str, help: str) -> HiperTyper:
    """A command group such as ``hiper kb``; ``help`` must contain an ``Example:``."""
    return HiperTyper(name=name, help=help, no_args_is_help=True, add_completion=False)


class FrameBar:
    """A rich progress bar over frames: ``start(total)`` once, then ``update(done, total)``."""

    def __init__(self, bar: Any) -> None:
        self._bar = bar
        self._task: Any = None

    def start(self, total: int) -> None:
        self._task = self._bar.add_task("frames", total=total, rate=0.0)

    def advance(self, *_: Any) -> None:
        self._bar.advance(self._task)

    def update(self, done: int, total: int) -> None:
        if self._task is None:
            self.start(total)
        elapsed = self._bar.tasks[0].elapsed or 0.0
        self._bar.update(self._task, completed=done, total=total, rate=done / elapsed if elapsed > 0 else 0.0)


@contextmanager
def frame_progress(label: str, out: Any, *, enabled: bool = True, total: int | None = None
                   ) -> Iterator[FrameBar | None]:
    """A ``FrameBar`` labelled ``label`` on console ``out`` (started when ``total`` is given);
    ``None`` when not ``enabled`` (``--json``)."""
    if not enabled:
        yield None
        return
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    with Progress(TextColumn(f"[bold]{label}"), BarColumn(), MofNCompleteColumn(),
                  TextColumn("{task.fields[rate]:.1f} frames/s"), TimeElapsedColumn(), console=out) as bar:
        frame_bar = FrameBar(bar)
        if total is not None:
            frame_bar.start(total)
        yield frame_bar

def _click_exception_types() -> tuple[type[BaseException], ...]:
    """click's exception base, and the one of the click copy that newer typer versions carry."""
    import click

    found: list[type[BaseException]] = [click.ClickException]
    typer_base = getattr(typer, "TyperException", None)
    if isinstance(typer_base, type) and issubclass(typer_base, BaseException):
        found.append(typer_base)
    return tuple(found)


def is_usage_error(exc: BaseException) -> bool:
    """Whether ``exc`` is click's (or typer's) report of a bad command line."""
    return isinstance(exc, _click_exception_types()) and hasattr(exc, "format_message")


def _close(word: str, choices: list[str]) -> str | None:
    import difflib

    found = difflib.get_close_matches(word, choices, n=1, cutoff=0.5)
    return found[0] if found else None


def usage_error_lines(exc: BaseException) -> tuple[str | None, str]:
    """The usage line of the command a click usage error belongs to (None when there is no
    command context) and one line naming the bad word, with the nearest valid command or option."""
    import re

    ctx = getattr(exc, "ctx", None)
    usage = ctx.get_usage() if ctx is not None else None
    command = getattr(ctx, "command", None)
    path = getattr(ctx, "command_path", "hiper")
    help_hint = f"see '{path} --help'"
    option = getattr(exc, "option_name", None)
    if option is not None and hasattr(exc, "possibilities"):  # NoSuchOption
        names = [o for p in getattr(command, "params", []) for o in (*p.opts, *p.secondary_opts)]
        best = _close(option, names) or next(iter(sorted(getattr(exc, "possibilities", None) or [])), None)
        hint = f"did you mean {best!r}? " if best else ""
        return usage, f"no such option {option!r} for '{path}'; {hint}({help_hint})"
    message = str(getattr(exc, "message", "") or "")
    unknown = re.match(r"No such command '(.*?)'", message)
    if unknown and command is not None and hasattr(command, "list_commands"):
        word = unknown.group(1)
        commands = [c for c in command.list_commands(ctx) if not c.startswith("_")]
        best = _close(word, commands)
        hint = f"did you mean {best!r}?" if best else f"expected one of {', '.join(commands)}"
        return usage, f"no such command {word!r} for '{path}'; {hint} ({help_hint})"
    text = " ".join(str(exc.format_message()).split())  # type: ignore[attr-defined]
    return usage, f"{text} ({help_hint})"


def print_usage_error(exc: BaseException) -> int:
    """Print a click usage error as its usage line and one red line; returns the exit code (2).
    A group called without a command (``hiper kb``) prints its help instead."""
    if type(exc).__name__ == "NoArgsIsHelpError":
        typer.echo(str(exc.format_message()), err=True)  # type: ignore[attr-defined]
        return int(getattr(exc, "exit_code", 2))
    usage, line = usage_error_lines(exc)
    if usage:
        sys.stderr.write(usage.rstrip() + "\n")
    print_error(line)
    return int(getattr(exc, "exit_code", 2) or 2)
