"""One static object, one track: tracks whose blobs fill one object's box are one object.

The frame-to-frame association leaves one static object as several tracks in three ways: the
robot comes back to it after the first track closed (a revisit), a second track starts on a
piece of it beside the first (a chair's back over a table, a bed's side through a doorway, a
table leg that a young track took before it settled on the chair) and both live on, or a
track first saw a part of a large object (the foot end of a bed) and a later one the whole.
``stitch.find_target`` judges such a pair by the boxes their blobs fill (``SeenBox``); this
module decides *when* and *which way* it is asked, and what "static" means for a pair:

- **when**: a track's box is young when it is confirmed (three blobs, one of them perhaps a
  table leg it took first), so a confirmed track is asked again each time its observations
  double (``due``), as walkers already were: the pair is judged on what both tracks saw;
- **which way**: the older track keeps its instance; when the track asked is the older one, a
  newer live track it matches folds into it (``newer_match``, ``fold``);
- **static**: two tracks are one static object when neither walks, they did not take blobs
  side by side in the same frames (two bottles side by side seen at once are two bottles,
  whatever a blob that once joined them did to one track's box; a chair's back above a table
  and its seat below it, each named by a detection of its own, are one chair), and the boxes
  of all their blobs together did not move (``static_together``): views of one object from
  different sides each show some of it, so a track that saw only the foot end of a bed and
  then its side looks as if it moved on its own, but together with the track that saw the
  whole bed its first and last views overlap. A cart that drove away does not: its last
  views lie apart from its first ones whatever else saw it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

import numpy as np

from hiper_cli.model import ROW_STAMP
from hiper_cli.perceive.foreground.class_vote import UNKNOWN
from hiper_cli.perceive.foreground.seen_box import SeenBox
from hiper_cli.perceive.foreground.stitch import (
    REVISIT,
    STITCH_MIN_OVERLAP,
    STITCH_OVERLAP_M,
    absorb,
    find_target,
    footprint_share,
    provisional_class,
)
from hiper_cli.perceive.foreground.track import NamedBlob

if TYPE_CHECKING:
    from hiper_cli.perceive.foreground.config import TrackerConfig
    from hiper_cli.perceive.foreground.track import Track

__all__ = ["APART_SETTLED_NAMED", "APART_SHARE", "GROWN_FACTOR", "STACKED_SHARE", "NamedBlob", "cut_in_two",
           "due", "fold", "footprint_m2", "newer_match", "seen_apart", "static_together"]

APART_SHARE = 0.5  # of the shorter track's frames, taken apart at once: two objects
APART_SETTLED_NAMED = 10  # named frames of each track behind a "seen apart" that stands
STACKED_SHARE = 0.5  # of the narrower detection's width, in columns both cover: one above the other
STAMP_DECIMALS = 4  # stamps of one frame agree to well within this (0.1 ms)
GROWN_FACTOR = 1.5  # a static track's footprint this many times what it was when last offered


def footprint_m2(track: Track) -> float:
    """The area (m²) of the footprint of the boxes its blobs fill (``SeenBox``)."""
    found = track.seen.box()
    return 0.0 if found is None else float(found[1][0] * found[1][1])


def due(track: Track, walkers: tuple[str, ...], every_class: bool) -> bool:
    """Whether a confirmed track is to be offered to stitching now: its (provisional) class
    changed since it was last offered, its observations doubled (a walker's always, any
    other track's when ``every_class``: ``stitch_static_again``), or, for a static one, its
    footprint grew by ``GROWN_FACTOR`` (a table seen in two pieces past a chair in front of
    it: as the robot moves, each piece's box grows over the hidden middle into the other's)."""
    if provisional_class(track) != track.stitch_class:
        return True
    if not (every_class or track.stitch_class in walkers):
        return False
    if track.hits >= 2 * track.stitch_hits:
        return True
    return track.stitch_class not in walkers and footprint_m2(track) >= GROWN_FACTOR * track.stitch_area_m2


def seen_apart(a: Track, b: Track, config: TrackerConfig) -> bool:
    """Whether different detections named blobs of ``a`` and of ``b`` in the same frames as two
    things, in at least ``APART_SHARE`` of the frames detections named the less often named
    one: the detector saw two things at once (two bottles side by side, one track's box
    stretched over both by a blob that once joined them). One detection naming two blobs (a
    chair's back above a table and its seat below it) saw one thing, and so did two
    detections one above the other in the image whose blobs are one object (``cut_in_two``),
    when the votes of both tracks gave them that class: a piece the detector mostly left
    unnamed may be something else.

    A pair found apart when each track had ``APART_SETTLED_NAMED`` named frames stays apart
    (``Track.apart_from``): two chairs side by side at the image's border, later seen only as
    one blob that one detection names, add frames to the share's denominator that cannot
    show them apart, and would fold the two into one."""
    if b.uuid in a.apart_from or a.uuid in b.apart_from:
        return True
    if not a.named_at or not b.named_at:
        return False
    one_class = a.class_name == b.class_name != UNKNOWN
    apart = 0
    for stamp, seen_a in a.named_at.items():
        seen_b = b.named_at.get(stamp)
        if seen_b is not None and seen_b.detection != seen_a.detection:
            apart += not (one_class and cut_in_two(seen_a, seen_b, config))
    fewer = min(len(a.named_at), len(b.named_at))
    if apart < APART_SHARE * fewer:
        return False
    if fewer >= APART_SETTLED_NAMED:
        a.apart_from.add(b.uuid)
        b.apart_from.add(a.uuid)
    return True


def cut_in_two(a: NamedBlob, b: NamedBlob, config: TrackerConfig) -> bool:
    """Whether two detections of one frame named two pieces of one object: the detections
    stand one above the other in the image (their columns overlap by ``STACKED_SHARE`` of
    the narrower one), and their blobs share a footprint as two tracks of one object do
    (``stitch_min_overlap``, at most ``stitch_overlap_m`` apart vertically). A table top
    cuts a chair behind it into its back and its seat for the detector too; two chairs side
    by side stand side by side in the image, whatever a blob that joined them spans."""
    if a.xyxy_px is None or b.xyxy_px is None:
        return False
    common_px = min(a.xyxy_px[2], b.xyxy_px[2]) - max(a.xyxy_px[0], b.xyxy_px[0])
    narrower_px = min(a.xyxy_px[2] - a.xyxy_px[0], b.xyxy_px[2] - b.xyxy_px[0])
    if common_px < STACKED_SHARE * narrower_px:
        return False
    share = footprint_share((a.lower_m, a.upper_m), (b.lower_m, b.upper_m), max_gap_m=STITCH_OVERLAP_M)
    return share >= STITCH_MIN_OVERLAP


def static_together(
    a: Track, b: Track, config: TrackerConfig, filter_moving: Callable[[Track], bool]
) -> bool:
    """Whether ``a`` and ``b`` together are one static object: neither is of a walking class,
    an ``unknown`` one (perhaps a person not named yet) was not moving by its filter
    (``filter_moving``), they were not seen apart at the same time (``seen_apart``), and the
    boxes of all their blobs, older track first, did not move (``SeenBox.moved``)."""
    for track in (a, b):
        name = provisional_class(track)
        if name in config.walker_classes or (name == UNKNOWN and filter_moving(track)):
            return False
    if seen_apart(a, b, config):
        return False
    both = SeenBox()
    for track in sorted((a, b), key=lambda t: t.first_seen_s):
        both.extend(track.seen)
    return not both.moved()


def newer_match(
    older: Track,
    tracks: Iterable[Track],
    config: TrackerConfig,
    moving: Callable[[Track], bool],
    together: Callable[[Track, Track], bool],
) -> Track | None:
    """A confirmed track (live or closed) that started after ``older`` and is the same static
    object (``find_target`` asked from the newer one's side, ``older`` its only candidate)."""
    if provisional_class(older) in config.walker_classes:
        return None
    for new in tracks:
        if new is older or not new.confirmed or new.first_seen_s < older.first_seen_s:
            continue
        found = find_target(new, [older], config, moving, together)
        if found is not None and found[1] == REVISIT:
            return new
    return None


def fold(keep: Track, gone: Track) -> None:
    """Fold the static track ``gone`` into ``keep`` (``stitch.absorb`` as a revisit), whichever
    of the two was updated last: ``keep`` goes on with the motion state of the more recently
    updated one, its first sighting is the earlier of the two, and the trajectory rows of both
    are in time order (two tracks that lived side by side interleave; their filter covariances
    then no longer follow one another and are dropped, so no smoother runs across them)."""
    if gone.last_update_s > keep.last_update_s:
        absorb(keep, gone, REVISIT)
    else:
        state = (keep.motion, keep.extent_m, keep.last_update_s, keep.last_time_s,
                 keep.unseen_in_view_s, keep.closed)
        absorb(keep, gone, REVISIT)
        (keep.motion, keep.extent_m, keep.last_update_s, keep.last_time_s,
         keep.unseen_in_view_s, keep.closed) = state
    keep.first_seen_s = min(keep.first_seen_s, gone.first_seen_s)
    keep.named_at.update(gone.named_at)
    stamps = np.array([row[ROW_STAMP] for row in keep.trajectory], dtype=np.float64)
    if len(stamps) > 1 and np.any(np.diff(stamps) < 0):
        order = np.argsort(stamps, kind="stable")
        keep.trajectory[:] = [keep.trajectory[i] for i in order]
        keep.covariances.clear()
        keep.noises.clear()
    keep._moving = None
