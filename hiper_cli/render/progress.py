"""Progress bars of long runs: frames (perceive, sim, convert), downloads, benchmark units."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any

from hiper_cli.render.text import console

__all__ = ["DownloadBar", "FrameBar", "UnitBar", "download_bar", "frame_progress", "log_bars",
           "unit_progress"]


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


def _frame_bar(label: str, out: Any) -> Any:
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(TextColumn(f"[bold]{label}"), BarColumn(), MofNCompleteColumn(),
                    TextColumn("{task.fields[rate]:.1f} frames/s"), TimeElapsedColumn(), console=out)


class _LateFrameBar(FrameBar):
    """A ``FrameBar`` that appears only once ``start`` is called: nothing is drawn for a run
    refused before its first frame."""

    def __init__(self, label: str, out: Any, stack: ExitStack) -> None:
        super().__init__(None)
        self._label, self._out, self._stack = label, out, stack

    def start(self, total: int) -> None:
        self._bar = self._stack.enter_context(_frame_bar(self._label, self._out))
        super().start(total)


@contextmanager
def frame_progress(label: str, out: Any, *, enabled: bool = True, total: int | None = None,
                   late: bool = False) -> Iterator[FrameBar | None]:
    """A ``FrameBar`` labelled ``label`` on console ``out`` (started when ``total`` is given);
    ``None`` when not ``enabled`` (``--json``). ``late``: drawn from its ``start`` on."""
    if not enabled:
        yield None
        return
    if late:
        with ExitStack() as stack:
            yield _LateFrameBar(label, out, stack)
        return
    with _frame_bar(label, out) as bar:
        frame_bar = FrameBar(bar)
        if total is not None:
            frame_bar.start(total)
        yield frame_bar


class DownloadBar:
    """A transient download bar on stderr, drawn from ``start(name, total)`` on; then
    ``update(done, total)`` as ``fetch_model`` reports."""

    def __init__(self, stack: ExitStack) -> None:
        self._stack = stack
        self._bar: Any = None
        self._task: Any = None

    def start(self, name: str, total: int | None) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, DownloadColumn, Progress, TextColumn, TransferSpeedColumn

        self._bar = self._stack.enter_context(Progress(
            TextColumn("{task.description}"), BarColumn(), DownloadColumn(), TransferSpeedColumn(),
            console=Console(stderr=True), transient=True))
        self._task = self._bar.add_task(name, total=total)

    def update(self, done: int, total: int | None) -> None:
        self._bar.update(self._task, completed=done, total=total)


@contextmanager
def download_bar() -> Iterator[DownloadBar]:
    """A ``DownloadBar``, closed on leaving."""
    with ExitStack() as stack:
        yield DownloadBar(stack)


class UnitBar:
    """A rich progress bar over units of work, drawn from ``start(total)`` on (nothing for a
    run refused before it starts); then ``step(what, n)``."""

    def __init__(self, label: str, out: Any, stack: ExitStack) -> None:
        self._label, self._out, self._stack = label, out, stack
        self._bar: Any = None
        self._task: Any = None

    def start(self, total: int) -> None:
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        self._bar = self._stack.enter_context(Progress(
            TextColumn(f"[bold]{self._label}"), BarColumn(), MofNCompleteColumn(),
            TextColumn("{task.description}"), TimeElapsedColumn(), console=self._out))
        self._task = self._bar.add_task("", total=total)

    def step(self, what: str, n: int) -> None:
        self._bar.update(self._task, advance=n, description=what)


@contextmanager
def unit_progress(label: str, out: Any, *, enabled: bool = True) -> Iterator[UnitBar | None]:
    """A ``UnitBar`` labelled ``label`` on console ``out``; ``None`` when not ``enabled``."""
    if not enabled:
        yield None
        return
    with ExitStack() as stack:
        yield UnitBar(label, out, stack)


@contextmanager
def log_bars(n: int, *, enabled: bool = True) -> Iterator[Callable[[int, Path], Any]]:
    """One frame bar per log of ``n`` (rich shows a single live display: each closes the last);
    yields ``on_log(i, log)``, which returns that log's ``progress(done, total)`` or None."""
    bars = ExitStack()

    def on_log(i: int, log: Path) -> Any:
        bars.close()
        if not enabled:
            return None
        bar = bars.enter_context(frame_progress(f"perceive {i + 1}/{n} {log.name}", console()))
        return None if bar is None else bar.update

    with bars:
        yield on_log
