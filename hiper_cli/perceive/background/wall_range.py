"""Whether a view of a vertical plane is near enough to be a wall's evidence.

A depth camera's noise grows with the square of the range (σ(z) ≈ ``cell_noise_m`` z², the
segmenter's model; docs/sensors.md). Far enough, a plane's relief hides in it: the book rows
of a shelf front fit one flat plane, a glass door lies flush with its wall, and the tests that
tell a furniture front from a wall (``bounds.py``, ``fronts.py``) see no step. So a view whose
noise exceeds ``wall_view_max_noise_m`` starts no wall: it only extends a wall that a nearer
view mapped (it matches one, Algorithm 2's criteria, or lies on its plane further along).
Off by default: a plane it keeps out of the walls becomes foreground to the object map, where
its clutter costs more than the wall it removes (docs/results/2026-12-07-degraded-background.md).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

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


def _on_plane(mo: MapObservation, inst: Instance, cfg: BackgroundConfig) -> bool:
    """Whether ``mo`` lies on the plane of ``inst`` (Algorithm 2's alignment: normals within
    ``merge_angle_deg``, its centroid within ``merge_offset_m`` of the plane), anywhere along it."""
    plane = np.asarray(inst.data.get("plane_map", ()), dtype=np.float64)
    if plane.shape != (4,):
        return False
    cos = abs(float(plane[:3] @ mo.plane_map[:3]))
    offset = abs(float(plane[:3] @ mo.centroid_map + plane[3]))
    return cos >= np.cos(np.radians(cfg.merge_angle_deg)) and offset <= cfg.merge_offset_m


def unconfirmed_far_wall(mo: MapObservation, live: Iterable[Instance], cfg: BackgroundConfig) -> bool:
    """Whether ``mo`` is a wall seen only from too far (``beyond_wall_range``) that no mapped
    wall in ``live`` takes: it matches none, nor lies on one's plane further along it (the far
    end of a wall whose near end a nearer view mapped)."""
    if mo.obs.class_name != "wall" or not beyond_wall_range(_depth_m(mo.obs), cfg):
        return False
    walls = [inst for inst in live if inst.class_name == "wall"]
    return not (match_instances(mo, walls, cfg) or any(_on_plane(mo, w, cfg) for w in walls))
