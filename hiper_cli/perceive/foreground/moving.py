"""Whether a track is a static object, was moving when last seen, or is a dynamic object.

A static object's filtered velocity is no evidence (partial views move a blob's centroid); its
blobs staying where they were is (``SeenBox.moved``). An ``unknown`` track may be a person not
named yet, so it is judged by its filter and its displacement together (``was_moving``).

An instance's state says what the object is, not what it did last: a person who walked and
then stood, or whose track ended with the log, is ``dynamic`` (``is_dynamic``), so "moving
people" finds the people who walked after the log is perceived.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from hiper_cli.model import ROW_POSITION, ROW_STAMP, ROW_VELOCITY, Box3D
from hiper_cli.perceive.foreground.class_vote import UNKNOWN
from hiper_cli.perceive.foreground.config import TrackerConfig

if TYPE_CHECKING:
    from hiper_cli.perceive.foreground.track import Track

__all__ = ["at_rest", "has_moved", "is_dynamic", "is_static", "note_travel", "was_moving"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
MOVING_SPEED_MPS: float = 0.3
"""Only a track that was moving faster than this when last seen (filtered velocity and
displacement over ``moving_window_s``) widens its gate while unseen: static objects do not
walk away, people walk at 0.5-1.4 m/s ..."""
MOVING_WINDOW_S: float = 1.0
MIN_MOVING_SPAN_S: float = 0.5
"""... and a track observed for less than this long is not known to move."""
DYNAMIC_MOVING_S: float = 1.0
DYNAMIC_TRAVEL_M: float = 0.5
"""A track is ``dynamic`` once it was moving (as above) and both sides of its blobs' box
went this far horizontally, one not of a walker class only after it kept moving at every
update for ``dynamic_moving_s`` and when its blobs moved (``SeenBox.moved``; not asked of
``unknown``) (``moving.is_dynamic``); it stays so after it stops or is lost: a person who
walked is a dynamic object. A static blob that changes as the camera passes moves in spells
of a few frames, and one that grew as more of it came into view went nowhere."""


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


def note_travel(track: Track, config: TrackerConfig) -> None:
    """Mark ``track`` ``travelled`` once it is moving (``was_moving``) and its blobs went
    ``dynamic_travel_m`` or more (``SeenBox.shift_m``: both sides of the box moved; a blob that
    grew as more of a shelf came into view moved its centre 0.9 m but one side only). A track
    not of a walker class must also have kept moving at every update for ``dynamic_moving_s``:
    a static blob that changes as the camera passes moves in spells of a few frames, while a
    person, named so, may be seen walking for a second only. A walker's travel is read from all
    of its blobs, not only the named ones: the tracker gives a walking track only blobs of a
    person's size, and a real camera's blur and noise leave a walker unnamed in many frames (on
    the degraded bookstore a person was named in 11 of the 25 frames of a 1.7 m walk: its named
    blobs moved 0.48 m, all of them 1.3 m). Called after each update, so any stretch of walking
    counts (a walker back where it started did go somewhere); the boxes are read only while it
    moves."""
    if track.travelled:
        return
    if not was_moving(track, config):
        track.moving_since_s = None
        return
    stamp = track.trajectory[-1][ROW_STAMP]
    if track.moving_since_s is None:
        track.moving_since_s = stamp
    walker = track.class_name in config.walker_classes
    if walker or stamp - track.moving_since_s >= DYNAMIC_MOVING_S:
        track.travelled = track.seen.shift_m(every_blob=walker) >= DYNAMIC_TRAVEL_M


def is_dynamic(track: Track, config: TrackerConfig) -> bool:
    """Whether the object moved while seen: it travelled (``note_travel``), and for a class
    that does not walk its blobs moved too (``SeenBox.moved``: a TV seen in parts as the view
    panned was also seen whole in between). An ``unknown`` may be a person not named yet: a
    walker seen all along bridges where it was and where it went, so travelling is enough."""
    if track.class_name in config.walker_classes or track.class_name == UNKNOWN:
        return track.travelled
    return track.travelled and track.seen.moved()


def has_moved(track: Track, config: TrackerConfig) -> bool:
    """Whether the instance is ``dynamic``: it moved while seen (``is_dynamic``), or, not of a
    walking class, its observed surface left where it was (``SeenBox.moved``: the boxes of its
    first and last blobs apart, no view reaching both) even if its filter never showed it
    travelling (a part of a walker tracked as ``unknown``). Anything else is ``static`` and
    stores no motion (``at_rest``): the filter's velocity alone is no evidence."""
    if is_dynamic(track, config):
        return True
    return track.class_name not in config.walker_classes and track.seen.moved()


def _moving_rows(rows: list[list[float]], config: TrackerConfig) -> bool:
    if not rows or math.hypot(*rows[-1][ROW_VELOCITY][:2]) <= MOVING_SPEED_MPS:
        return False
    t_end = rows[-1][ROW_STAMP]
    start = rows[0]
    for row in reversed(rows):
        if t_end - row[ROW_STAMP] >= MOVING_WINDOW_S:
            start = row
            break
    span = t_end - start[ROW_STAMP]
    if span < MIN_MOVING_SPAN_S:
        return False
    (x_end, y_end), (x_start, y_start) = rows[-1][ROW_POSITION][:2], start[ROW_POSITION][:2]
    dx, dy = x_end - x_start, y_end - y_start
    return math.hypot(dx, dy) / span > MOVING_SPEED_MPS


def at_rest(rows: list[list[float]], box: Box3D) -> list[list[float]]:
    """Trajectory rows of an object that did not move: one per row of ``rows`` (the stamps it was
    seen at), each at the centre of ``box`` with no velocity."""
    if not rows:
        return []
    out = np.zeros((len(rows), len(rows[0])), dtype=np.float64)
    out[:, ROW_STAMP] = [r[ROW_STAMP] for r in rows]
    out[:, ROW_POSITION] = box.center_m
    return out.tolist()
