"""Changes as data: what a session changed about the place, as events.

At the end of a session the static objects of the place as they stood before it are compared
with what they are after it (re-identification and the empty-place test have run: see
``perceive/foreground/reidentify.py`` and ``vacated.py``):

- **removed**: an object present before whose place this session saw empty (``vacated_s`` set
  now): negative evidence, from views that would have shown it. An object this session did not
  see keeps its state: unseen is not removed.
- **moved**: an object found again whose centre is more than ``MOVED_M`` from where it was.
- **added**: a new object where the earlier sessions saw free space (``FreeBefore``: their
  background cloud holds the floor or table under it and nothing in its box); a new object in
  a corner no session saw, or where something unrecognised stood, is not an addition.

Each change is a document of type ``change`` (``Change.to_dict``), written with the session;
the graph holds it as a ``hiper:Change`` (a ``prov:Activity``) that ``prov:used`` the
instance. An instance's validity follows from its fields: valid from its first sighting, to
``vacated_s`` when its place was seen empty (``validity``).
"""

from __future__ import annotations

import uuid as _uuid
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from hiper_cli.model import Instance

__all__ = ["CHANGE_KINDS", "MOVED_M", "Change", "FreeBefore", "Placed", "session_changes", "snapshot",
           "validity"]

CHANGE_KINDS = ("added", "removed", "moved")
MOVED_M = 0.5  # a static object found again this far (footprint centres) from where it was moved
NOT_CHANGING = frozenset({"unknown", "person"})  # debris and walkers make no change events


@dataclass(frozen=True)
class Placed:
    """A static object as it stood before the session."""

    uuid: str
    class_name: str
    center_m: tuple[float, float, float]
    vacated_s: float | None


@dataclass(frozen=True)
class Change:
    kind: str
    class_name: str
    instance_uuid: str
    session_id: int
    stamp_s: float
    from_m: list[float] | None
    to_m: list[float] | None
    uuid: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {"uuid": self.uuid or str(_uuid.uuid4()), "type": "change", "layer": "foreground",
                "kind": self.kind, "class": self.class_name, "instance_uuid": self.instance_uuid,
                "session": self.session_id, "stamp_s": self.stamp_s, "from_m": self.from_m, "to_m": self.to_m}


def validity(doc: dict[str, Any]) -> dict[str, Any]:
    """An instance document's validity: ``valid_from_s``, ``valid_to_s`` and ``state``
    (present | removed)."""
    vacated = (doc.get("data") or {}).get("vacated_s")
    return {"valid_from_s": doc.get("first_seen_s"), "valid_to_s": vacated,
            "state": "present" if vacated is None else "removed"}


def _changes_here(inst: Instance) -> bool:
    return inst.layer == "foreground" and inst.state == "static" and inst.class_name not in NOT_CHANGING


def _centre(inst: Instance) -> tuple[float, float, float]:
    c = inst.box.center_m
    return (round(float(c[0]), 3), round(float(c[1]), 3), round(float(c[2]), 3))


def snapshot(instances: Iterable[Instance]) -> dict[str, Placed]:
    """The static objects that can change, as they stand now (copied: the stages fold into
    the instances in place)."""
    return {i.uuid: Placed(i.uuid, i.class_name, _centre(i), i.data.get("vacated_s"))
            for i in instances if _changes_here(i)}


def session_changes(
    before: dict[str, Placed],
    after: Iterable[Instance],
    session_id: int,
    *,
    seen_before: Callable[[Instance], bool],
) -> list[Change]:
    """The change events of one session (see the module docstring), in stamp order."""
    out: list[Change] = []
    for inst in after:
        if not _changes_here(inst):
            continue
        now = _centre(inst)
        old = before.get(inst.uuid)
        vacated = inst.data.get("vacated_s")
        if old is None:
            if before and vacated is None and seen_before(inst):
                out.append(Change("added", inst.class_name, inst.uuid, session_id, float(inst.first_seen_s),
                                  None, list(now)))
        elif old.vacated_s is None and vacated is not None:
            out.append(Change("removed", inst.class_name, inst.uuid, session_id, float(vacated),
                              list(old.center_m), None))
        elif vacated is None and float(np.hypot(now[0] - old.center_m[0],
                                                now[1] - old.center_m[1])) > MOVED_M:
            out.append(Change("moved", inst.class_name, inst.uuid, session_id, float(inst.last_seen_s),
                              list(old.center_m), list(now)))
    return sorted(out, key=lambda c: (c.stamp_s, c.kind, c.instance_uuid))


class FreeBefore:
    """Whether the place's earlier sessions saw an object's space free: their background cloud
    (``mapcloud.py``) holds a support under its footprint (``SUPPORT_POINTS`` points within
    ``SUPPORT_M`` of one level at or below its box's bottom: the floor, a table top) and hardly
    anything between that support and the box's top (at most ``INSIDE_POINTS``). A space never
    seen, or one where something stood that was not recognised then, is not free: an object
    found there is not an addition."""

    SUPPORT_M = 0.08
    SUPPORT_POINTS = 2
    INSIDE_POINTS = 1
    SURFACE_M = 0.1  # a surface point this near a point of the earlier cloud was seen then
    SURFACE_SHARE = 0.5

    def __init__(self, points_m: np.ndarray | None) -> None:
        self.points = np.zeros((0, 3)) if points_m is None else np.asarray(points_m, dtype=np.float64)
        self._tree: Any = None  # a KD-tree of the points, built when first needed

    def __call__(self, inst: Instance) -> bool:
        support, inside = self._counts(inst)
        return support >= self.SUPPORT_POINTS and inside <= self.INSIDE_POINTS

    def occupied(self, inst: Instance) -> bool:
        """Whether the earlier sessions saw the object's surface where it is now: at least
        ``SURFACE_SHARE`` of its observed surface points (``data["surface_map"]``, those above
        its foot) lie within ``SURFACE_M`` of the earlier cloud; for an object without them,
        something inside its box (more than ``INSIDE_POINTS`` above its support band). An
        object found there stood there then, unrecognised, and did not move there
        (``reidentify.py`` pairs moves only elsewhere); a chair pushed under a table keeps the
        table top off its surface."""
        surface = np.asarray(inst.data.get("surface_map") or [], dtype=np.float64).reshape(-1, 3)
        if len(surface):
            surface = surface[surface[:, 2] >= surface[:, 2].min() + self.SUPPORT_M]
        if len(surface) == 0:
            return self._counts(inst)[1] > self.INSIDE_POINTS
        if len(self.points) == 0:
            return False
        if self._tree is None:
            from scipy.spatial import cKDTree

            self._tree = cKDTree(self.points)
        dist, _ = self._tree.query(surface, distance_upper_bound=self.SURFACE_M)
        return float(np.mean(np.isfinite(dist))) >= self.SURFACE_SHARE

    def _counts(self, inst: Instance) -> tuple[int, int]:
        """Points of the earlier cloud over the box's footprint: in its support band, and in the
        space from the support up to the box's top. The support is at the box's bottom (within
        ``SUPPORT_M`` below it) or, when no points lie there, the highest level under the box
        (a band ``SUPPORT_M`` thick) that holds most of the points under it (the floor, a table
        top): a fused box need not reach what the object stands on (a plant whose pot no view
        showed whole), and the space it stands in was free when nothing lay between that
        support and the box's top. Points under the box spread over heights (the side of
        something standing there) make no support."""
        if len(self.points) == 0:
            return 0, 0
        lo, hi = inst.box.aabb()
        p = self.points
        over = (p[:, 0] >= lo[0]) & (p[:, 0] <= hi[0]) & (p[:, 1] >= lo[1]) & (p[:, 1] <= hi[1])
        z = p[over, 2]
        margin = min(self.SUPPORT_M, 0.3 * float(hi[2] - lo[2]))  # a cup is barely taller than this
        inside = int(((z >= lo[2] + margin) & (z <= hi[2])).sum())
        support = int(((z >= lo[2] - self.SUPPORT_M) & (z < lo[2] + margin)).sum())
        if support >= self.SUPPORT_POINTS:
            return support, inside
        below = np.sort(z[z < lo[2] + margin])[::-1]  # highest first
        for n, top in enumerate(below):  # the first level (from the top) that holds most of them
            support = int(np.searchsorted(-below, -(top - self.SUPPORT_M), side="right")) - n
            if support >= max(self.SUPPORT_POINTS, 0.5 * len(below)):
                return support, inside + n  # what lay above the support and below the box
        return 0, inside
