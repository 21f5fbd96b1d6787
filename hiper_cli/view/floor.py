"""Grids to lay on the floor: heatmaps and map layers that ``hiper analyze`` stored, and an
environment's occupancy map.

A grid is found in an analysis document whose ``values`` (or an environment's ``data["map"]``)
hold a 2-D array under one of ``GRID_KEYS``, its cell size under ``resolution_m`` (or
``cell_m``) and the map-frame (x, y) of the corner of cell [0, 0] under ``origin_m``; row i
runs along +y, column j along +x. Anything else is skipped, so a KB without analyses, or with
analyses of another shape, still views (docs/view.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from hiper_cli.view.scene import TimeWindow

__all__ = ["FLOOR_KINDS", "GRID_KEYS", "FloorImage", "floor_images"]

FLOOR_KINDS = ("heatmap", "map", "occupancy", "costmap")
GRID_KEYS = ("grid", "image", "heatmap", "density", "counts", "cells", "probability", "cost")


@dataclass(frozen=True)
class FloorImage:
    """A (H, W) float64 grid on the floor: cell [i, j] covers x in origin_x + j·res, y in
    origin_y + i·res. ``name`` is its entity under ``/map`` (``heatmap/person``, ``occupancy``)."""

    name: str
    kind: str
    class_name: str
    grid: NDArray[np.float64]
    resolution_m: float
    origin_m: tuple[float, float]

    @property
    def extent_m(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) in the map frame."""
        h, w = self.grid.shape
        x0, y0 = self.origin_m
        return x0, x0 + w * self.resolution_m, y0, y0 + h * self.resolution_m

    def normalised(self) -> NDArray[np.float64]:
        """The grid scaled to [0, 1] (NaN cells as 0)."""
        g = np.nan_to_num(self.grid, nan=0.0, posinf=0.0, neginf=0.0)
        lo, hi = float(g.min()), float(g.max())
        return (g - lo) / (hi - lo) if hi > lo else np.zeros_like(g)


def _grid(values: dict[str, Any], name: str, kind: str, class_name: str) -> FloorImage | None:
    raw = next((values[k] for k in GRID_KEYS if k in values), None)
    res = values.get("resolution_m", values.get("cell_m"))
    origin = values.get("origin_m")
    if raw is None or res is None or origin is None:
        return None
    try:
        grid = np.asarray(raw, dtype=np.float64)
        res_m = float(res)
        x0, y0 = (float(v) for v in list(origin)[:2])
    except (TypeError, ValueError):
        return None
    if grid.ndim != 2 or grid.size == 0 or not res_m > 0:
        return None
    return FloorImage(name, kind, class_name, grid, res_m, (x0, y0))


def floor_images(
    analyses: Sequence[dict[str, Any]], environments: Sequence[dict[str, Any]], window: TimeWindow
) -> tuple[FloorImage, ...]:
    """The newest grid per (kind, class) among analysis documents overlapping ``window``, then
    each environment's map."""
    newest: dict[tuple[str, str], dict[str, Any]] = {}
    for doc in analyses:
        kind, cls = str(doc.get("kind", "")), str(doc.get("class", ""))
        if kind not in FLOOR_KINDS or not isinstance(doc.get("values"), dict):
            continue
        if not window.overlaps(float(doc.get("t_start_s", 0.0)), float(doc.get("t_end_s", 0.0))):
            continue
        if (kind, cls) not in newest or doc.get("created_s", 0) >= newest[(kind, cls)].get("created_s", 0):
            newest[(kind, cls)] = doc
    out = []
    for (kind, cls), doc in sorted(newest.items()):
        image = _grid(doc["values"], f"{kind}/{cls}" if cls else kind, kind, cls)
        if image is not None:
            out.append(image)
    for k, data in enumerate(environments):
        if isinstance(data.get("map"), dict):
            image = _grid(data["map"], "occupancy" if k == 0 else f"occupancy_{k}", "occupancy", "")
            if image is not None:
                out.append(image)
    return tuple(out)
