"""The simulated robot of the tasks: drives A* paths and turns in place while the simulator's
people walk (``hiper_cli.sim.people.Crowd``, which also lets them give way to the robot).

Time advances in steps of ``dt_s``; after each step a ``look`` callback sees the robot's pose and
may end the motion (a detection). The robot waits while a person stands within
``stop_distance_m`` in front of it (±30°), at most ``max_wait_s`` at a time, like the sim route.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from hiper_cli.bench.nav import XY, NavMap
from hiper_cli.sim.people import Crowd

__all__ = ["Robot", "RobotConfig"]

Look = Callable[["Robot"], bool]


@dataclass(frozen=True)
class RobotConfig:
    dt_s: float = 0.25
    stop_distance_m: float = 1.0
    max_wait_s: float = 2.0
    close_m: float = 0.5  # a person this close counts as a close encounter (safety)


class Robot:
    """Pose, clock and the crowd around it; ``drive`` / ``turn`` return True when ``look`` fired."""

    def __init__(self, nav: NavMap, crowd: Crowd, xy: XY, yaw_rad: float, deadline_s: float,
                 config: RobotConfig | None = None) -> None:
        self.nav, self.crowd, self.xy, self.yaw = nav, crowd, xy, yaw_rad
        self.cfg = config or RobotConfig()
        self.t_s = 0.0
        self.deadline_s = deadline_s
        self.waited_s = 0.0
        self.close_encounters = 0
        self.driven_m = 0.0

    @property
    def timed_out(self) -> bool:
        return self.t_s >= self.deadline_s

    def _tick(self) -> None:
        self.t_s += self.cfg.dt_s
        self.crowd.step(self.cfg.dt_s, self.xy)
        if len(self.crowd.pos) and float(
            np.min(np.hypot(*(self.crowd.pos - np.asarray(self.xy)).T))
        ) < self.cfg.close_m:
            self.close_encounters += 1

    def _blocked(self) -> bool:
        for p in self.crowd.pos:
            d = math.dist(self.xy, (float(p[0]), float(p[1])))
            if d < self.cfg.stop_distance_m:
                bearing = math.atan2(p[1] - self.xy[1], p[0] - self.xy[0])
                if abs((bearing - self.yaw + math.pi) % (2 * math.pi) - math.pi) < math.radians(30):
                    return True
        return False

    def turn(self, angle_rad: float, look: Look | None = None) -> bool:
        """Turn in place by ``angle_rad`` (signed)."""
        rate = self.nav.cfg.turn_rate_rps
        steps = max(1, math.ceil(abs(angle_rad) / (rate * self.cfg.dt_s)))
        for _ in range(steps):
            if self.timed_out:
                return False
            self.yaw += angle_rad / steps
            self._tick()
            if look is not None and look(self):
                return True
        return False

    def turn_to(self, target: XY, look: Look | None = None) -> bool:
        want = math.atan2(target[1] - self.xy[1], target[0] - self.xy[0])
        return self.turn((want - self.yaw + math.pi) % (2 * math.pi) - math.pi, look)

    def drive(self, path: list[XY], look: Look | None = None) -> bool:
        """Follow ``path`` (turning toward each next point first) at the configured speed."""
        step_m = self.nav.cfg.speed_mps * self.cfg.dt_s
        for p in path[1:]:
            if self.turn_to(p, look):
                return True
            waited = 0.0
            while math.dist(self.xy, p) > 1e-6:
                if self.timed_out:
                    return False
                if self._blocked() and waited < self.cfg.max_wait_s:
                    waited += self.cfg.dt_s
                    self.waited_s += self.cfg.dt_s
                else:
                    waited = 0.0
                    d = math.dist(self.xy, p)
                    f = min(1.0, step_m / d)
                    self.xy = (self.xy[0] + (p[0] - self.xy[0]) * f, self.xy[1] + (p[1] - self.xy[1]) * f)
                    self.driven_m += min(step_m, d)
                self._tick()
                if look is not None and look(self):
                    return True
        return False
