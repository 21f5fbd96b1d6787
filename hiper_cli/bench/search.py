"""Where the robot looks for something: the inverse-heatmap strategy (C1-C2) or coverage (C3-C5).

``heat_goals`` takes the heatmap's peaks (paper VI-B: the inverse map draws a search to where
the class was found): the hottest cell, then the hottest outside ``suppress_m`` of the goals so
far, while a peak holds at least ``min_share`` of the cap; each goal is moved onto a free cell.
``coverage_goals`` is a lattice of viewpoints over the free space, nearest first, in a tour.
Both lists are visited in order, scanning a full turn at each goal, and repeated until the time
limit; the heat goals are followed by the coverage tour when they are exhausted.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from hiper_cli.analyze.heatmap import Heatmap, heatmap_from_rows
from hiper_cli.analyze.window import TimeWindow
from hiper_cli.bench.nav import XY, NavMap

__all__ = ["coverage_goals", "heat_goals", "heatmap_of", "points_as_rows"]


def heatmap_of(
    nav: NavMap, class_name: str, rows: NDArray[np.float64], track: NDArray[np.int64], speed_mps: float | None
) -> Heatmap | None:
    """The class's heatmap on the navigation grid (``None`` without rows)."""
    if len(rows) == 0:
        return None
    order = np.lexsort((rows[:, 0], track))
    return heatmap_from_rows(class_name, rows[order], track[order], nav.grid, TimeWindow(), speed_mps)


def points_as_rows(points: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Static object centres (N, 3) as one-row tracks for ``heatmap_of``."""
    rows = np.zeros((len(points), 7))
    rows[:, 1:4] = points
    return rows, np.arange(len(points), dtype=np.int64)


def heat_goals(nav: NavMap, hm: Heatmap, max_goals: int = 8, suppress_m: float = 2.0,
               min_share: float = 0.1) -> list[XY]:
    heat = hm.heat.astype(np.float64).copy()
    cap = hm.config.occupancy_cap
    h, w = heat.shape
    ys, xs = np.mgrid[0:h, 0:w]
    r_cells = suppress_m / nav.grid.resolution_m
    goals: list[XY] = []
    while len(goals) < max_goals:
        iy, ix = np.unravel_index(int(np.argmax(heat)), heat.shape)
        if heat[iy, ix] < min_share * cap:
            break
        goals.append(nav.viewpoint(nav.center((int(iy), int(ix)))))
        heat[(ys - iy) ** 2 + (xs - ix) ** 2 <= r_cells**2] = 0.0
    return goals


def coverage_goals(nav: NavMap, start: XY, spacing_m: float = 2.5) -> list[XY]:
    """Viewpoints on a ``spacing_m`` lattice over the map's free space (each lattice point moved
    to a free cell within half the spacing, else dropped) as a nearest-neighbour tour from
    ``start``: a systematic coverage of every room."""
    g = nav.grid
    h, w = g.shape
    x0, y0 = g.origin_xy_m
    free = nav.free
    idx = np.argwhere(free)
    left: list[XY] = []
    for y in np.arange(y0 + spacing_m / 2, y0 + h * g.resolution_m, spacing_m):
        for x in np.arange(x0 + spacing_m / 2, x0 + w * g.resolution_m, spacing_m):
            iy, ix = nav.cell((float(x), float(y)))
            d = np.hypot(idx[:, 0] - iy, idx[:, 1] - ix) * g.resolution_m
            k = int(np.argmin(d))
            if d[k] <= spacing_m / 2:
                p = nav.center((int(idx[k, 0]), int(idx[k, 1])))
                if p not in left:
                    left.append(p)
    tour: list[XY] = []
    here = start
    while left:
        k = min(range(len(left)), key=lambda i: math.dist(here, left[i]))
        here = left.pop(k)
        tour.append(here)
    return tour
