"""Whether a wall was seen near enough to be told from a door or a furniture front.

A depth camera's noise grows with the square of the range (σ(z) ≈ ``cell_noise_m`` z², the
segmenter's model; docs/sensors.md). Far enough, a plane's relief hides in it: the book rows
of a shelf front fit one flat plane, a glass door lies flush with its wall, and the tests that
tell a furniture front from a wall (``bounds.py``, ``fronts.py``) see no step. A view whose
noise exceeds ``wall_view_max_noise_m`` is no evidence that a plane is a wall rather than one
of those.

Such a plane is still a surface the room's free space ends at, whatever it is: while the log
runs it stays in the map as the wall it looks like, so the object map does not take its points
for objects. ``FarWalls`` remembers which wall observations came only from too far; when the
log ends, a wall instance made of such observations alone (no nearer view ever joined it) is
withdrawn: the map keeps no wall it has no evidence for.
"""

from __future__ import annotations

from collections.abc import Iterable

from hiper_cli.model import Instance, Observation
from hiper_cli.perceive.background.config import BackgroundConfig

__all__ = ["FarWalls", "beyond_wall_range"]


def beyond_wall_range(depth_m: float, cfg: BackgroundConfig) -> bool:
    """Whether the depth noise at a view's range ``depth_m`` exceeds ``wall_view_max_noise_m``
    (0: every view counts)."""
    if cfg.wall_view_max_noise_m <= 0:
        return False
    return cfg.cell_noise_m * depth_m * depth_m > cfg.wall_view_max_noise_m


def _depth_m(obs: Observation) -> float:
    """The view's range: the mean depth of its plane's samples."""
    return float(obs.data.get("centroid_cam", obs.box.center_m)[2])


class FarWalls:
    """The uuids of this run's wall observations seen only from beyond ``beyond_wall_range``."""

    def __init__(self, cfg: BackgroundConfig) -> None:
        self.cfg = cfg
        self._far: set[str] = set()

    def note(self, obs: Observation) -> None:
        """Remember ``obs`` if it is a wall seen from too far to tell."""
        if obs.class_name == "wall" and beyond_wall_range(_depth_m(obs), self.cfg):
            self._far.add(obs.uuid)

    def unconfirmed(self, live: Iterable[Instance]) -> list[str]:
        """The uuids of the wall instances in ``live`` all of whose observations are far ones
        of this run (an instance from an earlier session, or with one nearer view, is kept)."""
        return [inst.uuid for inst in live if inst.class_name == "wall" and inst.observation_uuids
                and all(u in self._far for u in inst.observation_uuids)]
