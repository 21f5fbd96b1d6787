"""Tables the background layer does not map are still tables.

The background layer finds a table by its top plane; a top seen only at a grazing angle, past
the chair in front of it, or through a doorway (a desk in a study, a bedside table in a
hospital room, 0.6 m wide) gives too thin a band of pixels for its plane cells, and the table
is never mapped. The foreground finds such a top in a blob (``tables.py``: a horizontal slab
at table height, of columns that end there, wide both ways, in a blob a detection names or
that holds a detected object) and takes it and its legs out of the blob. That slab is a table:
the stage makes it an observation of class ``table`` (``table_match``: ``TABLE_CLASS``, the
background's name for it), tracked as any object, so it needs ``min_class_observations``
frames, as a detector's class would, before it is an instance.

One table, one instance: the background layer is where tables belong. Once it maps a table
that the foreground's touches at the height of its top (within ``table_leg_reach_m``: the
background's table extents are estimates, often of a part of the top), the foreground's table
is withdrawn (``withdraw_mapped``); after that the background filter takes its top and
``legs.py`` its legs, so no new one starts there.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground.match import Match
from hiper_cli.perceive.foreground.stitch import provisional_class

if TYPE_CHECKING:
    from hiper_cli.perceive.foreground.tracking import Track, Tracker

__all__ = ["TABLE_CLASS", "TABLE_SCORE", "table_match", "withdraw_mapped"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
UNSEEN_TABLE_INSTANCES: bool = True
"""A table top found so (and its legs) is an observation of class ``table``, tracked as
any object (``unmapped_tables.py``): a bedside table or a desk the background layer never
maps is still a table. It is withdrawn once the background layer maps a table that it
touches at the height of its top (within ``table_leg_reach_m``)."""

TABLE_CLASS = "table"
TABLE_SCORE = 1.0  # the geometry says so: a vote as strong as a sure detection's


def table_match() -> Match:
    """The class a table found by its geometry takes (no detection behind it)."""
    return Match(TABLE_CLASS, TABLE_SCORE, None, 0.0)


def _same_table(track: Track, table: Box3D, reach_m: float) -> bool:
    """Whether the track's seen box and the mapped ``table`` are one table: their footprints,
    grown by ``reach_m``, touch, and their tops lie within ``reach_m`` of one height (the
    background layer often maps a part of a top, a piece 0.4 m wide of a 1.6 m desk). The
    track's top is that of its views as a table, where it has them (``SeenBox.top_of``)."""
    found = track.seen.corners()
    if found is None:
        return False
    lo, hi = found
    t_lo, t_hi = table.aabb()
    if not (np.all(lo[:2] <= t_hi[:2] + reach_m) and np.all(hi[:2] >= t_lo[:2] - reach_m)):
        return False  # the footprints do not touch
    top = track.seen.top_of(TABLE_CLASS)  # not the bottles a detector named on it
    return abs(float(hi[2] if top is None else top) - float(t_hi[2])) <= reach_m


def withdraw_mapped(tracker: Tracker, mapped: Sequence[Box3D], reach_m: float) -> list[str]:
    """Drop the foreground table tracks (live and closed) that are a table the background layer
    mapped (``_same_table``); returns the uuids of those that were instances."""
    if not mapped:
        return []
    gone: list[Track] = []
    for track in [*tracker.tracks, *tracker.dormant]:
        if provisional_class(track) != TABLE_CLASS:
            continue
        if any(_same_table(track, table, reach_m) for table in mapped):
            gone.append(track)
    if not gone:
        return []
    tracker.tracks = [t for t in tracker.tracks if t not in gone]
    tracker.dormant = [t for t in tracker.dormant if t not in gone]
    return [t.uuid for t in gone if t.confirmed]
