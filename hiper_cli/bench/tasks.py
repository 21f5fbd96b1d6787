"""The fetch-and-carry tasks (paper VII-A) as a discrete-time simulation against the sim's truth.

One episode per (world, run, configuration) runs T1-T4 in turn with the simulator's people
walking (``hiper_cli.sim.people.Crowd``, warmed up for a seeded time, the same for every
configuration of a run):

- T1 find a person: search from the idle position (``search``: inverse heatmap of the
  configuration's person tracks in C1-C2, coverage in C3-C5); it ends at the first detection,
  a success when it is a true person, a failure when it is one of the configuration's false
  "person" instances (a picture, the TV);
- T2 find a bottle: the same from where T1 ended, guided by the bottle heatmap of the
  configuration's bottle instances (in C1 only those within the learned altitude);
- T3 grasp: approach the detected bottle, plan on the workspace and grasp; a success when the
  configuration's estimate of that bottle (its bottle instance nearest the bottle) is within
  ``grasp_tolerance_m`` of the truth; the time adds planning proportional to the workspace's
  unexplained points;
- T4 carry back to the idle position, the people heatmap as path cost in C1-C2.

A detection needs the target in the camera's frustum and range (``nav.NavMap.sees``) and
succeeds with the truth detector's hit rate; it is reported after the configuration's measured
detection latency. A task fails beyond ``time_limit_s`` (the paper: 600 s).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.bench.configs import BenchConfig
from hiper_cli.bench.nav import XY, NavMap
from hiper_cli.bench.perception import Knowledge
from hiper_cli.bench.robot import Look, Robot
from hiper_cli.bench.search import coverage_goals, heat_goals, heatmap_of, points_as_rows
from hiper_cli.errors import ConfigError
from hiper_cli.sim.people import Crowd, SocialForceConfig
from hiper_cli.sim.route import Grid

__all__ = ["TASKS", "TaskConfig", "TaskResult", "grasp_error", "run_episode"]

TASKS = ("T1", "T2", "T3", "T4")
GRASP_SEARCH_M = 0.5  # the bottle instance a grasp aims at lies this near the bottle found


@dataclass(frozen=True)
class TaskConfig:
    time_limit_s: float = 600.0
    detect_prob: float = 0.9  # per look: the truth detector's miss rate is 0.1
    person_height_m: float = 1.75
    bottle_height_m: float = 0.25
    warmup_s: tuple[float, float] = (30.0, 120.0)
    grasp_s: float = 8.0
    plan_s: float = 1.0  # planning a grasp on an empty workspace
    plan_s_per_kpoint: float = 0.5  # ... plus this per 1000 points the workspace leaves unexplained
    grasp_tolerance_m: float = 0.10
    workspace_m: float = 1.5


@dataclass
class TaskResult:
    world: str
    config: str
    run: int
    seed: int
    task: str
    success: bool
    time_s: float
    reason: str
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


class _PeopleGrid(Grid):
    """The people's planning grid; a person pushed into a pocket with no path waits there
    (``hiper sim`` never meets this at its step; the tasks step the people at 0.1 s)."""

    def astar(self, a: XY, b: XY) -> list[XY]:
        try:
            return super().astar(a, b)
        except ConfigError:
            return [a]


def _search(robot: Robot, nav: NavMap, goals: list[XY], tour: list[XY], look: Look) -> bool:
    if look(robot):
        return True
    plan = list(goals)
    while not robot.timed_out:
        if not plan:
            plan = list(tour)
        path, _ = nav.astar(robot.xy, plan.pop(0))
        if robot.drive(path, look) or robot.turn(2 * math.pi, look):
            return True
    return False


def _finder(
    nav: NavMap, rng: np.random.Generator, targets: Any, false_xy: list[tuple[float, float]],
    range_m: float, p: float, found: dict[str, Any],
) -> Look:
    def look(robot: Robot) -> bool:
        for q in targets():
            xy = (float(q[0]), float(q[1]))
            if nav.sees(robot.xy, robot.yaw, xy, range_m) and rng.random() < p:
                found.update(kind="true", xy=xy)
                return True
        for xy in false_xy:
            if nav.sees(robot.xy, robot.yaw, xy, range_m) and rng.random() < p:
                found.update(kind="false", xy=xy)
                return True
        return False

    return look


def _search_task(
    name: str, cfg: BenchConfig, robot: Robot, nav: NavMap, look: Look, found: dict[str, Any],
    goals: list[XY], latency_s: float, base: dict[str, Any],
) -> TaskResult:
    tour = coverage_goals(nav, robot.xy)
    hit = _search(robot, nav, goals if cfg.heatmaps else [], tour, look)
    t = robot.t_s + latency_s
    if not hit:
        return TaskResult(**base, task=name, success=False, time_s=t, reason="time limit")
    ok = found["kind"] == "true" and t <= robot.deadline_s
    reason = "found" if ok else ("false positive" if found["kind"] == "false" else "time limit")
    extra = {"driven_m": round(robot.driven_m, 2), "heat_goals": len(goals) if cfg.heatmaps else 0}
    return TaskResult(**base, task=name, success=ok, time_s=t, reason=reason, extra=extra)


def grasp_error(
    knowledge: Knowledge, bottles_m: NDArray[np.float64], target: XY, localisation_m: float | None
) -> tuple[float | None, str]:
    """(error, where it comes from) of the estimate T3 grasps at for the true bottle at
    ``target`` (``bottles_m``: the true centres). The estimate is the configuration's bottle
    instance nearest the bottle (within ``GRASP_SEARCH_M``), and its error is its distance to
    that bottle, whatever truth its observations voted for; without one, the median error of
    the configuration's bottle instances, else its localisation of classified observations."""
    truth_k = int(np.argmin(np.hypot(bottles_m[:, 0] - target[0], bottles_m[:, 1] - target[1])))
    near = np.hypot(knowledge.bottles[:, 0] - target[0], knowledge.bottles[:, 1] - target[1])
    if near.size and near.min() < GRASP_SEARCH_M:
        estimate = knowledge.bottles[int(np.argmin(near))]
        return float(np.linalg.norm(estimate - bottles_m[truth_k])), "this bottle's instance"
    errors = [e[2] for e in knowledge.bottle_errors_m]
    if errors:
        return float(np.median(errors)), "median over the bottle instances"
    return localisation_m, "classified observations"


def run_episode(
    nav: NavMap, knowledge: Knowledge, cfg: BenchConfig, run: int, seed: int,
    task_config: TaskConfig | None = None, localisation_m: float | None = None,
) -> list[TaskResult]:
    """T1-T4 for one configuration and run (see the module doc); ``seed`` fixes the people's
    start, the warm-up and the detector's luck, the same for every configuration."""
    tc = task_config or TaskConfig()
    world = nav.world
    rng = np.random.default_rng(seed)
    crowd = Crowd(world, seed, SocialForceConfig(dt_s=0.1))
    crowd.grid.__class__ = _PeopleGrid
    crowd.step(float(rng.uniform(*tc.warmup_s)))
    idle = nav.idle_position()
    base: dict[str, Any] = {"world": world.name, "config": cfg.name, "run": run, "seed": seed}
    needs_depth = cfg.foreground
    results: list[TaskResult] = []

    people_hm = heatmap_of(nav, "person", knowledge.person_rows, knowledge.person_track,
                           knowledge.person_speed_mps)
    # T1
    robot = Robot(nav, crowd, idle, 0.0, tc.time_limit_s)
    found: dict[str, Any] = {}
    look = _finder(nav, rng, lambda: crowd.pos, knowledge.false_people_xy,
                   nav.detect_range_m(tc.person_height_m, needs_depth), tc.detect_prob, found)
    goals = heat_goals(nav, people_hm) if people_hm is not None else []
    results.append(_search_task("T1", cfg, robot, nav, look, found, goals, knowledge.detect_latency_s, base))

    # T2
    bottles = np.array([o.box.center_m for o in world.objects if o.class_name == "bottle"]).reshape(-1, 3)
    robot = Robot(nav, crowd, robot.xy, robot.yaw, tc.time_limit_s)
    found = {}
    look = _finder(nav, rng, lambda: bottles, knowledge.false_bottles_xy,
                   nav.detect_range_m(tc.bottle_height_m, needs_depth), tc.detect_prob, found)
    rows, track = points_as_rows(knowledge.bottles)
    bottle_hm = heatmap_of(nav, "bottle", rows, track, 0.0)
    goals = heat_goals(nav, bottle_hm) if bottle_hm is not None else []
    t2 = _search_task("T2", cfg, robot, nav, look, found, goals, knowledge.detect_latency_s, base)
    t2.extra["learned_altitude_m"] = knowledge.bottle_altitude_m
    results.append(t2)

    # T3: grasp the bottle found (or, after a failed T2, the nearest true one)
    if t2.success:
        target = found["xy"]
    else:
        k = int(np.argmin(np.hypot(bottles[:, 0] - robot.xy[0], bottles[:, 1] - robot.xy[1])))
        target = (float(bottles[k, 0]), float(bottles[k, 1]))
    robot = Robot(nav, crowd, robot.xy, robot.yaw, tc.time_limit_s)
    path, _ = nav.astar(robot.xy, nav.viewpoint(target, 1.0))
    robot.drive(path)
    robot.turn_to(target)
    error, source = grasp_error(knowledge, bottles, target, localisation_m)
    plan_s = tc.plan_s + tc.plan_s_per_kpoint * knowledge.workspace_points / 1000.0
    t3_time = robot.t_s + plan_s + tc.grasp_s
    support = any(x0 <= target[0] <= x1 and y0 <= target[1] <= y1 for x0, y0, x1, y1 in knowledge.tables)
    movers = int(np.sum(np.hypot(crowd.pos[:, 0] - target[0], crowd.pos[:, 1] - target[1]) < tc.workspace_m))
    ok = error is not None and error <= tc.grasp_tolerance_m and t3_time <= tc.time_limit_s
    results.append(TaskResult(
        **base, task="T3", success=bool(ok), time_s=t3_time,
        reason="grasped" if ok else ("no estimate" if error is None else "missed the bottle"),
        extra={"error_m": error, "error_source": source, "plan_s": plan_s, "support_known": support,
               "movers_near": movers, "movers_tracked": cfg.foreground, "after_failed_t2": not t2.success},
    ))

    # T4: carry back, the people heatmap as path cost in C1-C2
    robot = Robot(nav, crowd, robot.xy, robot.yaw, tc.time_limit_s)
    heat = people_hm.heat if (cfg.heatmaps and people_hm is not None) else None
    path, length = nav.astar(robot.xy, idle, heat)
    robot.drive(path)
    done = math.dist(robot.xy, path[-1]) < 1e-6
    results.append(TaskResult(
        **base, task="T4", success=done, time_s=robot.t_s, reason="arrived" if done else "time limit",
        extra={"path_m": round(length, 2), "waited_s": robot.waited_s,
               "close_encounters": robot.close_encounters, "heat_cost": heat is not None},
    ))
    return results
