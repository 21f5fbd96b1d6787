"""Two pieces of one table, cut apart by a chair in front of it, are one table.

A chair between the camera and a table the background layer has not mapped hides a band of
the table's top: ``tables.py`` then finds two tops in one frame, each with its legs, and each
becomes a table of its own. What tells one table with its middle hidden from two tables with
floor between them is the band itself: seen from the camera, the top's height between the
two pieces is hidden behind something nearer (the chair), where between two tables the camera
would see past that height to the floor or the wall behind.

Two pieces of one frame are joined (``join_hidden_pieces``) when their tops lie at one height
(within ``TOP_HEIGHT_TOLERANCE_M``), they face each other across at most
``table_pieces_max_gap_m`` or touch (their footprints overlap along the other axis by half
the narrower one), the joined table is at most ``table_pieces_max_length_m`` long (two desks
side by side with a chair before the gap stay two when together they would be longer than a
table), and most of the samples of the band at the top's height (``HIDDEN_SHARE``) that the
camera's view holds are hidden. When the frames show one piece at a time, each piece is a
table track of its own; ``join_hidden_tracks`` applies the same test to the boxes of a table
track updated in this frame and another one, against this frame's depth.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.foreground.config import RefineConfig
from hiper_cli.perceive.foreground.same_object import fold
from hiper_cli.perceive.foreground.segment import Blob, concat_blobs
from hiper_cli.perceive.foreground.stitch import provisional_class
from hiper_cli.perceive.foreground.unmapped_tables import TABLE_CLASS

if TYPE_CHECKING:
    from hiper_cli.perceive.foreground.tracking import Track, Tracker

__all__ = ["HIDDEN_SHARE", "TOP_HEIGHT_TOLERANCE_M", "join_hidden_pieces", "join_hidden_tracks"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
TABLE_PIECES_MAX_GAP_M: float = 0.8
"""Two such tables of one frame facing each other across at most this gap, their tops at
one height and the band between them at that height hidden from the camera by something
nearer (a chair in front of the table), are one table cut in two (``table_pieces.py``;
0: off) ..."""
TABLE_PIECES_MAX_LENGTH_M: float = 3.5
"""... unless joined they would be longer than this (two desks in a row, a chair before
the gap between them)."""

FloatArray = NDArray[np.float64]
Hidden = Callable[[FloatArray], tuple[NDArray[np.bool_], NDArray[np.bool_]]]

TOP_HEIGHT_TOLERANCE_M = 0.04  # two slab bins of ``tables.py``
HIDDEN_SHARE = 0.7  # of the band's samples in view that something nearer hides
TOP_QUANTILE = 95  # a piece's top: this percentile of its points' heights (legs below)
BAND_SAMPLES = 5  # per axis of the band between two pieces


def _footprint(blob: Blob) -> tuple[FloatArray, FloatArray]:
    lo, hi = np.percentile(blob.points_map[:, :2], [2, 98], axis=0)
    return lo, hi


def _band(
    lo_a: FloatArray, hi_a: FloatArray, top_a: float, lo_b: FloatArray, hi_b: FloatArray, top_b: float,
    config: RefineConfig,
) -> FloatArray | None:
    """Samples (K, 3) of the band at the top's height between two footprints (``lo``, ``hi``:
    their horizontal corners; none when they touch or overlap: nothing lies between them), or
    None when the tops are not at one height, the footprints do not face each other across a
    gap of at most ``table_pieces_max_gap_m``, or would be longer than
    ``table_pieces_max_length_m`` joined."""
    if abs(top_a - top_b) > TOP_HEIGHT_TOLERANCE_M:
        return None
    gap = np.maximum(lo_b - hi_a, lo_a - hi_b)  # per axis; negative: they overlap along it
    axis = int(np.argmax(gap))
    other = 1 - axis
    if gap[axis] > TABLE_PIECES_MAX_GAP_M:
        return None
    overlap = min(hi_a[other], hi_b[other]) - max(lo_a[other], lo_b[other])
    narrower = min(hi_a[other] - lo_a[other], hi_b[other] - lo_b[other])
    if overlap < 0.5 * narrower:
        return None
    if max(hi_a[axis], hi_b[axis]) - min(lo_a[axis], lo_b[axis]) > TABLE_PIECES_MAX_LENGTH_M:
        return None
    if gap[axis] <= 0.0:
        return np.zeros((0, 3))
    start = min(hi_a[axis], hi_b[axis])
    across = np.linspace(start, start + gap[axis], BAND_SAMPLES + 2)[1:-1]
    along = np.linspace(max(lo_a[other], lo_b[other]), min(hi_a[other], hi_b[other]), BAND_SAMPLES)
    grid = np.zeros((len(across) * len(along), 3))
    grid[:, axis] = np.repeat(across, len(along))
    grid[:, other] = np.tile(along, len(across))
    grid[:, 2] = 0.5 * (top_a + top_b)
    return grid


def _band_hidden(band: FloatArray | None, hidden: Hidden) -> bool:
    """Whether the camera cannot see the band: most of its samples in view lie behind something
    nearer (an empty band: the pieces touch)."""
    if band is None:
        return False
    if len(band) == 0:
        return True
    in_view, behind = hidden(band)
    n_view = int(np.count_nonzero(in_view))
    return n_view >= BAND_SAMPLES and int(np.count_nonzero(behind & in_view)) >= HIDDEN_SHARE * n_view


def _hidden_between(a: Blob, b: Blob, hidden: Hidden, config: RefineConfig) -> bool:
    (lo_a, hi_a), (lo_b, hi_b) = _footprint(a), _footprint(b)
    top_a = float(np.percentile(a.points_map[:, 2], TOP_QUANTILE))
    top_b = float(np.percentile(b.points_map[:, 2], TOP_QUANTILE))
    return _band_hidden(_band(lo_a, hi_a, top_a, lo_b, hi_b, top_b, config), hidden)


def join_hidden_pieces(
    tables: Sequence[Blob], hidden: Hidden, config: RefineConfig, width: int, height: int
) -> list[Blob]:
    """The table blobs of one frame (``tables.split_unseen_tables``) with each pair that is one
    table hidden in its middle joined (see the module docstring). ``hidden(points_map (K, 3))``
    returns (in the camera's view, hidden behind something nearer) per point."""
    pieces = list(tables)
    if TABLE_PIECES_MAX_GAP_M <= 0 or len(pieces) < 2:
        return pieces
    joined = True
    while joined:  # three pieces past two chairs join in two rounds
        joined = False
        for i in range(len(pieces)):
            for j in range(i + 1, len(pieces)):
                if _hidden_between(pieces[i], pieces[j], hidden, config):
                    pieces[i] = concat_blobs([pieces[i], pieces[j]], config.pixel_step, width, height,
                                             pieces[i].support_z_m)
                    del pieces[j]
                    joined = True
                    break
            if joined:
                break
    return pieces


def join_hidden_tracks(tracker: Tracker, hidden: Hidden, config: RefineConfig) -> dict[str, Track]:
    """Tracks of one table cut in two (see the module docstring), when its pieces were found in
    different frames: a confirmed table track updated in this frame and another confirmed,
    unmoved table track (live or closed) whose boxes (``SeenBox``) have their tops at one
    height, lie in line and have the band between them hidden from the camera now are one
    table. The newer folds into the older (``same_object.fold``). Returns gone uuid -> keeper."""
    if TABLE_PIECES_MAX_GAP_M <= 0:
        return {}

    def is_table(track: Track) -> bool:
        return track.confirmed and provisional_class(track) == TABLE_CLASS and not track.seen.moved()

    aliases: dict[str, Track] = {}
    now = [t for t in tracker.tracks if is_table(t) and t.last_update_s == tracker.last_stamp_s]
    for a in now:
        if a.uuid in aliases:
            continue
        for b in [*tracker.tracks, *tracker.dormant]:
            if b is a or b.uuid in aliases or not is_table(b):
                continue
            box_a, box_b = a.seen.corners(), b.seen.corners()
            if box_a is None or box_b is None:
                continue
            band = _band(box_a[0][:2], box_a[1][:2], float(box_a[1][2]),
                         box_b[0][:2], box_b[1][:2], float(box_b[1][2]), config)
            if not _band_hidden(band, hidden):
                continue
            keep, gone = (a, b) if a.first_seen_s <= b.first_seen_s else (b, a)
            fold(keep, gone)
            if gone in tracker.tracks and keep in tracker.dormant:  # the older goes on live
                tracker.dormant.remove(keep)
                tracker.tracks[tracker.tracks.index(gone)] = keep
            else:
                (tracker.tracks if gone in tracker.tracks else tracker.dormant).remove(gone)
            aliases[gone.uuid] = keep
            break
    return aliases
