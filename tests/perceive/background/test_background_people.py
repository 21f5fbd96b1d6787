"""People are never background: a person, or a group standing side by side, against a wall or
in the open, is narrow, not flat and lower than a wall, and stands a body's depth before the
wall behind it (``fronts.py``); no background instance lies on them."""

import numpy as np
from shapely.geometry import Point

from hiper_cli.perceive.background import BackgroundStage
from hiper_cli.perceive.background.contour import PlaneFrame, to_polygon
from hiper_cli.perceive.runner import run_stages
from tests._bg_scenes import SceneBox, box_room, look_at, make_frame


def _person(x, y):
    """Legs, torso and head as boxes, 0.5 m wide, 0.3 m deep, 1.75 m tall, facing -y."""
    return [
        SceneBox(43, "person", (x - 0.2, y, 0.0), (x + 0.2, y + 0.25, 0.9)),
        SceneBox(43, "person", (x - 0.25, y, 0.9), (x + 0.25, y + 0.3, 1.5)),
        SceneBox(43, "person", (x - 0.1, y + 0.05, 1.5), (x + 0.1, y + 0.25, 1.75)),
    ]


def _on_people(boxes, people):
    poses = []
    for x, y in ((3.0, 0.6), (2.0, 0.8), (4.0, 1.0), (3.0, 1.5), (2.5, 2.0)):
        for tx in (2.0, 3.0, 4.0):
            dist = float(np.hypot(tx - x, 4.8 - y))
            poses.append(look_at((x, y, 1.2), (tx, 4.8, 1.2 - dist * np.tan(np.radians(15.0)))))
    frames = [make_frame(boxes, T, pose_id=i, noise_m=0.001) for i, T in enumerate(poses)]
    world, _ = run_stages(frames, [BackgroundStage()])
    return [inst.class_name for inst in world.background.values() if _mostly_on(inst, people)]


def _mostly_on(inst, boxes):
    """Whether most of a grid of points on the instance's outline lie within 0.1 m of ``boxes``."""
    frame = PlaneFrame(np.asarray(inst.data["plane_map"]))
    poly = to_polygon(np.asarray(inst.data["contour_map"]), frame)
    lo, hi = np.array(poly.bounds[:2]), np.array(poly.bounds[2:])
    grid = [(u, v) for u in np.linspace(lo[0], hi[0], 9) for v in np.linspace(lo[1], hi[1], 9)
            if poly.contains(Point(u, v))]
    if not grid:
        return False
    points = frame.to_3d(np.array(grid))
    near = [min(float(np.linalg.norm(np.maximum(np.maximum(np.array(b.lo) - p, 0.0), p - np.array(b.hi))))
                for b in boxes) <= 0.1 for p in points]
    return float(np.mean(near)) > 0.5

def test_three_people_standing_against_a_wall_are_not_background():
    people = _person(2.5, 4.68) + _person(3.0, 4.68) + _person(3.5, 4.68)
    assert _on_people([*box_room(), *people], people) == []


def test_three_people_standing_in_the_room_are_not_background():
    people = _person(2.5, 3.2) + _person(3.0, 3.2) + _person(3.5, 3.2)
    assert _on_people([*box_room(), *people], people) == []
