"""Wall bounds (``bounds.py``, ``not_walls.py``): a wall reaches the ceiling and the floor and
ends at a corner; a furniture front ends in the room."""

import numpy as np

from hiper_cli.perceive.background import BackgroundConfig, BackgroundStage
from hiper_cli.perceive.background.bounds import edge_evidence, is_open
from hiper_cli.perceive.background.planes import extract_planes
from hiper_cli.perceive.runner import run_stages
from tests._bg_scenes import SceneBox, box_room, look_at, make_frame, with_dropouts

# a wardrobe 1.2 m wide, 2.0 m tall, 0.6 m deep, 1.4 m in front of the wall at y = 5
WARDROBE = SceneBox(40, "cabinet", (2.4, 3.0, 0.0), (3.6, 3.6, 2.0))
FROM_NEAR = look_at((3.0, 1.0, 1.2), (3.0, 5.0, 0.9))  # its top above the image: only its sides tell
# from its front left: the camera sees its left side face run 0.6 m back, then the room behind
FROM_LEFT = look_at((1.2, 1.0, 1.2), (2.4, 3.0, 0.7))


def _walls_facing_minus_y(world):
    return [i for i in world.background.values() if i.class_name == "wall" and i.data["plane_map"][1] < -0.9]


def _run(boxes, poses, **options):
    frames = [make_frame(boxes, T, pose_id=i, noise_m=0.001) for i, T in enumerate(poses)]
    world, _ = run_stages(frames, [BackgroundStage(**options)])
    return world


def test_a_wardrobe_front_is_not_a_wall_but_the_wall_behind_it_is():
    """Seen from the front only, open at both its sides, the front stayed no wall before; a
    wall between two doorways looks the same (it was deleted in corridors), so both sides
    open no longer end a wall: the view that sees its side face a furniture depth long does
    (``fronts.deep_sides``)."""
    world = _run([*box_room(), WARDROBE], [FROM_NEAR, FROM_LEFT])
    offsets = sorted({round(abs(w.data["plane_map"][3]), 1) for w in _walls_facing_minus_y(world)})
    assert offsets == [5.0]


def test_without_the_bounds_the_wardrobe_front_is_a_wall():
    world = _run([*box_room(), WARDROBE], [FROM_NEAR], wall_bounds=False)
    offsets = sorted({round(abs(w.data["plane_map"][3]), 1) for w in _walls_facing_minus_y(world)})
    assert offsets == [3.0, 5.0]


def test_edges_of_a_room_wall_are_closed_and_of_the_front_open_at_its_sides():
    frame = make_frame([*box_room(), WARDROBE], FROM_NEAR)
    cfg = BackgroundConfig()
    grid, segments = extract_planes(frame.depth_m, frame.camera, cfg)
    by_offset = {}
    for seg in segments:
        normal = frame.T_map_cam[:3, :3] @ seg.plane_cam[:3]
        if abs(normal[2]) < 0.2 and seg.n_points > 100:
            centre = frame.T_map_cam[:3, :3] @ grid.points_cam[seg.mask].mean(axis=0) + frame.T_map_cam[:3, 3]
            by_offset[round(float(centre[1]), 1)] = edge_evidence(grid, frame.camera, seg, cfg)
    front, wall = by_offset[3.0], by_offset[5.0]
    # open at both its sides, as a wall between two doorways is: that alone ends no wall
    assert front["left"] == "open" and front["right"] == "open" and not is_open(front)
    assert not is_open(wall)
    assert is_open({**front, "left": "front"})


def test_a_wardrobe_seen_near_after_far_stays_out_of_the_walls():
    far = look_at((3.0, 0.3, 1.2), (3.0, 5.0, 1.4))  # from 2.7 m: the camera sees past its top
    world = _run([*box_room(), WARDROBE], [far, FROM_NEAR])
    assert all(abs(abs(w.data["plane_map"][3]) - 3.0) > 0.2 for w in _walls_facing_minus_y(world))
    offsets = sorted(abs(w.data["plane_map"][3]) for w in _walls_facing_minus_y(world))
    assert np.isclose(offsets[-1], 5.0, atol=0.05)


def test_a_far_wall_over_shelves_is_as_tall_as_the_view_shows_it():
    # from 4.8 m, pitched 15 degrees down, the camera sees the wall at y = 6 up to 2.0 m only;
    # bookshelves 1.06 m tall stand at it: 0.94 m of wall shows, less than wall_min_height_m
    shelves = SceneBox(41, "shelf", (0.0, 5.75, 0.0), (6.0, 6.0, 1.06))
    pose = look_at((3.0, 1.2, 1.2), (3.0, 6.0, 1.2 - 4.8 * np.tan(np.radians(15.0))))
    far = [*box_room(size=(6.0, 6.0, 3.0)), shelves]

    def far_walls(**options):
        world = _run(far, [pose], **options)
        return [w for w in _walls_facing_minus_y(world) if abs(abs(w.data["plane_map"][3]) - 6.0) < 0.05]

    every_view = {"wall_view_max_noise_m": 0.0}
    assert len(far_walls(**every_view)) == 1
    assert far_walls(wall_view_bounded=False, **every_view) == []
    assert far_walls() == []  # seen from too far to tell from a front (``wall_range.py``)


def _wall_edges(frame, offset_m):
    """The edges of the largest vertical plane at y = ``offset_m``."""
    cfg = BackgroundConfig()
    grid, segments = extract_planes(frame.depth_m, frame.camera, cfg)
    for seg in sorted(segments, key=lambda s: -s.n_points):
        normal = frame.T_map_cam[:3, :3] @ seg.plane_cam[:3]
        if abs(normal[2]) < 0.2:
            centre = frame.T_map_cam[:3, :3] @ grid.points_cam[seg.mask].mean(axis=0) + frame.T_map_cam[:3, 3]
            if abs(centre[1] - offset_m) < 0.1:
                return edge_evidence(grid, frame.camera, seg, cfg)
    raise AssertionError(f"no vertical plane at y = {offset_m}")


def test_dropouts_on_a_wall_and_its_floor_do_not_open_it():
    """A tenth of the returns lost in patches (the degraded bookstore's wall 1.9 m away lost
    a quarter of its probes below its foot): a probe line that sees the floor go on at the
    wall's foot, or nearer things, is no view of the room beyond (with any missing probe
    opening its line, this wall was open at its foot); a line with no return at all still is."""
    pose = look_at((3.0, 2.0, 1.2), (3.0, 5.0, 0.6))
    frame = with_dropouts(make_frame(box_room(), pose), 0.1)
    edges = _wall_edges(frame, 5.0)
    assert edges["top"] != "open" and edges["bottom"] != "open"
    assert not is_open(edges)
    # the wardrobe seen from 2.7 m, patchy too: past its top the wall behind is farther
    far = look_at((3.0, 0.3, 1.2), (3.0, 5.0, 1.4))
    front = _wall_edges(with_dropouts(make_frame([*box_room(), WARDROBE], far), 0.1), 3.0)
    assert front["top"] == "open"
