"""The exact geometry of queries, vectorised in numpy over the candidates that the SPARQL
prefilter returned: field of view, footprint distances, box gaps, support, goal poses.

Boxes are axis-aligned in the map frame: centres and full extents as (N, 3) arrays (m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import QueryError

__all__ = [
    "Frustum",
    "box_gap_m",
    "camera_from_yaw",
    "footprint_distance_m",
    "goal_in_front",
    "in_frustum",
    "parse_vector",
    "standing_on",
    "standing_on_any",
]

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class Frustum:
    """A camera's field of view: full horizontal and vertical angles and the range (m). The
    defaults are a Kinect-like RGB-D camera (525 px focal length at 640×480) and the 5 m
    depth range of the paper's sensor."""

    hfov_deg: float = 62.7
    vfov_deg: float = 49.1
    range_m: float = 5.0

    def __post_init__(self) -> None:
        if not (0 < self.hfov_deg < 180 and 0 < self.vfov_deg < 180 and self.range_m > 0):
            raise QueryError(
                f"field of view {self.hfov_deg}° × {self.vfov_deg}°, range {self.range_m} m: "
                "angles must be in (0, 180) and the range positive"
            )


def parse_vector(text: str) -> tuple[float, float, float]:
    """A graph literal "x y z" as three floats."""
    parts = text.split()
    if len(parts) != 3:
        raise QueryError(f"graph value {text!r}: expected three numbers 'x y z'; run 'hiper kb check'")
    return float(parts[0]), float(parts[1]), float(parts[2])


def camera_from_yaw(x_m: float, y_m: float, z_m: float, yaw_rad: float) -> F64:
    """T_map_cam of a level camera at (x, y, z) looking along ``yaw`` (optical frame: z
    forward, x right, y down)."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    T = np.eye(4)
    T[:3, 0] = (s, -c, 0.0)  # x: right
    T[:3, 1] = (0.0, 0.0, -1.0)  # y: down
    T[:3, 2] = (c, s, 0.0)  # z: forward
    T[:3, 3] = (x_m, y_m, z_m)
    return T


def in_frustum(T_map_cam: F64, points_m: F64, frustum: Frustum) -> NDArray[np.bool_]:
    """Which (N, 3) map points lie in the camera's field of view and within its range."""
    if len(points_m) == 0:
        return np.zeros(0, dtype=bool)
    R, t = T_map_cam[:3, :3], T_map_cam[:3, 3]
    p = (points_m - t) @ R  # camera frame
    z = p[:, 2]
    tan_h = math.tan(math.radians(frustum.hfov_deg) / 2.0)
    tan_v = math.tan(math.radians(frustum.vfov_deg) / 2.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ok = (z > 0) & (np.abs(p[:, 0]) <= tan_h * z) & (np.abs(p[:, 1]) <= tan_v * z)
    return np.asarray(ok & (np.linalg.norm(p, axis=1) <= frustum.range_m))


def footprint_distance_m(xy: F64, centers_m: F64, extents_m: F64) -> F64:
    """Horizontal distance from the point ``xy`` (2,) to each box's footprint (0 inside)."""
    if len(centers_m) == 0:
        return np.zeros(0)
    gap = np.maximum(np.abs(centers_m[:, :2] - xy[:2]) - extents_m[:, :2] / 2.0, 0.0)
    return np.asarray(np.linalg.norm(gap, axis=1))


def box_gap_m(centers_m: F64, extents_m: F64, other_center_m: F64, other_extent_m: F64) -> F64:
    """3-D distance between each box and one other box (0 when they touch or overlap)."""
    if len(centers_m) == 0:
        return np.zeros(0)
    gap = np.maximum(np.abs(centers_m - other_center_m) - (extents_m + other_extent_m) / 2.0, 0.0)
    return np.asarray(np.linalg.norm(gap, axis=1))


def standing_on(
    centers_m: F64,
    extents_m: F64,
    support_center_m: F64,
    support_extent_m: F64,
    gap_m: float,
    margin_m: float,
) -> NDArray[np.bool_]:
    """Which boxes stand on one support: their bottom within ``gap_m`` of the support's top
    and their footprint centre inside the support's footprint grown by ``margin_m``."""
    return standing_on_any(
        centers_m, extents_m, support_center_m[None], support_extent_m[None], gap_m, margin_m
    )[:, 0]


def standing_on_any(
    centers_m: F64,
    extents_m: F64,
    support_centers_m: F64,
    support_extents_m: F64,
    gap_m: float,
    margin_m: float,
) -> NDArray[np.bool_]:
    """(N, S): whether box n stands on support s (``standing_on`` for S supports at once)."""
    if len(centers_m) == 0 or len(support_centers_m) == 0:
        return np.zeros((len(centers_m), len(support_centers_m)), dtype=bool)
    bottom = centers_m[:, 2] - extents_m[:, 2] / 2.0
    top = support_centers_m[:, 2] + support_extents_m[:, 2] / 2.0
    reach = support_extents_m[None, :, :2] / 2.0 + margin_m
    inside = np.all(np.abs(centers_m[:, None, :2] - support_centers_m[None, :, :2]) <= reach, axis=2)
    return np.asarray(inside & (np.abs(bottom[:, None] - top[None, :]) <= gap_m))


def goal_in_front(
    center_m: F64, extent_m: F64, from_xy: F64, standoff_m: float
) -> tuple[float, float, float]:
    """(x, y, yaw) of a goal ``standoff_m`` outside the box footprint, on the side facing
    ``from_xy``, looking at the box centre."""
    direction = np.asarray(from_xy[:2], dtype=np.float64) - center_m[:2]
    norm = float(np.linalg.norm(direction))
    direction = np.array([1.0, 0.0]) if norm < 1e-9 else direction / norm
    # distance from the centre to the footprint edge along ``direction``
    half = extent_m[:2] / 2.0
    with np.errstate(divide="ignore"):
        reach = float(np.min(np.where(np.abs(direction) > 1e-9, half / np.abs(direction), np.inf)))
    goal = center_m[:2] + direction * (reach + standoff_m)
    yaw = math.atan2(float(center_m[1] - goal[1]), float(center_m[0] - goal[0]))
    return float(goal[0]), float(goal[1]), yaw
