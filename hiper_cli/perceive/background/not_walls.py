"""The vertical planes seen ending in the room (``bounds.py``): furniture fronts, not walls.

Seen from near, a shelf front's top is above the image and it looks like a wall; seen from
farther, the camera sees past its top. ``NotWalls`` keeps such planes, merged like background
instances (Algorithm 2's criteria): a wall instance one of them matches, and covers mostly,
is deleted and folded into it, and a later wall observation that lies mostly on one is
dropped.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Instance
from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.contour import PlaneFrame, to_polygon
from hiper_cli.perceive.background.merge import MapObservation, match_instances, merge_into, new_instance

__all__ = ["NotWalls"]

# a plane seen ending in the room is the wall instance most of whose outline it covers (a
# wardrobe front seen near, then from far), not one it only touches or overlaps at its end
# (a wall whose last metre a far view saw wrongly)
MOST = 0.5


class NotWalls:
    """Memory of the planes that failed the wall bounds test, map frame."""

    def __init__(self, cfg: BackgroundConfig) -> None:
        self.cfg = cfg
        self.planes: dict[str, Instance] = {}

    def veto(self, open_walls: Sequence[MapObservation], live: dict[str, Instance]) -> list[str]:
        """Remember ``open_walls``; remove the wall instances they match from ``live`` and
        return their uuids."""
        deleted: list[str] = []
        for mo in open_walls:
            walls = [
                i for i in match_instances(mo, list(live.values()), self.cfg)
                if i.class_name == "wall" and _share_inside(_contour(i), mo.contour_map, mo.plane_map) >= MOST
            ]
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

    def covers(self, mo: MapObservation) -> bool:
        """Whether a wall observation lies, mostly, on a plane seen ending in the room."""
        return any(
            _share_inside(mo.contour_map, _contour(p), np.asarray(p.data["plane_map"])) >= MOST
            for p in match_instances(mo, list(self.planes.values()), self.cfg)
        )


def _contour(inst: Instance) -> NDArray[np.float64]:
    return np.asarray(inst.data["contour_map"], dtype=np.float64).reshape(-1, 3)


def _share_inside(inner: NDArray[np.float64], outer: NDArray[np.float64],
                  plane: NDArray[np.float64]) -> float:
    """The share of the outline ``inner``'s area inside the outline ``outer``, both (K, 3)
    projected into the plane ``plane``."""
    frame = PlaneFrame(plane)
    a, b = to_polygon(inner, frame), to_polygon(outer, frame)
    if a.is_empty or a.area <= 0 or b.is_empty:
        return 0.0
    return float(a.intersection(b).area / a.area)

