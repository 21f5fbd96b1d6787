"""Re-identification across sessions: a static object this session tracked is the instance an
earlier session of the environment made of it, when their boxes say so, or when it moved.

Within a session, stitching keeps one instance per object (``stitch.py``). A second log of the
same place (or ``perceive --again``) starts with no tracks, so without this every chair would
get a second instance and "how many chairs" would double. At the end of the session each
static instance of a class that stays put (not a walker) is paired with an earlier one:

- **stayed**: of its class, whose box's footprint it overlaps by ``stitch_min_overlap`` of the
  smaller footprint (of the larger for ``unknown``), at most ``stitch_overlap_m`` apart
  vertically (the rule that joins a static track seen again within a session);
- **moved**: an earlier one whose place this session saw empty (``vacated.py``), of its class,
  not paired otherwise, within ``reidentify_moved_m``.

Each is one assignment over all the objects of a class at once (``_assign``): as many pairs as
the rule allows, and among those the best overall (most overlap; for moves the least cost of
distance, shape and support, ``move_cost``), not the nearest pair first: two chairs taken away
and one set down between them go to the one whose size, height and support fit, and a nearest
first choice cannot take back a pair that leaves another object without its only partner.
Pairs are one to one; the earlier instance absorbs the new one (``fold``) and keeps its uuid.
An earlier instance seen empty and left unpaired is marked vacated by the stage, unless this
session saw an object of its class at its place all the same (``still_seen``): a small object
(a cup) a few centimetres off where it was, through pose drift, or a second instance an
earlier session made of one object, is seen empty by rays aimed at its old points, yet the
object is there. An instance this session found again as another earlier object is that
object: it stands for the gone one only where their footprints meet with no slack (two
instances of one object), not within the pose slack beside it, where a neighbouring object
of the class stands (a chair beside the one taken away, both boxes grown by what their blobs
caught).

A walker is not where it was, so it is never joined by place; but one seen at the same times
at the same place is the same walker (``cosighted_pairs``): the same log perceived again
(``--again``), or two robots' logs of one time. The rule is the one that joins two tracks of
one walker within a session (``stitch_duplicate_m``, median over the common stamps).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

import numpy as np

from hiper_cli.model import ROW_STAMP, Instance
from hiper_cli.perceive.foreground.stitch import STAMP_MATCH_S, common_distance_m, footprint_share

__all__ = ["cosighted_pairs", "fold", "fold_mover", "move_cost", "moved_pairs", "pairs", "still_seen"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
REIDENTIFY_MOVED_M: float = 3.0

UNKNOWN = "unknown"
SAME_ROW_M = 0.25  # a row at a stamp the earlier trajectory has, this near its row there, is it
# a move's cost: its distance over the reach, plus how unlike the two boxes are (log ratio of
# their heights and of their footprints' sides, per SHAPE_LOG unit) and how far their bottoms
# are apart (per SUPPORT_M: a chair stays on the floor, a cup on a table or shelf top)
SHAPE_LOG = 0.7  # a box half or twice as tall costs about as much as the whole reach
SUPPORT_M = 0.4
FORBIDDEN = 1e6  # no pair (far above any sum of allowed costs)
POSE_SLACK_M = 0.1  # how far two sessions' views of one object may lie apart (drift, alignment)


def pairs(
    new: Iterable[Instance],
    earlier: Iterable[Instance],
    *,
    min_share: float,
    max_gap_m: float,
) -> list[tuple[Instance, Instance]]:
    """(earlier, new) pairs of one object: same class, footprints overlapping by at least
    ``min_share`` (``footprint_share``), best overlap first, each instance in one pair at most.
    The caller passes only static instances of classes that stay put."""

    def cost(e: Instance, n: Instance) -> float | None:
        share = footprint_share(n.box.aabb(), e.box.aabb(), max_gap_m=max_gap_m,
                                larger=n.class_name == UNKNOWN)
        return 1.0 - share if share >= min_share else None

    return _assign(new, earlier, cost)


def moved_pairs(
    new: Iterable[Instance], gone: Iterable[Instance], *, max_m: float
) -> list[tuple[Instance, Instance]]:
    """(earlier, new) pairs of one object that moved: an earlier instance whose place this
    session saw empty (``vacated.py``) and a new one of its class no other earlier instance
    took, at most ``max_m`` apart (footprint centres), one to one, of least total
    ``move_cost``."""
    return _assign(new, gone, lambda e, n: move_cost(e, n, max_m=max_m))


def move_cost(earlier: Instance, new: Instance, *, max_m: float) -> float | None:
    """What pairing ``new`` with ``earlier`` as one object moved costs (None: beyond ``max_m``):
    the distance over ``max_m``, the shape unlike (``SHAPE_LOG``) and the support apart
    (``SUPPORT_M``)."""
    d = float(np.hypot(*(earlier.box.center_m[:2] - new.box.center_m[:2])))
    if d > max_m:
        return None
    size_e = np.maximum(np.asarray(earlier.box.extent_m, dtype=np.float64), 0.01)
    size_n = np.maximum(np.asarray(new.box.extent_m, dtype=np.float64), 0.01)
    # the footprint's sides sorted: a chair turned on the spot has the same footprint
    sides = np.abs(np.log(np.sort(size_e[:2]) / np.sort(size_n[:2]))).mean()
    shape = (abs(float(np.log(size_e[2] / size_n[2]))) + float(sides)) / SHAPE_LOG
    support = abs(float(earlier.box.aabb()[0][2] - new.box.aabb()[0][2])) / SUPPORT_M
    return d / max(max_m, 1e-9) + shape + support


def still_seen(
    gone: Iterable[Instance], seen: Iterable[Instance], *, slack_m: float = POSE_SLACK_M,
    found_again: Iterable[Instance] = (),
) -> set[str]:
    """The uuids of the ``gone`` instances (their place seen empty) that an instance of their
    class this session ``seen`` stands at all the same: their footprints, each grown by
    ``slack_m``, meet (and they are less than ``slack_m`` apart vertically, per box gap). Those
    of ``seen`` in ``found_again`` (found again as another earlier object) stand at it only
    where the boxes themselves meet."""
    again = {n.uuid for n in found_again}
    out = set()
    for g in gone:
        lo_g, hi_g = g.box.aabb()
        for n in seen:
            if n.class_name != g.class_name or n.uuid == g.uuid:
                continue
            slack = 0.0 if n.uuid in again else slack_m
            lo_n, hi_n = n.box.aabb()
            gap = np.maximum(lo_g - hi_n, lo_n - hi_g)  # per axis, > 0 where the boxes lie apart
            if gap[0] <= 2 * slack and gap[1] <= 2 * slack and gap[2] <= slack:
                out.add(g.uuid)
                break
    return out


def cosighted_pairs(
    new: Iterable[Instance], earlier: Iterable[Instance], *, max_m: float, min_common: int
) -> list[tuple[Instance, Instance]]:
    """(earlier, new) pairs of one walker seen twice at once: of one class, within ``max_m`` of
    each other (median, horizontal) at ``min_common`` or more of the new one's stamps. Each
    new instance joins its nearest; an earlier one may take several (a walker the first pass
    tracked whole and the second in pieces)."""
    earlier = [e for e in earlier if len(e.data.get("trajectory") or []) >= 2]
    out = []
    for n in sorted(new, key=lambda i: i.uuid):
        rows = n.data.get("trajectory") or []
        near = [(apart, e.uuid, e) for e in earlier if rows and e.class_name == n.class_name
                and (apart := common_distance_m(rows, e.data["trajectory"], min_common)) is not None
                and apart <= max_m]
        if near:
            out.append((min(near, key=lambda c: c[:2])[2], n))
    return out


def _assign(
    new: Iterable[Instance],
    earlier: Iterable[Instance],
    cost: Callable[[Instance, Instance], float | None],
) -> list[tuple[Instance, Instance]]:
    """One-to-one (earlier, new) pairs, per class: as many as ``cost`` allows (None: no pair),
    and of those the set of least total cost (scipy's Hungarian solver; both sides in uuid
    order, so a run gives the same pairs every time)."""
    from scipy.optimize import linear_sum_assignment

    out: list[tuple[Instance, Instance]] = []
    new, earlier = sorted(new, key=lambda i: i.uuid), sorted(earlier, key=lambda i: i.uuid)
    for cls in sorted({n.class_name for n in new}):
        ns = [n for n in new if n.class_name == cls]
        es = [e for e in earlier if e.class_name == cls]
        if not es:
            continue
        costs = np.full((len(es), len(ns)), FORBIDDEN)
        for i, e in enumerate(es):
            for j, n in enumerate(ns):
                if e.uuid != n.uuid and (c := cost(e, n)) is not None:
                    costs[i, j] = c
        rows, cols = linear_sum_assignment(costs)
        out += [(es[i], ns[j]) for i, j in zip(rows, cols, strict=True) if costs[i, j] < FORBIDDEN]
    return out


def fold(earlier: Instance, new: Instance) -> Instance:
    """``earlier`` with ``new`` absorbed (in place, and returned): its observations appended, its
    trajectory rows merged in time and the seen span widened. Unless the new sighting ended
    before the earlier one began (an older log perceived later; logs whose stamps all start at
    0 overlap), the new one says where the object is now: its box, class confidence and
    observed surface, and no longer vacated (``vacated.py``); a bed pushed half a metre
    between two visits is where the later visit saw it."""
    if new.last_seen_s >= earlier.first_seen_s:
        earlier.box, earlier.confidence = new.box, new.confidence
        earlier.data.pop("vacated_s", None)
        if "surface_map" in new.data:
            earlier.data["surface_map"] = new.data["surface_map"]
    earlier.state = "static"
    _absorb(earlier, new)
    return earlier


def fold_mover(earlier: Instance, new: Instance) -> Instance:
    """``earlier`` with ``new``, the same walker seen at the same times, absorbed (in place,
    and returned): its observations and the rows of stamps the earlier one lacks; the box and
    state of whichever was seen last."""
    if new.last_seen_s > earlier.last_seen_s:
        earlier.box, earlier.confidence, earlier.state = new.box, new.confidence, new.state
    _absorb(earlier, new)
    return earlier


def _absorb(earlier: Instance, new: Instance) -> None:
    """What both folds take from ``new``: its observations, its seen span and its rows. The two
    trajectories become one, in time. A new row at a stamp the earlier trajectory has,
    within ``SAME_ROW_M`` of its row there, is that row again (one log perceived twice gives
    every row twice) and is left out; logs whose stamps all start at 0 share stamps too, so
    the place must agree as well (a moved object's rows stay)."""
    old: Sequence[list[float]] = earlier.data.get("trajectory") or []
    arr = np.asarray([r[:3] for r in old], dtype=np.float64).reshape(-1, 3)
    arr = arr[np.argsort(arr[:, ROW_STAMP], kind="stable")]

    def again(row: Sequence[float]) -> bool:
        t = float(row[ROW_STAMP])
        k = int(np.searchsorted(arr[:, ROW_STAMP], t - STAMP_MATCH_S))
        while k < len(arr) and arr[k, ROW_STAMP] <= t + STAMP_MATCH_S:
            if np.hypot(arr[k, 1] - row[1], arr[k, 2] - row[2]) <= SAME_ROW_M:
                return True
            k += 1
        return False

    known = set(earlier.observation_uuids)
    earlier.observation_uuids.extend(u for u in new.observation_uuids if u not in known)
    earlier.first_seen_s = min(earlier.first_seen_s, new.first_seen_s)
    earlier.last_seen_s = max(earlier.last_seen_s, new.last_seen_s)
    rows = [*old, *(r for r in (new.data.get("trajectory") or []) if not again(r))]
    earlier.data["trajectory"] = sorted(rows, key=lambda r: r[ROW_STAMP])
    earlier.data["closed"] = True
