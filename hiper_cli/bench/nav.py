"""Navigation for the benchmark's tasks: the map, A* with a cost layer, and what the camera sees.

The map is an ``OccupancyGrid`` (``hiper_cli.analyze.gridmap``) of the world's walls and
furniture inflated by the robot's radius: the SLAM map every configuration has. A* runs over its
free cells (the largest connected free region), 8-connected, with an optional cost layer (the
people heatmap, paper VI-B: a crowded corridor costs the planner, never blocks it). A target is
seen when it lies in the camera's horizontal field of view, within range, and no wall stands
between (walls rasterised apart).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.analyze.gridmap import FREE, OCCUPIED, OccupancyGrid
from hiper_cli.errors import ConfigError
from hiper_cli.sim.route import Grid, grid_path
from hiper_cli.sim.worlds import World

__all__ = ["XY", "NavConfig", "NavMap"]

XY = tuple[float, float]


@dataclass(frozen=True)
class NavConfig:
    """The robot's drive and camera (the paper's robot drives at most 0.9 m/s)."""

    speed_mps: float = 0.8
    turn_rate_rps: float = 0.7
    robot_radius_m: float = 0.35
    resolution_m: float = 0.2
    hfov_deg: float = 62.0  # 640 px at 525 px focal length
    focal_px: float = 525.0
    sensor_range_m: float = 5.0  # depth range: what the 3D pipeline can localise
    min_box_px: float = 16.0  # the 2D detector needs a box at least this tall
    heat_weight: float = 4.0  # path cost per metre is 1 + weight * heat (heat in [0, 0.8])

    def __post_init__(self) -> None:
        if not 0.0 < self.speed_mps <= 0.9:
            raise ConfigError(f"robot speed {self.speed_mps} m/s: expected 0 < speed <= 0.9")


class NavMap:
    """The world's occupancy grid for planning, and a wall raster for line of sight."""

    def __init__(self, world: World, config: NavConfig | None = None) -> None:
        self.cfg = config or NavConfig()
        self.world = world
        grid = Grid(world, self.cfg.robot_radius_m, self.cfg.resolution_m)
        from scipy import ndimage

        free = grid.free.T  # Grid is [ix, iy]
        labels, n = ndimage.label(free, structure=np.ones((3, 3)))
        if n > 1:  # pockets the robot cannot reach (behind closed doors) count as occupied
            sizes = np.bincount(labels.ravel())[1:]
            free = labels == 1 + int(np.argmax(sizes))
        cells = np.where(free, FREE, OCCUPIED).astype(np.int8)
        self.grid = OccupancyGrid(cells, self.cfg.resolution_m, grid.origin)
        walls = Grid(world, 0.0, 0.05)
        self._walls = ~walls.free  # [ix, iy], furniture included: it occludes too
        only_walls = np.zeros_like(self._walls)
        x0, y0 = walls.origin
        for rx0, ry0, rx1, ry1 in world.walls:
            i0, i1 = int((rx0 - x0) / 0.05), math.ceil((rx1 - x0) / 0.05)
            j0, j1 = int((ry0 - y0) / 0.05), math.ceil((ry1 - y0) / 0.05)
            only_walls[max(i0, 0) : i1, max(j0, 0) : j1] = True
        self._walls = only_walls
        self._walls_origin = walls.origin

    @property
    def free(self) -> NDArray[np.bool_]:
        """(H, W) bool, bottom-up like the grid's cells."""
        return np.asarray(self.grid.cells == FREE)

    def cell(self, p: XY) -> tuple[int, int]:
        iy, ix, _ = self.grid.cell_of(np.array([p]))
        return int(iy[0]), int(ix[0])

    def center(self, c: tuple[int, int]) -> XY:
        r = self.grid.resolution_m
        return (self.grid.origin_xy_m[0] + (c[1] + 0.5) * r, self.grid.origin_xy_m[1] + (c[0] + 0.5) * r)

    def nearest_free(self, p: XY) -> XY:
        iy, ix = self.cell(p)
        free = self.free
        h, w = free.shape
        if 0 <= iy < h and 0 <= ix < w and free[iy, ix]:
            return p
        idx = np.argwhere(free)
        best = idx[np.argmin(((idx - np.array([iy, ix])) ** 2).sum(axis=1))]
        return self.center((int(best[0]), int(best[1])))

    def viewpoint(self, target: XY, max_m: float = 3.0) -> XY:
        """The nearest free cell within ``max_m`` that sees ``target`` (no wall between; an
        object on a table is seen from beside it), else the nearest free cell."""
        iy, ix = self.cell(target)
        r = int(max_m / self.grid.resolution_m)
        free = self.free
        h, w = free.shape
        cands = []
        for dy in range(-r, r + 1):
            for dx in range(-r, r + 1):
                y, x = iy + dy, ix + dx
                if 0 <= y < h and 0 <= x < w and free[y, x]:
                    cands.append((math.hypot(dx, dy), (y, x)))
        for _, c in sorted(cands):
            p = self.center(c)
            if self.line_of_sight(p, target):
                return p
        return self.nearest_free(target)

    def idle_position(self) -> XY:
        """The robot's idle place: the route waypoint farthest from where the people start and
        walk to (the paper's idle positions lie off the busy areas)."""
        spots = [s.start_xy for s in self.world.walkers] + [g for s in self.world.walkers for g in s.goals]
        wps = [self.nearest_free(p) for p in self.world.waypoints]
        if not spots:
            return wps[0]
        return max(wps, key=lambda p: min(math.dist(p, q) for q in spots))

    def astar(self, a: XY, b: XY, heat: NDArray[np.float32] | None = None) -> tuple[list[XY], float]:
        """Path of cell centres from ``a`` to ``b`` and its length in metres; ``heat`` (H, W) on
        the grid's cells weighs each step by ``1 + heat_weight * heat``."""
        a, b = self.nearest_free(a), self.nearest_free(b)
        weight = None if heat is None else self.cfg.heat_weight * np.asarray(heat, dtype=np.float64)
        cells = grid_path(self.free, self.cell(a), self.cell(b), weight)
        if cells is None:
            raise ConfigError(f"bench: no free path from {a} to {b} in world {self.world.name}")
        path = [a] + [self.center(c) for c in cells[1:-1]] + [b]
        length = sum(math.dist(p, q) for p, q in itertools.pairwise(path))
        return path, length

    def line_of_sight(self, a: XY, b: XY) -> bool:
        """No wall between ``a`` and ``b`` (sampled every 5 cm)."""
        n = max(2, int(math.dist(a, b) / 0.05) + 1)
        t = np.linspace(0.0, 1.0, n)
        xs = a[0] + (b[0] - a[0]) * t
        ys = a[1] + (b[1] - a[1]) * t
        i = ((xs - self._walls_origin[0]) / 0.05).astype(np.int64)
        j = ((ys - self._walls_origin[1]) / 0.05).astype(np.int64)
        nx, ny = self._walls.shape
        ok = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
        return not bool(self._walls[i[ok], j[ok]].any())

    def detect_range_m(self, height_m: float, needs_depth: bool) -> float:
        """How far a detector sees an object this tall (box of ``min_box_px``), capped by the
        depth range when the pipeline localises it with depth."""
        far = self.cfg.focal_px * height_m / self.cfg.min_box_px
        return min(far, self.cfg.sensor_range_m) if needs_depth else far

    def sees(self, robot: XY, yaw_rad: float, target: XY, range_m: float) -> bool:
        """``target`` in the camera frustum (horizontal FOV), within ``range_m``, not behind a wall."""
        d = math.dist(robot, target)
        if d > range_m or d < 0.3:
            return False
        bearing = math.atan2(target[1] - robot[1], target[0] - robot[0])
        off = (bearing - yaw_rad + math.pi) % (2 * math.pi) - math.pi
        if abs(off) > math.radians(self.cfg.hfov_deg) / 2:
            return False
        return self.line_of_sight(robot, target)
