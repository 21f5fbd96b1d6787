"""A pose row is written as compact JSON (rounded to 1e-6 rotation, 10 µm translation): about
half the bytes of full precision, read back as the same 4×4 matrix."""

import json

import numpy as np

from hiper_cli.graph import open_kb
from hiper_cli.graph.documents import pose_text


def _pose(yaw: float, pitch: float, t):
    """A camera turned by ``yaw`` about z and tilted by ``pitch`` about its x axis."""
    c, s = np.cos(yaw), np.sin(yaw)
    cp, sp = np.cos(pitch), np.sin(pitch)
    T = np.eye(4)
    T[:3, :3] = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, cp, -sp], [0.0, sp, cp]])
    T[:3, 3] = t
    return T


def test_pose_rows_are_short_and_read_back_as_written(tmp_path):
    T = _pose(0.7123456789, -1.83, (3.123456789, -1.987654321, 1.2))
    text = pose_text(T)
    assert len(text) < 0.55 * len(json.dumps(T.tolist()))
    with open_kb(tmp_path / "kb") as kb:
        session = kb.start_session(kb.environment("room"), "log", ["probe"])
        with kb.docs.transaction():
            kb.docs.record_frame(session.id, 0, 1.5, T)
        stamp, matrix = kb.docs.pose(session.id, 0)
        assert kb.docs.pose_before(2.0)[3] == matrix
    assert stamp == 1.5
    assert np.allclose(np.asarray(matrix), T, atol=1e-5) and matrix[3] == [0, 0, 0, 1]


def test_compaction_keeps_a_matrix_only_where_the_motion_bends(tmp_path):
    from hiper_cli.graph.compact import compact

    # 15 Hz: 4 s along a line turning slowly, then a sharp turn on the spot, then on again
    stamps = [k / 15.0 for k in range(90)]
    poses = [_pose(0.05 * t if t < 4.0 else 0.2 + (1.2 if t >= 4.2 else 6.0 * (t - 4.0)), -1.6,
                   (0.3 * t, 0.1 * t, 1.2)) for t in stamps]
    with open_kb(tmp_path / "kb") as kb:
        session = kb.start_session(kb.environment("room"), "log", ["probe"])
        for k, (t, T) in enumerate(zip(stamps, poses, strict=True)):
            with kb.docs.transaction():
                kb.docs.record_frame(session.id, k, t, T)
        report = compact(kb)
        assert report.pose_matrices_dropped > 60  # most rows lie on a line between others
        assert kb.check(repair=False).ok  # a row a frame stays
        assert compact(kb).pose_matrices_dropped == 0  # thinned once
        for k, (t, T) in enumerate(zip(stamps, poses, strict=True)):
            stamp, matrix = kb.docs.pose(session.id, k)
            M = np.asarray(matrix)
            turn = np.degrees(np.arccos(np.clip((np.trace(M[:3, :3].T @ T[:3, :3]) - 1) / 2, -1, 1)))
            assert stamp == t and np.linalg.norm(M[:3, 3] - T[:3, 3]) <= 0.0101 and turn <= 0.51, k
        assert np.allclose(kb.docs.pose_before(stamps[40] + 0.01)[3], kb.docs.pose(session.id, 40)[1])
        recorded = kb.session_poses(session.id)  # the whole session at once, interpolated alike
        assert np.allclose(recorded.stamps_s, stamps)
        assert np.abs(recorded.T_map_cam[:, :3, 3] - np.stack(poses)[:, :3, 3]).max() <= 0.0101


def test_the_rows_kept_are_those_a_row_by_row_check_keeps():
    """``_keep`` checks a stretch's rows all at once; a row-by-row check (``interpolate`` and the
    tolerances, one row at a time) keeps the same rows, on smooth, noisy and jerky paths."""
    from hiper_cli.graph import poserows
    from hiper_cli.perceive.logs.trajectory import rotation_about

    def close(T, U):
        turn = np.degrees(np.linalg.norm(poserows._log_so3(T[:3, :3].T @ U[:3, :3])))
        return np.linalg.norm(T[:3, 3] - U[:3, 3]) <= poserows.POSE_TOL_M and turn <= poserows.POSE_TOL_DEG

    def row_by_row(stamps, poses):
        def line_holds(i, end):
            share = [(stamps[k] - stamps[i]) / (stamps[end] - stamps[i]) for k in range(i + 1, end)]
            return all(close(poserows.interpolate(poses[i], poses[end], a), poses[k])
                       for k, a in zip(range(i + 1, end), share, strict=True))

        keep, i, n = [0], 0, len(stamps)
        while i < n - 1:
            j = i + 1
            while j + 1 < n and j + 1 - i <= poserows.SPAN_ROWS and line_holds(i, j + 1):
                j += 1
            keep.append(j)
            i = j
        return keep

    rng = np.random.default_rng(7)
    for noise in (0.0, 0.0005, 0.002, 0.01):
        n = 200
        stamps = np.cumsum(rng.uniform(0.02, 0.05, n)).tolist()
        turn, go = rng.normal(0, 0.5, 3), rng.normal(0, 0.5, 3)
        poses = []
        for s in stamps:
            T = np.eye(4)
            T[:3, :3] = rotation_about(turn * s * np.sin(s) + rng.normal(0, noise, 3))
            T[:3, 3] = go * s + np.array([0.3 * np.sin(s), 0.0, 0.0]) + rng.normal(0, noise, 3)
            poses.append(T)
        kept = poserows._keep(stamps, poses)
        assert kept == row_by_row(stamps, poses)
        assert 2 <= len(kept) <= n
