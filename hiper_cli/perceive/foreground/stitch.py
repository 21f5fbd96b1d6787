"""Stitching: a newly confirmed track that is an object the tracker already knows joins it.

The frame-to-frame association misses in three ways that leave one object as several instances:

- **resume**: a walker's track closed or lost it (an occluder, a turn, the image border, a blob
  too small for ``walker_min_size_ratio``) and a new track picked the walker up; the new track
  starts where the old one, keeping its pace (``stitch_pace_factor`` times its median speed, at
  most ``stitch_speed_mps``), could be after the gap (at most ``stitch_max_gap_s``) from any of
  its rows of that long before; lost for longer or farther (a gap up to
  ``stitch_appearance_gap_s``), the walker's clothes tell: the colour histograms of the two
  tracks (``appearance.py``) agree to at least ``stitch_min_similarity``;
- **duplicate**: two blobs of one walker (the head above a shelf, the legs below it) fed two
  tracks at once, or two tracks took it in turns; the new one stays within
  ``stitch_duplicate_m`` of the old one at the same times (``common_distance_m``); when
  the old one took the walker only once or twice after the new one started (at most
  ``HANDOVER_MAX_S`` later) and was within ``stitch_duplicate_m`` then, the new one resumes it;
- **revisit**: a static object (a chair, a shelf's junk) seen again after its track closed, or
  a part of it (a chair's back) tracked beside the whole: the footprints of the boxes the two
  tracks' blobs fill overlap by ``stitch_min_overlap``, at most ``stitch_overlap_m`` apart
  vertically (``_static_match``).

The old track absorbs the new one (``absorb``): its observations, trajectory rows and votes,
so the instance keeps its uuid and the knowledge base one instance per object.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import ROW_POSITION, ROW_STAMP, ROW_VELOCITY
from hiper_cli.perceive.foreground.appearance import similarity
from hiper_cli.perceive.foreground.class_vote import UNKNOWN, absorb_votes

if TYPE_CHECKING:
    from hiper_cli.perceive.foreground.config import TrackerConfig
    from hiper_cli.perceive.foreground.track import Track

__all__ = ["DUPLICATE", "RESUME", "REVISIT", "absorb", "common_distance_m", "find_target", "footprint_share",
           "gap_ok", "provisional_class", "stale_rows"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
STITCH_MAX_GAP_S: float = 3.0
"""... a walker's new track starting at most this long after one of the old one's rows ..."""
STITCH_SPEED_MPS: float = 1.5
STITCH_MARGIN_M: float = 0.5
"""... within ``stitch_margin_m`` plus this speed times the gap of that row's position ..."""
STITCH_PACE_FACTOR: float = 1.5
STITCH_MIN_PACE_MPS: float = 0.6
"""... where the speed is the old walker's own pace, at most this factor times its median
speed (at least ``stitch_min_pace_mps``, at most ``stitch_speed_mps``): a person who walked
at 0.6 m/s did not cover 5 m in 3 s, another person came into view (0: any walker may go
``stitch_speed_mps``) ..."""
STITCH_APPEARANCE_GAP_S: float = 60.0
STITCH_MIN_SIMILARITY: float = 0.8
"""... or after a longer gap, up to ``stitch_appearance_gap_s``, with colour histograms
(Bhattacharyya coefficient) at least this similar: one person's tracks 0.92-1.0 and two
people's 0.46-0.55 on the realistic worlds ..."""
STITCH_DUPLICATE_M: float = 0.4
"""... or, tracked at the same time, within this of it (median, horizontal) ..."""
STITCH_OVERLAP_M: float = 0.3
"""... and a static track whose box's footprint overlaps the other's, at most this far
apart vertically (a chair's back over a table, its seat under it) ..."""
STITCH_MIN_OVERLAP: float = 0.5
"""... by this share of the smaller footprint (of the larger when one is ``unknown``)."""

FloatArray = NDArray[np.float64]
RESUME, DUPLICATE, REVISIT = "resume", "duplicate", "revisit"
STAMP_MATCH_S = 1e-6  # two trajectory rows of one frame share its stamp
INTERPOLATE_MAX_S = 0.5  # a track's position between two of its rows at most this far apart
MAX_RESUME_ROWS = 300  # rows of the old track a resume looks back over (10 s at 30 Hz)
HANDOVER_MAX_S = 1.0  # the old walker track's last row at most this long after the new one began


def find_target(
    new: Track,
    candidates: Iterable[Track],
    config: TrackerConfig,
    moving: Callable[[Track], bool],
    together: Callable[[Track, Track], bool] | None = None,
) -> tuple[Track, str] | None:
    """The older confirmed track ``new`` continues, and how (``RESUME``, ``DUPLICATE``,
    ``REVISIT``), or None. ``moving(track)``: whether it is no static object (``moving.is_static``);
    ``together(new, old)``, when given, decides instead whether the two are one static object
    (``same_object.static_together``: a pair of partial views may look moving one by one)."""
    walkers = config.walker_classes
    name = provisional_class(new)
    best: tuple[float, Track, str] | None = None
    for old in candidates:
        if old is new or not old.confirmed or old.first_seen_s > new.first_seen_s:
            continue
        old_name = provisional_class(old)
        if name in walkers and old_name == name:
            found = _walker_match(new, old, config)
        elif (
            name not in walkers and old_name not in walkers
            and (together is not None or (not moving(new) and not moving(old)))
            and (name == old_name or UNKNOWN in (name, old_name))
        ):
            found = _static_match(new, old, config)
            if found is not None and together is not None and not together(new, old):
                found = None
        else:
            found = None
        if found is not None and (best is None or found[0] < best[0]):
            best = (found[0], old, found[1])
    return None if best is None else (best[1], best[2])


def provisional_class(track: Track) -> str:
    """The track's class, or while it has none (fewer than ``min_class_observations``
    detections) the known class detections named most: a person's new track is ``unknown``
    for its first observations, and must be stitched before it becomes an instance."""
    name = track.class_name
    if name != UNKNOWN:
        return name
    known = {k: v for k, v in track.class_votes.items() if k != UNKNOWN}
    return max(sorted(known), key=lambda k: known[k]) if known else UNKNOWN


def _walker_match(new: Track, old: Track, config: TrackerConfig) -> tuple[float, str] | None:
    """(score, kind): lower scores are better matches."""
    if new.first_seen_s >= old.last_update_s - STAMP_MATCH_S:
        # Any of the old track's rows of the last stitch_max_gap_s may be where the walker
        # was last: a lost track's last rows are often junk blobs it took while searching.
        gap_s, dist, reach, _ = _resume_geometry(new, old, config)
        near = gap_s <= STITCH_MAX_GAP_S
        paced = STITCH_MARGIN_M + _pace_mps(old, config) * np.maximum(gap_s, 0.0)
        if near.any() and (ratio := float((dist[near] / paced[near]).min())) <= 1.0:
            return ratio, RESUME
        # Lost for longer: the same clothes, and reachable walking from where it was.
        similar = _similarity(new, old)
        if (
            similar >= STITCH_MIN_SIMILARITY
            and gap_s[-1] <= STITCH_APPEARANCE_GAP_S
            and bool(np.any(dist <= reach))
        ):
            return 1.0 + (1.0 - similar), RESUME
        return None
    apart_m = common_distance_m(new.trajectory, old.trajectory, config.confirm_hits)
    if apart_m is not None and apart_m <= STITCH_DUPLICATE_M:
        return apart_m / STITCH_DUPLICATE_M, DUPLICATE
    if old.last_update_s - new.first_seen_s <= HANDOVER_MAX_S:
        # A handover: the old track took the walker once or twice more after the new one
        # started, too few common stamps for a duplicate; the new one goes on as the walker.
        apart_m = common_distance_m(new.trajectory, old.trajectory, 1)
        if apart_m is not None and apart_m <= STITCH_DUPLICATE_M:
            return apart_m / STITCH_DUPLICATE_M, RESUME
    return None


def _resume_geometry(
    new: Track, old: Track, config: TrackerConfig
) -> tuple[FloatArray, FloatArray, FloatArray, int]:
    """Over the old track's last ``MAX_RESUME_ROWS`` rows: the gap from each to the new track's
    start, the distance to it, the reach of a walk over the gap (``stitch_margin_m`` +
    ``stitch_speed_mps`` · gap), and the index of the first of those rows."""
    first = max(len(old.trajectory) - MAX_RESUME_ROWS, 0)
    rows = np.asarray(old.trajectory[first:], dtype=np.float64)
    gap_s = new.first_seen_s - rows[:, ROW_STAMP]
    start = np.asarray(new.trajectory[0][ROW_POSITION][:2])
    dist = np.hypot(*(rows[:, 1:3] - start).T)
    reach = STITCH_MARGIN_M + STITCH_SPEED_MPS * np.maximum(gap_s, 0.0)
    return gap_s, dist, reach, first


def _pace_mps(old: Track, config: TrackerConfig) -> float:
    """How fast the old walker may have gone while unseen: ``stitch_pace_factor`` times its
    median speed over the rows a resume looks back on, within [``stitch_min_pace_mps``,
    ``stitch_speed_mps``]; ``stitch_speed_mps`` when the factor is 0."""
    if STITCH_PACE_FACTOR <= 0:
        return STITCH_SPEED_MPS
    rows = np.asarray(old.trajectory[-MAX_RESUME_ROWS:], dtype=np.float64)
    speed = float(np.median(np.hypot(*rows[:, ROW_VELOCITY][:, :2].T)))
    pace = STITCH_PACE_FACTOR * speed
    return float(min(max(pace, STITCH_MIN_PACE_MPS), STITCH_SPEED_MPS))


def stale_rows(new: Track, old: Track, config: TrackerConfig) -> int:
    """How many of the old track's last rows a resume drops: those after the last one the new
    track's start is within a walk of (junk the lost track took while it searched; kept, a
    walker's path jumped metres there and back and its speed read 50 % high)."""
    _, dist, reach, first = _resume_geometry(new, old, config)
    hits = np.flatnonzero(dist <= reach)
    return 0 if len(hits) == 0 else len(old.trajectory) - (first + int(hits[-1]) + 1)


def _similarity(new: Track, old: Track) -> float:
    if new.appearance is None or old.appearance is None:
        return 0.0
    return similarity(new.appearance, old.appearance)


def common_distance_m(rows_new: Sequence[Sequence[float]], rows_old: Sequence[Sequence[float]],
                      min_common: int) -> float | None:
    """Median horizontal distance of two trajectories (rows [stamp_s, x, y, z, ...]) at the
    stamps of ``rows_new`` where the old one was where its rows say (at a row of that stamp,
    or between two rows at most ``INTERPOLATE_MAX_S`` apart: two tracks that took one walker
    in turns), when there are at least ``min_common`` of them (None otherwise)."""
    a = np.asarray(rows_new, dtype=np.float64).reshape(len(rows_new), -1)
    b = np.asarray(rows_old, dtype=np.float64).reshape(len(rows_old), -1)
    if len(a) == 0 or len(b) < 2:
        return None
    stamps = a[:, ROW_STAMP]
    after = np.clip(np.searchsorted(b[:, ROW_STAMP], stamps), 1, len(b) - 1)
    t0, t1 = b[after - 1, ROW_STAMP], b[after, ROW_STAMP]
    same = np.abs(t1 - stamps) <= STAMP_MATCH_S
    inside = (stamps >= t0) & (stamps <= t1) & (t1 - t0 <= INTERPOLATE_MAX_S)
    use = same | inside
    if int(use.sum()) < min_common:
        return None
    w = np.clip((stamps - t0) / np.maximum(t1 - t0, STAMP_MATCH_S), 0.0, 1.0)[:, None]
    xy_b = (1.0 - w) * b[after - 1, 1:3] + w * b[after, 1:3]
    return float(np.median(np.hypot(*(a[use, 1:3] - xy_b[use]).T)))


def _static_match(new: Track, old: Track, config: TrackerConfig) -> tuple[float, str] | None:
    """By the boxes the two tracks' blobs fill (``SeenBox``; a filter's position drifts): their
    footprints overlap by ``stitch_min_overlap`` of the smaller one (of the larger one when
    one is ``unknown``: a blob around several things is not the object), and at most
    ``stitch_overlap_m`` lies between them vertically (a chair's back over a table and its
    seat under it stay one chair; two cups side by side stay two)."""
    box_new, box_old = new.seen.box(), old.seen.box()
    c_new, e_new = box_new if box_new is not None else (new.position, new.extent_m)
    c_old, e_old = box_old if box_old is not None else (old.position, old.extent_m)
    share = footprint_share((c_new - e_new / 2.0, c_new + e_new / 2.0),
                            (c_old - e_old / 2.0, c_old + e_old / 2.0), max_gap_m=STITCH_OVERLAP_M,
                            larger=UNKNOWN in (provisional_class(new), provisional_class(old)))
    if share < STITCH_MIN_OVERLAP:
        return None
    return 1.0 - share, REVISIT


def footprint_share(a: tuple[FloatArray, FloatArray], b: tuple[FloatArray, FloatArray], *,
                    max_gap_m: float, larger: bool = False) -> float:
    """The share of the smaller (``larger``: the larger) footprint of boxes ``a`` and ``b``
    ((lower, upper) corners, map frame) their footprints have in common; 0 when the boxes lie
    more than ``max_gap_m`` apart vertically."""
    (lo_a, hi_a), (lo_b, hi_b) = a, b
    lo, hi = np.maximum(lo_a, lo_b), np.minimum(hi_a, hi_b)
    if float(lo[2] - hi[2]) > max_gap_m:
        return 0.0
    common = float(np.prod(np.maximum(hi[:2] - lo[:2], 0.0)))
    areas = sorted((float(np.prod((hi_a - lo_a)[:2])), float(np.prod((hi_b - lo_b)[:2]))))
    return common / max(areas[1] if larger else areas[0], 1e-9)


def absorb(old: Track, new: Track, kind: str, drop_rows: int = 0) -> None:
    """Fold ``new`` into ``old`` (in place; ``old``'s observations only grow, the knowledge base
    links an instance's observations by appending). ``DUPLICATE``: only the observations and
    votes; the old track's own rows already describe the walker. Otherwise the old track goes
    on as the live one: its last ``drop_rows`` rows go (``stale_rows``), the new rows follow,
    the motion state is the new track's (a revisited static object: at the hit-weighted mean
    of both positions)."""
    old.observation_uuids.extend(new.observation_uuids)
    old.seen.extend(new.seen)
    old.apart_from |= new.apart_from
    absorb_votes(old, new)
    old.score_sum += new.score_sum
    old.travelled = old.travelled or new.travelled
    old.whole_stamps_s = sorted(old.whole_stamps_s + new.whole_stamps_s)  # in time, as tracked
    old.unsure_views += new.unsure_views
    old.standing_tops_m.extend(new.standing_tops_m)
    old.floor_z_m = new.floor_z_m if new.floor_z_m is not None else old.floor_z_m
    if new.appearance is not None:
        old.appearance = new.appearance if old.appearance is None else old.appearance + new.appearance
    if kind == DUPLICATE:
        old.hits += new.hits
        return
    if drop_rows > 0:
        unsmoothed = min(drop_rows, len(old.covariances))
        del old.trajectory[-drop_rows:]
        if unsmoothed:
            del old.covariances[-unsmoothed:]
            del old.noises[-unsmoothed:]
    old.trajectory.extend(new.trajectory)
    if new.covariances_from == 0:  # none of the new rows smoothed: one run with the old ones left
        old.covariances.extend(new.covariances)
        old.noises.extend(new.noises)
    else:  # the new track's first rows were smoothed already: only its last rows are left
        old.covariances, old.noises = list(new.covariances), list(new.noises)
    if kind == REVISIT:
        centre = (old.hits * old.position + new.hits * new.position) / (old.hits + new.hits)
        x = np.array(new.motion.x, dtype=np.float64)
        x[:3] = centre
        new.motion.reset(x, np.array(new.motion.P, dtype=np.float64))
    old.extent_m = new.extent_m
    old.motion = new.motion
    old.moving_since_s = new.moving_since_s
    old.hits += new.hits
    old.max_size_m = max(old.max_size_m, new.max_size_m)
    old.last_update_s = new.last_update_s
    old.last_time_s = new.last_time_s
    old.unseen_in_view_s = 0.0
    old.velocity_initialised = new.velocity_initialised or old.velocity_initialised
    old.closed = False
    old._moving = None


def gap_ok(old: Track, now_s: float, config: TrackerConfig) -> bool:
    """Whether a closed track may still be stitched at ``now_s``: a static one always (it is
    where it was), a walker within ``stitch_appearance_gap_s``."""
    if old.class_name not in config.walker_classes:
        return True
    return now_s - old.last_update_s <= max(STITCH_MAX_GAP_S, STITCH_APPEARANCE_GAP_S)
