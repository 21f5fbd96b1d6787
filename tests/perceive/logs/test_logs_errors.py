"""Every bad input gets a one-line error naming the file/topic/frame and the fix, or a counted skip."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import LogError
from hiper_cli.perceive.logs import TUM_PRESETS, BagTopics, TumWriter, open_log, read_tum_trajectory
from hiper_cli.perceive.logs.bag_writer import BagWriter
from tests.logs_scene import CAMERA, make_frames

runner = CliRunner()


def tum(tmp_path, n=6, name="log"):
    root = tmp_path / name
    with TumWriter(root, CAMERA) as writer:
        for frame in make_frames(n=n, detections=False):
            writer.write(frame)
    return root


def cli_fails(args, match):
    result = runner.invoke(app, [str(a) for a in args])
    assert result.exit_code != 0, result.output
    assert match in result.output, result.output
    lines = [ln for ln in result.output.splitlines() if ln.strip()]
    assert len(lines) == 1, result.output  # one line
    return result


def first_line(path):
    return next(ln for ln in path.read_text().splitlines() if not ln.startswith("#"))


# --- images -------------------------------------------------------------------------------


def test_corrupt_image_is_skipped_counted_and_reported(tmp_path):
    root = tum(tmp_path)
    name = first_line(root / "rgb.txt").split()[1]
    stem = sorted((root / "rgb").iterdir())[2]
    stem.write_bytes(b"not a png")
    (root / "depth" / sorted((root / "depth").iterdir())[4].name).unlink()
    reader = open_log(root)
    frames = list(reader)
    assert [f.pose_id for f in frames] == [0, 1, 3, 5]
    reasons = [reason for _, reason in reader.skipped]
    assert len(reasons) == 2
    assert "cannot decode the image (corrupt or not PNG/JPEG)" in reasons[0]
    assert "depth file missing" in reasons[1]
    assert name.startswith("rgb/")
    result = runner.invoke(app, ["info", str(root), "--check", "--json"])
    assert result.exit_code == 0
    assert '"readable_frames": 4' in result.output
    result = runner.invoke(app, ["info", str(root), "--check"])
    assert "skipped" in result.output and "depth file missing" in result.output


def test_nothing_readable_is_an_error(tmp_path):
    root = tum(tmp_path, n=3)
    for png in (root / "rgb").iterdir():
        png.write_bytes(b"garbage")
    with pytest.raises(LogError, match=r"none of the 3 frames can be read; first problem: .*cannot decode"):
        list(open_log(root))


# --- poses --------------------------------------------------------------------------------


def test_nan_pose_names_file_and_line(tmp_path):
    root = tum(tmp_path)
    lines = (root / "groundtruth.txt").read_text().splitlines()
    parts = lines[3].split()
    parts[2] = "nan"
    lines[3] = " ".join(parts)
    (root / "groundtruth.txt").write_text("\n".join(lines) + "\n")
    with pytest.raises(LogError, match=r"groundtruth\.txt:4: pose contains NaN or infinite values"):
        open_log(root)
    cli_fails(["info", root], "groundtruth.txt:4: pose contains NaN")


def test_non_monotonic_pose_names_file_and_line(tmp_path):
    root = tum(tmp_path)
    lines = (root / "groundtruth.txt").read_text().splitlines()
    lines[3], lines[4] = lines[4], lines[3]
    (root / "groundtruth.txt").write_text("\n".join(lines) + "\n")
    with pytest.raises(LogError, match=r"groundtruth\.txt:5: stamp .* does not increase .*sort the poses"):
        open_log(root)
    cli_fails(["info", root], "does not increase after the previous line")


def test_bad_trajectory_lines(tmp_path):
    path = tmp_path / "traj.txt"
    path.write_text("1.0 0 0 0 0 0 0 2\n")
    with pytest.raises(LogError, match=r"traj\.txt:1: quaternion norm is 2\.0000; expected a unit"):
        read_tum_trajectory(path)
    path.write_text("1.0 0 0 0 0 0 1\n")
    with pytest.raises(LogError, match=r"traj\.txt:1: expected 8 values"):
        read_tum_trajectory(path)
    with pytest.raises(LogError, match=r"missing\.txt: trajectory file not found"):
        read_tum_trajectory(tmp_path / "missing.txt")


def test_missing_poses(tmp_path):
    root = tum(tmp_path)
    (root / "groundtruth.txt").unlink()
    with pytest.raises(LogError, match=r"no poses \(no groundtruth\.txt\); pass --poses traj\.txt"):
        open_log(root)
    cli_fails(["info", root, "--poses", tmp_path / "nope.txt"], "trajectory file not found")


def test_nan_pose_in_a_bag(tmp_path):
    frames = make_frames(n=3, detections=False)
    with BagWriter(tmp_path / "nan.bag", "rosbag1", CAMERA) as writer:
        for k, frame in enumerate(frames):
            if k == 1:
                T = frame.T_map_cam.copy()
                object.__setattr__(frame, "T_map_cam", T)
                T[0, 3] = np.nan  # after validation: a broken recording
            writer.write(frame)
    with pytest.raises(LogError, match=r"nan\.bag /tf: pose contains NaN or infinite values"):
        open_log(tmp_path / "nan.bag")


class CorruptSecondImage(BagWriter):
    def _put(self, topic, msgtype, msg, stamp_s):
        if msgtype == "sensor_msgs/msg/CompressedImage" and self.frames == 1:
            msg.data = np.frombuffer(b"broken png", dtype=np.uint8)
        super()._put(topic, msgtype, msg, stamp_s)


def test_corrupt_image_in_a_bag_is_skipped(tmp_path):
    from hiper_cli.perceive.logs.bag_writer import BagLayout

    path = tmp_path / "corrupt"
    with CorruptSecondImage(path, "mcap", CAMERA, BagLayout(rgb_format="png")) as writer:
        for frame in make_frames(n=4, detections=False):
            writer.write(frame)
    reader = open_log(path)
    assert [f.pose_id for f in reader] == [0, 2, 3]
    assert len(reader.skipped) == 1
    _, reason = reader.skipped[0]
    assert "/camera/color/image_raw/compressed #1" in reason
    assert "cannot decode the compressed image" in reason


# --- topics and encodings -----------------------------------------------------------------


def bag(tmp_path, name="log.bag", writer_class=BagWriter, n=3):
    path = tmp_path / name
    with writer_class(path, "rosbag1" if name.endswith(".bag") else "rosbag2", CAMERA) as writer:
        for frame in make_frames(n=n, detections=False):
            writer.write(frame)
    return path


def test_missing_topic(tmp_path):
    path = bag(tmp_path)
    with pytest.raises(LogError, match=r"topic '/nope' is not in the bag \(it has: .*/color/image_raw"):
        open_log(path, topics=BagTopics(rgb_topic="/nope"))
    cli_fails(["info", path, "--rgb-topic", "/nope"], "pass an existing --rgb-topic")
    cli_fails(["info", path, "--pose-topic", "/camera/color/camera_info"],
              "--pose-topic expects")


class Yuv(BagWriter):
    def _image(self, stamp_s, frame_id, image, encoding):
        return super()._image(stamp_s, frame_id, image, "yuv422" if encoding == "rgb8" else encoding)


def test_unknown_encoding(tmp_path):
    path = bag(tmp_path, writer_class=Yuv)
    message = r"topic '/camera/color/image_raw' has unknown rgb encoding 'yuv422'; expected one of rgb8"
    with pytest.raises(LogError, match=message):
        open_log(path)
    with pytest.raises(LogError, match=message):
        open_log(path, topics=BagTopics(rgb_topic="/camera/color/image_raw"))
    cli_fails(["info", path, "--rgb-topic", "/camera/color/image_raw"], "unknown rgb encoding 'yuv422'")


class NoInfo(BagWriter):
    def _put(self, topic, msgtype, msg, stamp_s):
        if msgtype != "sensor_msgs/msg/CameraInfo":
            super()._put(topic, msgtype, msg, stamp_s)


def test_missing_camera_intrinsics(tmp_path):
    path = bag(tmp_path, name="noinfo", writer_class=NoInfo)
    with pytest.raises(LogError, match=r"missing camera intrinsics \(no sensor_msgs/CameraInfo topic\)"):
        open_log(path)
    cli_fails(["info", path], "missing camera intrinsics")
    flags = ["--fx", "30", "--fy", "30", "--cx", "15.5", "--cy", "11.5", "--width", "32", "--height", "24"]
    result = runner.invoke(app, ["info", str(path), *flags, "--json"])
    assert result.exit_code == 0, result.output
    root = tum(tmp_path)
    (root / "camera.json").unlink()
    with pytest.raises(LogError, match=r"missing camera intrinsics \(no camera\.json"):
        open_log(root)
    cli_fails(["info", root], "pass --camera camera.json, --preset fr1|fr2|fr3")
    cli_fails(["info", root, "--fx", "30"], "camera flags: missing --fy --cx --cy --width --height")
    cli_fails(["info", root, "--preset", "fr9"], "--preset fr9: unknown preset")


# --- unreadable files ---------------------------------------------------------------------


def test_unreadable_files(tmp_path):
    broken = tmp_path / "broken.bag"
    broken.write_bytes(b"#ROSBAG V2.0\n" + bytes(range(256)) * 4)
    with pytest.raises(LogError, match=r"broken\.bag: cannot open the bag"):
        open_log(broken)
    cli_fails(["info", broken], "cannot open the bag")
    other = tmp_path / "notes.txt"
    other.write_text("hello")
    cli_fails(["info", other], "unknown log type '.txt'")
    cli_fails(["info", tmp_path / "absent"], "no such file or folder")
    root = tum(tmp_path)
    (root / "rgb.txt").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(LogError, match=r"rgb\.txt: cannot read"):
        open_log(root)
    (root / "rgb.txt").write_text("1.0 rgb/a.png\nabc rgb/b.png\n")
    cli_fails(["info", root], "rgb.txt:2: 'abc' is not a timestamp")
    (root / "camera.json").write_text("{broken")
    cli_fails(["info", root], "camera.json: not valid JSON")


def test_installed_entry_point_exits_non_zero(tmp_path):
    result = subprocess.run([sys.executable, "-m", "hiper_cli", "info", str(tmp_path / "absent")],
                            capture_output=True, text=True)
    assert result.returncode == 1
    assert "no such file or folder" in result.stderr


def test_bag_size_mismatches_are_caught_when_opening(tmp_path):
    path = bag(tmp_path)
    with pytest.raises(LogError, match=r"colour topic '/camera/color/image_raw' is 32×24 but the intrinsics "
                                       r"\(flags\) are for 640×480"):
        open_log(path, camera=TUM_PRESETS["fr1"])


class HalfDepth(BagWriter):
    def _image(self, stamp_s, frame_id, image, encoding):
        return super()._image(stamp_s, frame_id, image[::2, ::2] if encoding == "16UC1" else image, encoding)


def test_unregistered_depth(tmp_path):
    path = bag(tmp_path, writer_class=HalfDepth)
    cli_fails(["info", path], "depth topic '/camera/aligned_depth_to_color/image_raw' is 16×12 but colour")
