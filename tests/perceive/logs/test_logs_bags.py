"""One scene as TUM folder, rosbag1, rosbag2 (sqlite3) and MCAP: the readers yield the same frames."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.perceive.logs import TumWriter, open_log
from hiper_cli.perceive.logs.bag_writer import BagLayout, BagWriter
from tests.logs_scene import CAMERA, make_frames

FORMATS = ("tum", "rosbag1", "rosbag2", "mcap")
NAMES = {"tum": "log_tum", "rosbag1": "log.bag", "rosbag2": "log_db3", "mcap": "log_mcap"}


def write_log(root, kind, frames, layout=None):
    path = root / NAMES[kind]
    if kind == "tum":
        with TumWriter(path, CAMERA) as writer:
            for frame in frames:
                writer.write(frame)
    else:
        with BagWriter(path, kind, CAMERA, layout or BagLayout()) as writer:
            for frame in frames:
                writer.write(frame)
    return path


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    root = tmp_path_factory.mktemp("scene")
    frames = make_frames(n=6)
    return frames, {kind: write_log(root, kind, frames) for kind in FORMATS}


def assert_same_frames(want, got, depth_atol):
    assert len(got) == len(want)
    for w, f in zip(want, got, strict=True):
        assert f.stamp_s == pytest.approx(w.stamp_s, abs=1e-6)
        assert f.pose_id == w.pose_id
        np.testing.assert_array_equal(f.rgb, w.rgb)
        np.testing.assert_allclose(f.depth_m, w.depth_m, atol=depth_atol)
        np.testing.assert_allclose(f.T_map_cam, w.T_map_cam, atol=1e-6)
        assert f.detections is not None and w.detections is not None
        got_records = f.detections.to_records()
        assert [r["class"] for r in got_records] == list(w.detections.class_names)
        if len(w.detections):
            np.testing.assert_allclose(f.detections.xyxy, w.detections.xyxy, atol=1e-9)
            np.testing.assert_allclose(f.detections.scores, w.detections.scores, atol=1e-9)


@pytest.mark.parametrize("kind", FORMATS)
def test_every_format_yields_the_scene(scene, kind):
    frames, paths = scene
    reader = open_log(paths[kind])
    got = list(reader)
    assert reader.skipped == []
    # 16-bit depth: 1/5000 m quantisation for TUM, 1 mm for 16UC1 bags; the scene's depths are whole mm
    assert_same_frames(frames, got, depth_atol=1e-6)
    info = reader.info()
    assert info.frames == 6 and info.has_detections
    assert info.format.startswith({"tum": "tum", "rosbag1": "rosbag1", "rosbag2": "rosbag2-sqlite3",
                                   "mcap": "rosbag2-mcap"}[kind])
    intrinsics = info.camera.to_dict()
    intrinsics.pop("depth_scale")
    want = CAMERA.to_dict()
    want.pop("depth_scale")
    assert intrinsics == want


def test_bare_mcap_file(scene):
    frames, paths = scene
    mcap_file = next(paths["mcap"].glob("*.mcap"))
    reader = open_log(mcap_file)
    assert reader.info().format == "mcap"
    assert_same_frames(frames, list(reader), depth_atol=1e-6)


def test_info_json_is_identical_across_formats(scene):
    _, paths = scene
    runner = CliRunner()
    reports = {}
    for kind in FORMATS:
        result = runner.invoke(app, ["info", str(paths[kind]), "--json", "--frames"])
        assert result.exit_code == 0, result.output
        reports[kind] = json.loads(result.output)
    keys = ("frames", "first_stamp_s", "last_stamp_s", "duration_s", "rate_hz", "resolution",
            "has_detections", "stamp_gaps", "frame_list")
    for kind in FORMATS[1:]:
        for key in keys:
            assert reports[kind][key] == reports["tum"][key], (kind, key)
    assert len(reports["tum"]["frame_list"]) == 6


@pytest.mark.parametrize(
    "layout",
    [
        BagLayout(pose_as="odometry", pose_topic="/odom"),
        BagLayout(pose_as="pose", pose_topic="/slam/pose"),
        BagLayout(base_frame="base_link"),
        BagLayout(rgb_format="png", depth_encoding="32FC1"),
    ],
    ids=["odometry", "posestamped", "tf-chain", "png-32FC1"],
)
def test_bag_variants(tmp_path, layout):
    frames = make_frames(n=4)
    path = write_log(tmp_path, "rosbag2", frames, layout)
    reader = open_log(path)
    assert_same_frames(frames, list(reader), depth_atol=1e-6)
    if layout.pose_as != "tf":
        assert layout.pose_topic in reader.info().pose_source


def test_jpeg_colour_is_close(tmp_path):
    frames = make_frames(n=2, detections=False)
    for frame in frames:  # smooth images so that jpeg stays close
        frame.rgb[:] = 100
    path = write_log(tmp_path, "rosbag1", frames, BagLayout(rgb_format="jpeg"))
    got = list(open_log(path))
    assert np.abs(got[0].rgb.astype(int) - 100).max() <= 3
    assert "compressed" in open_log(path).info().sources["rgb"]


def test_poses_flag_replaces_bag_poses(tmp_path):
    from hiper_cli.perceive.logs import Trajectory, write_tum_trajectory

    frames = make_frames(n=4, detections=False)
    path = write_log(tmp_path, "mcap", frames)
    stamps = np.array([f.stamp_s for f in frames])
    T = np.stack([f.T_map_cam for f in frames])
    T[:, 0, 3] -= 3.0
    write_tum_trajectory(tmp_path / "slam.txt", Trajectory.from_matrices(stamps, T))
    got = list(open_log(path, poses=tmp_path / "slam.txt"))
    np.testing.assert_allclose(got[2].T_map_cam, T[2], atol=1e-6)


@pytest.mark.parametrize("kind", FORMATS)
def test_read_frame_random_access(scene, kind):
    frames, paths = scene
    reader = open_log(paths[kind])
    for k in (4, 0):
        frame = reader.read_frame(k)
        np.testing.assert_array_equal(frame.rgb, frames[k].rgb)
        np.testing.assert_allclose(frame.depth_m, frames[k].depth_m, atol=1e-6)
        assert frame.pose_id == k


@pytest.mark.parametrize("to", ["rosbag1", "rosbag2", "mcap", "tum"])
def test_convert_round_trip(scene, tmp_path, to):
    frames, paths = scene
    source = paths["rosbag1"] if to == "tum" else paths["tum"]
    out = tmp_path / ("out.bag" if to == "rosbag1" else "out")
    result = CliRunner().invoke(app, ["convert", str(source), str(out), "--to", to, "--json"])
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    assert report["frames_written"] == 6 and report["skipped"] == []
    assert_same_frames(frames, list(open_log(out)), depth_atol=1e-6)


def test_convert_rejects_bad_choices(scene, tmp_path):
    _, paths = scene
    result = CliRunner().invoke(app, ["convert", str(paths["tum"]), str(tmp_path / "o"), "--to", "rosbag3"])
    assert result.exit_code != 0
    assert "--to rosbag3: unknown; expected one of tum, rosbag1, rosbag2, mcap" in result.output
    result = CliRunner().invoke(app, ["convert", str(paths["tum"]), str(paths["mcap"]), "--to", "mcap"])
    assert result.exit_code != 0
    assert "exists already; choose a new output path" in result.output


def test_detections_of_both_vision_msgs_layouts():
    from types import SimpleNamespace as NS

    from hiper_cli.perceive.logs.rosbag import _detections_from_msg

    ros2 = NS(detections=[NS(results=[NS(hypothesis=NS(class_id="person", score=0.4)),
                                      NS(hypothesis=NS(class_id="chair", score=0.9))],
                             bbox=NS(center=NS(position=NS(x=10.0, y=20.0), theta=0.0), size_x=4.0,
                                     size_y=6.0))])
    ros1 = NS(detections=[NS(results=[NS(id=62, score=0.7)],
                             bbox=NS(center=NS(x=10.0, y=20.0, theta=0.0), size_x=4.0, size_y=6.0))])
    for msg, name, score in ((ros2, "chair", 0.9), (ros1, "62", 0.7)):
        dets = _detections_from_msg(msg)
        assert dets.class_names == (name,)
        np.testing.assert_allclose(dets.xyxy, [[8.0, 17.0, 12.0, 23.0]])
        assert dets.scores[0] == pytest.approx(score)
