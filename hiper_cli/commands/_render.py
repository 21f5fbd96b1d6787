"""Shared rendering for commands: rich tables for people, ``--json`` for machines."""

from __future__ import annotations

import json
import sys
from typing import Any

import typer

JSON_OPTION = typer.Option(False, "--json", help="Print machine-readable JSON on stdout.")


def print_error(message: str) -> None:
    """One red line on stderr."""
    from rich.console import Console

    Console(stderr=True, highlight=False, soft_wrap=True).print(f"[bold red]error:[/] {message}")


def print_json(data: Any) -> None:
    from hiper_cli.model import json_default

    sys.stdout.write(json.dumps(data, indent=2, default=json_default) + "\n")


def console() -> Any:
    from rich.console import Console

    return Console(highlight=False)


class HiperTyper(typer.Typer):
    """A Typer whose commands turn ``HiperError`` into one red line and its exit code.

    Use it for the root app and every command group (``hiper kb ...``) so that both the
    installed script and typer's ``CliRunner`` in tests behave the same.
    """

    def command(self, *args: Any, **kwargs: Any) -> Any:
        decorator = super().command(*args, **kwargs)

        def wrap(func: Any) -> Any:
            import functools

            from hiper_cli.errors import HiperError

            @functools.wraps(func)
            def guarded(*f_args: Any, **f_kwargs: Any) -> Any:
                try:
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
