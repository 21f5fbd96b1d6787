"""A bad command line as its usage line and one red line naming the bad word and the nearest fix."""

from __future__ import annotations

import sys

import typer

from hiper_cli.render import print_error

__all__ = ["is_usage_error", "print_usage_error", "usage_error_lines"]


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
