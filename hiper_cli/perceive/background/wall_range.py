"""Whether a view of a vertical plane is near enough to be a wall's evidence.

A depth camera's noise grows with the square of the range (σ(z) ≈ ``cell_noise_m`` z², the
segmenter's model; docs/sensors.md). Far enough, a plane's relief hides in it: the book rows
of a shelf front (some 0.1 m deep) fit one flat plane, a glass door lies flush with its wall,
and the tests that tell a furniture front from a wall (``bounds.py``, ``fronts.py``) see no
step. On the degraded bookstore the planes seen as walls only from 4.5-4.7 m were a shelf
front and the storefront door (and one real wall); every wall of the other logs has a view
within 4 m. So a view whose noise exceeds ``wall_view_max_noise_m`` starts no wall: it only
extends a wall that a nearer view mapped (it matches one, Algorithm 2's criteria).
"""

from __future__ import annotations

from collections.abc import Iterable

from hiper_cli.model import Instance, Observation
from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.merge import MapObservation, match_instances

__all__ = ["beyond_wall_range", "unconfirmed_far_wall"]


def beyond_wall_range(depth_m: float, cfg: BackgroundConfig) -> bool:
    """Whether the depth noise at a view's range ``depth_m`` exceeds ``wall_view_max_noise_m``
    (0: every view counts)."""
    if cfg.wall_view_max_noise_m <= 0:
        return False
    return cfg.cell_noise_m * depth_m * depth_m > cfg.wall_view_max_noise_m


def _depth_m(obs: Observation) -> float:
    """The view's range: the mean depth of its plane's samples."""
    return float(obs.data.get("centroid_cam", obs.box.center_m)[2])


def unconfirmed_far_wall(mo: MapObservation, live: Iterable[Instance], cfg: BackgroundConfig) -> bool:
    """Whether ``mo`` is a wall seen only from too far (``beyond_wall_range``) that no mapped
    wall in ``live`` takes."""
    if mo.obs.class_name != "wall" or not beyond_wall_range(_depth_m(mo.obs), cfg):
        return False
    walls = [inst for inst in live if inst.class_name == "wall"]
    return not match_instances(mo, walls, cfg)
