"""The live half of ``hiper perceive``: a ``zenoh://`` source instead of a log (see ``hiper_cli.live``)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from hiper_cli.commands._render import console, print_json, safe_text

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
    from hiper_cli.live import LiveReport, LiveSettings, perceive_live

    url = "zenoh://" + url[len("zenoh:"):].lstrip("/")  # a Path argument keeps one slash
    out = console()
    settings = LiveSettings(capacity=queue, idle_timeout_s=idle_timeout_s, look_ahead=look_ahead)
    status = None if as_json else out.status(f"live {url}: waiting for frames (Ctrl-C ends the run)")

    def progress(frames: int, report: LiveReport) -> None:
        if status is not None:
            p95 = report.latency_ms()["p95"]
            status.update(f"live {safe_text(url)}: {frames} frames perceived, "
                          f"{report.frames_dropped} dropped, latency p95 {p95} ms (Ctrl-C ends the run)")

    def on_status(kind: str, text: str) -> None:
        if not as_json:
            shown = safe_text(text)
            out.print(f"[yellow]{kind}:[/] {shown}" if kind == "silent" else f"{kind}: {shown}")

    if status is not None:
        status.start()
    try:
        summary, report = perceive_live(url, kb, log_options, options, settings, kb_docs=kb_docs,
                                        on_status=on_status, progress=progress)
    finally:
        if status is not None:
            status.stop()
    data: dict[str, Any] = {**summary.to_dict(), "live": report.to_dict()}
    if as_json:
        print_json(data)
        return
    from hiper_cli.commands._tables import show_perceive

    show_perceive(out, data)
    live = data["live"]
    out.print(f"live: {live['frames_assembled']} frames received, {live['frames_dropped']} dropped to keep "
              f"up, {live['frames_unmatched']} without depth or pose; {len(live['silences'])} silences; "
              f"ended by {live['stopped_by']}")
    if live["bad_messages"]:
        out.print(f"[yellow]{live['bad_messages']} messages could not be read[/] "
                  f"(last: {live['last_error']})")
    if stats:
        lat = live["latency_ms"]
        out.print(f"latency from sending to queryable: p50 {lat['p50']} ms, p95 {lat['p95']} ms, "
                  f"max {lat['max']} ms")
