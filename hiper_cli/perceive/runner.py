"""Run recognition stages over a stream of frames, in memory.

This is the one loop every consumer shares: the knowledge-base pipeline persists each frame's
merged result in ``on_frame``; the evaluators run it without a store and read the ``World``.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from hiper_cli.perceive.stage import FrameResult, Stage, World
from hiper_cli.types import Frame

__all__ = ["RunStats", "prefetch", "run_stages"]

OnFrame = Callable[[Frame | None, FrameResult], None]


@dataclass
class RunStats:
    """Counts and per-frame wall times of one run."""

    frames: int = 0
    observations: int = 0
    frame_times_s: list[float] = field(default_factory=list)
    stage_times_s: dict[str, list[float]] = field(default_factory=dict)

    @property
    def frames_per_s(self) -> float:
        total = sum(self.frame_times_s)
        return self.frames / total if total > 0 else 0.0


def run_stages(
    frames: Iterable[Frame],
    stages: Sequence[Stage],
    world: World | None = None,
    on_frame: OnFrame | None = None,
    *,
    look_ahead: bool = True,
) -> tuple[World, RunStats]:
    """Feed every frame through ``stages`` in order, applying each result to ``world``.

    ``on_frame(frame, merged_result)`` is called after every frame, and once more with
    ``frame=None`` for what the stages flush in ``finish``. Each stage sees the world as
    updated by the stages before it in the same frame. A stage with a ``prepare(frame)``
    method is handed the next frame before the current one is processed, to start work that
    needs no world (the foreground stage runs its detector on it in a worker thread, so the
    detector is busy while this frame's point cloud is processed); ``look_ahead=False`` processes
    each frame as soon as it is read, without waiting for the next (a live stream), and hands
    the frame itself to ``prepare`` first (its detector runs while the stages before run). A frame
    that cannot be read raises its error after the frames before it are processed and handed
    to ``on_frame``; ``finish`` does not run then. ``finish`` runs the stages in reverse order.
    """
    world = world if world is not None else World()
    stats = RunStats()
    ahead = [p for p in (getattr(stage, "prepare", None) for stage in stages) if callable(p)]
    stream = iter(frames)
    upcoming = next(stream, None)
    unreadable: Exception | None = None
    def read_next() -> None:
        nonlocal upcoming, unreadable
        try:
            upcoming = next(stream, None)
        except Exception as err:  # the next frame cannot be read: finish this one first
            upcoming, unreadable = None, err

    while upcoming is not None:
        frame = upcoming
        if look_ahead:
            read_next()
        else:
            upcoming = None
        start = time.perf_counter()
        # the next frame when reading ahead; else this one, so that the detector runs while
        # the stages before the foreground (the background) process it
        early = upcoming if look_ahead else frame
        if early is not None:
            for prepare in ahead:
                prepare(early)
        merged = FrameResult()
        for stage in stages:
            t0 = time.perf_counter()
            result = stage.process(frame, world)
            stats.stage_times_s.setdefault(stage.name, []).append(time.perf_counter() - t0)
            world.apply(result)
            merged.extend(result)
        stats.frames += 1
        stats.observations += len(merged.observations)
        stats.frame_times_s.append(time.perf_counter() - start)
        if on_frame is not None:
            on_frame(frame, merged)
        if not look_ahead:
            read_next()
    if unreadable is not None:
        raise unreadable
    final = FrameResult()
    # last stage first: each flushes what it built on the stages before it while they still
    # hold what they held during the log (the background withdraws its unconfirmed walls last)
    for stage in reversed(stages):
        result = stage.finish(world)
        world.apply(result)
        final.extend(result)
    stats.observations += len(final.observations)
    if on_frame is not None:
        on_frame(None, final)
    return world, stats


def prefetch(frames: Iterator[Frame], depth: int = 4) -> Iterator[Frame]:
    """Read frames in a background thread (image decoding releases the GIL), ``depth`` ahead."""
    import queue
    import threading

    q: queue.Queue[Any] = queue.Queue(maxsize=depth)
    done = object()
    stop = threading.Event()

    def work() -> None:
        try:
            for frame in frames:
                if stop.is_set():
                    return
                q.put(frame)
        except BaseException as err:  # handed to the consumer, raised there
            q.put(err)
        q.put(done)

    thread = threading.Thread(target=work, name="hiper-read", daemon=True)
    thread.start()
    try:
        while True:
            item = q.get()
            if item is done:
                return
            if isinstance(item, BaseException):
                raise item
            yield item
    finally:
        stop.set()
        while thread.is_alive():
            try:
                q.get_nowait()
            except queue.Empty:
                thread.join(timeout=0.01)
