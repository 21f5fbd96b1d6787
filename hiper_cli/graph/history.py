"""Changes as data: what a session changed about the place, as events.

At the end of a session the static objects of the place as they stood before it are compared
with what they are after it (re-identification and the empty-place test have run: see
``perceive/foreground/reidentify.py`` and ``vacated.py``):

- **removed**: an object present before whose place this session saw empty (``vacated_s`` set
  now): negative evidence, from views that would have shown it. An object this session did not
  see keeps its state: unseen is not removed.
- **moved**: an object found again whose centre is more than ``MOVED_M`` from where it was.
- **added**: a new object where an earlier session's camera looked (``seen_before``), so the
  space was seen free then; a new object in a corner no session saw before is not an addition.

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

__all__ = ["CHANGE_KINDS", "MOVED_M", "Change", "Placed", "Views", "session_changes", "snapshot", "validity"]

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
    seen_before: Callable[[np.ndarray], bool],
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
            if before and vacated is None and seen_before(np.asarray(now)):
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


class Views:
    """Where earlier sessions' cameras looked: a point was in view of one of these poses
    (within ``range_m``, within ``half_fov_deg`` of its optical axis). Occlusion is not
    modelled: a spot behind a wall within range counts as seen."""

    def __init__(self, T_map_cams: np.ndarray, range_m: float = 4.0, half_fov_deg: float = 25.0) -> None:
        T = np.asarray(T_map_cams, dtype=np.float64).reshape(-1, 4, 4)
        self.origins = T[:, :3, 3]
        self.axes = T[:, :3, 2]
        self.range_m = range_m
        self.cos_fov = float(np.cos(np.radians(half_fov_deg)))

    def __call__(self, point_m: np.ndarray) -> bool:
        if len(self.origins) == 0:
            return False
        d = np.asarray(point_m, dtype=np.float64)[None, :3] - self.origins
        dist = np.linalg.norm(d, axis=1)
        ok = (dist > 0.3) & (dist < self.range_m)
        cos = (d * self.axes).sum(axis=1) / np.maximum(dist, 1e-9)
        return bool(np.any(ok & (cos > self.cos_fov)))
