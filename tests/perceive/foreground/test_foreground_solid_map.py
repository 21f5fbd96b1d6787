"""Geometry-only objects (``solid_map.py``): a solid thing on the floor that no detector names is
one ``unknown`` part, fused over views; what passes, what is flat, what floats and what an
instance already holds is not.

The scenes are rendered here: boxes' surfaces sampled every 1.5 cm, projected into a small
depth image with a z-buffer, seen by a camera that drives past them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground.solid_map import KEYFRAME_S, MAX_EXTENT_M, SolidMap, is_solid
from hiper_cli.types import CameraIntrinsics, Frame

CAM = CameraIntrinsics(width=160, height=120, fx=100.0, fy=100.0, cx=79.5, cy=59.5)
FLOOR = Box3D(np.array([0.0, 0.0, -0.05]), np.array([20.0, 20.0, 0.1]))


def box_surface(lo: list[float], hi: list[float], step_m: float = 0.015) -> NDArray[np.float64]:
    """Points on the faces of the axis-aligned box ``lo``..``hi`` (map frame)."""
    lo_a, hi_a = np.array(lo, float), np.array(hi, float)
    faces = []
    for axis in range(3):
        a, b = [k for k in range(3) if k != axis]
        ua = np.arange(lo_a[a], hi_a[a] + 1e-9, step_m)
        ub = np.arange(lo_a[b], hi_a[b] + 1e-9, step_m)
        grid_a, grid_b = np.meshgrid(ua, ub, indexing="ij")
        for level in (lo_a[axis], hi_a[axis]):
            face = np.zeros((grid_a.size, 3))
            face[:, a], face[:, b], face[:, axis] = grid_a.ravel(), grid_b.ravel(), level
            faces.append(face)
    return np.concatenate(faces)


def pose_looking_at(eye: list[float], target: list[float]) -> NDArray[np.float64]:
    """T_map_cam of an optical camera (z forward, y down) at ``eye`` looking at ``target``."""
    eye_a, tgt = np.array(eye, float), np.array(target, float)
    z = (tgt - eye_a) / np.linalg.norm(tgt - eye_a)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, :3] = np.stack([x, y, z], axis=1)
    T[:3, 3] = eye_a
    return T


def render(points_map: list[NDArray[np.float64]], T_map_cam: NDArray[np.float64], stamp_s: float
           ) -> tuple[Frame, list[NDArray[np.float64]]]:
    """The depth image of ``points_map`` (one array per thing) and, per thing, its visible points."""
    T_cam_map = np.linalg.inv(T_map_cam)
    depth = np.full((CAM.height, CAM.width), np.inf)
    owner = np.full((CAM.height, CAM.width), -1)
    projected = []
    for pts in points_map:
        p = pts @ T_cam_map[:3, :3].T + T_cam_map[:3, 3]
        p = p[p[:, 2] > 0.1]
        u = np.floor(CAM.fx * p[:, 0] / p[:, 2] + CAM.cx).astype(int)
        v = np.floor(CAM.fy * p[:, 1] / p[:, 2] + CAM.cy).astype(int)
        inside = (u >= 0) & (u < CAM.width) & (v >= 0) & (v < CAM.height)
        projected.append((v[inside], u[inside], p[inside, 2]))
        np.minimum.at(depth, (v[inside], u[inside]), p[inside, 2])
    for k, (v, u, z) in enumerate(projected):  # the nearest thing owns the pixel
        nearest = z <= depth[v, u]
        owner[v[nearest], u[nearest]] = k
    depth[~np.isfinite(depth)] = 0.0
    vs, us = np.nonzero(owner >= 0)
    zs = depth[vs, us]
    cam_pts = np.stack([(us + 0.5 - CAM.cx) / CAM.fx * zs, (vs + 0.5 - CAM.cy) / CAM.fy * zs, zs], axis=1)
    map_pts = cam_pts @ T_map_cam[:3, :3].T + T_map_cam[:3, 3]
    seen = [map_pts[owner[vs, us] == k] for k in range(len(points_map))]
    frame = Frame(stamp_s=stamp_s, rgb=np.zeros((CAM.height, CAM.width, 3), np.uint8),
                  depth_m=depth.astype(np.float32), camera=CAM, T_map_cam=T_map_cam, pose_id=0)
    return frame, seen


def drive_past(things: list[NDArray[np.float64]], unnamed: list[int], movers: dict[int, NDArray[np.float64]]
               | None = None, views: int = 8) -> SolidMap:
    """A camera 1.2 m high driving along y = -3 past the things at the origin, a keyframe per
    view; ``unnamed``: the things whose blobs no detector names; ``movers``: thing -> its
    velocity (m per view)."""
    solid = SolidMap()
    for k in range(views):
        x = -2.0 + 4.0 * k / (views - 1)
        shifted = [pts + (movers or {}).get(i, np.zeros(3)) * k for i, pts in enumerate(things)]
        frame, seen = render(shifted, pose_looking_at([x, -3.0, 1.2], [0.0, 0.0, 0.4]), 10.0 + k * KEYFRAME_S)
        assert solid.due(frame.stamp_s)
        solid.add(frame, [(f"obs-{k}-{i}", seen[i]) for i in unnamed if len(seen[i])])
    return solid


def floor_points() -> NDArray[np.float64]:
    return box_surface([-4.0, -2.0, -0.02], [4.0, 4.0, -0.01], step_m=0.03)[:, :]


def test_a_box_on_the_floor_seen_from_several_sides_is_one_part_with_its_box() -> None:
    crate = box_surface([-0.4, -0.3, 0.0], [0.4, 0.3, 0.7])
    parts = drive_past([crate, floor_points()], unnamed=[0]).parts(0.0, [FLOOR], [], [])
    assert len(parts) == 1
    lo, hi = parts[0].box.aabb()
    assert np.allclose(lo, [-0.4, -0.3, 0.0], atol=0.15) and np.allclose(hi[2], 0.7, atol=0.15)
    assert hi[0] > 0.25 and hi[1] > 0.15  # faces seen from the side and from the front
    assert parts[0].seen_share > 0.9 and parts[0].observation_uuids


def test_a_thing_that_moves_on_is_seen_through_and_is_no_part() -> None:
    crate = box_surface([-0.2, -0.2, 0.0], [0.2, 0.2, 1.6])
    solid = drive_past([crate, floor_points()], unnamed=[0], movers={0: np.array([0.0, 0.5, 0.0])})
    assert solid.parts(0.0, [FLOOR], [], []) == []


def test_a_flat_piece_of_a_surface_is_no_part() -> None:
    board = box_surface([-0.6, 0.0, 0.0], [0.6, 0.0, 1.0])  # a sheet facing the camera
    assert drive_past([board, floor_points()], unnamed=[0]).parts(0.0, [FLOOR], [], []) == []
    frame, seen = render([board], pose_looking_at([0.0, -3.0, 1.2], [0.0, 0.0, 0.4]), 0.0)
    cam = (seen[0] - frame.T_map_cam[:3, 3]) @ frame.T_map_cam[:3, :3]
    assert not is_solid(cam)


def test_a_thing_afloat_is_no_part_and_one_an_instance_holds_is_that_instance() -> None:
    lamp = box_surface([-0.3, -0.3, 1.0], [0.3, 0.3, 1.5])
    assert drive_past([lamp, floor_points()], unnamed=[0]).parts(0.0, [FLOOR], [], []) == []
    crate = box_surface([-0.4, -0.3, 0.0], [0.4, 0.3, 0.7])
    solid = drive_past([crate, floor_points()], unnamed=[0])
    chair = Box3D(np.array([0.0, 0.0, 0.35]), np.array([0.8, 0.6, 0.7]))
    assert solid.parts(0.0, [FLOOR], [chair], []) == []
    wall = Box3D(np.array([0.0, 0.0, 0.35]), np.array([1.0, 1.0, 1.0]))
    assert solid.parts(0.0, [FLOOR], [], [wall]) == []  # the background's


def test_keyframes_come_every_half_second() -> None:
    solid = SolidMap()
    frame, _ = render([floor_points()], pose_looking_at([0.0, -3.0, 1.2], [0.0, 0.0, 0.4]), 5.0)
    assert solid.due(5.0)
    solid.add(frame, [])
    assert not solid.due(5.0 + KEYFRAME_S / 2) and solid.due(5.0 + KEYFRAME_S)


def test_a_part_from_the_floor_to_the_ceiling_is_the_buildings() -> None:
    column = box_surface([-0.3, -0.3, 0.0], [0.3, 0.3, 2.5])
    solid = drive_past([column, floor_points()], unnamed=[0])
    assert len(solid.parts(0.0, [FLOOR], [], [])) == 1  # no ceiling mapped: a tall thing
    assert solid.parts(0.0, [FLOOR], [], [], ceiling_z_m=2.6) == []
    assert len(solid.parts(0.0, [FLOOR], [], [], ceiling_z_m=4.0)) == 1


def test_a_camera_that_turns_or_moves_makes_a_keyframe_before_the_half_second() -> None:
    solid = SolidMap()
    start = pose_looking_at([0.0, -3.0, 1.2], [0.0, 0.0, 0.4])
    frame, _ = render([floor_points()], start, 5.0)
    solid.add(frame, [])
    soon = 5.0 + KEYFRAME_S / 5
    assert not solid.due(soon, start) and not solid.due(soon)
    assert not solid.due(soon, pose_looking_at([0.0, -3.0, 1.2], [0.3, 0.0, 0.4]))  # 5°: the same view
    assert solid.due(soon, pose_looking_at([0.0, -3.0, 1.2], [0.8, 0.0, 0.4]))  # 15°: a new one
    moved = start.copy()
    moved[:3, 3] += [0.5, 0.0, 0.0]
    assert solid.due(soon, moved)


def test_two_things_side_by_side_are_two_parts_when_the_views_held_them_apart() -> None:
    # a crate and a lower bin 2 cm apart, seen from the front: their voxels touch
    crate = box_surface([-0.8, -0.3, 0.0], [-0.01, 0.3, 0.7])
    bin_ = box_surface([0.01, -0.3, 0.0], [0.8, 0.3, 0.5])
    for apart in (True, False):  # the segmenter's blobs part them in every view, or never
        solid = SolidMap()
        for k in range(8):
            x = -0.2 + 0.4 * k / 7
            pose = pose_looking_at([x, -3.0, 1.2], [x, 0.0, 0.4])
            frame, seen = render([crate, bin_, floor_points()], pose, 10.0 + k * KEYFRAME_S)
            one = [(f"obs-{k}", np.concatenate(seen[:2]))]
            solid.add(frame, [(f"obs-{k}-{i}", seen[i]) for i in (0, 1)] if apart else one)
        parts = solid.parts(0.0, [FLOOR], [], [])
        if apart:  # the crate's box and the bin's, side by side
            (left, right) = sorted(parts, key=lambda p: float(p.box.center_m[0]))
            assert left.box.aabb()[1][0] < 0.15 and right.box.aabb()[0][0] > -0.15
            assert left.box.aabb()[1][2] > right.box.aabb()[1][2] + 0.1
        else:
            assert len(parts) == 1


def test_a_run_longer_than_one_object_is_parted_in_compact_pieces() -> None:
    # an L-shaped row of shelves along two walls: 6 m one way, 3 m the other
    row = [box_surface([-3.0, 0.0, 0.0], [3.0, 0.4, 1.8]), box_surface([2.6, -3.0, 0.0], [3.0, 0.0, 1.8])]
    solid = SolidMap()
    for k in range(12):
        eye = [-2.5 + 5.0 * k / 11, -2.5, 1.2]
        frame, seen = render([*row, floor_points()], pose_looking_at(eye, [eye[0] + 1.0, 0.0, 0.9]),
                             10.0 + k * KEYFRAME_S)
        solid.add(frame, [(f"obs-{k}", np.concatenate(seen[:2]))])
    parts = solid.parts(0.0, [FLOOR], [], [])
    assert len(parts) >= 2
    for part in parts:
        lo, hi = part.box.aabb()
        assert max(hi[:2] - lo[:2]) <= MAX_EXTENT_M + 0.1
        assert min(hi[:2] - lo[:2]) < 1.0  # a piece of one leg, not the corner's square


def test_a_table_against_an_unmapped_wall_is_kept_and_the_wall_is_not() -> None:
    # the wall's columns reach the ceiling: the building's; the table before it stands on the floor
    wall = box_surface([-1.5, 0.4, 0.0], [1.5, 0.5, 2.5])
    table = box_surface([-0.6, -0.2, 0.0], [0.6, 0.4, 0.75])
    solid = drive_past([wall, table, floor_points()], unnamed=[0, 1])
    (part,) = solid.parts(0.0, [FLOOR], [], [], ceiling_z_m=2.6)
    lo, hi = part.box.aabb()
    assert hi[2] < 1.0 and lo[1] > -0.35 and hi[1] < 0.55  # the table's box
    (joined,) = solid.parts(0.0, [FLOOR], [], [])  # no ceiling mapped: the table joined to the wall
    assert joined.box.aabb()[1][2] > 2.0


def test_a_thing_beyond_the_supports_footprint_stands_on_nothing() -> None:
    crate = box_surface([-0.4, -0.3, 0.0], [0.4, 0.3, 0.7])
    solid = drive_past([crate, floor_points()], unnamed=[0])
    elsewhere = Box3D(np.array([5.0, 5.0, -0.05]), np.array([2.0, 2.0, 0.1]))  # a floor piece away from it
    assert solid.parts(0.0, [elsewhere], [], []) == []
    assert len(solid.parts(0.0, [FLOOR, elsewhere], [], [])) == 1


def test_stray_points_under_the_floor_are_left_out_and_the_floor_at_range_is_no_part() -> None:
    # stray points 0.3 m under the floor (depth noise at range) in the crate's blobs: the floor
    # hides them from every view, so nothing sees through them; they are no part of the crate
    crate = box_surface([-0.4, -0.3, 0.0], [0.4, 0.3, 0.7])
    stray = box_surface([-0.1, -0.1, -0.32], [0.1, 0.1, -0.28], step_m=0.05)
    solid = SolidMap()
    for k in range(8):
        frame, seen = render([crate, floor_points()], pose_looking_at([-2.0 + 4.0 * k / 7, -3.0, 1.2],
                                                                     [0.0, 0.0, 0.4]), 10.0 + k * KEYFRAME_S)
        solid.add(frame, [(f"obs-{k}", np.concatenate([seen[0], stray]))])
    (part,) = solid.parts(0.0, [FLOOR], [], [])
    lo, hi = part.box.aabb()
    assert -0.1 - 1e-9 <= lo[2] <= 0.05 and hi[2] > 0.6  # the crate from its base, not 0.3 m under it
    # a mapped floor 0.2 m above the crate's base: a fifth of it lies under that floor, as the
    # floor seen at range does (its noise spreads below it as above): no part
    higher = Box3D(np.array([0.0, 0.0, 0.15]), np.array([20.0, 20.0, 0.1]))
    assert solid.parts(0.2, [higher], [], []) == []


def two_bodies_and_a_bridge(seen_bridge: int) -> SolidMap:
    """A crate and a taller bin 0.3 m apart on the floor, and a bar of stray points across the
    gap between them that the first ``seen_bridge`` views show and the others miss (no return
    there: a dropout at the depth edges); one blob holds all three in every view."""
    crate = box_surface([-0.9, -0.3, 0.0], [-0.15, 0.3, 0.7])
    bin_ = box_surface([0.15, -0.3, 0.0], [0.9, 0.3, 1.0])
    bridge = box_surface([-0.2, -0.32, 0.3], [0.2, -0.3, 0.35], step_m=0.01)
    solid = SolidMap()
    for k in range(8):
        pose = pose_looking_at([-1.0 + 2.0 * k / 7, -3.0, 1.2], [0.0, 0.0, 0.4])
        frame, seen = render([crate, bin_, bridge, floor_points()], pose, 10.0 + k * KEYFRAME_S)
        if k >= seen_bridge:
            bare, _ = render([crate, bin_, floor_points()], pose, frame.stamp_s)
            dropout = np.abs(bare.depth_m - frame.depth_m) > 1e-6
            frame = replace(frame, depth_m=np.where(dropout, 0.0, frame.depth_m).astype(np.float32))
            seen[2] = seen[2][:0]
        solid.add(frame, [(f"obs-{k}", np.concatenate(seen[:3]))])
    return solid


def test_two_bodies_joined_only_by_stray_points_seen_in_few_views_are_two_parts() -> None:
    parts = two_bodies_and_a_bridge(seen_bridge=2).parts(0.0, [FLOOR], [], [])
    (left, right) = sorted(parts, key=lambda p: float(p.box.center_m[0]))
    assert left.box.aabb()[1][0] <= 0.25 and right.box.aabb()[0][0] >= -0.25  # the bar joins one side
    assert right.box.aabb()[1][2] > left.box.aabb()[1][2] + 0.15
    # a bar every view shows is a real joint: one part
    assert len(two_bodies_and_a_bridge(seen_bridge=8).parts(0.0, [FLOOR], [], [])) == 1


def test_what_one_keyframe_found_and_the_next_saw_through_is_not_confirmed() -> None:
    crate = box_surface([-0.4, -0.3, 0.0], [0.4, 0.3, 0.7])
    solid = drive_past([crate, floor_points()], unnamed=[0])
    assert solid.confirmed(Box3D(np.array([0.0, 0.0, 0.35]), np.array([0.8, 0.6, 0.7])))
    assert solid.confirmed(Box3D(np.array([3.0, 3.0, 0.35]), np.array([0.4, 0.4, 0.4])))  # nothing there
    once = SolidMap()  # a passer-by's piece: one keyframe found it, the next sees through it
    pose = pose_looking_at([0.0, -3.0, 1.2], [0.0, 0.0, 0.4])
    for k, things in enumerate(([crate, floor_points()], [floor_points()])):
        frame, seen = render(things, pose, 10.0 + k * KEYFRAME_S)
        once.add(frame, [(f"obs-{k}", seen[0])] if k == 0 else [])
    assert not once.confirmed(Box3D(np.array([0.0, 0.0, 0.35]), np.array([0.8, 0.6, 0.7])))
    unseen = SolidMap()  # found once and never looked at again: nothing refutes it
    frame, seen = render([crate, floor_points()], pose, 10.0)
    unseen.add(frame, [("obs-0", seen[0])])
    assert unseen.confirmed(Box3D(np.array([0.0, 0.0, 0.35]), np.array([0.8, 0.6, 0.7])))


def test_the_noise_in_front_of_a_mapped_wall_joins_no_table_to_it(monkeypatch) -> None:
    # a wall mapped with its face at y = 0.46 (its box 2 cm thick); seen from afar the face puts
    # points 6-8 cm in front of it, up to 2.1 m: not the ceiling (2.6 m), so no building column
    from hiper_cli.perceive.foreground import geometry_only

    wall_box = Box3D(np.array([0.0, 0.47, 1.3]), np.array([3.0, 0.02, 2.6]))
    face = box_surface([-1.5, 0.46, 0.0], [1.5, 0.48, 2.6])
    noise = box_surface([-1.2, 0.38, 0.0], [1.2, 0.40, 2.1], step_m=0.03)
    table = box_surface([-0.6, -0.35, 0.0], [0.6, 0.3, 0.75])
    solid = drive_past([face, noise, table, floor_points()], unnamed=[0, 1, 2])
    (part,) = solid.parts(0.0, [FLOOR], [], [geometry_only.grown_box(wall_box, tall=True)], ceiling_z_m=2.6)
    assert part.box.aabb()[1][2] < 1.0  # the table's height
    monkeypatch.setattr(geometry_only, "WALL_NOISE_M", 0.0)  # the wall's box alone: the sheet joins the table
    (joined,) = solid.parts(0.0, [FLOOR], [], [geometry_only.grown_box(wall_box, tall=True)], ceiling_z_m=2.6)
    assert joined.box.aabb()[1][2] > 2.0
