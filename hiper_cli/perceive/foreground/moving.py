"""Whether a track is a static object or was moving when last seen.

A static object's filtered velocity is no evidence (partial views move a blob's centroid); its
blobs staying where they were is (``SeenBox.moved``). An ``unknown`` track may be a person not
named yet, so it is judged by its filter and its displacement together (``was_moving``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from hiper_cli.model import ROW_POSITION, ROW_STAMP, ROW_VELOCITY
from hiper_cli.perceive.foreground.config import TrackerConfig
from hiper_cli.perceive.foreground.stitch import UNKNOWN

if TYPE_CHECKING:
    from hiper_cli.perceive.foreground.tracking import Track

__all__ = ["is_static", "was_moving"]


def is_static(track: Track, config: TrackerConfig) -> bool:
    """Whether a track is a static object: not of a walking class, and its blobs stayed where
    they were (``SeenBox.moved``; for ``unknown``, which may be a person not named yet: the
    filter, ``was_moving``). A static object's filtered velocity is no evidence: partial
    views move a blob's centroid, and beds that never moved read 2 m/s."""
    name = track.class_name
    if name in config.walker_classes:
        return False
    if name == UNKNOWN:
        return not was_moving(track, config)
    return not track.seen.moved()


def was_moving(track: Track, config: TrackerConfig) -> bool:
    """Whether the track was moving when last updated: its filtered velocity then and its
    filtered displacement over the last ``moving_window_s`` (at least ``min_moving_span_s`` of
    history) both exceed ``moving_speed_mps``. Either alone is fooled: the velocity by noise,
    the displacement by a blob that grew or lost a part; a track seen too briefly is not
    known to move. Computed once per trajectory length (an update adds a row)."""
    rows = track.trajectory
    if track._moving is not None and track._moving[0] == len(rows):
        return track._moving[1]
    moving = _moving_rows(rows, config)
    track._moving = (len(rows), moving)
    return moving


def _moving_rows(rows: list[list[float]], config: TrackerConfig) -> bool:
    if not rows or math.hypot(*rows[-1][ROW_VELOCITY][:2]) <= config.moving_speed_mps:
        return False
    t_end = rows[-1][ROW_STAMP]
    start = rows[0]
    for row in reversed(rows):
        if t_end - row[ROW_STAMP] >= config.moving_window_s:
            start = row
            break
    span = t_end - start[ROW_STAMP]
    if span < config.min_moving_span_s:
        return False
    (x_end, y_end), (x_start, y_start) = rows[-1][ROW_POSITION][:2], start[ROW_POSITION][:2]
    dx, dy = x_end - x_start, y_end - y_start
    return math.hypot(dx, dy) / span > config.moving_speed_mps
