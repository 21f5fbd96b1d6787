"""TUM folders: written by TumWriter, read back by open_log; association, presets, poses."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs import LogReader, TumWriter, open_log
from hiper_cli.perceive.logs.trajectory import Trajectory, write_tum_trajectory
from tests.logs_scene import CAMERA, make_frames


def write_tum(root, frames, camera=CAMERA):
    with TumWriter(root, camera) as writer:
        for frame in frames:
            writer.write(frame)
    return root


def test_tum_round_trip(tmp_path):
    frames = make_frames()
    root = write_tum(tmp_path / "log", frames)
    reader = open_log(root)
    assert isinstance(reader, LogReader)
    assert len(reader) == len(frames)
    got = list(reader)
    assert reader.skipped == []
    for want, frame in zip(frames, got, strict=True):
        assert frame.stamp_s == pytest.approx(want.stamp_s, abs=1e-6)
        np.testing.assert_array_equal(frame.rgb, want.rgb)
        np.testing.assert_allclose(frame.depth_m, want.depth_m, atol=0.5 / CAMERA.depth_scale)
        np.testing.assert_allclose(frame.T_map_cam, want.T_map_cam, atol=1e-6)
        assert frame.detections is not None
        assert frame.detections.to_records() == want.detections.to_records()
        assert frame.camera == CAMERA
    assert [f.pose_id for f in got] == list(range(len(frames)))
    info = reader.info()
    assert info.frames == len(frames)
    assert info.rate_hz == pytest.approx(10.0, rel=1e-3)
    assert info.duration_s == pytest.approx(0.5, abs=1e-5)
    assert info.resolution == (32, 24)
    assert info.has_detections
    assert info.stamp_gaps == ()


def test_association_by_nearest_stamp_and_interpolated_poses(tmp_path):
    frames = make_frames(n=5, detections=False)
    root = write_tum(tmp_path / "log", frames)
    # shift depth stamps by 5 ms and thin the trajectory to every other pose
    lines = (root / "depth.txt").read_text().splitlines()
    shifted = [ln if ln.startswith("#") else f"{float(ln.split()[0]) + 0.005:.6f} {ln.split()[1]}"
               for ln in lines]
    (root / "depth.txt").write_text("\n".join(shifted) + "\n")
    gt = [ln for ln in (root / "groundtruth.txt").read_text().splitlines() if not ln.startswith("#")]
    (root / "groundtruth.txt").write_text("\n".join(gt[::2]) + "\n")
    reader = open_log(root)
    got = list(reader)
    assert len(got) == 5
    # frame 1 sits halfway between poses 0 and 2: linear position, slerped yaw
    np.testing.assert_allclose(got[1].T_map_cam[:3, 3], frames[1].T_map_cam[:3, 3], atol=1e-6)
    np.testing.assert_allclose(got[1].T_map_cam[:3, :3], frames[1].T_map_cam[:3, :3], atol=1e-6)
    with pytest.raises(LogError, match=r"no colour image has a depth image within 0\.001 s"):
        open_log(root, max_dt_s=0.001)


def test_frames_outside_the_trajectory_are_skipped_and_counted(tmp_path):
    frames = make_frames(n=6, detections=False)
    root = write_tum(tmp_path / "log", frames)
    gt = [ln for ln in (root / "groundtruth.txt").read_text().splitlines() if not ln.startswith("#")]
    (root / "groundtruth.txt").write_text("\n".join(gt[2:]) + "\n")
    reader = open_log(root)
    assert len(reader) == 4
    info = reader.info()
    assert len(info.skipped) == 2 and "outside the poses' time span" in info.skipped[0][1]
    got = list(reader)
    assert got[0].stamp_s == pytest.approx(frames[2].stamp_s)
    assert len(reader.skipped) == 2


def test_associations_file_and_preset_camera(tmp_path):
    frames = make_frames(n=3, detections=False)
    root = write_tum(tmp_path / "rgbd_dataset_freiburg3_tiny", frames)
    (root / "camera.json").unlink()
    with pytest.raises(LogError, match=r"is 32×24 but the camera intrinsics \(preset fr3\) are for 640×480"):
        open_log(root)
    (root / "camera.json").write_text(json.dumps(CAMERA.to_dict()))
    rgb = [ln.split() for ln in (root / "rgb.txt").read_text().splitlines() if not ln.startswith("#")]
    (root / "rgb.txt").unlink()
    (root / "depth.txt").unlink()
    lines = [f"{s} {p} {s} {p.replace('rgb', 'depth')}\n" for s, p in rgb]
    (root / "associations.txt").write_text("".join(lines))
    reader = open_log(root)
    assert len(list(reader)) == 3
    assert "associations.txt" in reader.info().sources["rgb"]


def test_preset_chosen_from_folder_name(tmp_path):
    from hiper_cli.perceive.logs import TUM_PRESETS

    fr1 = TUM_PRESETS["fr1"]
    frames = make_frames(n=2, detections=False, camera=fr1)
    root = write_tum(tmp_path / "rgbd_dataset_freiburg1_xyz", frames, camera=fr1)
    (root / "camera.json").unlink()
    info = open_log(root).info()
    assert info.camera == TUM_PRESETS["fr1"]
    assert info.sources["camera"] == "preset fr1"


def test_poses_file_replaces_groundtruth(tmp_path):
    frames = make_frames(n=4, detections=False)
    root = write_tum(tmp_path / "log", frames)
    stamps = np.array([f.stamp_s for f in frames])
    T = np.stack([f.T_map_cam for f in frames])
    T[:, 2, 3] += 1.0
    write_tum_trajectory(tmp_path / "slam.txt", Trajectory.from_matrices(stamps, T))
    reader = open_log(root, poses=tmp_path / "slam.txt")
    got = list(reader)
    np.testing.assert_allclose(got[3].T_map_cam, T[3], atol=1e-6)
    assert "slam.txt" in reader.info().pose_source


def test_stamp_gap_is_reported(tmp_path):
    frames = make_frames(n=8, detections=False)
    root = write_tum(tmp_path / "log", frames[:4] + frames[6:])
    gaps = open_log(root).info().stamp_gaps
    assert len(gaps) == 1
    assert gaps[0].gap_s == pytest.approx(0.3, abs=1e-5)


def test_writer_refuses_non_increasing_stamps(tmp_path):
    frames = make_frames(n=2, detections=False)
    with TumWriter(tmp_path / "log", CAMERA) as writer:
        writer.write(frames[1])
        with pytest.raises(LogError, match="does not increase"):
            writer.write(frames[0])
    with pytest.raises(LogError, match="folder exists and is not empty"):
        TumWriter(tmp_path / "log", CAMERA)


def test_depth_scale_flag_applies_to_a_tum_folder(tmp_path):
    from typer.testing import CliRunner

    from hiper_cli.cli import app

    root = write_tum(tmp_path / "log", make_frames(n=2, detections=False))
    result = CliRunner().invoke(app, ["info", str(root), "--depth-scale", "1000", "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.output)["camera"]["depth_scale"] == 1000.0
