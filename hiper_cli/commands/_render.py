"""Shared rendering for commands: rich tables for people, ``--json`` for machines."""

from __future__ import annotations

import json
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import typer

from hiper_cli.commands._common import JSON_OPTION

__all__ = ["JSON_OPTION", "HiperTyper", "console", "frame_progress", "group", "print_error", "print_json"]


def print_error(message: str) -> None:
    """One red line on stderr."""
    from rich.console import Console
    from rich.markup import escape

    # Escaped: a message such as "pip install 'hiper[view]'" keeps its brackets.
    Console(stderr=True, highlight=False, soft_wrap=True).print(f"[bold red]error:[/] {escape(message)}")


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

