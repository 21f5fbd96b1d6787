"""Aligning a session to its place: global registration + ICP recovers a turned and shifted
frame; a cloud of another place is refused; ``--align FILE`` reads a matrix."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.align import BackgroundCloud, register
from hiper_cli.session_align import _read_matrix


def _box_surface(lo, hi, step, rng):
    """Points on the faces of an axis-aligned box."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    pts = []
    for axis in range(3):
        for side in (lo[axis], hi[axis]):
            others = [a for a in range(3) if a != axis]
            u = np.arange(lo[others[0]], hi[others[0]] + 1e-9, step)
            v = np.arange(lo[others[1]], hi[others[1]] + 1e-9, step)
            U, V = np.meshgrid(u, v)
            p = np.zeros((U.size, 3))
            p[:, others[0]], p[:, others[1]], p[:, axis] = U.ravel(), V.ravel(), side
            pts.append(p)
    out = np.concatenate(pts)
    return out + rng.normal(0, 0.005, out.shape)


def _room(seed=0):
    rng = np.random.default_rng(seed)
    parts = [_box_surface((0, 0, 0), (7.0, 5.0, 2.5), 0.04, rng),  # floor, walls, ceiling
             _box_surface((1.0, 1.0, 0), (2.6, 1.9, 0.75), 0.04, rng),  # a table
             _box_surface((5.2, 0.2, 0), (6.8, 0.6, 1.8), 0.04, rng),  # a shelf
             _box_surface((0.3, 3.9, 0), (2.3, 4.8, 0.8), 0.04, rng),  # a couch
             _box_surface((4.0, 3.0, 0), (4.5, 3.5, 1.2), 0.04, rng)]  # a cabinet
    return np.concatenate(parts)


def _rot_z(deg, t):
    a = np.radians(deg)
    T = np.eye(4)
    T[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
    T[:3, 3] = t
    return T


def _error(T_est, T_true):
    D = np.linalg.inv(T_true) @ T_est
    cos = np.clip((np.trace(D[:3, :3]) - 1) / 2, -1, 1)
    return float(np.linalg.norm(D[:3, 3])), float(np.degrees(np.arccos(cos)))


def test_a_turned_and_shifted_session_is_found_within_5_cm_and_1_degree():
    room = _room()
    T_log_map = _rot_z(33.0, (2.1, -1.4, 0.0))
    log_points = (room @ T_log_map[:3, :3].T + T_log_map[:3, 3])[::2]  # another sampling of the place
    found = register(log_points, room[1::2])
    metres, degrees = _error(found.T_map_log, np.linalg.inv(T_log_map))
    assert metres <= 0.05 and degrees <= 1.0, (metres, degrees)
    assert found.fitness > 0.8


def test_another_place_fits_poorly():
    rng = np.random.default_rng(3)
    elsewhere = _box_surface((0, 0, 0), (3.0, 11.0, 3.2), 0.04, rng)  # a corridor, nothing in it
    found = register(elsewhere[::3], _room()[::3], tries=1)
    assert found.fitness < 0.4


def test_background_cloud_keeps_one_centroid_per_voxel():
    cloud = BackgroundCloud(voxel_m=0.1)
    cloud.add_points(np.array([[0.01, 0.01, 0.01], [0.03, 0.05, 0.01], [0.51, 0.0, 0.0]]))
    cloud.add_points(np.array([[0.02, 0.03, 0.01]]))
    pts = cloud.points()
    assert len(cloud) == 2
    assert np.allclose(sorted(pts[:, 0]), [0.02, 0.51])


def test_align_file_reads_json_or_numbers_and_refuses_anything_else(tmp_path):
    T = _rot_z(20.0, (1.0, 2.0, 0.0))
    (tmp_path / "t.json").write_text(json.dumps(T.tolist()))
    (tmp_path / "t.txt").write_text(" ".join(str(v) for v in T.ravel()))
    (tmp_path / "bad.txt").write_text("1 2 3")
    assert np.allclose(_read_matrix(tmp_path / "t.json"), T)
    assert np.allclose(_read_matrix(tmp_path / "t.txt"), T)
    with pytest.raises(ConfigError, match="expected a 4x4 rigid transform"):
        _read_matrix(tmp_path / "bad.txt")
    with pytest.raises(ConfigError, match="cannot read it"):
        _read_matrix(tmp_path / "missing.json")
