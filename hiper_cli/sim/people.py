"""People walking by the Social Force Model (Helbing and Molnár 1995) and carts that roll.

Each person feels (1) attraction to the next point of an A* path to their goal, relaxing
to the preferred velocity in ``tau_s``; (2) exponential repulsion from every other person
and from the robot, weighted by the field of view (anisotropy ``lambda_``); (3) exponential
repulsion from walls and furniture footprints. The forces set the walking direction (toward the
velocity the model relaxes to, v0·e + tau·F, turning at most ``max_turn_rps``); the
speed stays the preferred speed (the paper's hospital people walk at a constant 0.6 m/s),
so people steer around each other instead of slowing down. A hard constraint keeps the
body centre at least ``body_radius_m`` from any wall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiper_cli.sim.route import Grid
from hiper_cli.sim.worlds import XY, CartSpec, Rect, WalkerSpec, World

__all__ = ["Carts", "Crowd", "SocialForceConfig"]


@dataclass(frozen=True)
class SocialForceConfig:
    """Social Force Model constants (Helbing and Molnár 1995; Helbing et al. 2000 for A, B)."""

    tau_s: float = 0.5
    agent_A_mps2: float = 2.1
    agent_B_m: float = 0.3
    agent_radius_m: float = 0.3
    wall_A_mps2: float = 10.0
    wall_B_m: float = 0.2
    lambda_: float = 0.35  # field-of-view anisotropy: behind counts this much
    body_radius_m: float = 0.25  # hard clearance from walls
    robot_radius_m: float = 0.35
    robot_A_mps2: float = 2.1  # people give way to the robot like to another person
    robot_B_m: float = 0.3
    replan_s: float = 1.0  # re-plan the path when its next point is out of sight, this often
    goal_tolerance_m: float = 0.5
    max_turn_rps: float = 3.0  # people turn their walking direction at most this fast
    dt_s: float = 0.05  # integration step


def _nearest_on_rect(p: NDArray[np.float64], r: Rect) -> NDArray[np.float64]:
    return np.array([min(max(p[0], r[0]), r[2]), min(max(p[1], r[1]), r[3])])


class Crowd:
    """The people of a world; ``step`` advances them, ``positions``/``velocities`` read them."""

    def __init__(self, world: World, seed: int, config: SocialForceConfig | None = None) -> None:
        self.cfg = config or SocialForceConfig()
        self.world = world
        self.specs: list[WalkerSpec] = list(world.walkers)
        self.rng = np.random.default_rng(seed + 7919)
        self.grid = Grid(world, self.cfg.body_radius_m + 0.05, 0.1)
        n = len(self.specs)
        self.pos = np.array([s.start_xy for s in self.specs], dtype=np.float64).reshape(n, 2)
        self.pos = np.array([self.grid.nearest_free(tuple(p)) for p in self.pos]).reshape(n, 2)
        self.vel = np.zeros((n, 2))
        self.heading = np.zeros(n)
        self.walked_m = np.zeros(n)
        self.goal_index = [s.start_goal for s in self.specs]
        self.pause_until = np.zeros(n)
        self.next_check = np.zeros(n)
        self.paths: list[list[XY]] = [[] for _ in self.specs]
        self.t_s = 0.0
        for i in range(n):
            self._new_path(i)
            if self.paths[i]:
                d = np.asarray(self.paths[i][0]) - self.pos[i]
                self.heading[i] = math.atan2(d[1], d[0])
                self.vel[i] = self.specs[i].speed_mps * np.array(
                    [math.cos(self.heading[i]), math.sin(self.heading[i])]
                )

    def _new_path(self, i: int) -> None:
        spec = self.specs[i]
        goal = spec.goals[self.goal_index[i] % len(spec.goals)] if spec.goals else self._random_goal()
        self.paths[i] = self.grid.astar(tuple(self.pos[i]), goal)[1:]

    def _random_goal(self) -> XY:
        areas = self.world.walkable
        weights = np.array([(r[2] - r[0]) * (r[3] - r[1]) for r in areas])
        for _ in range(100):
            r = areas[int(self.rng.choice(len(areas), p=weights / weights.sum()))]
            p = (float(self.rng.uniform(r[0], r[2])), float(self.rng.uniform(r[1], r[3])))
            if self.grid.is_free(p):
                return p
        return self.grid.nearest_free(p)

    def step(
        self, dt_s: float, robot_xy: XY | None = None, extra_obstacles: list[Rect] | None = None
    ) -> None:
        """Advance everyone by ``dt_s`` (in sub-steps of ``config.dt_s``)."""
        steps = max(1, math.ceil(dt_s / self.cfg.dt_s - 1e-9))
        for _ in range(steps):
            self._substep(dt_s / steps, robot_xy, extra_obstacles or [])

    def _substep(self, h: float, robot_xy: XY | None, extra: list[Rect]) -> None:
        cfg = self.cfg
        self.t_s += h
        n = len(self.specs)
        obstacles = [*self.world.obstacles, *extra]
        new_vel = np.zeros_like(self.vel)
        for i, spec in enumerate(self.specs):
            if self.t_s < self.pause_until[i]:
                continue
            path = self._waypoints(i, spec)
            if not path:
                continue
            to_goal = np.asarray(path[0]) - self.pos[i]
            e = to_goal / max(np.linalg.norm(to_goal), 1e-9)
            force = self._social_force(i, e, robot_xy, obstacles)
            # The velocity the model relaxes to: preferred velocity plus tau times the social forces.
            v = spec.speed_mps * e + cfg.tau_s * force
            want = math.atan2(v[1], v[0]) if np.linalg.norm(v) > 1e-9 else math.atan2(e[1], e[0])
            turn = (want - self.heading[i] + math.pi) % (2 * math.pi) - math.pi
            limit = cfg.max_turn_rps * h
            direction = self.heading[i] + max(-limit, min(limit, turn))
            new_vel[i] = spec.speed_mps * np.array([math.cos(direction), math.sin(direction)])
        for i in range(n):
            moved = self._move(self.pos[i], new_vel[i] * h)
            self.walked_m[i] += float(np.linalg.norm(moved - self.pos[i]))
            self.pos[i] = moved
            self.vel[i] = new_vel[i]
            if np.linalg.norm(new_vel[i]) > 1e-6:
                self.heading[i] = math.atan2(new_vel[i][1], new_vel[i][0])

    def _waypoints(self, i: int, spec: WalkerSpec) -> list[XY]:
        """Person ``i``'s remaining path: reached waypoints dropped, replanned when blocked, a new
        path (or a pause, for a wanderer) when done; empty while the person stands."""
        cfg = self.cfg
        path = self.paths[i]
        while path and math.dist(tuple(self.pos[i]), path[0]) < cfg.goal_tolerance_m:
            path.pop(0)
        if path and self.t_s >= self.next_check[i]:
            self.next_check[i] = self.t_s + cfg.replan_s
            if not self.grid.line_free(tuple(self.pos[i]), path[0]):
                self.paths[i] = path = self.grid.astar(tuple(self.pos[i]), path[-1])[1:]
        if path:
            return path
        if spec.goals:
            self.goal_index[i] += 1
        else:
            self.pause_until[i] = self.t_s + float(self.rng.uniform(*spec.pause_s))
        self._new_path(i)
        return self.paths[i] if spec.goals else []

    def _social_force(
        self, i: int, e: NDArray[np.float64], robot_xy: XY | None, obstacles: list[Rect]
    ) -> NDArray[np.float64]:
        """The repulsive forces on person ``i`` (walking along ``e``): other people, the robot,
        walls and obstacles (Helbing's social force model, anisotropic by ``lambda_``)."""
        cfg = self.cfg
        force = np.zeros(2)
        others = [self.pos[j] for j in range(len(self.specs)) if j != i]
        params = [(cfg.agent_radius_m * 2, cfg.agent_A_mps2, cfg.agent_B_m)] * len(others)
        if robot_xy is not None:
            others.append(np.asarray(robot_xy))
            params.append((cfg.agent_radius_m + cfg.robot_radius_m, cfg.robot_A_mps2, cfg.robot_B_m))
        for q, (r_ab, A, B) in zip(others, params, strict=True):
            d_vec = self.pos[i] - q
            d = float(np.linalg.norm(d_vec))
            if d > 3.0 or d < 1e-9:
                continue
            n_ab = d_vec / d
            cos_phi = float(-n_ab @ e)
            w = cfg.lambda_ + (1 - cfg.lambda_) * (1 + cos_phi) / 2
            force += w * A * math.exp((r_ab - d) / B) * n_ab
        for r in obstacles:
            near = _nearest_on_rect(self.pos[i], r)
            d_vec = self.pos[i] - near
            d = float(np.linalg.norm(d_vec))
            if d > 1.5 or d < 1e-9:
                continue
            force += cfg.wall_A_mps2 * math.exp((cfg.body_radius_m - d) / cfg.wall_B_m) * d_vec / d
        return force

    def _move(self, p: NDArray[np.float64], step: NDArray[np.float64]) -> NDArray[np.float64]:
        """Move by ``step`` but keep ``body_radius_m`` clear of every wall.

        A step into a wall turns along the wall at the same length (people slide past walls
        without slowing down); what still breaks the clearance is pushed back out.
        """
        length = float(np.linalg.norm(step))
        q = p + step
        for r in self.world.walls:
            near = _nearest_on_rect(q, r)
            d_vec = q - near
            d = float(np.linalg.norm(d_vec))
            if d >= self.cfg.body_radius_m:
                continue
            n_vec = p - _nearest_on_rect(p, r)
            n_len = float(np.linalg.norm(n_vec))
            if n_len > 1e-9 and length > 1e-9:
                n = n_vec / n_len
                tangent = step - min(float(step @ n), 0.0) * n
                t_len = float(np.linalg.norm(tangent))
                if t_len > 1e-9:
                    step = tangent / t_len * length
                    q = p + step
                    near = _nearest_on_rect(q, r)
                    d_vec = q - near
                    d = float(np.linalg.norm(d_vec))
            if d < self.cfg.body_radius_m:
                if d < 1e-9:
                    return p.copy()
                q = near + d_vec / d * self.cfg.body_radius_m
        return q

    def stride(self, i: int) -> float:
        """Leg swing in [-1, 1] from the distance walked (a 1.4 m gait cycle)."""
        if self.t_s < self.pause_until[i]:
            return 0.0
        return math.sin(2 * math.pi * self.walked_m[i] / 1.4)


class Carts:
    """Carts that wait ``wait_s`` then roll to their next position, back and forth."""

    def __init__(self, specs: list[CartSpec], seed: int) -> None:
        self.specs = specs
        self.rng = np.random.default_rng(seed + 104729)
        self.pos = np.array([s.positions[0] for s in specs], dtype=np.float64).reshape(len(specs), 2)
        self.vel = np.zeros_like(self.pos)
        self.target = [1 % len(s.positions) for s in specs]
        self.direction = [1] * len(specs)
        self.wait_until = [float(self.rng.uniform(*s.wait_s)) for s in specs]
        self.t_s = 0.0

    def step(self, dt_s: float, moving: bool) -> None:
        self.t_s += dt_s
        for i, spec in enumerate(self.specs):
            self.vel[i] = 0.0
            if not moving:
                self.wait_until[i] = max(
                    self.wait_until[i], self.t_s + float(self.rng.uniform(0, spec.wait_s[0]))
                )
                continue
            if self.t_s < self.wait_until[i]:
                continue
            goal = np.asarray(spec.positions[self.target[i]])
            d = goal - self.pos[i]
            dist = float(np.linalg.norm(d))
            stepped = min(dist, spec.speed_mps * dt_s)
            if dist > 1e-9:
                self.pos[i] += d / dist * stepped
                self.vel[i] = d / dist * spec.speed_mps if stepped < dist else d / dist * stepped / dt_s
            if dist - stepped < 1e-6:
                n = len(spec.positions)
                k = self.target[i] + self.direction[i]
                if not 0 <= k < n:
                    self.direction[i] *= -1
                    k = self.target[i] + self.direction[i]
                self.target[i] = k % n
                self.wait_until[i] = self.t_s + float(self.rng.uniform(*spec.wait_s))

    def footprints(self) -> list[Rect]:
        out = []
        for i, spec in enumerate(self.specs):
            lo, hi = spec.mesh.bounds()
            out.append(
                (
                    self.pos[i, 0] + lo[0],
                    self.pos[i, 1] + lo[1],
                    self.pos[i, 0] + hi[0],
                    self.pos[i, 1] + hi[1],
                )
            )
        return out
