"""hiper reanchor on a knowledge base written by hiper perceive (background stage only)."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.graph import open_kb
from hiper_cli.perceive.logs import Trajectory, TumWriter, write_tum_trajectory
from tests._bg_scenes import CAMERA, box_room, look_at, make_frame

POSES = [
    look_at((2.0, 1.5, 1.2), (3.0, 5.0, 1.3)),
    look_at((4.5, 1.0, 1.2), (3.5, 5.0, 1.3)),
    look_at((3.0, 2.5, 1.2), (6.0, 2.0, 1.0)),
]


@pytest.fixture(scope="module")
def kb_path(tmp_path_factory):
    root = tmp_path_factory.mktemp("reanchor")
    with TumWriter(root / "log", CAMERA) as writer:
        for i, T in enumerate(POSES):
            writer.write(make_frame(box_room(), T, pose_id=i, stamp_s=0.5 * i, noise_m=0.001))
    kb = root / "kb.hiper"
    args = ["perceive", str(root / "log"), "--kb", str(kb), "--stages", "background"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    return kb


def _walls_x(kb):
    with open_kb(kb) as knowledge:  # read_only=True fails on close (kb branch: flush)
        return sorted(
            -i.data["plane_map"][3] / i.data["plane_map"][0]
            for i in knowledge.instances(layer="background", class_name="wall")
            if abs(i.data["plane_map"][0]) > 0.9
        )


def test_reanchor_with_a_shifted_trajectory_moves_the_walls(kb_path, tmp_path):
    assert _walls_x(kb_path) == pytest.approx([6.0], abs=0.03)
    shifted = np.stack([T.copy() for T in POSES])
    shifted[:, 0, 3] += 0.5
    traj = tmp_path / "optimised.txt"
    write_tum_trajectory(traj, Trajectory.from_matrices(np.array([0.0, 0.5, 1.0]), shifted))
    runner = CliRunner()
    dry = runner.invoke(app, ["reanchor", "--kb", str(kb_path), "--poses", str(traj), "--dry-run", "--json"])
    assert dry.exit_code == 0, dry.output
    assert json.loads(dry.output)["shift_mean_m"] == pytest.approx(0.5, abs=0.05)
    assert _walls_x(kb_path) == pytest.approx([6.0], abs=0.03)  # nothing written
    result = runner.invoke(app, ["reanchor", "--kb", str(kb_path), "--poses", str(traj), "--json"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.output)
    assert summary["instances"] >= 3 and summary["merged"] == 0 and summary["written"]
    assert _walls_x(kb_path) == pytest.approx([6.5], abs=0.03)


def test_reanchor_with_a_short_trajectory_fails_cleanly(kb_path, tmp_path):
    traj = tmp_path / "short.txt"
    write_tum_trajectory(traj, Trajectory.from_matrices(np.array([0.0]), np.stack([POSES[0]])))
    result = CliRunner().invoke(app, ["reanchor", "--kb", str(kb_path), "--poses", str(traj)])
    assert result.exit_code == 1
    assert "no pose for" in result.output
