"""``hiper perceive zenoh://...``: perceive a running ROS 2 robot into a knowledge base, as a session.

A ``LiveSource`` stands in for the log reader in ``pipeline.perceive``; frames are perceived
as they come, the newest first when perception falls behind (older waiting frames are
dropped and counted). Every frame is written in one transaction as for logs, and the scene
graph follows after each frame by default (``graph_sync_s=0``), so what a frame shows can be
asked (``hiper query``/``serve``/``mcp`` on the same knowledge base) once it is written. The
latency of a frame is from the moment its colour image was sent (rmw_zenoh's attachment
source time; the receive time when absent) to the moment it is queryable: written, and in
the scene graph the queries read.
Ctrl-C ends the run after the frame in hand, with the session finished and everything written.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from hiper_cli.perceive.live.rmw import parse_endpoint
from hiper_cli.perceive.live.source import DEFAULT_SILENCE_S, LiveSource
from hiper_cli.perceive.logs import LogOptions
from hiper_cli.perceive.stage import FrameResult
from hiper_cli.pipeline import PerceiveOptions, PerceiveSummary, perceive, select_stages
from hiper_cli.types import Frame

__all__ = ["LiveReport", "LiveSettings", "perceive_live"]

DEFAULT_ENV = "live"


@dataclass(frozen=True)
class LiveSettings:
    """How a live run reads: ``capacity`` frames may wait (then the oldest is dropped);
    ``idle_timeout_s`` ends the run without frames (``None``: only Ctrl-C ends it); a
    silence of ``silence_s`` is reported; ``wait_s`` is how long to wait for the endpoint.
    ``look_ahead``: take the next frame before perceiving this one, as for a log (the detector
    runs on it meanwhile, and the run's last frame is known, which the background maps): the
    same knowledge base as the log, more frames per second, but a frame waits for the next one
    (about twice the latency). Off: each frame is perceived as it comes."""

    capacity: int = 1
    idle_timeout_s: float | None = None
    silence_s: float = DEFAULT_SILENCE_S
    wait_s: float = 30.0
    domain_id: int = 0
    graph_sync_s: float = 0.0
    look_ahead: bool = False


@dataclass
class LiveReport:
    """What a live run received, dropped and how fast frames became queryable."""

    endpoint: str
    session: str = ""
    frames_assembled: int = 0
    frames_dropped: int = 0
    frames_unmatched: int = 0
    bad_messages: int = 0
    last_error: str = ""
    silences: list[dict[str, float]] = field(default_factory=list)
    publisher_restarts: int = 0
    stopped_by: str = ""
    latency_s: list[float] = field(default_factory=list)

    def latency_ms(self) -> dict[str, float | None]:
        values = np.array(self.latency_s) * 1000.0
        if not len(values):
            return {"p50": None, "p95": None, "max": None}
        return {"p50": round(float(np.percentile(values, 50)), 1),
                "p95": round(float(np.percentile(values, 95)), 1), "max": round(float(values.max()), 1)}

    def to_dict(self) -> dict[str, Any]:
        return {"endpoint": self.endpoint, "session": self.session, "frames_assembled": self.frames_assembled,
                "frames_dropped": self.frames_dropped, "frames_unmatched": self.frames_unmatched,
                "bad_messages": self.bad_messages, "last_error": self.last_error, "silences": self.silences,
                "publisher_restarts": self.publisher_restarts, "stopped_by": self.stopped_by,
                "latency_ms": self.latency_ms()}


@contextmanager
def _sigint_stops(source: LiveSource, report: LiveReport) -> Iterator[None]:
    """The first Ctrl-C stops the source after the frame in hand; a second one interrupts."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGINT)

    def handler(signum: int, frame: Any) -> None:
        if report.stopped_by == "interrupt":
            signal.signal(signal.SIGINT, previous)
            raise KeyboardInterrupt
        report.stopped_by = "interrupt"
        source.stop()

    signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def perceive_live(
    url: str,
    kb: str,
    log_options: LogOptions | None = None,
    options: PerceiveOptions | None = None,
    settings: LiveSettings | None = None,
    *,
    kb_docs: Path | None = None,
    on_status: Callable[[str, str], None] | None = None,
    progress: Callable[[int, LiveReport], None] | None = None,
    on_frame: Callable[[Frame | None, FrameResult], None] | None = None,
) -> tuple[PerceiveSummary, LiveReport]:
    """Perceive the robot at ``url`` (``zenoh://tcp/HOST:PORT``) into ``kb`` until stopped.

    ``progress(frames, report)`` after every frame written; ``on_status(kind, text)`` when the
    stream falls silent (``silent``), comes back (``resumed``) or the run ends (``idle``).
    A live run is always a new session of its environment (default ``live``).
    """
    from hiper_cli.graph import open_kb

    endpoint = parse_endpoint(url)
    settings = settings or LiveSettings()
    options = options or PerceiveOptions()
    options = replace(options, env_name=options.env_name or DEFAULT_ENV, on_existing="again",
                      graph_sync_s=settings.graph_sync_s)
    stages = select_stages(Path(DEFAULT_ENV), options)
    report = LiveReport(endpoint=endpoint)
    source = LiveSource(endpoint, log_options or LogOptions(), capacity=settings.capacity,
                        idle_timeout_s=settings.idle_timeout_s, silence_s=settings.silence_s,
                        domain_id=settings.domain_id, wait_s=settings.wait_s, on_status=on_status)
    source.look_ahead = settings.look_ahead

    unsynced: list[float] = []  # send times of frames written but not yet in the scene graph

    def queryable() -> None:
        now = time.time()
        report.latency_s.extend(now - sent_s for sent_s in unsynced)
        unsynced.clear()

    source.start()  # nobody on the endpoint: an error before any knowledge base is made
    report.session = source.how
    try:
        knowledge_cm = open_kb(kb, docs_dir=kb_docs)
    except BaseException:
        source.close()
        raise
    with knowledge_cm as knowledge:

        def written(frame: Frame | None, result: FrameResult) -> None:
            if frame is not None:
                unsynced.append(float(frame.extras.get("sent_s", time.time())))
                if knowledge.graph_in_sync():
                    queryable()
                _copy_counts(source, report)
                if progress is not None:
                    progress(source.counts.frames, report)
            if on_frame is not None:
                on_frame(frame, result)

        try:
            with _sigint_stops(source, report):
                summary = perceive(source, knowledge, stages, options, on_frame=written)
        finally:
            source.close()
    queryable()
    _copy_counts(source, report)
    report.stopped_by = report.stopped_by or "idle timeout"
    return summary, report


def _copy_counts(source: LiveSource, report: LiveReport) -> None:
    sync, counts = source.sync, source.counts
    report.frames_assembled, report.frames_dropped = sync.assembled, sync.dropped
    report.frames_unmatched, report.publisher_restarts = sync.unmatched, sync.restarts
    report.bad_messages, report.last_error = counts.bad_messages, counts.last_error
    report.silences = list(counts.silences)
