"""People (Social Force Model) and the robot route: speeds, walls, coverage; no rendering."""

import math

import numpy as np
import pytest

from hiper_cli.sim import make_world
from hiper_cli.sim.people import Carts, Crowd
from hiper_cli.sim.route import RouteConfig, plan_route


def _dist_to_rect(p, r):
    dx = max(r[0] - p[0], 0.0, p[0] - r[2])
    dy = max(r[1] - p[1], 0.0, p[1] - r[3])
    return math.hypot(dx, dy)


def _walk(world_name, seed, seconds, dt=0.1):
    world = make_world(world_name, seed)
    route = plan_route(world, seconds + 1)
    crowd = Crowd(world, seed)
    carts = Carts(world.carts, seed)
    positions, stamps = [crowd.pos.copy()], [0.0]
    for k in range(1, int(seconds / dt) + 1):
        x, y, _ = route.state_at(k * dt)
        crowd.step(dt, (x, y), carts.footprints())
        carts.step(dt, True)
        positions.append(crowd.pos.copy())
        stamps.append(k * dt)
    return world, np.array(stamps), np.array(positions)  # (T,), (T, N, 2)


def test_hospital_corridor_people_walk_at_0_6_mps():
    world, stamps, pos = _walk("hospital", 2, 75.0)
    assert pos.shape[1] == 5
    speed = np.linalg.norm(np.diff(pos, axis=0), axis=2) / np.diff(stamps)[:, None]
    assert np.all(np.abs(speed - 0.6) <= 0.05), f"speeds from {speed.min():.3f} to {speed.max():.3f} m/s"
    # all five stay in corridor A (south of the rooms); corridor B (the parallel one) stays empty
    assert pos[:, :, 1].max() < world.bounds[3] / 2 - 1.5
    # they cover the corridor: each walks more than 40 m in 75 s
    assert np.all(np.linalg.norm(np.diff(pos, axis=0), axis=2).sum(axis=0) > 40.0)


def test_truth_tracks_speed_matches_the_walk(tmp_path):
    from hiper_cli.sim import RenderConfig, SimConfig, load_truth, simulate

    cfg = SimConfig(rate_hz=10.0, mapping_s=0.5, render=RenderConfig(width=32, height=24))
    simulate("hospital", 6.0, 1, tmp_path / "h", cfg)
    truth = load_truth(tmp_path / "h")
    people = [i for i, inst in truth.instances.items() if inst.class_name == "person"]
    assert len(people) == 5
    for pid in people:
        rows = truth.tracks[pid]
        fd = np.linalg.norm(np.diff(rows[:, 1:3], axis=0), axis=1) / np.diff(rows[:, 0])
        assert np.all(np.abs(fd - 0.6) <= 0.05)
        assert np.allclose(np.linalg.norm(rows[:, 4:6], axis=1), 0.6, atol=0.05)


@pytest.mark.parametrize("world_name", ["house", "hospital", "office"])
def test_nobody_walks_through_a_wall(world_name):
    world, _, pos = _walk(world_name, 4, 60.0)
    n = pos.shape[1]
    assert n >= 1
    for i in range(n):
        track = pos[:, i, :]
        min_d = min(_dist_to_rect(p, r) for p in track for r in world.walls)
        assert min_d >= 0.2, f"{world_name} person {i} came {min_d:.2f} m to a wall"
        steps = np.linalg.norm(np.diff(track, axis=0), axis=1)
        assert steps.max() < 0.2  # no jumps: with 0.2 m clearance a step cannot cross a wall
    if world_name != "hospital":  # random walkers must actually go places (through doorways)
        assert np.ptp(pos[:, 0, 0]) + np.ptp(pos[:, 0, 1]) > 3.0


@pytest.mark.parametrize("world_name", ["house", "hospital", "office"])
def test_robot_route_is_collision_free_and_within_speed(world_name):
    world = make_world(world_name, 3)
    cfg = RouteConfig()
    route = plan_route(world, 240.0, cfg)
    t = np.arange(0.0, 240.0, 0.05)
    xy = np.array([route.state_at(s)[:2] for s in t])
    speed = np.linalg.norm(np.diff(xy, axis=0), axis=1) / 0.05
    assert speed.max() <= 0.9 + 1e-6
    clearance = min(_dist_to_rect(p, r) for p in xy[::4] for r in world.obstacles)
    assert clearance >= cfg.robot_radius_m - 0.08  # grid resolution 0.1 m
    T = route.pose_at(10.0)
    assert T[2, 3] == pytest.approx(1.2)
    forward = T[:3, 2]  # optical z axis
    assert -0.35 < forward[2] < -0.05, "camera looks slightly down"
    # it covers the world: the route visits every waypoint within the first loop
    visited = [min(math.dist(p, q) for q in xy) for p in world.waypoints]
    assert max(visited) < 0.4


def test_house_has_the_false_positive_trap_and_furniture():
    world = make_world("house", 0)
    classes = [o.class_name for o in world.objects]
    for name in ("table", "chair", "couch", "shelf", "bed", "bottle", "tv", "picture", "door"):
        assert name in classes, name
    assert classes.count("chair") >= 4 and classes.count("picture") >= 2
    assert len(world.walkers) == 1 and not world.walkers[0].goals
    rooms = [o for o in world.objects if o.class_name == "wall"]
    assert len(rooms) >= 6
