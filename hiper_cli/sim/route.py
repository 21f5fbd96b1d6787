"""Collision-free robot route through a world and the camera pose along it.

The free space is a 2D occupancy grid of the world's obstacle footprints inflated by a
radius; A* (8-connected) joins consecutive waypoints, the path is shortened by line of
sight, and the robot drives it at constant speed, turning in place at each corner.
The route repeats (waypoints are visited cyclically) until the log ends.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError
from hiper_cli.sim.worlds import XY, Rect, World

__all__ = ["Grid", "Route", "RouteConfig", "T_map_cam", "plan_route"]

# Camera optical axes (x right, y down, z forward) expressed in the robot base frame (x forward, z up).
_R_BASE_OPT = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


@dataclass(frozen=True)
class RouteConfig:
    """Robot motion: speeds (the paper's robot drives at most 0.9 m/s) and the camera mount."""

    speed_mps: float = 0.6
    turn_rate_rps: float = 0.7
    robot_radius_m: float = 0.35
    camera_height_m: float = 1.2
    camera_pitch_deg: float = 6.0  # tilted slightly down
    grid_m: float = 0.1
    stop_distance_m: float = 1.0  # the robot waits while a person is this close in front of it (±30°)
    max_wait_s: float = 2.0  # ... but for at most this long, then it drives on

    def __post_init__(self) -> None:
        if not 0.0 < self.speed_mps <= 0.9:
            raise ConfigError(f"robot speed {self.speed_mps} m/s: expected 0 < speed <= 0.9")


Cell = tuple[int, int]
_STEPS = [(di, dj, math.hypot(di, dj)) for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj]


def grid_path(
    free: NDArray[np.bool_], start: Cell, goal: Cell, weight: NDArray[np.float64] | None = None
) -> list[Cell] | None:
    """A*: the cells of the cheapest 8-connected path from ``start`` to ``goal`` (both included)
    through ``free`` cells, never cutting a corner; a step into a cell costs its length times
    ``1 + weight`` there. None when there is no such path."""
    nx, ny = free.shape
    came: dict[Cell, Cell] = {}
    cost = {start: 0.0}
    heap = [(0.0, start)]
    while heap:
        _, cur = heapq.heappop(heap)
        if cur == goal:
            break
        for di, dj, step in _STEPS:
            nxt = (cur[0] + di, cur[1] + dj)
            if not (0 <= nxt[0] < nx and 0 <= nxt[1] < ny) or not free[nxt]:
                continue
            if di and dj and not (free[cur[0] + di, cur[1]] and free[cur[0], cur[1] + dj]):
                continue
            c = cost[cur] + (step if weight is None else step * (1.0 + weight[nxt]))
            if c < cost.get(nxt, math.inf):
                cost[nxt] = c
                came[nxt] = cur
                heapq.heappush(heap, (c + math.hypot(goal[0] - nxt[0], goal[1] - nxt[1]), nxt))
    if goal not in cost:
        return None
    cells = [goal]
    while cells[-1] != start:
        cells.append(came[cells[-1]])
    return cells[::-1]


class Grid:
    """Occupancy grid of a world: ``free[i, j]`` for cell centre (x0 + (i + ½)·res, y0 + (j + ½)·res)."""

    def __init__(self, world: World, radius_m: float, res_m: float = 0.1, extra: Sequence[Rect] = ()) -> None:
        x0, y0, x1, y1 = world.bounds
        self.origin = (x0, y0)
        self.res = res_m
        nx, ny = math.ceil((x1 - x0) / res_m), math.ceil((y1 - y0) / res_m)
        xs = x0 + (np.arange(nx) + 0.5) * res_m
        ys = y0 + (np.arange(ny) + 0.5) * res_m
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        free = np.ones((nx, ny), dtype=bool)
        for rx0, ry0, rx1, ry1 in [*world.obstacles, *extra]:
            dx = np.maximum(np.maximum(rx0 - X, X - rx1), 0.0)
            dy = np.maximum(np.maximum(ry0 - Y, Y - ry1), 0.0)
            free &= np.hypot(dx, dy) > radius_m
        self.free = free

    def cell(self, p: XY) -> tuple[int, int]:
        return (int((p[0] - self.origin[0]) / self.res), int((p[1] - self.origin[1]) / self.res))

    def center(self, c: tuple[int, int]) -> XY:
        return (self.origin[0] + (c[0] + 0.5) * self.res, self.origin[1] + (c[1] + 0.5) * self.res)

    def is_free(self, p: XY) -> bool:
        i, j = self.cell(p)
        return 0 <= i < self.free.shape[0] and 0 <= j < self.free.shape[1] and bool(self.free[i, j])

    def nearest_free(self, p: XY) -> XY:
        if self.is_free(p):
            return p
        idx = np.argwhere(self.free)
        if len(idx) == 0:
            raise ConfigError("world has no free space for the robot")
        c = np.array(self.cell(p))
        best = idx[np.argmin(((idx - c) ** 2).sum(axis=1))]
        return self.center((int(best[0]), int(best[1])))

    def line_free(self, a: XY, b: XY) -> bool:
        n = max(2, int(math.dist(a, b) / (self.res / 2)) + 1)
        return all(
            self.is_free((a[0] + (b[0] - a[0]) * k / (n - 1), a[1] + (b[1] - a[1]) * k / (n - 1)))
            for k in range(n)
        )

    def astar(self, a: XY, b: XY) -> list[XY]:
        """Shortest 8-connected path from ``a`` to ``b`` through free cells, shortened by line of sight."""
        a, b = self.nearest_free(a), self.nearest_free(b)
        cells = grid_path(self.free, self.cell(a), self.cell(b))
        if cells is None:
            raise ConfigError(f"no free path from {a} to {b}; the world layout blocks the route")
        points = [a] + [self.center(c) for c in cells[1:-1]] + [b]
        out = [points[0]]
        k = 0
        while k < len(points) - 1:
            far = len(points) - 1
            while far > k + 1 and not self.line_free(points[k], points[far]):
                far -= 1
            out.append(points[far])
            k = far
        return out


def T_map_cam(x: float, y: float, yaw_rad: float, height_m: float, pitch_deg: float) -> NDArray[np.float64]:
    """Camera optical frame in the map for a robot at (x, y) heading ``yaw_rad``."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    p = math.radians(pitch_deg)
    Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    Ry = np.array([[math.cos(p), 0.0, math.sin(p)], [0.0, 1.0, 0.0], [-math.sin(p), 0.0, math.cos(p)]])
    T = np.eye(4)
    T[:3, :3] = Rz @ Ry @ _R_BASE_OPT
    T[:3, 3] = (x, y, height_m)
    return T


@dataclass(frozen=True)
class Route:
    """Keyframes (t_s, x, y, yaw) of the robot; poses between them are interpolated."""

    keys: NDArray[np.float64]  # (K, 4)
    config: RouteConfig

    def state_at(self, t_s: float) -> tuple[float, float, float]:
        k = self.keys
        t = min(max(t_s, k[0, 0]), k[-1, 0])
        x = float(np.interp(t, k[:, 0], k[:, 1]))
        y = float(np.interp(t, k[:, 0], k[:, 2]))
        yaw = float(np.interp(t, k[:, 0], k[:, 3]))
        return x, y, yaw

    def pose_at(self, t_s: float) -> NDArray[np.float64]:
        x, y, yaw = self.state_at(t_s)
        return T_map_cam(x, y, yaw, self.config.camera_height_m, self.config.camera_pitch_deg)


def plan_route(world: World, duration_s: float, config: RouteConfig | None = None) -> Route:
    """Drive the world's waypoints cyclically until ``duration_s``; turn in place at corners."""
    cfg = config or RouteConfig()
    grid = Grid(world, cfg.robot_radius_m, cfg.grid_m)
    if len(world.waypoints) < 2:
        raise ConfigError(f"world {world.name}: needs at least two robot waypoints")
    wps = [grid.nearest_free(p) for p in world.waypoints]
    legs = [grid.astar(wps[i], wps[(i + 1) % len(wps)]) for i in range(len(wps))]
    x, y = wps[0]
    first = legs[0][1] if len(legs[0]) > 1 else wps[1]
    yaw = math.atan2(first[1] - y, first[0] - x)
    t = 0.0
    keys = [(t, x, y, yaw)]
    leg = 0
    while t < duration_s:
        for p in legs[leg % len(legs)][1:]:
            d = math.dist((x, y), p)
            if d < 1e-6:
                continue
            target = math.atan2(p[1] - y, p[0] - x)
            turn = (target - yaw + math.pi) % (2 * math.pi) - math.pi
            if abs(turn) > 1e-6:
                t += abs(turn) / cfg.turn_rate_rps
                yaw += turn
                keys.append((t, x, y, yaw))
            t += d / cfg.speed_mps
            x, y = p
            keys.append((t, x, y, yaw))
        leg += 1
        if leg > 10_000:
            raise ConfigError(f"world {world.name}: the robot route does not move")
    return Route(np.array(keys, dtype=np.float64), cfg)
