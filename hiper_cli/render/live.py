"""What a live ``hiper perceive zenoh://...`` shows while it runs: one status line, and the
robot's own reports (a topic gone silent, a message that could not be read)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from hiper_cli.render.text import console, safe_text

__all__ = ["live_display"]


@contextmanager
def live_display(url: str, *, enabled: bool = True
                 ) -> Iterator[tuple[Callable[[int, Any], None], Callable[[str, str], None]]]:
    """Yields ``progress(frames, report)`` and ``on_status(kind, text)`` for ``perceive_live``;
    both silent when not ``enabled`` (``--json``)."""
    out = console()
    status = out.status(f"live {url}: waiting for frames (Ctrl-C ends the run)") if enabled else None

    def progress(frames: int, report: Any) -> None:
        if status is not None:
            p95 = report.latency_ms()["p95"]
            status.update(f"live {safe_text(url)}: {frames} frames perceived, "
                          f"{report.frames_dropped} dropped, latency p95 {p95} ms (Ctrl-C ends the run)")

    def on_status(kind: str, text: str) -> None:
        if enabled:
            shown = safe_text(text)
            out.print(f"[yellow]{kind}:[/] {shown}" if kind == "silent" else f"{kind}: {shown}")

    if status is not None:
        status.start()
    try:
        yield progress, on_status
    finally:
        if status is not None:
            status.stop()
