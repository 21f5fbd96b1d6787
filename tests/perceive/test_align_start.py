"""Refining a session's alignment on its first metres: a start that sees the floor and one wall
fixes the directions they constrain and leaves the one along the wall as the whole log had it
(no slide); a start rich enough fixes all six; the start's cloud stops after its first metres."""

from __future__ import annotations

import numpy as np

from hiper_cli.perceive.align_start import refine_at_start
from hiper_cli.session_align import START_MOTION_M, start_cloud
from hiper_cli.types import CameraIntrinsics, Frame


def _plane(origin, u, v, size_u, size_v, step, rng):
    a, b = np.meshgrid(np.arange(0, size_u, step), np.arange(0, size_v, step))
    pts = (np.asarray(origin, float) + a.reshape(-1, 1) * np.asarray(u, float)
           + b.reshape(-1, 1) * np.asarray(v, float))
    return pts + rng.normal(0, 0.003, pts.shape)


def _corner(rng, walls=1):
    """A floor 6 x 6 m and ``walls`` walls (x = 0, then y = 0), 2.5 m high."""
    parts = [_plane((0, 0, 0), (1, 0, 0), (0, 1, 0), 6, 6, 0.05, rng),
             _plane((0, 0, 0), (0, 1, 0), (0, 0, 1), 6, 2.5, 0.05, rng)]
    if walls > 1:
        parts.append(_plane((0, 0, 0), (1, 0, 0), (0, 0, 1), 6, 2.5, 0.05, rng))
        parts.append(_plane((1.5, 1.5, 0), (1, 0, 0), (0, 0, 1), 0.8, 0.9, 0.05, rng))  # a cabinet's side
        parts.append(_plane((1.5, 1.5, 0), (0, 1, 0), (0, 0, 1), 0.6, 0.9, 0.05, rng))
    return np.concatenate(parts)


def _turn(deg, t):
    a = np.radians(deg)
    T = np.eye(4)
    T[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
    T[:3, 3] = t
    return T


def _tilt(deg_x, T):
    a = np.radians(deg_x)
    R = np.eye(4)
    R[1:3, 1:3] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
    return R @ T


def test_a_floor_and_one_wall_fix_five_directions_and_leave_the_one_along_the_wall():
    rng = np.random.default_rng(1)
    place = _corner(rng)
    T_map_log = _turn(30.0, (1.0, -2.0, 0.0))
    start = (place[::2] - T_map_log[:3, 3]) @ T_map_log[:3, :3]  # the map's points in the log's frame
    # the whole log's fit: 4 cm off from the wall, 6 cm along it, 2 cm high, tilted and turned 0.5 deg
    T0 = _tilt(0.5, _turn(0.5, (0.04, 0.06, 0.02))) @ T_map_log
    fit = refine_at_start(start, place[1::2], T0)
    assert fit.constrained == 5
    err = fit.T_map_log @ np.linalg.inv(T_map_log)  # map-frame error of the refined transform
    origin = np.array([0.0, 3.0, 1.0])  # a point on the wall, in the map
    moved = err[:3, :3] @ origin + err[:3, 3] - origin
    assert abs(moved[0]) < 0.005 and abs(moved[2]) < 0.005  # off the wall, height: fixed
    assert abs(moved[1] - 0.06) < 0.02  # along the wall: as the whole log had it, no slide
    assert np.degrees(np.arccos(np.clip((np.trace(err[:3, :3]) - 1) / 2, -1, 1))) < 0.1


def test_a_start_that_sees_two_walls_and_furniture_fixes_all_six():
    rng = np.random.default_rng(2)
    place = _corner(rng, walls=2)
    T_map_log = _turn(-25.0, (2.0, 0.5, 0.0))
    start = (place[::2] - T_map_log[:3, 3]) @ T_map_log[:3, :3]
    T0 = _tilt(-0.4, _turn(0.8, (-0.05, 0.07, 0.03))) @ T_map_log
    fit = refine_at_start(start, place[1::2], T0)
    assert fit.constrained == 6
    err = fit.T_map_log @ np.linalg.inv(T_map_log)
    assert np.linalg.norm(err[:3, 3]) < 0.01
    assert np.degrees(np.arccos(np.clip((np.trace(err[:3, :3]) - 1) / 2, -1, 1))) < 0.1
    assert fit.inliers > 0.6  # corners and edges give no normal


class _Walk:
    """A log whose camera moves 0.1 m a frame along x, each frame seeing a wall 2 m ahead."""

    def __init__(self, frames: int) -> None:
        self.camera = CameraIntrinsics(width=32, height=24, fx=30.0, fy=30.0, cx=16.0, cy=12.0)
        self.poses = [_turn(0.0, (0.1 * k, 0.0, 0.0)) for k in range(frames)]
        self.read: list[int] = []

    def __len__(self) -> int:
        return len(self.poses)

    def info(self):
        return type("Info", (), {"T_map_cam": np.stack(self.poses)})()

    def read_frame(self, k: int) -> Frame:
        self.read.append(k)
        return Frame(stamp_s=0.2 * k, rgb=np.zeros((24, 32, 3), np.uint8),
                     depth_m=np.full((24, 32), 2.0, np.float32), camera=self.camera, T_map_cam=self.poses[k],
                     pose_id=k)


def test_the_start_cloud_reads_only_the_first_metres():
    log = _Walk(200)  # 20 m of motion
    points = start_cloud(log)
    assert len(points) > 0
    assert max(log.read) * 0.1 <= START_MOTION_M + 1e-9
    assert max(log.read) * 0.1 > START_MOTION_M - 0.2


def test_a_later_session_adds_new_space_but_does_not_move_the_map():
    from hiper_cli.perceive.static_cloud import StaticCloud
    from hiper_cli.types import CameraIntrinsics, Frame

    w, h = 60, 40
    camera = CameraIntrinsics(width=w, height=h, fx=50.0, fy=50.0, cx=w / 2, cy=h / 2)
    earlier = np.array([[0.35, 0.25, 3.05]])  # the place as the first session saw it
    cloud = StaticCloud(earlier, voxel_m=0.1)
    depth = np.full((h, w), 3.09, dtype=np.float32)  # a later session sees that wall 4 cm deeper
    depth[:, : w // 2] = 0.0
    depth[0, 0] = 2.0  # and something new, nearer
    frame = Frame(stamp_s=0.0, rgb=np.zeros((h, w, 3), np.uint8), depth_m=depth, camera=camera,
                  T_map_cam=np.eye(4), pose_id=0)
    cloud.add_frame(frame)
    pts = cloud.points()
    stored = pts[np.all(np.floor(pts / 0.1) == np.floor(earlier / 0.1), axis=1)]
    assert np.allclose(stored, earlier)  # not pulled toward the later session
    assert len(pts) > 1  # new space is added
