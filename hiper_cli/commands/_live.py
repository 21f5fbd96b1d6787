"""The live half of ``hiper perceive``: a ``zenoh://`` source instead of a log (see ``hiper_cli.live``)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from hiper_cli.render import emit
from hiper_cli.render.live import live_display
from hiper_cli.render.perceive import show_live

if TYPE_CHECKING:
    from hiper_cli.perceive.logs import LogOptions
    from hiper_cli.pipeline import PerceiveOptions

__all__ = ["is_live", "perceive_live_command"]


def is_live(log: Path | str) -> bool:
    """Whether the LOG argument names a live source (``zenoh://...``; a Path keeps one slash)."""
    return str(log).startswith("zenoh:")


def perceive_live_command(url: str, kb: str, kb_docs: Path | None, log_options: LogOptions,
                          options: PerceiveOptions, *, queue: int, idle_timeout_s: float | None,
                          look_ahead: bool, stats: bool, as_json: bool) -> None:
    """Run ``perceive_live`` with a one-line progress display and print its summary."""
    from hiper_cli.live import LiveSettings, perceive_live

    url = "zenoh://" + url[len("zenoh:"):].lstrip("/")  # a Path argument keeps one slash
    settings = LiveSettings(capacity=queue, idle_timeout_s=idle_timeout_s, look_ahead=look_ahead)
    with live_display(url, enabled=not as_json) as (progress, on_status):
        summary, report = perceive_live(url, kb, log_options, options, settings, kb_docs=kb_docs,
                                        on_status=on_status, progress=progress)
    data = {**summary.to_dict(), "live": report.to_dict()}
    emit(data, as_json, lambda out, shown: show_live(out, shown, stats))
