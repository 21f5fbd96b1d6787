"""Plane classification in the map frame (z up): wall, floor, ceiling, table or unknown.

The paper classifies "based on the alignment of the normal vector"; heights and sizes make
it robust: a standing person or a shelf side is vertical too, but narrower and lower than a
wall; a table top is horizontal like the floor but higher and bounded in size.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiper_cli.perceive.background.config import BackgroundConfig
from hiper_cli.perceive.background.contour import PlaneFrame, to_polygon

__all__ = ["BACKGROUND_CLASSES", "classify_plane"]

BACKGROUND_CLASSES: tuple[str, ...] = ("wall", "floor", "ceiling", "table")


def classify_plane(plane_map: NDArray[np.float64], contour_map: NDArray[np.float64],
                   cfg: BackgroundConfig, *, view_bounded: bool = False) -> str | None:
    """The class of a plane seen with outline ``contour_map`` (K, 3), or None (unknown).

    ``plane_map`` is [n, d] in the map frame with the unit normal facing the camera.
    ``view_bounded``: a vertical plane seen up to the image's top and down to an occluder in
    front (``bounds.view_bounded``): it is as tall as the view lets it be seen, so the wall
    height test does not apply (the others do).
    """
    if len(contour_map) < 3:
        return None
    nz = float(plane_map[2])
    frame = PlaneFrame(plane_map)
    area = float(to_polygon(contour_map, frame).area)
    z = contour_map[:, 2]
    cos_h = np.cos(np.radians(cfg.horizontal_deg))
    if nz > cos_h:  # facing up
        height = float(np.mean(z))
        if height <= cfg.floor_max_height_m:
            return "floor"
        uv = frame.to_2d(contour_map)
        extent = float(np.max(uv.max(axis=0) - uv.min(axis=0)))
        if (
            cfg.table_min_height_m <= height <= cfg.table_max_height_m
            and area >= cfg.table_min_area_m2
            and extent <= cfg.table_max_extent_m
        ):
            return "table"
        return None
    if nz < -cos_h:  # facing down
        return "ceiling" if float(np.mean(z)) >= cfg.ceiling_min_height_m else None
    if abs(nz) < np.sin(np.radians(cfg.vertical_deg)):
        uv = frame.to_2d(contour_map)
        width = float(uv[:, 0].max() - uv[:, 0].min())
        tall = float(z.max() - z.min())
        if (
            width >= cfg.wall_min_width_m
            and (tall >= cfg.wall_min_height_m or view_bounded)
            and area >= cfg.wall_min_area_m2
            and float(z.max()) >= cfg.wall_top_min_m
        ):
            return "wall"
    return None
