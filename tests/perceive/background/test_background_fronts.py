"""Furniture fronts (``fronts.py``): a vertical plane that stands before a parallel surface a
furniture depth behind it, seen past one of its side edges, is not a wall."""

import numpy as np

from hiper_cli.perceive.background import BackgroundConfig, BackgroundStage
from hiper_cli.perceive.background.bounds import edge_evidence
from hiper_cli.perceive.background.fronts import front_sides, segment_labels
from hiper_cli.perceive.background.planes import extract_planes
from hiper_cli.perceive.runner import run_stages
from tests._bg_scenes import SceneBox, box_room, look_at, make_frame

ROOM = box_room(size=(6.0, 5.0, 2.6))  # walls' inner faces at x = 0, 6 and y = 0, 5


def _pitched(x, y, tx, ty):
    """A camera 1.2 m high at (x, y) looking at (tx, ty), 15 degrees down."""
    dist = float(np.hypot(tx - x, ty - y))
    return look_at((x, y, 1.2), (tx, ty, 1.2 - dist * np.tan(np.radians(15.0))))


def _run(boxes, poses, **options):
    frames = [make_frame(boxes, T, pose_id=i, noise_m=0.001) for i, T in enumerate(poses)]
    world, _ = run_stages(frames, [BackgroundStage(**options)])
    return world


def _walls_at_y(world, y, tol=0.1):
    """Wall instances facing -y whose plane lies at y (within tol)."""
    return [i for i in world.background.values() if i.class_name == "wall"
            and i.data["plane_map"][1] < -0.9 and abs(abs(i.data["plane_map"][3]) - y) < tol]


# the room's corner at x = 0, y = 5 holds a wardrobe 1.0 m wide, 0.6 m deep, 2.15 m tall: its
# top is above every view, its left side is the corner; only past its right side the camera
# sees the wall 0.6 m behind it
WARDROBE = SceneBox(40, "cabinet", (0.0, 4.4, 0.0), (1.0, 5.0, 2.15))
VIEWS = [_pitched(x, y, tx, 4.8) for x, y in ((1.5, 1.0), (2.5, 1.5), (1.0, 2.0)) for tx in (0.5, 2.0)]


def test_a_wardrobe_in_a_corner_is_not_a_wall():
    world = _run([*ROOM, WARDROBE], VIEWS)
    assert _walls_at_y(world, 4.4) == []
    assert len(_walls_at_y(world, 5.0)) >= 1  # the wall beside it


def test_without_the_front_test_the_wardrobe_in_a_corner_is_a_wall():
    world = _run([*ROOM, WARDROBE], VIEWS, wall_fronts=False)
    assert len(_walls_at_y(world, 4.4)) == 1


def test_a_row_of_bookshelves_against_a_wall_is_not_a_wall():
    # 4 m of shelves 2.14 m tall, 0.33 m deep, from the corner at x = 0; the wall shows beyond
    shelves = SceneBox(41, "shelf", (0.0, 4.67, 0.0), (4.0, 5.0, 2.14))
    poses = [_pitched(x, 1.0, tx, 4.8) for x in (2.5, 3.5) for tx in (2.0, 4.5)]
    assert _walls_at_y(_run([*ROOM, shelves], poses), 4.67) == []
    assert len(_walls_at_y(_run([*ROOM, shelves], poses, wall_fronts=False), 4.67)) == 1


def test_a_wall_beside_a_door_recessed_into_it_is_a_wall():
    # a door 0.1 m behind the wall's face, in a doorway 1.2 m wide: past the wall's edge the
    # door is parallel but only the wall's thickness back
    room = box_room(size=(6.0, 5.0, 2.6), thickness=0.2, door=(2.0, 3.2, 2.1))
    door = SceneBox(42, "door", (2.0, 5.1, 0.0), (3.2, 5.14, 2.1))
    poses = [_pitched(x, 2.5, 2.6, 4.8) for x in (1.5, 2.6, 3.7)]
    assert len(_walls_at_y(_run([*room, door], poses), 5.0)) >= 1


def test_a_wall_whose_end_turns_away_seen_face_on_is_a_wall():
    # an L of walls: one faces the camera at x = 6.95 from its end at y = 6.21 northwards, the
    # other runs from that corner east along y = 6.21; seen down a corridor from the west (no
    # return beyond 5 m), past the first wall's end its neighbour recedes, at one place across
    # and at many depths, a few samples wide: when it is no plane of the image, its samples
    # still lie on no surface parallel to the first wall
    floor = SceneBox(1, "floor", (0.0, 3.9, -0.1), (16.0, 10.6, 0.0))
    walls = [
        SceneBox(2, "wall", (6.95, 6.21, 0.0), (7.05, 10.6, 2.7)),
        SceneBox(3, "wall", (6.95, 6.21, 0.0), (16.0, 6.31, 2.7)),
        SceneBox(4, "wall", (0.0, 3.9, 0.0), (16.0, 4.0, 2.7)),
        SceneBox(5, "ceiling", (0.0, 3.9, 2.7), (16.0, 10.6, 2.8)),
    ]
    frame = make_frame([floor, *walls], look_at((2.55, 4.45, 1.2), (6.45, 5.15, 0.8)), noise_m=0.001)
    frame.depth_m[frame.depth_m > 5.0] = 0.0
    cfg = BackgroundConfig()
    grid, segments = extract_planes(frame.depth_m, frame.camera, cfg)
    normals = [frame.T_map_cam[:3, :3] @ s.plane_cam[:3] for s in segments]
    facing = [s for s, n in zip(segments, normals, strict=True) if n[0] < -0.9]
    others = [s for s, n in zip(segments, normals, strict=True) if abs(n[1]) < 0.9]  # not the receding one
    assert len(facing) == 1
    assert edge_evidence(grid, frame.camera, facing[0], cfg)["right"] == "open"
    assert front_sides(grid, frame.camera, facing[0], others, segment_labels(grid.shape, others), cfg) == []


def _corridor_with_doorways():
    """A corridor 2.6 m wide along x (0..14 m), its north wall at y = 2.6 (0.15 m thick) with
    three doorways 1.1 m wide, 2.1 m high, rooms beyond it."""
    boxes = [
        SceneBox(1, "floor", (-0.2, -0.2, -0.1), (14.2, 7.0, 0.0)),
        SceneBox(2, "ceiling", (-0.2, -0.2, 2.7), (14.2, 7.0, 2.8)),
        SceneBox(3, "wall", (-0.2, -0.2, 0.0), (14.2, 0.0, 2.7)),
        SceneBox(4, "wall", (-0.2, 6.7, 0.0), (14.2, 6.9, 2.7)),
        SceneBox(5, "wall", (-0.2, 0.0, 0.0), (0.0, 6.7, 2.7)),
        SceneBox(6, "wall", (14.0, 0.0, 0.0), (14.2, 6.7, 2.7)),
        SceneBox(7, "wall", (4.5, 2.6, 0.0), (4.6, 6.7, 2.7)),
        SceneBox(8, "wall", (8.5, 2.6, 0.0), (8.6, 6.7, 2.7)),
    ]
    x0 = 0.0
    for a, b in ((2.0, 3.1), (6.0, 7.1), (10.0, 11.1)):
        boxes.append(SceneBox(10, "wall", (x0, 2.6, 0.0), (a, 2.75, 2.7)))
        boxes.append(SceneBox(10, "wall", (a, 2.6, 2.1), (b, 2.75, 2.7)))
        x0 = b
    boxes.append(SceneBox(10, "wall", (x0, 2.6, 0.0), (14.0, 2.75, 2.7)))
    return boxes


def test_the_wall_pieces_between_doorways_of_a_corridor_stay_walls():
    # driving down the corridor the camera sees each piece between two doorways whole, open at
    # both its sides; past them only the doorways' jambs, the wall's thickness deep, and the
    # rooms beyond
    poses = [_pitched(x, 1.0, x + dx, 2.6) for x in np.arange(1.0, 13.0, 1.0) for dx in (-1.5, 0.0, 1.5)]
    world = _run(_corridor_with_doorways(), poses)
    pieces = sorted(
        (round(float(np.min(c[:, 0])), 1), round(float(np.max(c[:, 0])), 1))
        for c in (np.asarray(w.data["contour_map"]) for w in _walls_at_y(world, 2.6))
    )
    assert any(lo > 2.9 and hi < 6.3 for lo, hi in pieces)  # the piece from 3.1 to 6.0 m
    assert any(lo > 6.9 and hi < 10.3 for lo, hi in pieces)  # the piece from 7.1 to 10.0 m


def test_a_free_standing_bookcase_seen_along_its_side_is_not_a_wall():
    # 1.5 m wide, 0.7 m deep, 2.1 m tall, in the middle of the room; from its front left the
    # camera sees its side face run 0.7 m back from its front's edge, then the room behind
    case = SceneBox(43, "shelf", (2.0, 3.0, 0.0), (3.5, 3.7, 2.1))
    poses = [_pitched(0.8, 1.0, 2.6, 3.0), _pitched(1.0, 1.4, 2.8, 3.0)]
    assert _walls_at_y(_run([*ROOM, case], poses), 3.0) == []
