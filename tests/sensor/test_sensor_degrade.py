"""Sensor profiles on tiny scenes built in code: shadows, noise, misregistration, drift, the CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import ConfigError
from hiper_cli.perceive.logs import open_log
from hiper_cli.sensor import PROFILES, get_profile
from hiper_cli.sensor.colour import degrade_rgb
from hiper_cli.sensor.degrade import DegradedLog
from hiper_cli.sensor.depth import degrade_depth, error_std_m, projector_shadow
from hiper_cli.sensor.poses import drifting_poses, rotation_about
from hiper_cli.types import CameraIntrinsics
from tests import REPO_ROOT

CAMERA = CameraIntrinsics(160, 120, 120.0, 120.0, 79.5, 59.5)
FIXTURE = REPO_ROOT / "fixtures" / "house_small"


def _wall_and_box(z_far: float = 3.0, z_near: float = 1.0) -> np.ndarray:
    depth = np.full((CAMERA.height, CAMERA.width), z_far, dtype=np.float32)
    depth[40:80, 60:100] = z_near
    return depth


def test_shadow_lies_left_of_a_near_box_and_is_as_wide_as_the_baseline_predicts():
    depth = _wall_and_box()
    shadow = projector_shadow(depth, CAMERA.fx, 0.075)
    expected_px = CAMERA.fx * 0.075 * (1 / 1.0 - 1 / 3.0)  # 6 px
    widths = shadow[40:80].sum(axis=1)
    assert np.all(np.abs(widths - expected_px) <= 1 + 1e-9)
    assert shadow[40:80, 60 - int(expected_px) + 1:60].all()  # left of the box, on the wall
    assert not shadow[:, 60:].any() and not shadow[:39].any()


def test_ideal_profile_changes_nothing():
    rng = np.random.default_rng(0)
    depth = _wall_and_box()
    rgb = rng.integers(0, 255, (CAMERA.height, CAMERA.width, 3), dtype=np.uint8)
    ideal = get_profile("ideal")
    assert np.array_equal(degrade_depth(depth, rgb[..., 0], CAMERA, ideal, rng), depth)
    assert np.array_equal(degrade_rgb(rgb, np.array([300.0, 0.0]), ideal), rgb)


def test_depth_error_on_a_flat_wall_follows_the_documented_model():
    profile = get_profile("structured-light")
    for z in (1.0, 2.5, 4.0):
        depth = np.full((400, 400), z, dtype=np.float32)
        camera = CameraIntrinsics(400, 400, 300.0, 300.0, 199.5, 199.5)
        out = degrade_depth(depth, None, camera, profile, np.random.default_rng(1))
        error = out[out > 0] - z
        assert np.std(error) == pytest.approx(float(error_std_m(profile, np.array(z))), rel=0.05)


def test_misregistration_shifts_colour_against_depth_by_the_profile_offset():
    import cv2

    rng = np.random.default_rng(2)
    rgb = cv2.GaussianBlur(rng.integers(0, 255, (240, 320, 3), dtype=np.uint8), (5, 5), 1.5)
    profile = get_profile("structured-light")
    out = degrade_rgb(rgb, np.zeros(2), profile, jpeg=False)
    (dx, dy), _ = cv2.phaseCorrelate(rgb[..., 1].astype(np.float64), out[..., 1].astype(np.float64))
    assert (dx, dy) == pytest.approx(profile.misregistration_px, abs=0.2)


def test_camera_motion_blurs_and_skews_the_colour_image():
    rng = np.random.default_rng(3)
    rgb = rng.integers(0, 255, (120, 160, 3), dtype=np.uint8)
    profile = get_profile("structured-light")
    still = degrade_rgb(rgb, np.zeros(2), profile, jpeg=False)
    moving = degrade_rgb(rgb, np.array([600.0, 0.0]), profile, jpeg=False)  # 9 px over the exposure
    assert np.std(moving.astype(float)) < 0.7 * np.std(still.astype(float))


def _straight_path(n: int = 200, step_m: float = 0.05) -> np.ndarray:
    poses = np.repeat(np.eye(4)[None], n, axis=0)
    poses[:, 0, 3] = np.arange(n) * step_m
    return poses


def test_pose_source_drifts_with_distance_and_zero_drift_keeps_the_truth():
    truth = _straight_path()
    profile = get_profile("structured-light")
    estimate = drifting_poses(truth, profile, np.random.default_rng(4))
    error = np.linalg.norm(estimate[:, :3, 3] - truth[:, :3, 3], axis=1)
    assert error[0] == 0.0
    assert 0.003 < error[-1] < 0.25  # 10 m travelled at 0.5 % drift, bent by rotation drift
    assert error[-20:].mean() > error[10:30].mean()
    exact = drifting_poses(truth, profile.with_pose_drift(0.0), np.random.default_rng(4))
    assert np.array_equal(exact, truth)


def test_rotation_about_is_a_rotation():
    R = rotation_about(np.array([0.1, -0.2, 0.3]))
    assert np.allclose(R @ R.T, np.eye(3)) and np.linalg.det(R) == pytest.approx(1.0)


def test_unknown_profile_and_negative_drift_are_config_errors():
    with pytest.raises(ConfigError, match="expected one of ideal, structured-light, tof, stereo"):
        get_profile("lidar")
    with pytest.raises(ConfigError, match="--pose-drift -1"):
        PROFILES["tof"].with_pose_drift(-1)


@pytest.mark.parametrize("name", ["structured-light", "tof", "stereo"])
def test_each_profile_is_deterministic_for_a_seed(name):
    reader = open_log(FIXTURE)
    first = DegradedLog(reader, get_profile(name), seed=5).read_frame(10)
    again = DegradedLog(reader, get_profile(name), seed=5).read_frame(10)
    other = DegradedLog(reader, get_profile(name), seed=6).read_frame(10)
    assert np.array_equal(first.depth_m, again.depth_m) and np.array_equal(first.rgb, again.rgb)
    assert np.array_equal(first.T_map_cam, again.T_map_cam)
    assert not np.array_equal(first.depth_m, other.depth_m)


def test_convert_degrade_writes_a_tum_folder_with_the_truth_beside_it(tmp_path):
    out = tmp_path / "degraded"
    result = CliRunner().invoke(app, ["convert", str(FIXTURE), str(out), "--degrade", "structured-light",
                                      "--seed", "3", "--json"])
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    assert report["profile"] == "structured-light" and report["frames_written"] == 60
    assert report["gt_copied"] is True and report["pose_error"]["final_m"] > 0
    assert (out / "gt" / "instances.json").is_file() and (out / "gt" / "sensor.json").is_file()
    assert len(list((out / "rgb").glob("*.jpg"))) == 60
    degraded, clean = open_log(out).info(), open_log(FIXTURE).info()
    assert degraded.frames == clean.frames
    assert not np.allclose(degraded.T_map_cam[-1], clean.T_map_cam[-1], atol=1e-4)
    true_lines = [line.split() for line in (out / "gt" / "groundtruth.txt").read_text().splitlines()
                  if not line.startswith("#")]
    assert np.allclose([float(v) for v in true_lines[-1][1:4]], clean.T_map_cam[-1, :3, 3], atol=1e-6)
    assert len(true_lines) == 60


@pytest.mark.parametrize(("args", "message"), [
    (["--degrade", "lidar"], "sensor profile 'lidar': unknown"),
    (["--degrade", "tof", "--to", "rosbag1"], "--degrade writes a TUM folder"),
    (["--degrade", "tof", "--pose-drift", "-0.1"], "--pose-drift -0.1"),
    ([], "--to is missing"),
])
def test_convert_degrade_bad_flags_give_one_line_errors(tmp_path, args, message):
    result = CliRunner().invoke(app, ["convert", str(FIXTURE), str(tmp_path / "x"), *args])
    assert result.exit_code != 0
    assert message in result.output
    assert "Traceback" not in result.output


@pytest.mark.parametrize("name", ["structured-light", "tof", "stereo"])
def test_no_return_outside_the_profiles_range(name):
    profile = get_profile(name)
    for z in (profile.min_range_m * 0.8, profile.max_range_m * 1.1):
        depth = np.full((CAMERA.height, CAMERA.width), z, dtype=np.float32)
        out = degrade_depth(depth, None, CAMERA, profile, np.random.default_rng(0))
        assert (out == 0).mean() > 0.97


def test_degrade_worlds_script_makes_a_copy_of_every_world(tmp_path):
    import os
    import subprocess
    import sys

    worlds = tmp_path / "worlds"
    worlds.mkdir()
    (worlds / "house_small").symlink_to(FIXTURE)
    (worlds / "not_a_log").mkdir()
    script = REPO_ROOT / "scripts" / "degrade_worlds.sh"
    env = {**os.environ, "HIPER_WORLDS": str(worlds), "PYTHON": sys.executable}
    done = subprocess.run([str(script), str(tmp_path / "out"), "tof", "2"], env=env, capture_output=True,
                          text=True, check=False)
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "out" / "house_small-tof.json").read_text())
    assert report["profile"] == "tof" and report["seed"] == 2 and report["frames_written"] == 60
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["house_small-tof", "house_small-tof.json"]


def test_a_bag_can_be_degraded_too(tmp_path):
    runner = CliRunner()
    bag = tmp_path / "fx.bag"
    assert runner.invoke(app, ["convert", str(FIXTURE), str(bag), "--to", "rosbag1"]).exit_code == 0
    result = runner.invoke(app, ["convert", str(bag), str(tmp_path / "deg"), "--degrade", "stereo", "--json"])
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    assert report["frames_written"] == 60 and report["gt_copied"] is False
    assert (tmp_path / "deg" / "gt" / "groundtruth.txt").is_file()
