"""TUM trajectories and the tf buffer: rotations, slerp, interpolation, chains, validation."""

from __future__ import annotations

import numpy as np
import pytest

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs import open_log, read_tum_trajectory, write_tum_trajectory
from hiper_cli.perceive.logs.bag_writer import BagLayout, BagWriter
from hiper_cli.perceive.logs.tf import TfTree
from hiper_cli.perceive.logs.trajectory import Trajectory, matrix_to_quat_xyzw, quat_xyzw_to_matrix
from tests.logs_scene import CAMERA, make_frames


def random_quats(n, seed=0):
    q = np.random.default_rng(seed).normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def rot_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def test_quaternion_matrix_round_trip():
    for q in random_quats(200):
        R = quat_xyzw_to_matrix(q)
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)
        back = matrix_to_quat_xyzw(R)
        assert back[3] >= 0
        np.testing.assert_allclose(back, q if q[3] >= 0 else -q, atol=1e-9)


def test_slerp_is_constant_speed_and_takes_the_short_way():
    stamps = np.array([0.0, 1.0])
    T = np.tile(np.eye(4), (2, 1, 1))
    T[1, :3, :3] = rot_z(np.deg2rad(170.0))
    T[1, :3, 3] = [2.0, 0.0, 0.0]
    traj = Trajectory.from_matrices(stamps, T)
    traj = Trajectory(traj.stamps_s, traj.positions_m, traj.quats_xyzw * np.array([[1], [-1]]))  # flip sign
    out, valid = traj.interpolate(np.array([0.25, 0.5]))
    assert valid.all()
    np.testing.assert_allclose(out[0, :3, :3], rot_z(np.deg2rad(42.5)), atol=1e-9)
    np.testing.assert_allclose(out[1, :3, 3], [1.0, 0.0, 0.0])


def test_interpolation_coverage_and_extrapolation():
    traj = Trajectory(np.array([1.0, 2.0]), np.zeros((2, 3)), np.array([[0, 0, 0, 1.0]] * 2))
    _, valid = traj.interpolate(np.array([0.5, 0.99, 1.5, 2.01, 3.0]), max_extrapolation_s=0.02)
    assert valid.tolist() == [False, True, True, True, False]


def test_trajectory_file_round_trip(tmp_path):
    frames = make_frames(n=5, detections=False)
    stamps = np.array([f.stamp_s for f in frames])
    traj = Trajectory.from_matrices(stamps, np.stack([f.T_map_cam for f in frames]))
    write_tum_trajectory(tmp_path / "t.txt", traj)
    back = read_tum_trajectory(tmp_path / "t.txt")
    np.testing.assert_allclose(back.matrices(), traj.matrices(), atol=1e-8)
    np.testing.assert_allclose(back.stamps_s, traj.stamps_s, atol=1e-6)


def test_trajectory_validation_in_memory():
    quats = np.array([[0, 0, 0, 1.0]] * 2)
    with pytest.raises(LogError, match=r"odom: pose 1 stamp 1\.0 does not increase after 1\.0"):
        Trajectory(np.array([1.0, 1.0]), np.zeros((2, 3)), quats, source="odom")
    with pytest.raises(LogError, match=r"pose 0 \(stamp 1\.0\) contains NaN"):
        Trajectory(np.array([1.0, 2.0]), np.array([[np.nan, 0, 0], [0, 0, 0]]), quats)


def test_tf_chain_in_both_directions():
    tf = TfTree()
    T_map_odom = np.eye(4)
    T_map_odom[:3, 3] = [1.0, 2.0, 0.0]
    tf.add("/map", "odom", 0.0, T_map_odom, static=True)
    for stamp, yaw in ((0.0, 0.0), (1.0, 0.5)):
        T = np.eye(4)
        T[:3, :3] = rot_z(yaw)
        T[0, 3] = stamp
        tf.add("odom", "base_link", stamp, T, static=False)
    T_cam_base = np.eye(4)
    T_cam_base[:3, 3] = [0.0, 0.0, -0.3]
    tf.add("camera", "base_link", 0.0, T_cam_base, static=True)  # edge stored child -> parent
    T, valid = tf.lookup("map", "camera", np.array([0.5, 2.0]), 0.02, "test")
    assert valid.tolist() == [True, False]
    want = T_map_odom.copy()
    want_odom_base = np.eye(4)
    want_odom_base[:3, :3] = rot_z(0.25)
    want_odom_base[0, 3] = 0.5
    np.testing.assert_allclose(T[0], want @ want_odom_base @ np.linalg.inv(T_cam_base), atol=1e-9)
    back, _ = tf.lookup("camera", "map", np.array([0.5]), 0.02, "test")
    np.testing.assert_allclose(back[0], np.linalg.inv(T[0]), atol=1e-9)
    with pytest.raises(LogError, match=r"test: no tf chain from 'map' to 'lidar' \(frames seen: base_link"):
        tf.lookup("map", "lidar", np.array([0.5]), 0.02, "test")


class ReceivedInWriteOrder(BagWriter):
    """Bag time = the order of writing, header stamps = the frames' stamps."""

    def _put(self, topic, msgtype, msg, stamp_s):
        super()._put(topic, msgtype, msg, 1000.0 + self.frames)


def test_bag_pose_going_back_in_time(tmp_path):
    frames = make_frames(n=4, detections=False)
    layout = BagLayout(pose_as="odometry", pose_topic="/odom")
    with ReceivedInWriteOrder(tmp_path / "b.bag", "rosbag1", CAMERA, layout) as writer:
        for k in (0, 2, 1, 3):
            writer.write(frames[k])
    with pytest.raises(LogError, match=r"b\.bag /odom: pose message #2 stamp .* goes back in time"):
        open_log(tmp_path / "b.bag")
