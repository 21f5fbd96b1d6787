"""Correcting a session's drift along its path: a log whose odometry turns and stretches away
from the truth as it moves lands on the map frame by frame once corrected per segment, where
its one start transform leaves it decimetres off; a window that shows nothing of the map keeps
the previous correction; a frame between two keyframes gets a transform between theirs."""

from __future__ import annotations

import numpy as np

from hiper_cli.perceive.align import BackgroundCloud
from hiper_cli.perceive.align_path import PathCorrection, correct_path, travelled_m
from hiper_cli.perceive.logs.trajectory import rotation_about
from hiper_cli.types import CameraIntrinsics, Frame

CAMERA = CameraIntrinsics(width=160, height=120, fx=110.0, fy=110.0, cx=80.0, cy=60.0)
ROOM = (np.array([-1.0, -3.0, 0.0]), np.array([15.0, 3.0, 2.5]))  # inside: floor, walls, ceiling
# furniture along the wall the camera faces (y = 3): boxes of other sizes at other places
BOXES = [(np.array([x, 2.2 - 0.3 * (i % 3), 0.0]),
          np.array([x + 0.5 + 0.2 * (i % 2), 3.0, 0.5 + 0.3 * (i % 4)]))
         for i, x in enumerate(np.arange(0.0, 14.0, 1.3))]


def _pose(x: float) -> np.ndarray:
    """The camera at (x, 0, 1.2) looking at the +y wall, tilted 25 deg down (optical frame)."""
    R_look = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])  # z forward = +y, y down = -z
    T = np.eye(4)
    T[:3, :3] = rotation_about(np.array([np.radians(-25.0), 0.0, 0.0])) @ R_look
    T[:3, 3] = (x, 0.0, 1.2)
    return T


def _depth(T_map_cam: np.ndarray) -> np.ndarray:
    """A ray-cast depth image (z along the optical axis) of the room and its boxes."""
    v, u = np.mgrid[0:CAMERA.height, 0:CAMERA.width]
    rays = np.stack([(u - CAMERA.cx) / CAMERA.fx, (v - CAMERA.cy) / CAMERA.fy, np.ones(u.shape)], -1)
    rays = rays.reshape(-1, 3)
    d = rays @ T_map_cam[:3, :3].T
    o = T_map_cam[:3, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (ROOM[0] - o) / d, (ROOM[1] - o) / d
        t = np.where(np.isnan(np.maximum(t1, t2)), np.inf, np.maximum(t1, t2)).min(axis=1)
        for lo, hi in BOXES:
            b1, b2 = (lo - o) / d, (hi - o) / d
            near, far = np.nanmax(np.minimum(b1, b2), axis=1), np.nanmin(np.maximum(b1, b2), axis=1)
            hit = (near <= far) & (near > 0)
            t = np.where(hit & (near < t), near, t)
    return t.reshape(CAMERA.height, CAMERA.width).astype(np.float32)  # z of a ray with z = 1 is t


def _drift(s_m: float) -> np.ndarray:
    """The odometry's error after ``s_m`` of motion: turned 0.2 deg/m about the start, 1 % longer."""
    D = np.eye(4)
    D[:3, :3] = rotation_about(np.array([0.0, 0.0, np.radians(0.2 * s_m)]))
    D[:3, 3] = (0.01 * s_m, 0.0, 0.0)
    return D


class _DriftingLog:
    """A log walking 14 m along the room, its poses (log frame) drifting by ``_drift``."""

    def __init__(self, T_log_map: np.ndarray, drifting: bool = True, step_m: float = 0.1) -> None:
        self.true = [_pose(x) for x in np.arange(0.0, 14.0, step_m)]
        self.poses = [T_log_map @ (_drift(i * step_m) if drifting else np.eye(4)) @ T
                      for i, T in enumerate(self.true)]

    def __len__(self) -> int:
        return len(self.poses)

    def info(self):
        return type("Info", (), {"T_map_cam": np.stack(self.poses)})()

    def read_frame(self, k: int) -> Frame:
        return Frame(stamp_s=0.2 * k, rgb=np.zeros((CAMERA.height, CAMERA.width, 3), np.uint8),
                     depth_m=_depth(self.true[k]), camera=CAMERA, T_map_cam=self.poses[k], pose_id=k)


def _place(log: _DriftingLog) -> np.ndarray:
    """The map: the room as a session on the true path saw it."""
    cloud = BackgroundCloud()
    for k in range(0, len(log), 3):
        frame = log.read_frame(k)
        cloud.add_frame(frame, log.true[k])
    return cloud.points()


def _turn(deg: float, t) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = rotation_about(np.array([0.0, 0.0, np.radians(deg)]))
    T[:3, 3] = t
    return T


def _errors(T_map_log_of, log: _DriftingLog) -> np.ndarray:
    """Per frame: how far a point 2 m in front of the camera lands from where it is (m)."""
    ahead = np.array([0.0, 0.0, 2.0, 1.0])
    return np.array([np.linalg.norm((T_map_log_of(k) @ log.poses[k] @ ahead - log.true[k] @ ahead)[:3])
                     for k in range(len(log))])


def test_a_drifting_session_corrected_per_segment_lands_on_the_map():
    T_map_log = _turn(30.0, (2.0, -1.0, 0.0))
    log = _DriftingLog(np.linalg.inv(T_map_log))
    place = _place(log)
    path = correct_path(log, place, T_map_log)
    before = _errors(lambda k: T_map_log, log)
    after = _errors(path.T_map_log, log)
    assert before[-1] > 0.15  # one transform, right at the start: off by decimetres at the end
    assert after.max() < 0.04  # per segment: on the map all along
    assert path.used >= len(path.keys_m) - 3
    assert path.largest[0] > 0.1  # the correction the note reports


def test_a_session_that_does_not_drift_is_left_where_its_start_put_it():
    T_map_log = _turn(-20.0, (1.0, 0.5, 0.0))
    log = _DriftingLog(np.linalg.inv(T_map_log), drifting=False)
    path = correct_path(log, _place(log), T_map_log)
    assert _errors(path.T_map_log, log).max() < 0.015


def test_a_window_that_shows_nothing_of_the_map_keeps_the_previous_correction():
    T_map_log = _turn(10.0, (0.0, 0.0, 0.0))
    log = _DriftingLog(np.linalg.inv(T_map_log))
    place = _place(log)
    far = place[place[:, 0] < 6.0]  # the map knows only the first 6 m of the room
    path = correct_path(log, far, T_map_log)
    beyond = path.keys_m > 9.0
    assert np.allclose(path.T_keys[beyond], path.T_keys[beyond][0])  # carried on, not fitted to nothing
    assert path.used < len(path.keys_m) - 1


def test_a_frame_between_two_keyframes_gets_a_transform_between_theirs():
    T0, T1 = _turn(0.0, (0.0, 0.0, 0.0)), _turn(2.0, (0.1, 0.0, 0.0))
    path = PathCorrection(travelled_m=np.array([0.0, 0.25, 0.5, 1.0, 3.0]), keys_m=np.array([0.0, 1.0]),
                          T_keys=np.stack([T0, T1]), used=1, largest=(0.1, 2.0))
    mid = path.T_map_log(2)
    assert np.allclose(mid[:3, 3], (0.05, 0.0, 0.0))
    assert np.isclose(np.degrees(np.arctan2(mid[1, 0], mid[0, 0])), 1.0)
    assert np.allclose(path.T_map_log(0), T0) and np.allclose(path.T_map_log(4), T1)


def test_motion_counts_metres_and_turns():
    poses = np.stack([_turn(0.0, (0, 0, 0)), _turn(0.0, (1.0, 0, 0)), _turn(90.0, (1.0, 0, 0))])
    assert np.allclose(travelled_m(poses), [0.0, 1.0, 1.0 + 0.5 * np.pi / 2])


def test_a_frame_that_cannot_be_read_is_passed_over():
    from hiper_cli.errors import LogError

    class _Broken(_DriftingLog):
        def read_frame(self, k: int) -> Frame:
            if k % 7 == 3:
                raise LogError(f"frame {k}: depth image truncated")
            return super().read_frame(k)

    T_map_log = _turn(15.0, (0.5, 0.5, 0.0))
    log = _Broken(np.linalg.inv(T_map_log))
    path = correct_path(log, _place(_DriftingLog(np.linalg.inv(T_map_log))), T_map_log)
    assert _errors(path.T_map_log, log).max() < 0.04
