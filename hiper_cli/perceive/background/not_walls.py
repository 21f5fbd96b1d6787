"""The vertical planes seen ending in the room (``bounds.py``): furniture fronts, not walls.

Seen from near, a shelf front's top is above the image and it looks like a wall; seen from
farther, the camera sees past its top. ``NotWalls`` keeps such planes, merged like background
instances (Algorithm 2's criteria): a wall instance one of them matches is deleted and folded
into it, and a later wall observation it matches is dropped. A wall instance whose
observations, together, saw it open at both sides (one view the left end, another the right)
goes the same way, unless it was seen reaching higher than furniture does (a wall between
two doorways).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from hiper_cli.model import Instance
from hiper_cli.perceive.background.bounds import EdgeEvidence, is_open
from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.merge import (
    MapObservation,
    instance_matches,
    match_instances,
    merge_into,
    new_instance,
)

__all__ = ["NotWalls"]


class NotWalls:
    """Memory of the planes that failed the wall bounds test, map frame."""

    def __init__(self, cfg: BackgroundConfig) -> None:
        self.cfg = cfg
        self.planes: dict[str, Instance] = {}
        self._open_sides: dict[str, set[str]] = {}  # wall instance uuid: sides seen open

    def veto(self, open_walls: Sequence[MapObservation], live: dict[str, Instance]) -> list[str]:
        """Remember ``open_walls``; remove the wall instances they match from ``live`` and
        return their uuids."""
        deleted: list[str] = []
        for mo in open_walls:
            walls = [i for i in match_instances(mo, list(live.values()), self.cfg) if i.class_name == "wall"]
            for wall in walls:
                live.pop(wall.uuid, None)
                deleted.append(wall.uuid)
            found = match_instances(mo, list(self.planes.values()), self.cfg)
            if not found:
                plane = new_instance(mo, self.cfg)
            else:
                plane = merge_into(found[0], found[1:], mo, self.cfg)
                for dup in found[1:]:
                    self.planes.pop(dup.uuid, None)
            if walls:
                plane = merge_into(plane, walls, None, self.cfg)
            self.planes[plane.uuid] = plane
        return deleted

    def note(self, instance_uuid: str | None, edges: dict[str, EdgeEvidence]) -> None:
        """Remember the sides a wall observation, merged into ``instance_uuid``, saw open."""
        if instance_uuid is not None:
            sides = self._open_sides.setdefault(instance_uuid, set())
            sides.update(side for side, verdict in edges.items() if verdict == "open")

    def settle(self, live: dict[str, Instance]) -> list[str]:
        """Remove from ``live`` the wall instances whose observations together saw them end in
        the room, remembering their planes; returns their uuids."""
        failed = [
            uuid for uuid, sides in self._open_sides.items()
            if uuid in live and is_open(dict.fromkeys(sides, "open"))
            and _top_m(live[uuid]) < self.cfg.wall_tall_m
        ]
        for uuid in failed:
            wall = live.pop(uuid)
            found = match_instances_of(wall, self.planes, self.cfg)
            plane = merge_into(found[0], [*found[1:], wall], None, self.cfg) if found else wall
            for dup in found[1:]:
                self.planes.pop(dup.uuid, None)
            self.planes[plane.uuid] = plane
            del self._open_sides[uuid]
        return failed

    def covers(self, mo: MapObservation) -> bool:
        """Whether a wall observation lies on a plane seen ending in the room."""
        return bool(match_instances(mo, list(self.planes.values()), self.cfg))


def match_instances_of(inst: Instance, planes: dict[str, Instance], cfg: BackgroundConfig) -> list[Instance]:
    """The remembered planes an instance matches, oldest first."""
    found = [p for p in planes.values() if instance_matches(inst, p, cfg)]
    return sorted(found, key=lambda i: (i.first_seen_s, i.uuid))


def _top_m(inst: Instance) -> float:
    """The height of an instance's outline's highest point, map frame."""
    contour = np.asarray(inst.data.get("contour_map", []), dtype=np.float64).reshape(-1, 3)
    return float(contour[:, 2].max()) if len(contour) else 0.0
