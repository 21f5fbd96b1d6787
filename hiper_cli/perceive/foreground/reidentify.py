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
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

import numpy as np

from hiper_cli.model import ROW_STAMP, Instance
from hiper_cli.perceive.foreground.stitch import footprint_share

__all__ = ["fold", "moved_pairs", "pairs"]

UNKNOWN = "unknown"


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
    known = set(earlier.observation_uuids)
    earlier.observation_uuids.extend(u for u in new.observation_uuids if u not in known)
    if new.last_seen_s >= earlier.first_seen_s:
        earlier.box, earlier.confidence = new.box, new.confidence
        earlier.data.pop("vacated_s", None)
        if "surface_map" in new.data:
            earlier.data["surface_map"] = new.data["surface_map"]
    earlier.first_seen_s = min(earlier.first_seen_s, new.first_seen_s)
    earlier.last_seen_s = max(earlier.last_seen_s, new.last_seen_s)
    earlier.state = "static"
    rows: Sequence[list[float]] = [*(earlier.data.get("trajectory") or []),
                                   *(new.data.get("trajectory") or [])]
    earlier.data["trajectory"] = sorted(rows, key=lambda r: r[ROW_STAMP])
    earlier.data["closed"] = True
    return earlier
