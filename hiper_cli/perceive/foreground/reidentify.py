"""Re-identification across sessions: a static object this session tracked is the instance an
earlier session of the environment made of it, when their boxes say so, or when it moved.

Within a session, stitching keeps one instance per object (``stitch.py``). A second log of the
same place (or ``perceive --again``) starts with no tracks, so without this every chair would
get a second instance and "how many chairs" would double. At the end of the session each
static instance of a class that stays put (not a walker) is paired with an earlier one:

- **stayed**: of its class, whose box's footprint it overlaps by ``stitch_min_overlap`` of the
  smaller footprint (of the larger for ``unknown``), at most ``stitch_overlap_m`` apart
  vertically (the rule that joins a static track seen again within a session), best first;
- **moved**: an earlier one whose place this session saw empty (``vacated.py``), of its class,
  not paired otherwise, within ``reidentify_moved_m``, nearest first.

Pairs are one to one; the earlier instance absorbs the new one (``fold``) and keeps its uuid.
An earlier instance seen empty and left unpaired is marked vacated by the stage.

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

__all__ = ["cosighted_pairs", "fold", "fold_mover", "moved_pairs", "pairs"]

# Tuned once on the worlds; fixed values, not options (``ForegroundConfig`` holds those).
REIDENTIFY_MOVED_M: float = 3.0

UNKNOWN = "unknown"
SAME_ROW_M = 0.25  # a row at a stamp the earlier trajectory has, this near its row there, is it


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
        return -share if share >= min_share else None

    return _one_to_one(new, earlier, cost)


def moved_pairs(
    new: Iterable[Instance], gone: Iterable[Instance], *, max_m: float
) -> list[tuple[Instance, Instance]]:
    """(earlier, new) pairs of one object that moved: an earlier instance whose place this
    session saw empty (``vacated.py``) and a new one of its class no other earlier instance
    took, at most ``max_m`` apart (footprint centres), nearest first, one to one."""

    def cost(e: Instance, n: Instance) -> float | None:
        d = float(np.hypot(*(e.box.center_m[:2] - n.box.center_m[:2])))
        return d if d <= max_m else None

    return _one_to_one(new, gone, cost)


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


def _one_to_one(
    new: Iterable[Instance],
    earlier: Iterable[Instance],
    cost: Callable[[Instance, Instance], float | None],
) -> list[tuple[Instance, Instance]]:
    """Greedy one-to-one (earlier, new) pairs of one class, lowest ``cost`` first (None: no
    pair; ties go by uuid, so a run gives the same pairs every time)."""
    candidates = []
    earlier = list(earlier)
    for n in new:
        for e in earlier:
            if e.class_name == n.class_name and e.uuid != n.uuid:
                c = cost(e, n)
                if c is not None:
                    candidates.append((c, e.uuid, n.uuid, e, n))
    out: list[tuple[Instance, Instance]] = []
    used: set[str] = set()
    for _, e_uuid, n_uuid, e, n in sorted(candidates, key=lambda c: c[:3]):
        if e_uuid not in used and n_uuid not in used:
            used.update((e_uuid, n_uuid))
            out.append((e, n))
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
