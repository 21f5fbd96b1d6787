"""Objects hung on the walls (``wall_relief.py``): a picture 4 cm proud of a mapped wall, seen from
a camera passing by with depth noise, is one part with its box; a bare wall, a picture seen in one
view only, the back of a thing standing against the wall and a picture an instance stands beside
are none."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiper_cli.model import Box3D
from hiper_cli.perceive.foreground.wall_relief import WallRelief
from hiper_cli.types import CameraIntrinsics, Frame
from tests.perceive.foreground.test_foreground_solid_map import pose_looking_at

CAM = CameraIntrinsics(width=320, height=240, fx=262.5, fy=262.5, cx=159.5, cy=119.5)
WALL_Y = 3.0  # the wall's face, seen from y < 3
WALL = Box3D(np.array([0.0, WALL_Y + 0.01, 1.4]), np.array([6.0, 0.02, 2.8]))
PICTURE = ([-0.3, 1.1], [0.3, 1.9])  # x, z from its lower to its upper corner
DEPTH_M = 0.04  # how far it stands proud of the wall


def view(x_m: float, stamp_s: float, picture: tuple[list[float], list[float]] | None = PICTURE,
         seed: int = 0) -> Frame:
    """The depth image of the wall (and ``picture`` on it) from (``x_m``, 0.5, 1.4), looking at
    the wall's middle, with depth noise of 0.0015 · depth² m."""
    T = pose_looking_at([x_m, 0.5, 1.4], [0.0, WALL_Y, 1.4])
    v, u = np.mgrid[0:CAM.height, 0:CAM.width]
    rays = np.stack([(u + 0.5 - CAM.cx) / CAM.fx, (v + 0.5 - CAM.cy) / CAM.fy, np.ones(u.shape)], axis=-1)
    rays_map = rays @ T[:3, :3].T
    eye = T[:3, 3]

    def hit(y_m: float) -> NDArray[np.float64]:
        scale = (y_m - eye[1]) / rays_map[..., 1]
        return np.asarray(scale, dtype=np.float64)  # the camera depth: rays have z = 1

    depth = hit(WALL_Y)
    if picture is not None:
        near = hit(WALL_Y - DEPTH_M)
        at = eye + rays_map * near[..., None]
        (x0, z0), (x1, z1) = picture
        on = (at[..., 0] >= x0) & (at[..., 0] <= x1) & (at[..., 2] >= z0) & (at[..., 2] <= z1)
        depth = np.where(on, near, depth)
    depth = depth + np.random.default_rng(seed).normal(0.0, 1.0, depth.shape) * 0.0015 * depth**2
    return Frame(stamp_s=stamp_s, rgb=np.zeros((CAM.height, CAM.width, 3), np.uint8),
                 depth_m=depth.astype(np.float32), camera=CAM, T_map_cam=T, pose_id=0)


def pass_by(picture: tuple[list[float], list[float]] | None = PICTURE, views: int = 6) -> WallRelief:
    relief = WallRelief()
    for k in range(views):
        relief.add(view(-1.5 + 3.0 * k / max(views - 1, 1), 0.5 * k, picture, seed=k), [WALL])
    return relief


def test_a_picture_proud_of_a_wall_is_one_part_with_its_box() -> None:
    (part,) = pass_by().parts(0.0, [])
    lo, hi = part.box.aabb()
    np.testing.assert_allclose(lo[[0, 2]], [-0.3, 1.1], atol=0.11)
    np.testing.assert_allclose(hi[[0, 2]], [0.3, 1.9], atol=0.11)
    assert abs(part.box.center_m[1] - WALL_Y) < 0.1 and part.seen_share > 0.6
    assert (part.first_seen_s, part.last_seen_s) == (0.0, 2.5)


def test_a_bare_wall_and_a_picture_seen_once_are_none() -> None:
    assert pass_by(picture=None).parts(0.0, []) == []
    assert pass_by(views=1).parts(0.0, []) == []


def test_the_back_of_a_thing_standing_against_the_wall_is_none() -> None:
    low = ([-0.3, 0.0], [0.3, 0.8])  # from the floor: the map of solid things keeps what stands
    assert pass_by(picture=low).parts(0.0, []) == []


def test_a_picture_an_instance_stands_beside_at_its_height_is_that_instance() -> None:
    shelf = Box3D(np.array([0.0, WALL_Y - 0.4, 1.0]), np.array([1.0, 0.6, 2.0]))  # up to 2 m
    assert pass_by().parts(0.0, [shelf]) == []
    table = Box3D(np.array([0.0, WALL_Y - 0.5, 0.37]), np.array([1.0, 0.8, 0.75]))  # below it
    assert len(pass_by().parts(0.0, [table])) == 1


def test_a_long_narrow_strip_proud_of_the_wall_is_an_edge_of_the_building() -> None:
    strip = ([-0.1, 0.6], [0.1, 2.1])  # 0.2 m wide, 1.5 m high: a door frame, a corner
    assert pass_by(picture=strip).parts(0.0, []) == []


def test_views_folded_into_the_counts_as_they_come_give_the_same_part(monkeypatch) -> None:
    from hiper_cli.perceive.foreground import wall_relief

    (whole,) = pass_by().parts(0.0, [])
    monkeypatch.setattr(wall_relief, "FOLD_EVERY", 2)  # fold every second wall view
    (folded,) = pass_by().parts(0.0, [])
    np.testing.assert_allclose(folded.box.aabb(), whole.box.aabb())
    assert (folded.first_seen_s, folded.last_seen_s, folded.seen_share, folded.surface_m) == (
        whole.first_seen_s, whole.last_seen_s, whole.seen_share, whole.surface_m)
